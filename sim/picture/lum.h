/* SPDX-License-Identifier: ISC */
/* A Radiance picture's pixels as Radiance RGB and as luminance.
 *
 * Radiance's convention: a pixel holds radiance in W/(sr m2) per channel, and
 * luminance is 179 lm/W (WHTEFFICACY, the efficacy of Radiance's equal-energy
 * white) times Y, Y = 0.265074126 R + 0.670114631 G + 0.064811243 B for the
 * standard primaries (R 0.640 0.330, G 0.290 0.600, B 0.150 0.060, white
 * 0.3333 0.3333): the Y row of the RGB-to-XYZ matrix (ps_integrate_rgb_to_xyz),
 * the CIE_rf, CIE_gf, CIE_bf of Radiance's color.h, and psens's default
 * coefficients (what psfilter gives for an ideal V(lambda) filter).
 *
 * A picture with a PRIMARIES= line gets the Y row of its own primaries
 * balanced to the standard white (ps_integrate_own_rgb_to_xyz); an
 * XYZE picture's Y is luminance in cd/m2 as stored (EXPOSURE divided out;
 * Radiance's ra_xyze writes EXPOSURE=1/179 on the unchanged XYZ), so its
 * radiance is XYZ / 179, and its colour is shown in
 * the standard primaries.  RGB pictures are shown as stored, as Radiance's
 * ra_* converters do (white is R = G = B). */
#ifndef PS_LUM_H
#define PS_LUM_H

#include "picture.h"

#define PS_LUM_EFFICACY 179.0   /* lm/W, Radiance's WHTEFFICACY */

struct ps_lum {
	double to_rgb[3][3];   /* stored channels (exposure divided out) -> RGB shown */
	double y[3];           /* RGB shown -> Y */
};

void ps_lum_init(struct ps_lum *l, const struct ps_picture *pic);
/* Radiance RGB of pixel (x, row), standard orientation, exposure divided out. */
void ps_lum_rgb(const struct ps_lum *l, const struct ps_picture *pic, int x, int row, double rgb[3]);
/* Y of an RGB triple (W/(sr m2)); times PS_LUM_EFFICACY for cd/m2. */
double ps_lum_y(const struct ps_lum *l, const double rgb[3]);

#endif
