/* SPDX-License-Identifier: ISC */
/* A year of control: one zone's control law run against the loopback room
 * playing every day of the results' year (roomsetup.h, psd_roomsetup_from_year),
 * at the control period, directly (no devices, no database, no event loop:
 * the room model and the law are the same ones the daemon runs, so the
 * year's 525,600 steps at 60 s take seconds).  Sensor noise is off and the
 * ballast follows commands at once.  The lights are off outside the
 * occupied hours (as a vacancy sensor leaves them) and the law runs inside
 * them, from off at arrival.  Every date of the weather file's year:
 * 366 days when it has February 29 (a leap year), else 365.
 *
 * Figures over the occupied hours (occ_start to occ_end every day, standard
 * time):
 *   energy          sum of the light output x time (full-output hours);
 *   savings         1 - energy / occupied hours;
 *   ideal photocell DAYSIM's: the output that tops the task's true daylight
 *                   up to the target, min_level to 1, each step; its savings
 *                   and the law's effectiveness = savings / ideal savings;
 *   below 90 %      hours with the true task lux below 0.9 x target;
 *   over-dimming    hours with the output more than 0.01 below the ideal's
 *                   while the task is below the target (dimmed past what
 *                   daylight allows);
 *   changes         steps whose output moved by more than 0.005, per hour
 *                   (the switch-on at arrival not counted);
 *   estimate error  where the task's true daylight is 50 lx or more, the
 *                   law's daylight estimate (ratio x the reading's daylight
 *                   response) against it: with the one mean ratio, with
 *                   the dated one (dated.h) and with the dated one whose sky
 *                   class a rooftop sensor reading the hour's global
 *                   horizontal illuminance gives (psd_dated_rooftop_class),
 *                   mean and rms in percent.  The law itself runs on the
 *                   typical class. */
#ifndef PSD_ANNUAL_H
#define PSD_ANNUAL_H

#include "control.h"
#include "results.h"

#define PSD_ANNUAL_MAX_DAYS 366

struct psd_annual_month {
	double occ_h, energy_h, ideal_h, below_h, overdim_h;
};

struct psd_annual {
	double occ_h, energy_h, ideal_h, below_h, overdim_h, changes;
	double savings, ideal_savings, effectiveness, changes_per_h;
	double est_mean[3], est_rms[3];   /* [0] mean ratio, [1] dated (typical class),
	                                     [2] dated with the class from a rooftop
	                                     sensor reading the hour; percent */
	int est_rooftop;                  /* [2] is meaningful: the results carry the
	                                     hours' global horizontal lux and the site */
	double est_n;
	struct psd_annual_month month[12];
	double steps;                     /* control steps run */
	int days;                         /* days played: 365, or 366 with February 29 */
	double seconds;                   /* wall time */
};

struct psd_annual_opt {
	double period;           /* control period, s */
	double occ_start, occ_end;   /* occupied hours, s after midnight */
	int dated;               /* the law uses the dated ratio */
	/* the year as pictures, PSD_ANNUAL_MAX_DAYS x 144 (10-minute rows; day
	 * d of the year, from 1, in column d - 1), or NULL */
	float *task_img, *level_img;
};

/* Run the year for a law (ctl: the zone's constants, the model filled from
 * r as the engine does).  -1 when r has no year or no electric condition. */
int psd_annual_run(const struct ps_results *r, const struct psd_control *ctl,
                   const struct psd_annual_opt *o, struct psd_annual *a);

/* Draw the year's first `days` days (hour of day up, day of year across:
 * task lux and light output) into a PNG, 2 pixels a day. */
int psd_annual_png(const char *path, const float *task_img, const float *level_img, int days,
                   double target, const char *title, char *err, size_t errlen);

#endif
