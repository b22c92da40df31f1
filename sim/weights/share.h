/* SPDX-License-Identifier: ISC */
/* Where a sensor's signal comes from: each pixel's share of the response
 * (its exact weight x the colour coefficients . its radiance, over the sum
 * of these, which is what ps_integrate gives), and the shares of regions.
 * A region's share is the sum over pixels of the pixel's share times the
 * fraction of the pixel's solid angle in the region (ps_regions). */
#ifndef PS_SHARE_H
#define PS_SHARE_H

#include "err.h"
#include "picture.h"
#include "regions.h"
#include "weights.h"

struct ps_share {
	int width, height;
	double *share;        /* per pixel, row 0 at the top; sums to 1 */
	double response;      /* what the shares are parts of */
};

int ps_share_compute(struct ps_share *s, const struct ps_weights *w, const struct ps_picture *pic,
                     const double coef[3], struct ps_err *e);
void ps_share_free(struct ps_share *s);

struct ps_region_share {
	int label;            /* index into the regions' labels */
	double share;         /* of the response */
	double solid_angle;   /* sr of the picture's pixels in the region */
	double luminance;     /* cd/m2, mean over that solid angle */
};

/* Every label's share, largest first (r->nlabels entries).  omega: the
 * pixels' solid angles (the uniform sensor's weights for the same view and
 * size). */
int ps_share_regions(const struct ps_share *s, const struct ps_regions *r,
                     const struct ps_weights *omega, const struct ps_picture *pic,
                     struct ps_region_share **out, struct ps_err *e);

#endif
