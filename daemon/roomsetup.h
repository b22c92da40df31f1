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

/* A day of the results' year (day of year doy, non-leap numbering): one
 * point per hour with light at the hour's middle as the weather file gives
 * it (standard time), the room interpolating linearly between them, and
 * zero an hour before the first and an hour after the last (a day without
 * light: no points, dark all day).  -1 when the results carry no year or no
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
/* A day to play on a room (psd_roomsetup_play_day). */
struct psd_roomsetup_play {
	int month, mday;          /* the date of the results' year */
	double gain;              /* the sensor's volts per unit (no noise) */
	double period;            /* s between steps, the first at midnight */
	double level0;            /* the lights' level at midnight */
	/* the level to command at t for the sensor's reading */
	double (*law)(void *ctx, double t, double volts);
	/* the step: true task lux a millisecond after the command, true daylight
	 * lux at the task, the rooftop's global horizontal lux or NAN */
	void (*seen)(void *ctx, double t, double level, double task_lux, double daylight_lux, double rooftop_lux);
	void *ctx;
};
/* Play q's date of the results' year on a room (an instant ballast): every
 * period seconds from midnight, law gives the level to command, then seen
 * reports the step.  The room stays inside this file (psensd -Y:
 * annual.c).  -1 when the results have no year or no electric condition,
 * or out of memory. */
int psd_roomsetup_play_day(const struct ps_results *r, const struct psd_roomsetup_play *q);
/* The same from the results' year (psd_roomsetup_from_year): [simulate] year =
 * yes; 02-29 plays February 28 when the year has no 29th. */
struct ps_room_params *psd_roomsetup_new_year(const struct ps_results *r, const char *date);
void psd_roomsetup_free(struct ps_room_params *p);
/* Day of year of "MM-DD" (non-leap year); -1 if malformed. */
int psd_roomsetup_day_of_year(const char *mmdd);

#endif
