/* From the scene's precomputed results to the virtual room's parameters. */
#ifndef PSD_ROOMSETUP_H
#define PSD_ROOMSETUP_H

#include "results.h"
#include "room.h"

enum { PSD_DAY_POINTS = 97 };   /* every 15 minutes, midnight to midnight */

/* Build a day of daylight for day-of-year doy from the results' daylight
 * conditions, into day[PSD_DAY_POINTS], and the electric responses into p.
 * The scene gives daylight at a few dates and times; between them this
 * assumes a clear sky: each condition's value is scaled over the day by
 * sin(pi (t - sunrise) / (sunset - sunrise)), relative to its own time, and
 * conditions at other dates are interpolated linearly in day of year.
 * Returns -1 when the results have no electric or no daylight condition. */
int psd_room_from_results(const struct ps_results *r, int doy, double sunrise, double sunset,
                          struct ps_room_daypoint *day, struct ps_room_params *p);
/* Day of year of "MM-DD" (non-leap year); -1 if malformed. */
int psd_day_of_year(const char *mmdd);

#endif
