/* SPDX-License-Identifier: ISC */
/* Exact weights of a table sensor under the cell reading from the
 * picture's solid-angle map.  Under the cell reading the sensitivity is
 * constant in each cell (between two circles of constant polar angle and
 * two rays of constant azimuth), so a pixel whose footprint lies inside one
 * cell weighs that cell's value times the pixel's solid angle: exactly the
 * same integral as ps_weights_build's, without its edge integrals.  Only
 * the pixels that a cell's circle or ray, the table's end or the field's
 * edge meets or touches (found per row from where those curves cross the
 * row's band) take the exact edge route.
 *
 * The solid angles are the exact map of the uniform sensor (builtin:uniform,
 * rotation 0, the same view and size): the map the weight cache keeps and
 * mirrors (a quarter of it stored, an eighth computed on a square picture),
 * shared by every sensor and rotation of that view and size.  The result is
 * a full map laid out as ps_weights_build's; every weight agrees with it to
 * rounding (tests/unit/test_cellmap.c).  The work is shared by every core.
 *
 * The linear reading is bilinear in theta and phi inside each patch of the
 * table (between two rows and two columns): a pixel inside one patch weighs
 * the sensitivity at its centre times its solid angle plus the slopes
 * there times the pixel's moments of (theta - theta_c), (phi - phi_c) and
 * their product over its solid angle.  On the angular projection the
 * moments come from a Gauss-Legendre rule per pixel sized from an error
 * bound (computed for a quadrant and mirrored on a view not shifted); the
 * pixels the patches' circles and rays, the zenith's neighbourhood, the
 * table's end or the field's edge touch take the exact edge route, and on
 * the hemispherical projection every pixel does. */
#ifndef PS_CELLMAP_H
#define PS_CELLMAP_H

#include "err.h"
#include "sensor.h"
#include "view.h"
#include "weights.h"

/* Non-zero when this route gives s's exact map (method exact, a table
 * whose values change with azimuth: a table the same at every azimuth has
 * the mirrored route of ps_weights_build_ex, cheaper still):
 * PS_CELLMAP_CELL under the cell reading, PS_CELLMAP_LINEAR under the
 * linear one. */
enum { PS_CELLMAP_CELL = 1, PS_CELLMAP_LINEAR = 2 };
int ps_cellmap_fits(const struct ps_sensor *s, int method);

/* Build s's exact map (rotation in degrees, view v, width x height) from
 * omega, the uniform sensor's exact map of the same view and size (full or
 * compact). */
int ps_cellmap_build(struct ps_weights *w, const struct ps_sensor *s, double rotation_deg,
                     const struct ps_view *v, int width, int height,
                     const struct ps_weights *omega, struct ps_err *e);

/* The same with the weights stored where place says: once the runs are
 * laid out (w->nruns, w->nw known), place(ctx, w) returns memory for the
 * w->nw weights (8-byte aligned) and sets w->map and w->maplen to the
 * mapping that holds it (ps_weights_free unmaps it), or returns NULL for
 * the route's own allocation. */
typedef double *ps_cellmap_place_fn(void *ctx, struct ps_weights *w);
int ps_cellmap_build_placed(struct ps_weights *w, const struct ps_sensor *s, double rotation_deg,
                            const struct ps_view *v, int width, int height,
                            const struct ps_weights *omega, ps_cellmap_place_fn *place, void *ctx,
                            struct ps_err *e);

#endif
