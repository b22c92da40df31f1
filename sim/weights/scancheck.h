/* SPDX-License-Identifier: ISC */
/* The rotation scan's error estimate (sim/weights/rescan.h): the scan
 * against the exact route (the sensor's own exact weights at that rotation)
 * at the rotations where the scan is most likely off, and the scan redone on
 * cells four times finer in azimuth when the estimate exceeds a tolerance.
 *
 * The scan takes each pixel at its centre and each centre at its cell's; a
 * sensitivity that changes sharply within a cell or a pixel (an azimuthal
 * edge of a few degrees) over bright pixels (a sun disc) is where that
 * costs most, and there the scan's response jumps from one rotation to the
 * next.  The checked rotations are the two sides of the largest jump, of
 * the largest jump relative to the smaller response beside it, and the
 * largest response.  The estimate is the largest relative
 * difference found there: a measurement at those rotations, not a bound
 * between them. */
#ifndef PS_SCANCHECK_H
#define PS_SCANCHECK_H

#include "err.h"
#include "picture.h"
#include "rescan.h"
#include "sensor.h"
#include "view.h"
#include "wcache.h"
#include "weights.h"

#define PS_SCANCHECK_TOLERANCE 1e-3   /* the default tolerance: relative */
enum { PS_SCANCHECK_MAX = 5 };       /* rotations checked at most */

struct ps_scancheck {
	double tolerance;                 /* in: relative; 0 or less: no check */
	double estimate;                  /* out: the largest |scan - exact| / |exact| found */
	double at_deg;                    /* out: the rotation it was found at */
	int nchecked;                     /* out: rotations checked (0: none) */
	double checked_deg[PS_SCANCHECK_MAX];
	int refined;                      /* out: 1: out[] is the refined scan */
	double first_estimate;            /* out: the estimate before refining */
};

/* Scan sensor s over p (ps_rescan_scan_mt's arguments) into out[], then
 * check it: the exact route at the chosen rotations (through the weight
 * cache, NULL for none; the picture pic of view v, colour coef).  When the
 * estimate exceeds c->tolerance and omega (the uniform sensor's exact
 * weights, as given to ps_rescan_project) is not NULL, the picture is
 * projected again on cells a quarter of p's in azimuth and scanned again;
 * out[] holds that scan when its estimate is lower.  A scan with a
 * response that is not finite is not checked (c->nchecked 0).  c->estimate above
 * c->tolerance afterwards is for the caller to report. */
int ps_scancheck_scan(const struct ps_rescan *p, const struct ps_weights *omega,
                      const struct ps_picture *pic, const struct ps_view *v, const double coef[3],
                      const struct ps_sensor *s, double rot0_deg, double step_deg, int n,
                      int nthreads, const struct ps_wcache_dir *cache, double *out,
                      struct ps_scancheck *c, struct ps_err *e);

/* The rotations (indices into out[0 .. n-1]) to check: the two sides of the
 * largest jump between neighbours and of the largest jump relative to the
 * smaller response beside it (around the turn too when the n rotations
 * close it), and the largest response, without repeats.  Returns
 * how many (at most PS_SCANCHECK_MAX). */
int ps_scancheck_pick(const double *out, int n, int closed, int idx[PS_SCANCHECK_MAX]);

#endif
