/* SPDX-License-Identifier: ISC */
/* The combinations through the year: each row's results built once and
 * every law of it run with the zone's devices (psd_annual_run), a hook
 * gathering the hours below the target and by how much, over-lighting and
 * each day's acceptance criteria; the ranking (within the under-lighting
 * allowed by energy, then by hours below) and the Pareto front of energy
 * against the lux missing. */
#ifndef PSD_PLACERUN_H
#define PSD_PLACERUN_H

#include "place.h"
#include "results.h"

/* what the step hook gathers */
struct watch {
	const struct psd_annual_opt *o;
	const struct psd_control *c;
	double deficit_lxh, over_h;
	/* the acceptance tests of a day (accept.h's criteria on the simulated day) */
	int day, day_seen, day_fail;
	double days, days_pass;
	double last_swing_t, last_out;
	int last_dir;
	double *hour_power;   /* 8784 hours: the power fraction's sum, or NULL */
	double *hour_level;
	double *hour_steps;
};

/* Run the laws of combinations k[0 .. n-1], which share one row; wx (NULL:
 * none) gathers the hours.  -1 when a year could not run. */
int psd_placerun_row(const struct search *s, struct combo *k, int n, const double *row, double elec, struct watch *wx);
/* Combination k's projected row and electric response. */
const double *psd_placerun_row_of(const struct search *s, const struct combo *k);
double psd_placerun_elec_of(const struct search *s, const struct combo *k);
/* Rotation r's angle, degrees. */
double psd_placerun_rot_deg(const struct search *s, int r);
/* Project every pose (psd_placeset_project) on s->o->threads threads;
 * -1 with the first failing pose's error. */
int psd_placerun_project(struct search *s, char *err, size_t errlen);
/* Run every combination of s on s->o->threads threads. */
void psd_placerun_all(struct search *s);
/* Rank s->c and mark the Pareto front. */
void psd_placerun_rank(struct search *s);

#endif
