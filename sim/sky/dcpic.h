/* SPDX-License-Identifier: ISC */
/* Daylight-coefficient pictures of an unobstructed sky, made exactly: for a
 * fisheye view, one picture per sky patch (ground included) with radiance 1
 * where a pixel's centre ray falls in that patch and 0 elsewhere.  That is
 * what rcontrib / rfluxmtx write with -o dc_%03d.hdr for a view that sees
 * only the sky and the ground, one ray a pixel without jitter, except that
 * these pictures carry EXPOSURE=1.00390625: RGBE stores 1 as 128.5/128
 * (Radiance decodes a mantissa m as m + 0.5), and the exposure makes every
 * reader see exactly 1.
 *
 * The coefficient of patch p for a sensor is psens's integration of picture
 * p with the sensor's exact pixel weights (ps_dcpic_coefficients), so that
 * sum over p of coefficient x patch radiance is the sensor's response to a
 * sky vector.  That is the only place the integration is called. */
#ifndef PS_DCPIC_H
#define PS_DCPIC_H

#include "err.h"
#include "patches.h"
#include "picture.h"
#include "view.h"
#include "weights.h"

#define PS_DCPIC_EXPOSURE 1.00390625   /* the decoded value of a stored 1 */

/* The view's frame: f[0] its up vector made normal to the direction, f[1]
 * its left (the sensor azimuth 90 degrees), f[2] the direction; unit. */
void ps_dcpic_frame(const struct ps_view *v, double f[3][3]);

/* The patch of every pixel's centre ray (width x height, row 0 at the top;
 * -1 outside the fisheye's field). */
int ps_dcpic_map(const struct ps_patches *P, const struct ps_view *v, int width, int height,
                 int *map, struct ps_err *e);
/* Picture of one patch in memory (free with ps_picture_free). */
int ps_dcpic_picture(const int *map, int width, int height, int patch, struct ps_picture *pic,
                     struct ps_err *e);
/* Write every patch's picture: path_fmt is a printf format with one integer
 * conversion (dc_%03d.hdr); view is written as VIEW= (NULL: none, as
 * rfluxmtx). */
int ps_dcpic_write(const char *path_fmt, const struct ps_patches *P, const int *map, int width,
                   int height, const char *view, struct ps_err *e);
/* The file of patch p: path_fmt's one %d, %Nd or %0Nd replaced by p (an
 * error names the pattern when it has none or more than one). */
int ps_dcpic_path(const char *path_fmt, int p, char *out, size_t size, struct ps_err *e);
/* Coefficient of every patch (P->n values) for a weight map of the same
 * size: psens's response to each patch's picture with colour coefficients
 * coef (their sum is the response to a grey patch of radiance 1). */
int ps_dcpic_coefficients(const struct ps_weights *w, const int *map, int npatch,
                          const double coef[3], double *out, struct ps_err *e);

#endif
