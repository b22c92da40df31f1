/* SPDX-License-Identifier: ISC */
#include "chart.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>

/* Ticks k * step for every whole k with lo <= k * step <= hi (a little
 * slack so that a range ending on a tick keeps it). */
static int fill(double lo, double hi, double step, struct psd_ticks *t)
{
	double eps = step * 1e-9;
	double k0 = ceil((lo - eps) / step), k1 = floor((hi + eps) / step);
	t->n = 0;
	t->step = step;
	if (k1 - k0 + 1 > PSD_TICKS_MAX)
		return -1;
	for (double k = k0; k <= k1; k++) {
		double v = k * step;
		t->v[t->n++] = fabs(v) < eps ? 0 : v;
	}
	return 0;
}

static int bad(double lo, double hi, int max)
{
	return !isfinite(lo) || !isfinite(hi) || hi < lo || max < 2;
}

int psd_chart_ticks_num(double lo, double hi, int max, struct psd_ticks *t)
{
	static const double mult[] = { 1, 2, 5 };
	double span, p;
	if (bad(lo, hi, max)) {
		errno = EINVAL;
		return -1;
	}
	if (max > PSD_TICKS_MAX)
		max = PSD_TICKS_MAX;
	span = hi - lo;
	if (span <= 0)
		span = fabs(hi) > 0 ? fabs(hi) : 1;
	/* start a decade below span / max: the first step that fits wins */
	p = pow(10, floor(log10(span / max)) - 1);
	for (int d = 0; d < 4; d++, p *= 10)
		for (int m = 0; m < 3; m++) {
			double step = mult[m] * p;
			if (fill(lo, hi, step, t) == 0 && t->n <= max) {
				double l = floor(log10(step) + 1e-9);
				t->decimals = l >= 0 ? 0 : (int)-l;
				return 0;
			}
		}
	errno = ERANGE;
	return -1;
}

int psd_chart_ticks_time(double lo, double hi, int max, struct psd_ticks *t)
{
	static const double steps[] = { 300, 600, 900, 1800, 3600, 7200, 10800, 21600, 43200, 86400,
	                                2 * 86400, 7 * 86400, 14 * 86400, 28 * 86400 };
	if (bad(lo, hi, max)) {
		errno = EINVAL;
		return -1;
	}
	if (max > PSD_TICKS_MAX)
		max = PSD_TICKS_MAX;
	for (size_t i = 0; i < sizeof steps / sizeof steps[0]; i++)
		if (fill(lo, hi, steps[i], t) == 0 && t->n <= max) {
			t->decimals = 0;
			return 0;
		}
	errno = ERANGE;
	return -1;
}

void psd_chart_ticks_round_range(double *lo, double *hi, int max)
{
	struct psd_ticks t;
	if (psd_chart_ticks_num(*lo, *hi, max, &t) != 0)
		return;
	/* widen to the neighbouring ticks, then make sure they still fit max */
	for (int tries = 0; tries < 4; tries++) {
		double l = floor(*lo / t.step + 1e-9) * t.step, h = ceil(*hi / t.step - 1e-9) * t.step;
		if (h <= l)
			h = l + t.step;
		if (psd_chart_ticks_num(l, h, max, &t) == 0 && t.n >= 2 && fabs(t.v[0] - l) < t.step * 1e-6 &&
		    fabs(t.v[t.n - 1] - h) < t.step * 1e-6) {
			*lo = l;
			*hi = h;
			return;
		}
		*lo = l;
		*hi = h;
	}
}

void psd_chart_tick_num_label(const struct psd_ticks *t, double v, char *buf, size_t n)
{
	snprintf(buf, n, "%.*f", t->decimals, v);
}

void psd_chart_tick_time_label(double seconds, char *buf, size_t n)
{
	long s = lround(fmod(fmod(seconds, 86400) + 86400, 86400));
	snprintf(buf, n, "%02ld:%02ld", s / 3600 % 24, s / 60 % 60);
}
