#include "dated.h"

#include <math.h>
#include <stdio.h>
#include <time.h>

double psd_dated_ratio(const struct ps_results *r, int month, double tod_s, int *cls)
{
	const struct ps_year *y = &r->year;
	int h, best = -1, most = 0;
	if (!r->have_year || month < 1 || month > 12 || !isfinite(tod_s))
		return NAN;
	h = (int)floor(fmod(fmod(tod_s, 86400.0) + 86400.0, 86400.0) / 3600.0);
	if (h > 23)
		h = 23;
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

int psd_dated_month(const char *mmdd)
{
	int m, d, n = 0;
	if (!mmdd) {
		time_t t = time(NULL);
		struct tm tm;
		return localtime_r(&t, &tm) ? tm.tm_mon + 1 : 0;
	}
	if (sscanf(mmdd, "%d-%d%n", &m, &d, &n) != 2 || mmdd[n] || m < 1 || m > 12)
		return 0;
	return m;
}
