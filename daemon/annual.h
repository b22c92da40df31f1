/* SPDX-License-Identifier: ISC */
/* A year of control: one zone's control law run against the loopback room
 * playing every day of the results' year (roomsetup.h, psd_roomsetup_from_year),
 * at the control period, directly (no devices, no database, no event loop:
 * the room model and the law are the same ones the daemon runs, so the
 * year's 525,600 steps at 60 s take seconds).  Sensor noise is off; the
 * ballast is the zone's own model (psd_annual_devices): the loopback room's
 * fade rate, minimum level and lamp lag, integrated exactly over each step,
 * and a DALI output's commands on the logarithmic arc power levels.  The
 * room starts each day at midnight as the loopback room does (full output,
 * then commanded to the night's level).  The lights are off outside the
 * occupied hours (as a vacancy sensor leaves them) and the law runs inside
 * them, from off at arrival.  Every date of the weather file's year:
 * 366 days when it has February 29 (a leap year), else 365.
 *
 * Figures over the occupied hours (occ_start to occ_end every day, standard
 * time):
 *   light           the lamp's light output integrated over time
 *                   (full-output hours);
 *   energy          the input power integrated over time (full-power hours):
 *                   each step's mean light output through the power curve
 *                   (psd_annual_power), x lamp watts for kWh;
 *   savings         1 - energy / occupied hours;
 *   ideal photocell DAYSIM's: the output that tops the task's true daylight
 *                   up to the target, min_level to 1, each step, through
 *                   the same power curve; its savings
 *                   and the law's effectiveness = savings / ideal savings;
 *   short of target hours with the true task lux more than 0.1 % below
 *                   the target (less is rounding) and the power below the
 *                   ideal's: the law saving by under-lighting, which is how
 *                   an effectiveness passes 100 %; the lux-hours it is short
 *                   by and the full-power hours it saves there; the
 *                   effectiveness at target charges those steps the
 *                   ideal's power (lighting delivered at target);
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

#include <stddef.h>

#include "control.h"
#include "results.h"

#include "roomsetup.h"

struct psd_config;
struct psd_zone_conf;

#define PSD_ANNUAL_MAX_DAYS 366

struct psd_annual_month {
	double occ_h, light_h, energy_h, ideal_h, below_h, overdim_h;
};

struct psd_annual {
	double occ_h, light_h, energy_h, ideal_h, below_h, overdim_h, changes;
	double kwh;                       /* energy_h x watts / 1000 (0 without watts) */
	double day_light_h[PSD_ANNUAL_MAX_DAYS];   /* light output over each day's occupied
	                                              hours (day of year from 1 at [0]) */
	double savings, ideal_savings, effectiveness, changes_per_h;
	double short_h, short_lxh, short_saved_h;   /* short of target (above) */
	double effectiveness_at_target;
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
	/* the devices (psd_annual_devices): the ballast (all zero: instant,
	 * without a minimum); dali: commands go out on DALI's logarithmic levels */
	struct psd_roomsetup_ballast ballast;
	int dali;
	/* the power curve: input power (fraction of full) against light output y:
	 * 0 when off; power_at_min + (1 - power_at_min) (y - light_min) /
	 * (1 - light_min) from light_min to 1; proportional below light_min;
	 * power_at_min < 0: power proportional to light throughout */
	double light_min, power_at_min, watts;
	/* the year as pictures, PSD_ANNUAL_MAX_DAYS x 144 (10-minute rows; day
	 * d of the year, from 1, in column d - 1), or NULL */
	float *task_img, *level_img;
	/* every control step (occupied or not) handed to step(step_ctx, day of
	 * the year from 1, seconds after midnight, commanded level, light
	 * output, true task lux, its daylight part), or step NULL */
	void (*step)(void *step_ctx, int doy, double t, double level, double output, double truth, double dl);
	void *step_ctx;
	int no_estimate;         /* 1: leave the estimate error out (est_* NAN): faster */
	/* 1 (with no_estimate and without task_img): step is called for the
	 * occupied steps only, and the unoccupied ones run the law and the
	 * ballast without looking at the room (the same figures, faster) */
	int occupied_only;
	/* the true task lux at time t (s after midnight) of day doy (from 1)
	 * for the lamps' light output lamp (0..1), in place of the room's
	 * (the results' task daylight + lamp x electric task lux): a task
	 * whose figure is not linear in its points (a grid's minimum); NULL:
	 * the room's.  The law does not see it; the figures on the truth do. */
	double (*task)(void *task_ctx, int doy, double t, double lamp);
	void *task_ctx;
	/* the ideal photocell's light output at time t (s after midnight, the
	 * step's) of day doy for the target (before clamping to min_level..1),
	 * in place of (target - task daylight) / electric task lux: a task
	 * whose figure is not linear in its points; NULL: the room's */
	double (*ideal)(void *task_ctx, int doy, double t, double target);
};

