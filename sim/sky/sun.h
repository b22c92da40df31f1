/* SPDX-License-Identifier: ISC */
/* The sun's position from the date, the standard time and the site, with the
 * approximate formulas of the IES Lighting Handbook that Radiance's gensky
 * and gendaymtx use (declination and equation of time as sines of the day of
 * the year), so that a sky matrix agrees with Radiance's hour by hour.
 * Against the Astronomical Almanac's algorithm (ps_sun_almanac, 0.01 degree)
 * over a year, hour by hour, their declination errs by up to 1.23 degrees,
 * their equation of time by up to 1.4 minutes and the sun's direction by up
 * to 1.13 degrees (test_sky measures it).
 *
 * Conventions: latitude north positive, longitude EAST positive, time zone in
 * hours EAST of Greenwich (standard time: -8 for US Pacific).  A .wea file
 * states longitude and time zone the other way round (degrees west); the
 * weather readers convert.  Azimuth is measured from north towards east, in
 * Radiance's scene axes (X east, Y north, Z up). */
#ifndef PS_SUN_H
#define PS_SUN_H

struct ps_site {
	char name[128];      /* place (and country), as the weather file names it */
	double lat;          /* degrees north */
	double lon;          /* degrees east (west negative) */
	double tz;           /* standard time zone, hours east of Greenwich */
	double elevation;    /* metres */
};

struct ps_sunpos {
	double alt;          /* altitude above the horizon, radians (negative at night) */
	double azi;          /* azimuth from north towards east, radians in [0, 2 pi) */
	double decl;         /* declination, radians */
	double solar_hour;   /* apparent solar time, hours (12 = solar noon) */
};

/* Day of the year (1 = January 1st) for month 1-12 and day 1-31; leap = 1
 * counts February 29 and shifts the days after it by one. */
int ps_sun_day_of_year(int month, int day, int leap);
/* Equation of time, hours (apparent solar minus mean solar time). */
double ps_sun_equation_of_time(int doy);
/* Apparent solar time (hours) at standard time std_hour on day doy. */
double ps_sun_solar_hour(const struct ps_site *s, int doy, double std_hour);
/* Position of the sun at standard time std_hour (decimal hours) on day doy. */
void ps_sun_position(const struct ps_site *s, int doy, double std_hour, struct ps_sunpos *p);
/* The Astronomical Almanac's approximate solar position (Michalsky 1988,
 * Solar Energy 40(3) 227-235; 0.01 degree from 1950 to 2050) at standard
 * time std_hour of a calendar date (the real year, leap years counted);
 * no refraction.  For checking the IES formulas; the sky uses those. */
void ps_sun_almanac(const struct ps_site *s, int year, int month, int day, double std_hour,
                    struct ps_sunpos *p);
/* The Almanac's declination (radians) and equation of time (hours) at a
 * Julian date. */
void ps_sun_almanac_jd(double jd, double *decl, double *eot);
/* Unit vector of altitude and azimuth (X east, Y north, Z up). */
void ps_sun_direction(double alt, double azi, double dir[3]);

#endif
