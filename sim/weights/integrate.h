/* SPDX-License-Identifier: ISC */
/* The response of a sensor to a picture: sum over pixels of
 * (R r + G g + B b) x pixel weight, in double with compensated sums. */
#ifndef PS_INTEGRATE_H
#define PS_INTEGRATE_H

#include "err.h"
#include "picture.h"
#include "weights.h"

/* psens's default colour coefficients: the luminance of Radiance's RGB
 * primaries (the photopic curve). */
#define PS_RGB_DEFAULT_R 0.265074126
#define PS_RGB_DEFAULT_G 0.670114631
#define PS_RGB_DEFAULT_B 0.064811243

struct ps_response {
	double response;       /* sum of (coef . rgb) x weight */
	double rgb[3];         /* the same per channel, without the coefficients */
	double solid_angle;    /* the weight map's total solid angle */
	double brightest_share;/* the largest single pixel's share of the response */
	int brightest_x, brightest_row;
	double top1_share;     /* share of the brightest 1 % of weighted pixels; NaN unless
	                          the brightest pixel alone gives more than 0.1 % */
	size_t npixels;        /* pixels with non-zero weight */
};

/* Apply a weight map to a picture of the same size.  XYZE pictures and
 * RGBE pictures with their own PRIMARIES= are converted to Radiance RGB
 * radiance first (see ps_integrate_pic_matrix). */
int ps_integrate(const struct ps_weights *w, const struct ps_picture *pic, const double coef[3],
                 struct ps_response *r, struct ps_err *e);

/* The pixel loop that ps_integrate and ps_stream_integrate share, so both give
 * the same numbers bit for bit.  kc = coef^T k (k from ps_integrate_pic_matrix):
 * one pixel's response is kc . raw, raw the stored channels decoded and
 * times the weight; a row's channel sums are k times the row's raw sums
 * (ps_integrate_row_rgb), which is linear, so no per-pixel matrix is needed. */
static inline double ps_integrate_pixel_response(const uint8_t *px, double wt, const double kc[3],
                                                 double raw_sum[3])
{
	double f = ps_picture_rgbe_scale[px[3]] * wt;
	double r0 = (px[0] + 0.5) * f, r1 = (px[1] + 0.5) * f, r2 = (px[2] + 0.5) * f;
	raw_sum[0] += r0;
	raw_sum[1] += r1;
	raw_sum[2] += r2;
	return kc[0] * r0 + kc[1] * r1 + kc[2] * r2;
}

static inline void ps_integrate_coef_k(const double coef[3], const double k[3][3], double kc[3])
{
	for (int i = 0; i < 3; i++)
		kc[i] = coef[0] * k[0][i] + coef[1] * k[1][i] + coef[2] * k[2][i];
}

static inline void ps_integrate_row_rgb(const double k[3][3], const double raw_sum[3], double rgb[3])
{
	for (int c = 0; c < 3; c++)
		rgb[c] = k[c][0] * raw_sum[0] + k[c][1] * raw_sum[1] + k[c][2] * raw_sum[2];
}

/* A response that is not finite (NaN or infinite) is an error, never a
 * result: 0 when r's response and channels are finite, else -1 with e
 * naming the cause (the coefficients, the weights' sum, or the picture's
 * weighted radiance or its product with the coefficients overflowing). */
int ps_integrate_check_finite(const struct ps_response *r, const double coef[3], double sens_sum,
                              struct ps_err *e);

/* The share of response of the largest 1 % of the n contributions (at
 * least one); contrib is reordered. */
double ps_integrate_top1_share(double *contrib, size_t n, double response);

/* Radiance's standard primaries (CIE x, y of R, G, B and white 0.3333 0.3333). */
extern const double ps_integrate_std_primaries[8];
/* The 3 x 3 matrix from RGB with the given primaries to CIE XYZ (Y of white = 1). */
void ps_integrate_rgb_to_xyz(const double prim[8], double m[3][3]);
/* The 3 x 3 matrix from RGB in a picture's own primaries and white to CIE
 * XYZ seen under the standard white (0.3333, 0.3333, Radiance's
 * equal-energy white), as Radiance reads such a picture (ra_xyze, and its
 * RGB to standard RGB conversion): the primaries' matrix, then a von Kries
 * white balance in the Sharp cone space from the picture's white to the
 * standard white.  The picture's white (R = G = B) becomes the standard
 * white exactly; for the standard white it is ps_integrate_rgb_to_xyz. */
void ps_integrate_own_rgb_to_xyz(const double prim[8], double m[3][3]);
/* The inverse of a 3 x 3 matrix by its adjugate (the matrices here are
 * colour primaries, far from singular). */
void ps_integrate_mat3_invert(const double a[3][3], double out[3][3]);

/* Radiance's luminous efficacy of its equal-energy white, lm/W (WHTEFFICACY). */
#define PS_WHTEFFICACY 179.0

/* The matrix k from a pixel's decoded stored channels ((m + 0.5) 2^(e-136),
 * EXPOSURE not yet divided out) to standard-primaries RGB radiance,
 * W/(sr m2): rgb[i] = sum_c k[i][c] stored[c].
 *  - EXPOSURE= and COLORCORR= are divided out per stored channel;
 *  - XYZE: XYZ -> RGB of the standard primaries, then / 179 (XYZE values are
 *    luminance-based: Y in cd/m2, as Radiance's ra_xyze writes them);
 *  - RGBE with PRIMARIES=: own RGB -> XYZ balanced to the standard white
 *    (ps_integrate_own_rgb_to_xyz) -> standard RGB, so a grey pixel stays
 *    grey and its luminance is kept; an XYZE picture's PRIMARIES= line is
 *    ignored (XYZ has no primaries). */
void ps_integrate_pic_matrix(const struct ps_picture *pic, double k[3][3]);

#endif
