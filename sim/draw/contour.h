/* SPDX-License-Identifier: ISC */
/* Contour lines of a sampled field (marching squares), drawn on a canvas.
 *
 * The field is nx x ny samples, row-major, row 0 at the top; a NaN sample
 * (outside a fisheye's field) leaves its cells out.  On each cell edge whose
 * ends straddle the level the crossing is interpolated linearly; a cell with
 * crossings on all four edges (a saddle) is resolved by its centre's mean. */
#ifndef PS_CONTOUR_H
#define PS_CONTOUR_H

#include "canvas.h"

/* Called for each segment, in sample coordinates (x across, y down). */
typedef void (*ps_contour_fn)(void *arg, double x0, double y0, double x1, double y1);

/* Every segment of the level's contour; returns how many. */
long ps_contour(const double *val, int nx, int ny, double level, ps_contour_fn fn, void *arg);

/* How a contour is drawn: sample (i, j) at canvas (ox + i step, oy + j step),
 * a line of the colour and width, and the label (may be NULL) of that font
 * size on the segment nearest canvas (lx, ly), with a halo. */
struct ps_contour_style {
	double ox, oy, step;
	const double *rgb;             /* [3], 0..1 */
	double width;
	const char *label;
	double font;
	double lx, ly;
};

/* Draw the level's contour; returns the number of segments drawn. */
long ps_contour_draw(struct ps_canvas *c, const double *val, int nx, int ny, double level,
                     const struct ps_contour_style *st);

#endif
