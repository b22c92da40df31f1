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
/* Month of "MM-DD", or of today (local time) when mmdd is NULL; 0 if malformed. */
int psd_dated_month(const char *mmdd);

#endif
