/* SPDX-License-Identifier: ISC */
#include "sun.h"

#include <math.h>

/* days before each month in a common year */
static const int month_start[12] = { 0, 31, 59, 90, 120, 151, 181, 212, 243, 273, 304, 334 };

int ps_sun_day_of_year(int month, int day, int leap)
{
	if (month < 1 || month > 12)
		return 0;
	return month_start[month - 1] + day + (leap && month > 2 ? 1 : 0);
}

/* Declination (radians) on a day of the year. */
static double ps_sun_declination(int doy)
{
	/* amplitude 0.4093 rad (23.45 degrees), zero at the March equinox (day 81) */
	return 0.4093 * sin(2.0 * M_PI * (doy - 81) / 365.0);
}

double ps_sun_equation_of_time(int doy)
{
	return 0.170 * sin(4.0 * M_PI * (doy - 80) / 373.0) -
	       0.129 * sin(2.0 * M_PI * (doy - 8) / 355.0);
}

double ps_sun_solar_hour(const struct ps_site *s, int doy, double std_hour)
{
	/* four minutes a degree between the site and its time zone's meridian */
	return std_hour + ps_sun_equation_of_time(doy) + s->lon / 15.0 - s->tz;
}

void ps_sun_position(const struct ps_site *s, int doy, double std_hour, struct ps_sunpos *p)
{
	double lat = s->lat * (M_PI / 180.0);
	double d = ps_sun_declination(doy);
	double t = ps_sun_solar_hour(s, doy, std_hour);
	double h = (t - 12.0) * (M_PI / 12.0);      /* hour angle, positive after noon */
	double sa = sin(lat) * sin(d) + cos(lat) * cos(d) * cos(h);
	/* azimuth from south, positive towards west, then turned to north-east */
	double from_south = atan2(cos(d) * sin(h), sin(lat) * cos(d) * cos(h) - cos(lat) * sin(d));
	double azi = from_south + M_PI;
	if (sa > 1.0)
		sa = 1.0;
	else if (sa < -1.0)
		sa = -1.0;
	if (azi >= 2.0 * M_PI)
		azi -= 2.0 * M_PI;
	else if (azi < 0.0)
		azi += 2.0 * M_PI;
	p->alt = asin(sa);
	p->azi = azi;
	p->decl = d;
	p->solar_hour = t;
}

void ps_sun_direction(double alt, double azi, double dir[3])
{
	double c = cos(alt);
	dir[0] = c * sin(azi);
	dir[1] = c * cos(azi);
	dir[2] = sin(alt);
}

/* Julian date of 0h UT of a Gregorian calendar date (Meeus, chapter 7). */
static double julian_day(int year, int month, int day)
{
	int a, b;
	if (month <= 2) {
		year -= 1;
		month += 12;
	}
	a = year / 100;
	b = 2 - a + a / 4;
	return floor(365.25 * (year + 4716)) + floor(30.6001 * (month + 1)) + day + b - 1524.5;
}

static double wrap(double x, double period)
{
	x = fmod(x, period);
	return x < 0 ? x + period : x;
}

void ps_sun_almanac_jd(double jd, double *decl, double *eot)
{
	const double deg = M_PI / 180.0;
	double n = jd - 2451545.0;                        /* days from J2000.0 */
	double L = wrap(280.460 + 0.9856474 * n, 360.0);  /* mean longitude */
	double g = wrap(357.528 + 0.9856003 * n, 360.0) * deg;   /* mean anomaly */
	double lam = (L + 1.915 * sin(g) + 0.020 * sin(2 * g)) * deg;   /* ecliptic longitude */
	double eps = (23.439 - 4e-7 * n) * deg;           /* obliquity */
	double ra = atan2(cos(eps) * sin(lam), cos(lam));
	double e = wrap(L * deg - ra + M_PI, 2 * M_PI) - M_PI;
	*decl = asin(sin(eps) * sin(lam));
	*eot = e * (12.0 / M_PI);
}

void ps_sun_almanac(const struct ps_site *s, int year, int month, int day, double std_hour,
                    struct ps_sunpos *p)
{
	double ut = std_hour - s->tz, jd = julian_day(year, month, day) + ut / 24.0, d, eot;
	double lat = s->lat * (M_PI / 180.0), h, sa, from_south, azi;
	ps_sun_almanac_jd(jd, &d, &eot);
	p->solar_hour = ut + s->lon / 15.0 + eot;
	h = (p->solar_hour - 12.0) * (M_PI / 12.0);
	sa = sin(lat) * sin(d) + cos(lat) * cos(d) * cos(h);
	from_south = atan2(cos(d) * sin(h), sin(lat) * cos(d) * cos(h) - cos(lat) * sin(d));
	azi = wrap(from_south + M_PI, 2 * M_PI);
	p->alt = asin(sa > 1 ? 1 : sa < -1 ? -1 : sa);
	p->azi = azi;
	p->decl = d;
}
