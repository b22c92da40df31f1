/* SPDX-License-Identifier: ISC */
/* A daylight-coefficient picture set: one fisheye per sky patch (ground
 * included), as Radiance's rfluxmtx / rcontrib write them with
 * -o dc_%03d.hdr, and its coefficient row for a sensor.
 *
 * The set is named by a printf pattern with one integer conversion; patch p
 * is the file the pattern gives for p.  Its pictures carry no VIEW= line, so
 * the caller gives the view.  The count must be a subdivision's 144 MF^2 + 2
 * (146, 578, 2306, 5186 for MF 1, 2, 4, 6): every patch from 0 to n - 1
 * present, none beyond, all of one size.
 *
 * The row: for each patch, psens's response to its picture per channel
 * (R, G, B, without colour coefficients), with the sensor's exact pixel
 * weights built once for the set's view and size and applied to every
 * picture.  A sky's signal is then sum over patches and channels of
 * coef[c] x row[3p + c] x sky[3p + c] (ps_dcset_row_apply): in W/m2 for a cosine
 * sensor, the irradiance at the view's point.
 *
 * The weights are built once and the pictures read and integrated in
 * parallel through sim/weights/batch.h (each picture's numbers are the one-picture
 * route's, bit for bit; the set's view is written into each picture as it
 * is read, since the files carry none). */
#ifndef PS_DCSET_H
#define PS_DCSET_H

#include "err.h"
#include "sensor.h"
#include "view.h"

struct ps_dcset_row {
	int mf;              /* subdivision */
	int n;               /* patches, ground included */
	int width, height;   /* of the pictures */
	double *c;           /* 3 per patch: R, G, B coefficients */
	double coverage;     /* share of the sensitivity the pictures' field holds */
};

/* Read and integrate a whole set for a sensor turned by rotation degrees
 * (see ps_weights_build).  Errors name the file and patch; on error row is
 * left empty. */
int ps_dcset_row(const char *pattern, const struct ps_view *v, int mf, const struct ps_sensor *s,
                 double rotation, struct ps_dcset_row *row, struct ps_err *e);
void ps_dcset_row_free(struct ps_dcset_row *row);

/* sum over patches of coef . (row x sky), sky 3 per patch (ps_sky_vector). */
double ps_dcset_row_apply(const struct ps_dcset_row *row, const double coef[3], const double *sky);
/* The same over a list of patches only (those with a non-zero coefficient). */
double ps_dcset_row_apply_list(const struct ps_dcset_row *row, const double coef[3], const double *sky,
                               const int *list, int nlist);

#endif
