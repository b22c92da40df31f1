/* SPDX-License-Identifier: ISC */
/* Re-evaluation without re-weighting: a picture projected once onto a fine
 * (theta, phi) grid, then a sensor at any of many rotations (or several
 * sensors) evaluated in one pass over the grid's cells each.
 *
 * Each pixel's exact solid angle (the weights of a uniform sensor) times
 * its (coefficients . RGB) radiance goes to the cells around the pixel's
 * centre direction (shared between the two nearest cell centres in polar
 * angle and in azimuth, in proportion to the distance); a sensor then gives
 * sum over cells of that energy times its sensitivity at the cell's centre,
 * turned by the rotation.  Rotations
 * that are whole numbers of cells in phi reuse one table of the sensitivity
 * at the cell centres, so a scan of n rotations costs n passes over the
 * cells.  This is an approximation of the exact route (ps_weights_build at
 * each rotation): the pixel is taken at its centre and the sensitivity
 * between cell centres as linear; tests/unit/test_rescan.c and make bench
 * state its error, sim/weights/scancheck.h estimates it. */
#ifndef PS_RESCAN_H
#define PS_RESCAN_H

#include "err.h"
#include "picture.h"
#include "sensor.h"
#include "view.h"
#include "weights.h"

struct ps_rescan {
	int ntheta, nphi;     /* cells: theta from 0 in dtheta steps, phi from phi0 in dphi */
	double dtheta, dphi;  /* radians */
	double phi0;          /* radians: where cell 0 starts (sensor azimuth) */
	double *e;            /* ntheta x nphi: radiance x solid angle, W/m2 (coef applied) */
	double total;         /* the sum of e (the picture's integral over its field) */
};

/* Project pic (its view v) with omega, the weight map of the uniform sensor
 * (builtin:uniform) for the same view and size: cells of dtheta_deg x
 * dphi_deg starting at phi0_deg, up to polar angle theta_max_deg. */
int ps_rescan_project(struct ps_rescan *p, const struct ps_weights *omega,
                      const struct ps_picture *pic, const struct ps_view *v,
                      const double coef[3], double dtheta_deg, double dphi_deg,
                      double phi0_deg, double theta_max_deg, struct ps_err *e);
/* The same with the brightest pixels split: a pixel carrying at least
 * share (above 0) of the sum of the pixels' |energy| goes to the cells as
 * sub x sub parts (1 .. 8), each at its own centre with its share of the
 * pixel's solid angle (in proportion to the solid angle per plane area
 * there): the refinement where a few bright pixels (a sun disc) meet an
 * edge of the sensitivity sharper than a pixel (sim/weights/scancheck.h). */
int ps_rescan_project_split(struct ps_rescan *p, const struct ps_weights *omega,
                            const struct ps_picture *pic, const struct ps_view *v,
                            const double coef[3], double dtheta_deg, double dphi_deg,
                            double phi0_deg, double theta_max_deg, int sub, double share,
                            struct ps_err *e);
/* n (1 to PS_RESCAN_MAX_COEF) projections of one picture at once,
 * p[c] with the coefficients coef[c] (a colour channel each, say): each
 * pixel's direction is found once for all, and each p[c] is bit for bit
 * what ps_rescan_project would make with coef[c]. */
#define PS_RESCAN_MAX_COEF 4
int ps_rescan_project_many(struct ps_rescan *p, int n, const double (*coef)[3], const struct ps_weights *omega,
                           const struct ps_picture *pic, const struct ps_view *v, double dtheta_deg,
                           double dphi_deg, double phi0_deg, double theta_max_deg, struct ps_err *e);
void ps_rescan_free(struct ps_rescan *p);

/* The responses of sensor s at rotations rot0 + k step (degrees), k = 0 ..
 * n-1, into out[k]; step must be a whole number of cells (dphi) and rot0 -
 * phi0 too (else PS_EINVAL). */
int ps_rescan_scan(const struct ps_rescan *p, const struct ps_sensor *s, double rot0_deg,
                   double step_deg, int n, double *out, struct ps_err *e);
/* The same with the rotations shared among nthreads threads (the numbers
 * do not depend on how many). */
int ps_rescan_scan_mt(const struct ps_rescan *p, const struct ps_sensor *s, double rot0_deg,
                      double step_deg, int n, int nthreads, double *out, struct ps_err *e);

/* What a scan reads of a sensor on a projection's cells, turned by rot0:
 * each ring's row and weights and the rows' sensitivity at the cell
 * centres.  It depends on the sensor and the cells only (ntheta, nphi,
 * dtheta, dphi, phi0), not on the picture: made once, it serves every
 * projection on the same cells (the pictures and channels of a pose). */
struct ps_rescan_sens {
	int ntheta, nphi;
	double dtheta, dphi, phi0;   /* the cells it is for */
	double rot0;                 /* degrees */
	int nrow;                    /* rows the rings collapse onto */
	int *row;                    /* ntheta: ring it's row (weight wa), row + 1 (wb); -1: none */
	double *wa, *wb;
	int *used;                   /* nrow: 1 where some ring falls */
	int nused;
	double *sg;                  /* nused x 2 nphi: the used rows' sensitivity, doubled */
};
/* The table of sensor s at rotation rot0_deg for p's cells; rot0 - phi0
 * must be a whole number of cells (else PS_EINVAL). */
int ps_rescan_sens_init(struct ps_rescan_sens *t, const struct ps_rescan *p, const struct ps_sensor *s,
                        double rot0_deg, struct ps_err *e);
void ps_rescan_sens_free(struct ps_rescan_sens *t);
/* ps_rescan_scan_mt with the table t (made for p's cells: PS_EINVAL if
 * not): the same numbers, bit for bit, as a scan with the sensor. */
int ps_rescan_scan_sens(const struct ps_rescan *p, const struct ps_rescan_sens *t, double step_deg, int n,
                        int nthreads, double *out, struct ps_err *e);

#endif
