/* SPDX-License-Identifier: ISC */
/* From the scene's precomputed results to a simulated room's parameters
 * (drivers/room.h), which the daemon hands to a simulated device through
 * the driver table's setup hook.  The one daemon file that builds a room
 * (psvirt, which serves the room over Modbus, calls it too). */
#ifndef PSD_ROOMSETUP_H
#define PSD_ROOMSETUP_H

#include "results.h"

struct ps_room_daypoint;
struct ps_room_params;

enum { PSD_DAY_POINTS = 97 };   /* every 15 minutes, midnight to midnight */
/* a day of a weather file: one point a step (up to every 5 minutes) and two dark ends */
enum { PSD_YEAR_DAY_POINTS = 24 * 12 + 2 };

/* A day of the results' year (day of year doy, non-leap numbering): one
 * point per step with light at the time the weather file gives it (the
 * hour's middle in an hourly file; standard time), the room interpolating
 * linearly between them, and zero one step (an hour, or the file's step
 * when shorter) before the first and after the last (a day without light:
 * no points, dark all day); day holds PSD_YEAR_DAY_POINTS.  -1 when the results carry no year or no
 * electric condition. */
int psd_roomsetup_from_year(const struct ps_results *r, int doy, struct ps_room_daypoint *day,
                       struct ps_room_params *p);
/* The same, allocated with its day of daylight (free with
 * psd_roomsetup_free) for the date "MM-DD"; NULL when the results have no
 * electric or no daylight condition, or the date is malformed. */
struct ps_room_params *psd_roomsetup_new(const struct ps_results *r, const char *date, double sunrise,
                                         double sunset);
/* 1 when the results' year has February 29 (a leap year's weather file). */
int psd_roomsetup_has_feb29(const struct ps_results *r);
/* A ballast for a played day, as the loopback room's (drivers/room.h):
 * all zero is an instant one without a minimum. */
struct psd_roomsetup_ballast {
	double fade_rate;         /* fraction of full output a second; 0: instant */
	double min_level;         /* lowest output above off */
	double lag_tau;           /* the lamp's time constant, s */
	int off_below_min;        /* a command below min_level switches off */
};
/* A day to play on a room (psd_roomsetup_play_day). */
struct psd_roomsetup_play {
	int month, mday;          /* the date of the results' year */
	double gain;              /* the sensor's volts per unit (no noise) */
	double period;            /* s between steps, the first at midnight */
	double level0;            /* the lights' level at midnight */
	struct psd_roomsetup_ballast ballast;
	/* the level to command at t for the sensor's reading */
	double (*law)(void *ctx, double t, double volts);
	/* the step: the level commanded, the lamp's mean light output over the
	 * step (t to t + period, the ballast's exact integral), true task lux a
	 * millisecond after the command, true daylight lux at the task, the
	 * rooftop's global horizontal lux or NAN */
	void (*seen)(void *ctx, double t, double level, double output, double task_lux, double daylight_lux,
	             double rooftop_lux);
	void *ctx;
	/* lean: a step outside [busy_from, busy_to) only asks the law (with a
	 * reading of NAN) and commands the ballast, and seen is told NAN for
	 * the output, task, daylight and rooftop lux (the room is not looked
	 * at); inside, the rooftop is NAN (not read).  The ballast runs the
	 * same either way. */
	int lean;
	double busy_from, busy_to;
	/* the true task lux at time t for the lamps' light output lamp (0..1),
	 * or NULL: the room's (its daylight plus lamp x electric task lux) */
	double (*task)(void *ctx, double t, double lamp);
};
/* Play q's date of the results' year on a room (q's ballast): every
 * period seconds from midnight, law gives the level to command, then seen
 * reports the step.  The room stays inside this file (psensd -Y:
 * annual.c).  -1 when the results have no year or no electric condition,
 * or out of memory. */
int psd_roomsetup_play_day(const struct ps_results *r, const struct psd_roomsetup_play *q);
/* The same from the results' year (psd_roomsetup_from_year): [simulate] year =
 * yes; 02-29 plays February 28 when the year has no 29th.  The year's hours
 * are standard time: shift_s (local minus standard on that date,
 * psd_clock_dst_shift) moves them onto the local clock the room runs on. */
struct ps_room_params *psd_roomsetup_new_year(const struct ps_results *r, const char *date, double shift_s);
void psd_roomsetup_free(struct ps_room_params *p);
/* Day of year of "MM-DD" (non-leap year); -1 if malformed. */
int psd_roomsetup_day_of_year(const char *mmdd);

#endif
