/* SPDX-License-Identifier: ISC */
/* A weather series: the hours of a Radiance .wea or an EnergyPlus .epw file,
 * each with its date, standard time, direct and diffuse values, the dew point
 * the sky model uses and the sun's position.
 *
 * Reading is all or nothing: any bad line gives an error naming file:line
 * and the series stays empty.  The rules (see pssky(1), WEATHER FILES):
 *   - the header must name the site (a non-empty place, latitude, longitude,
 *     time zone, elevation, in range);
 *   - every data line has exactly its fields (5 in a .wea, 35 in an .epw),
 *     finite numbers, no negative irradiance or illuminance, a real date
 *     (February 29 allowed) and a time of day in range;
 *   - times increase strictly through the file (month, day, hour; an .epw's
 *     year column is not compared: typical years mix years month by month);
 *   - a file with February 29 is a leap year: the days after it are one
 *     later in the year, as gendaymtx counts them;
 *   - the dew point (.epw field 8) is the mean of the reading and the two
 *     before it, as gendaymtx; a missing one (99.9) takes the previous
 *     hour's value (11 C before any), and the mean restarts after it.
 *     A .wea has no dew point: 11 C throughout (Perez's and Radiance's
 *     default). */
#ifndef PS_WEATHER_H
#define PS_WEATHER_H

#include <stddef.h>

#include "err.h"
#include "sun.h"

enum ps_wx_format { PS_WX_WEA = 1, PS_WX_EPW = 2 };

/* What the two values of a step are (.wea weather_data_file_units). */
enum ps_wx_units {
	PS_WX_DN_DH = 1,     /* direct normal, diffuse horizontal irradiance, W/m2 */
	PS_WX_DHOR_DH = 2,   /* direct horizontal, diffuse horizontal irradiance, W/m2 */
	PS_WX_ILLUM = 3      /* direct normal, diffuse horizontal illuminance, lux */
};

/* Reading flags. */
enum { PS_WX_EPW_ILLUM = 1 };   /* take an .epw's illuminances (fields 18, 19) */

#define PS_WX_DEW_DEFAULT 11.0  /* C, when the file gives none */
#define PS_WX_MAX_STEPS 1100000 /* a year at half a minute */
#define PS_WX_MAX_FILE (256u << 20)

struct ps_wx_step {
	int month, day;      /* 1-12, 1-31 */
	int doy;             /* day of the year, 1-366 */
	double hour;         /* standard time, decimal hours (an hourly .epw record: its middle) */
	double dir, dif;     /* the two values, in the series' units */
	double dew;          /* dew point for the sky model, C */
	int dew_given;       /* 1: from the file's readings; 0: substituted */
	int line;            /* line in the file */
	struct ps_sunpos sun;
};

struct ps_weather {
	char name[256];      /* the file, for messages */
	int format;          /* enum ps_wx_format */
	int units;           /* enum ps_wx_units */
	struct ps_site site;
	int per_hour;        /* records an hour (an .epw's DATA PERIODS; 1 for a .wea) */
	int leap;            /* the file has February 29 */
	size_t n;            /* steps */
	struct ps_wx_step *step;
	size_t cap;          /* steps allocated */
	size_t dew_missing;  /* .epw records whose dew point was missing */
};

/* Read a .wea or .epw (told apart by the first line).  flags: PS_WX_EPW_ILLUM. */
int ps_weather_read(struct ps_weather *w, const char *path, unsigned flags, struct ps_err *e);
/* The same from memory; name is used in messages. */
int ps_weather_parse(struct ps_weather *w, const char *text, size_t len, const char *name,
                     unsigned flags, struct ps_err *e);
void ps_weather_free(struct ps_weather *w);

#endif
