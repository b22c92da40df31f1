/* SPDX-License-Identifier: ISC */
/* The dated daylight ratio: when the scene's results carry a year (psscene
 * with a weather file), the expected task lux per unit of daylight sensor
 * response for this month and hour of day under the sky condition the
 * weather file makes typical there (the class with the most hours in that
 * month and hour: clear, intermediate or overcast by Perez clearness),
 * instead of one mean ratio for every hour. */
#ifndef PSD_DATED_H
#define PSD_DATED_H

#include "results.h"

/* The ratio for month (1-12) at tod_s seconds after midnight (standard
 * time); *cls gets the sky class used.  NAN when the results have no year
 * or the year has no hour with light in that month and hour. */
double psd_dated_ratio(const struct ps_results *r, int month, double tod_s, int *cls);
/* The hour of the day (0-23) the dated ratios file tod_s under (finite). */
int psd_dated_hour(double tod_s);
/* Month of "MM-DD", or of today (local time) when mmdd is NULL; 0 if malformed. */
int psd_dated_month(const char *mmdd);
/* Day of the year (1-365, February 29 counting as March 1st) of "MM-DD",
 * or of today when mmdd is NULL or empty; 0 if malformed. */
int psd_dated_day(const char *mmdd);

/* With a rooftop sensor (a point with role rooftop named by the zone's
 * rooftop key): the class of the sky now from its global horizontal lux
 * (sim/sky/skyclass.h: clearness index, Erbs, Perez epsilon, the year's bins),
 * at the results' weather site, on day doy at tod_s (the clock's time of
 * day, taken as standard time).  -1 when the results carry no site, the sun
 * is below 5 degrees or the reading is not finite; the caller then uses
 * the typical class. */
int psd_dated_rooftop_class(const struct ps_results *r, int doy, double tod_s, double lux);
/* The ratio for month and hour under sky class cls; NAN when the year has
 * no hour of that class there. */
double psd_dated_ratio_class(const struct ps_results *r, int month, double tod_s, int cls);

#endif
