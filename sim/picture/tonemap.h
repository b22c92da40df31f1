/* SPDX-License-Identifier: ISC */
/* Tone mapping: a Radiance picture's radiances to 8-bit display values.
 *
 * Exposure multiplies radiance (W/(sr m2)) before the curve, so a value of 1
 * after it is display white.  "auto" maps the picture's log-average Y (the
 * geometric mean over pixels with Y > 0, the scene's key) to 0.18, the middle
 * grey of a photograph: exposure = 0.18 / exp(mean ln Y).  A text "+N" or
 * "-N" is N photographic stops (2^N), as Radiance's pfilt -e reads it;
 * any other number is the multiplier itself.
 *
 * Curves, each of x = exposure x channel:
 *   linear    255 min(x, 1): the PNG says gamma 1.0 (a linear display)
 *   gamma     255 min(x, 1)^(1/g): the PNG says gamma 1/g
 *   srgb      255 srgb(min(x, 1)), the IEC 61966-2-1 encoding: the PNG says sRGB
 *   reinhard  Reinhard et al.'s photographic operator (SIGGRAPH 2002, eq. 4) on
 *             luminance, L = exposure Y, Ld = L (1 + L / Lw^2) / (1 + L), each
 *             channel scaled by Ld / L (hue kept), clipped, then sRGB encoded.
 *             Lw, the smallest L shown as white, is the picture's largest by
 *             default.  A closed-form curve of one statistic: windows at 10^4
 *             cd/m2 and walls at 10^1 both stay visible, and a test can state
 *             its output; a histogram adjustment (Ward Larson 1997, Radiance's
 *             pcond) depends on the whole histogram and is iterative.
 * A value v in 0..1 becomes the byte floor(255 v + 0.5). */
#ifndef PS_TONEMAP_H
#define PS_TONEMAP_H

#include <stdint.h>

#include "lum.h"
#include "picture.h"

enum ps_tone { PS_TONE_LINEAR = 0, PS_TONE_GAMMA, PS_TONE_SRGB, PS_TONE_REINHARD };

#define PS_TONE_KEY 0.18   /* the log-average's display value under "auto" */

struct ps_tonemap {
	int curve;             /* enum ps_tone */
	double exposure;       /* multiplier on radiance */
	double gamma;          /* PS_TONE_GAMMA's g */
	double white;          /* PS_TONE_REINHARD's Lw, in exposed units (> 0) */
	struct ps_lum lum;     /* the picture's colour handling */
};

/* "linear", "gamma", "srgb" or "reinhard"; -1 for anything else. */
int ps_tonemap_parse(const char *name);
const char *ps_tonemap_name(int curve);
/* Parse an exposure: "auto" (returns 1, *mult untouched), a multiplier or
 * +N/-N stops (returns 0), or -1 when the text is none of these or not
 * positive and finite. */
int ps_tonemap_exposure_parse(const char *text, double *mult);

/* Log-average and largest Y of a picture (pixels with Y > 0; both 0 when
 * there is none). */
void ps_tonemap_stats(const struct ps_picture *pic, const struct ps_lum *l, double *logavg,
                      double *ymax);

/* Set a tone map up for a picture: exposure <= 0 means auto; white <= 0 means
 * the picture's largest Y (in radiance units, before exposure). */
void ps_tonemap_init(struct ps_tonemap *t, const struct ps_picture *pic, int curve,
                     double exposure, double gamma, double white);
/* Map one RGB radiance triple to display bytes. */
void ps_tonemap_rgb(const struct ps_tonemap *t, const double rgb[3], uint8_t out[3]);
/* The sRGB encoding of a linear value in 0..1. */
double ps_tonemap_srgb_encode(double v);
/* floor(255 v + 0.5) of v clamped to 0..1. */
uint8_t ps_tonemap_byte(double v);

#endif
