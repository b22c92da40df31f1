/* SPDX-License-Identifier: ISC */
#include "dated.h"

#include <math.h>
#include <stdio.h>
#include <time.h>

#include "skyclass.h"
#include "time.h"

/* fmod(fmod(tod_s, 86400) + 86400, 86400), the same number without the
 * calls when tod_s is within the day: the sum is in (0, 172800], where
 * fmod is a subtraction (exact: Sterbenz) or nothing */
static double day_mod(double tod_s)
{
	double x = (tod_s >= 0 && tod_s < 86400.0 ? tod_s : fmod(tod_s, 86400.0)) + 86400.0;
	return x >= 172800.0 ? x - 172800.0 : x >= 86400.0 ? x - 86400.0 : x;
}

int psd_dated_hour(double tod_s)
{
	int h = (int)floor(day_mod(tod_s) / 3600.0);
	return h > 23 ? 23 : h;
}

double psd_dated_ratio(const struct ps_results *r, int month, double tod_s, int *cls)
{
	const struct ps_year *y = &r->year;
	int h, best = -1, most = 0;
	if (!r->have_year || month < 1 || month > 12 || !isfinite(tod_s))
		return NAN;
	h = psd_dated_hour(tod_s);
	for (int c = 0; c < PS_SKY_NCLASS; c++)
		if (y->count[month - 1][h][c] > most) {
			most = y->count[month - 1][h][c];
			best = c;
		}
	if (best < 0)
		return NAN;
	if (cls)
		*cls = best;
	return y->ratio[month - 1][h][best];
}


double psd_dated_ratio_class(const struct ps_results *r, int month, double tod_s, int cls)
{
	int h;
	if (!r->have_year || month < 1 || month > 12 || !isfinite(tod_s) || cls < 0 || cls >= PS_SKY_NCLASS)
		return NAN;
	h = psd_dated_hour(tod_s);
	return r->year.count[month - 1][h][cls] > 0 ? r->year.ratio[month - 1][h][cls] : NAN;
}

int psd_dated_rooftop_class(const struct ps_results *r, int doy, double tod_s, double lux)
{
	if (!r->have_year || !r->year.have_site || !isfinite(tod_s))
		return -1;
	return ps_skyclass_from_global(&r->year.site, doy, day_mod(tod_s) / 3600.0,
	                               lux, NULL, NULL);
}

int psd_dated_day(const char *mmdd)
{
	static const int start[12] = { 0, 31, 59, 90, 120, 151, 181, 212, 243, 273, 304, 334 };
	int m, d, n = 0;
	if (!mmdd || !*mmdd) {
		struct tm tm;
		if (psd_time_local(psd_time_wall(), &tm) != 0)
			return 0;
		m = tm.tm_mon + 1;
		d = tm.tm_mday;
	} else if (sscanf(mmdd, "%d-%d%n", &m, &d, &n) != 2 || mmdd[n] || m < 1 || m > 12 || d < 1 || d > 31) {
		return 0;
	}
	return start[m - 1] + d > 365 ? 365 : start[m - 1] + d;
}

int psd_dated_month(const char *mmdd)
{
	int m, d, n = 0;
	if (!mmdd) {
		struct tm tm;
		return psd_time_local(psd_time_wall(), &tm) == 0 ? tm.tm_mon + 1 : 0;
	}
	if (sscanf(mmdd, "%d-%d%n", &m, &d, &n) != 2 || mmdd[n] || m < 1 || m > 12)
		return 0;
	return m;
}