/* The weather's step in the results' year, s: the shortest positive gap
 * between two steps with light on one day (3600 for an hourly file); 0
 * when no day has two. */
double psd_annual_weather_step(const struct ps_results *r);

/* Input power (fraction of full) at light output y through o's curve. */
double psd_annual_power(const struct psd_annual_opt *o, double y);

/* The zone's devices for the year, into o: the first dim point's
 * device, when it is the loopback room, gives its ballast (fade_rate,
 * min_level, lag_tau, off_below_min, with the driver's defaults); a DALI
 * device the logarithmic levels; any other an instant ballast.  The power
 * curve from [simulate] power_at_min and lamp_watts, its light_min the
 * ballast's min_level.  what: one line saying so.  -1 with err. */
int psd_annual_devices(const struct psd_config *cf, const struct psd_zone_conf *zc, struct psd_annual_opt *o,
                       char *what, size_t whatlen, char *err, size_t errlen);

/* Run the year for a law (ctl: the zone's constants, the model filled from
 * r as the engine does).  -1 when r has no year or no electric condition. */
int psd_annual_run(const struct ps_results *r, const struct psd_control *ctl,
                   const struct psd_annual_opt *o, struct psd_annual *a);

/* The sun's discretisation error, estimated for this scene: the year run
 * again with every hour's sensor response and task illuminance as they are
 * with the sun's light in its nearest patch instead of shared among the
 * four nearest (the results' sensor_alt, task_alt: psscene computes both
 * from the same coefficients), the dated table recomputed from them, the
 * same law and devices.  Over the occupied hours with 50 lx or more of task
 * daylight in the year as run: |alt / main - 1| per hour (largest, 95th
 * percentile, median) and the sum's relative change; the year's energy,
 * savings and hours below 90 % with the sun so placed.  -1 when the results
 * carry no alternative placement (or as psd_annual_run). */
struct psd_annual_sunbar {
	double hours;                       /* hours compared */
	double task_max, task_p95, task_median, task_sum;   /* fractions */
	struct psd_annual alt;              /* the year with the sun in its nearest patch */
	double seconds;                     /* the estimate's cost, wall time */
};
int psd_annual_sunbar(const struct ps_results *r, const struct psd_control *ctl,
                      const struct psd_annual_opt *o, struct psd_annual_sunbar *b);

/* The daylight's in-hour error, measured for this scene when its weather
 * is sub-hourly and has a step at every hour's middle (as NREL's hours
 * interpolated to shorter steps have): the year run again on those steps
 * alone, so that the room interpolates linearly between the hours as it
 * does on an hourly file, against the year at the file's own steps, the
 * same law and devices.  Over the occupied control steps: the task
 * daylight's sum (hourly / sub-hourly - 1) and its rms a step where the
 * sub-hourly daylight is 50 lx or more; hourly: that year's figures.
 * -1 when the weather is hourly or has no steps at the hours' middles,
 * -2 when memory runs out, -3 when a year does not run or the two runs'
 * occupied steps differ in number. */
struct psd_annual_inhour {
	double hours;          /* the hourly points taken */
	double task_sum;       /* fraction */
	double task_rms;       /* fraction, over task_n steps */
	double task_n;
	struct psd_annual hourly;
};
int psd_annual_inhour(const struct ps_results *r, const struct psd_control *ctl,
                      const struct psd_annual_opt *o, struct psd_annual_inhour *b);

/* Draw the year's first `days` days (hour of day up, day of year across:
 * task lux and light output) into a PNG, 2 pixels a day. */
int psd_annual_png(const char *path, const float *task_img, const float *level_img, int days,
                   double target, const char *title, char *err, size_t errlen);

#endif
