/* SPDX-License-Identifier: ISC */
/* EnergyPlus .epw weather files (EnergyPlus Auxiliary Programs, "EnergyPlus
 * Weather File (EPW) Data Dictionary"): eight header lines
 *   LOCATION,city,state,country,source,WMO,latitude,longitude,time zone,elevation
 *   DESIGN CONDITIONS,...  TYPICAL/EXTREME PERIODS,...  GROUND TEMPERATURES,...
 *   HOLIDAYS/DAYLIGHT SAVINGS,...  COMMENTS 1,...  COMMENTS 2,...
 *   DATA PERIODS,count,records per hour,name,start weekday,start,end
 * then one record a line of 35 comma-separated fields; the ones read here:
 *    1 year (not compared)  2 month  3 day  4 hour (1-24, the hour ending)
 *    5 minute  8 dew point (C; 99.9 = missing)
 *   15 direct normal, 16 diffuse horizontal irradiance (W/m2; 9999 = missing)
 *   18 direct normal, 19 diffuse horizontal illuminance (lux; >= 999900 missing)
 * A record's time is the middle of its interval: hour - 0.5 for hourly data,
 * hour - 1 + minute/60 - 1/(2 n) with n records an hour.  Irradiance is
 * used unless PS_WX_EPW_ILLUM asks for the illuminances; a missing value
 * that is used is an error naming the line; a missing dew point is
 * substituted (see weather.h). */
#ifndef PS_EPW_H
#define PS_EPW_H

#include <stddef.h>

#include "err.h"
#include "weather.h"

enum { PS_EPW_FIELDS = 35 };

/* Parse the header and the records into w (started with ps_series_init);
 * the caller finishes with ps_series_finish. */
int ps_epw_parse(struct ps_weather *w, const char *text, size_t len, unsigned flags,
                 struct ps_err *e);

#endif
