/* SPDX-License-Identifier: ISC */
/* The year every combination shares: the sky vector of each hour with
 * light (the Perez sky, as gendaymtx) and the work-plane grid's figure of
 * its daylight (min, mean, pNN, points:i,j,...); and one combination's
 * results (psscene's format: the hours with its sensor signal, a daylight
 * and an electric condition) for the year's engine. */
#ifndef PSD_PLACEYEAR_H
#define PSD_PLACEYEAR_H

#include <stddef.h>

#include "gridmtx.h"
#include "place.h"
#include "results.h"
#include "roomsetup.h"

/* The grid's figure stat of the points' lux v[n] (scratch: n doubles). */
double psd_placeyear_stat(const char *stat, const double *v, int n, double *scratch);
/* 0, or -1 with err: stat names a figure of an n-point grid. */
int psd_placeyear_check(const char *stat, int n, char *err, size_t errlen);
/* The hours of s->o->weather with their sky vectors and the grid's figure. */
int psd_placeyear_hours(struct search *s, const struct ps_gridmtx *g, char *err, size_t errlen);
/* The results of one row (patches x 3) and electric response; the year's
 * summed signal into *sensor_sum.  -1: out of memory. */
int psd_placeyear_results(const struct search *s, const double *row, double elec, const struct ps_sensor *sens,
                          struct ps_results *r, double *sensor_sum);
/* The year's sensor signals of rows[0 .. nrow - 1] into sig[j x hours + i]
 * (the same numbers psd_placeyear_results puts in the year).  -1: out of
 * memory. */
int psd_placeyear_signals(const struct search *s, const double *const *rows, const double *const *wts, int nrow,
                          double *sig);
/* psd_placeyear_results from a row's signals sig[hours]. */
int psd_placeyear_results_of(const struct search *s, const double *sig, double elec, const struct ps_sensor *sens,
                             struct ps_results *r, double *sensor_sum);
/* The grid's figure of the points' true lux, each its daylight at the
 * time (linear between the hours, as the room's day) plus the lamps'
 * output x its electric lux, for the annual run's task hook. */
struct psd_placeyear_task {
	const struct search *s;
	int q;                     /* the rank the figure takes (from 0); -1: the minimum */
	int doy, n;                /* the day whose points t, at are */
	double t[PSD_YEAR_DAY_POINTS];
	long at[PSD_YEAR_DAY_POINTS];   /* the hour of each point, -1: dark */
	double *v;                 /* npoints: scratch */
	double *zero;              /* npoints zeros: a dark point */
	int ideal_doy;             /* the last ideal output asked for (-1: none) */
	double ideal_t, ideal_target, ideal;
};
int psd_placeyear_task_init(struct psd_placeyear_task *k, const struct search *s);
double psd_placeyear_task(void *ctx, int doy, double t, double lamp);
/* The ideal photocell's light output at time t of day doy, unclamped: the
 * smallest at which the grid's figure of the points' daylight plus the
 * output x their electric light reaches target (psd_annual_opt's ideal). */
double psd_placeyear_ideal(void *ctx, int doy, double t, double target);
void psd_placeyear_task_free(struct psd_placeyear_task *k);
void psd_placeyear_release(struct ps_results *r);

#endif
