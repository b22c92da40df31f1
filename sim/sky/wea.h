/* SPDX-License-Identifier: ISC */
/* Radiance / DAYSIM .wea weather files:
 *   place <name>                     (any text; city_country by convention)
 *   latitude <degrees north>
 *   longitude <degrees WEST>
 *   time_zone <degrees WEST of the standard meridian: 120 for US Pacific>
 *   site_elevation <metres>
 *   weather_data_file_units <1|2|3>
 *   month day hour direct diffuse    (one line per time step)
 * units 1: direct normal and diffuse horizontal irradiance (W/m2);
 *       2: direct horizontal and diffuse horizontal irradiance (W/m2);
 *       3: direct normal and diffuse horizontal illuminance (lux)
 * (as Radiance's gendaymtx reads them).  hour is standard time in decimal
 * hours (5.5 is the hour from 5 to 6).  Blank lines are skipped. */
#ifndef PS_WEA_H
#define PS_WEA_H

#include <stddef.h>

#include "err.h"
#include "weather.h"

/* Parse the header and the steps into w (started with ps_series_init);
 * the caller finishes with ps_series_finish. */
int ps_wea_parse(struct ps_weather *w, const char *text, size_t len, struct ps_err *e);

#endif
