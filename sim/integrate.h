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

/* Apply a weight map to a picture of the same size.  XYZE pictures are
 * converted to Radiance RGB first. */
int ps_integrate(const struct ps_weights *w, const struct ps_picture *pic, const double coef[3],
                 struct ps_response *r, struct ps_err *e);

/* Radiance's standard primaries (CIE x, y of R, G, B and white 0.3333 0.3333). */
extern const double ps_std_primaries[8];
/* The 3 x 3 matrix from RGB with the given primaries to CIE XYZ (Y of white = 1). */
void ps_rgb_to_xyz_matrix(const double prim[8], double m[3][3]);

#endif
