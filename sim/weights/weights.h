/* SPDX-License-Identifier: ISC */
/* Pixel weights: for each pixel of a fisheye picture, the integral of the
 * sensor's sensitivity over the pixel's footprint on the sphere.
 *
 * Exact method: with M(theta, phi) = integral_0^theta S(t, phi) sin t dt
 * (continuous in theta for every reading), Fubini along each ray gives
 *   W(pixel) = closed integral along the pixel's boundary of M d(alpha)
 * (alpha the plane azimuth, counter-clockwise).  Each boundary edge is a
 * straight segment, split where it crosses a sensitivity cell's circle or
 * ray, the end of the table or the field's edge; on each piece the integrand
 * is smooth and Gauss-Legendre quadrature is accurate to rounding, its order
 * chosen per piece from an error bound (the nearest singularity's Bernstein
 * ellipse).  A pixel edge (axis-parallel) inside one cell is integrated in
 * its plane coordinate instead, with the cell's closed form of M and no
 * break search (weights.c, edge_fast).  So the
 * result does not depend on where a boundary falls, and a pixel the sensor
 * cannot see costs nothing.  Every edge is shared by two pixels and computed
 * once.  A sensor the same at every azimuth on a view not shifted (-vs 0
 * -vl 0) gives a map symmetric in x and y: only the lower left quarter is
 * integrated and the rest mirrored (a quarter of the work; each mirrored
 * weight is its mirror pixel's, exact to the same rounding); a square
 * picture with -vh equal to -vv is symmetric in the diagonal too, and only
 * an eighth is integrated.
 *
 * Centre-point method (the paper's psens, kept for comparison): sensitivity
 * at the pixel's centre times the projection's Jacobian there times the
 * pixel's plane area. */
#ifndef PS_WEIGHTS_H
#define PS_WEIGHTS_H

#include <stddef.h>

#include "err.h"
#include "sensor.h"
#include "view.h"

enum ps_wmethod { PS_W_EXACT = 0, PS_W_CENTRE = 1 };

/* A run of consecutive weighted pixels on one row (row 0 = top). */
struct ps_weights_run {
	int row, x0, n;
	size_t off;          /* index of the run's first weight in w[] */
};

struct ps_weights {
	int width, height, method;
	struct ps_weights_run *runs;
	size_t nruns;
	double *w;           /* weights of the runs' pixels, steradian x sensitivity */
	size_t nw;           /* weights stored in w */
	size_t npix;         /* pixels the runs cover (nw, or about 4 nw when mirrored) */
	int mirror;          /* 1: a compact symmetric map (below) */
	double solid_angle;  /* total solid angle of the picture's pixels in the field, sr */
	double sens_sum;     /* sum of all weights */
	double sens_full;    /* the sensitivity's integral over the whole sphere */
	double coverage;     /* sens_sum / sens_full: below 1 when the picture misses part */
	char key[512];       /* equal keys give equal maps */
	void *map;           /* non-NULL: w lives in this file map (wcache.c) */
	size_t maplen;
	int built_in_map;    /* the map was filled here (a new cache entry's): its pages
	                      * are resident already and stay, not released row by row */
};

/* A compact symmetric map (mirror = 1, from ps_weights_build_ex with
 * PS_WB_COMPACT when the map is symmetric in x and y): every run is a
 * palindrome, its pixels i and n-1-i have the same weight and only its
 * first (n+1)/2 weights are stored at off; the runs of rows r and
 * height-1-r are equal and share their weights.  A 4000 x 4000 map then
 * holds a quarter of the weights (25 MB instead of 100).  Read a weight
 * with ps_weights_run_at or ps_weights_run_index, never w[off + i]. */
static inline size_t ps_weights_run_index(const struct ps_weights *w, const struct ps_weights_run *r, int i)
{
	return r->off + (size_t)(w->mirror && 2 * i >= r->n ? r->n - 1 - i : i);
}

static inline double ps_weights_run_at(const struct ps_weights *w, const struct ps_weights_run *r, int i)
{
	return w->w[ps_weights_run_index(w, r, i)];
}

/* The number of weights a run has stored. */
static inline int ps_weights_run_stored(const struct ps_weights *w, const struct ps_weights_run *r)
{
	return w->mirror ? (r->n + 1) / 2 : r->n;
}

enum { PS_WB_COMPACT = 1 };

/* Build the map for a sensor (with its reading), rotation in degrees (turns
 * the sensitivity towards growing azimuth), a fisheye view and a size. */
int ps_weights_build(struct ps_weights *w, const struct ps_sensor *s, double rotation_deg,
                     const struct ps_view *v, int width, int height, int method,
                     struct ps_err *e);
/* The same with flags: PS_WB_COMPACT gives a compact map when the map is
 * symmetric (same weights, a quarter of the memory), else a full one. */
int ps_weights_build_ex(struct ps_weights *w, const struct ps_sensor *s, double rotation_deg,
                        const struct ps_view *v, int width, int height, int method, int flags,
                        struct ps_err *e);
void ps_weights_free(struct ps_weights *w);
/* The key ps_weights_build would give. */
void ps_weights_key(const struct ps_sensor *s, double rotation_deg, const struct ps_view *v,
                    int width, int height, int method, char *buf, size_t len);

/* Exact solid angle of the part of a plane-coordinate rectangle inside the
 * field (for tests and the total). */
double ps_weights_rect_solid_angle(int type, double u0, double v0, double u1, double v1);

/* Routes that compute the exact weights of some pixels only
 * (sim/weights/cellmap.c): an evaluator of one pixel's exact weight (its
 * four edges, the general route: the same numbers as ps_weights_build's up
 * to the rounding of edges it shares), and the runs of a full map as
 * ps_weights_build lays them out (w->w allocated, not filled; sens_sum and
 * coverage left to the caller, sens_full and solid_angle set). */
struct ps_weights_exact;
int ps_weights_exact_open(struct ps_weights_exact **out, const struct ps_sensor *s,
                          double rotation_deg, const struct ps_view *v, int width, int height,
                          struct ps_err *e);
/* The edge integral along line `line` (0..height from the bottom) across
 * pixel column px, left to right; along column line col (0..width) across
 * bottom-based row jb (the run's row is height - 1 - jb), upwards. */
double ps_weights_exact_hedge(const struct ps_weights_exact *x, int px, int line);
double ps_weights_exact_vedge(const struct ps_weights_exact *x, int col, int jb);
/* A pixel's weight from its four edges as above (compensated, counter-
 * clockwise; rounding below 1e-15 on a pixel the sensor barely sees is 0). */
double ps_weights_exact_pixel(double bottom, double right, double top, double left);
void ps_weights_exact_close(struct ps_weights_exact *x);
int ps_weights_layout(struct ps_weights *w, const struct ps_sensor *s, double rotation_deg,
                      const struct ps_view *v, int width, int height, struct ps_err *e);

#endif
