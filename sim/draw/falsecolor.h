/* SPDX-License-Identifier: ISC */
/* False colour: a value on a linear or logarithmic scale to a colour of a
 * blue-to-red palette (Radiance falsecolor's order: dark blue low, red at the
 * top), white above the scale, and the legend strip that names the colours'
 * values.
 *
 * The palette is piecewise linear between eight anchor colours (display
 * values, sRGB-encoded) at fractions 0, .15, .30, .45, .60, .75, .88, 1 of
 * the scale.  Linear scale: fraction = value / max.  Log scale over n
 * decades: fraction = log10(value / min) / n, min = max / 10^n; values at or
 * below min take the bottom colour.  The legend draws each row of its bar in
 * the colour of the fraction at the row's centre and puts a tick at each
 * labelled value. */
#ifndef PS_FALSECOLOR_H
#define PS_FALSECOLOR_H

#include <stdint.h>

#include "canvas.h"

struct ps_falsecolor_scale {
	double max;        /* top of the scale (> 0) */
	int log;           /* 1: logarithmic over `decades` decades below max */
	int decades;       /* log scale only: 1 to 12 */
};

/* Fraction of the scale at value (may be < 0 or > 1). */
double ps_falsecolor_scale_fraction(const struct ps_falsecolor_scale *s, double value);
/* The palette's colour for a fraction: bottom colour below 0, white above 1. */
void ps_falsecolor_rgb8(double fraction, uint8_t out[3]);
/* The smallest 1, 1.5, 2, 2.5, 3, 4, 5, 6 or 8 x 10^k at or above v (v > 0). */
double ps_falsecolor_nice_ceil(double v);
/* The labelled values of a scale, from the bottom; returns how many (<= max). */
int ps_falsecolor_scale_ticks(const struct ps_falsecolor_scale *s, double *ticks, int max);

/* The legend's bar: its left x, top y (the scale's max) and bottom y (its
 * bottom), and width; placed in a strip of the canvas. */
struct ps_falsecolor_legend {
	int x, top, bottom, width;
	double font;
	int above;       /* draw the white "above" swatch (1 after layout) */
};
/* Lay a legend out in the strip (sx, sy, sw, sh). */
void ps_falsecolor_legend_layout(struct ps_falsecolor_legend *l, int sx, int sy, int sw, int sh);
/* Draw it: the title over the bar, the bar, a tick and label per value, and
 * a white swatch for values above the scale. */
void ps_falsecolor_legend_draw(struct ps_canvas *c, const struct ps_falsecolor_legend *l, const struct ps_falsecolor_scale *s,
                               const char *title);
/* The row of the bar whose centre is nearest to a fraction. */
int ps_falsecolor_legend_row(const struct ps_falsecolor_legend *l, double fraction);

#endif
