/* SPDX-License-Identifier: ISC */
/* The daemon's clocks, HH:MM and dates: see time.h. */
#include "time.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static double seconds_of(clockid_t id)
{
	struct timespec ts;
	clock_gettime(id, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

double psd_time_mono(void)
{
	return seconds_of(CLOCK_MONOTONIC);
}

double psd_time_wall(void)
{
	return seconds_of(CLOCK_REALTIME);
}

double psd_time_thread_cpu(void)
{
	return seconds_of(CLOCK_THREAD_CPUTIME_ID);
}

/* Unix seconds that time_t and struct tm hold without overflow: years
 * 1970 +- 3000, and no NaN. */
static int sane(double utc)
{
	return utc >= -1e11 && utc <= 1e11;
}

int psd_time_local(double utc, struct tm *tm)
{
	time_t t;
	if (!sane(utc))
		return -1;
	t = (time_t)floor(utc);
	return localtime_r(&t, tm) ? 0 : -1;
}

static int digit(char c)
{
	return c >= '0' && c <= '9';
}

int psd_time_hhmm_scan(const char *s, int *h, int *m)
{
	int i = 0, hh = 0, mm;
	if (!s || !digit(s[0]))
		return -1;
	while (i < 2 && digit(s[i]))
		hh = hh * 10 + (s[i++] - '0');
	if (s[i] != ':' || !digit(s[i + 1]) || !digit(s[i + 2]))
		return -1;
	mm = (s[i + 1] - '0') * 10 + (s[i + 2] - '0');
	if (hh > 23 || mm > 59)
		return -1;
	*h = hh;
	*m = mm;
	return i + 3;
}

int psd_time_hhmm(const char *s, double *seconds)
{
	int h, m, n = psd_time_hhmm_scan(s, &h, &m);
	if (n < 0 || s[n])
		return -1;
	*seconds = h * 3600.0 + m * 60.0;
	return 0;
}

/* strftime with the form's format (literals, so the compiler checks them) */
static size_t form_text(int form, const struct tm *tm, char *out, size_t n)
{
	switch (form) {
	case PSD_TIME_DATE:
		return strftime(out, n, "%Y-%m-%d", tm);
	case PSD_TIME_MINUTE:
		return strftime(out, n, "%Y-%m-%d %H:%M", tm);
	case PSD_TIME_SECOND:
		return strftime(out, n, "%Y-%m-%d %H:%M:%S", tm);
	default:   /* the ISO forms */
		return strftime(out, n, "%Y-%m-%dT%H:%M:%S", tm);
	}
}

static int text(double utc, int form, int local, char *out, size_t n)
{
	struct tm tm;
	time_t t;
	size_t len;
	int z = !local && (form == PSD_TIME_ISO || form == PSD_TIME_ISO_MS);
	if (n == 0)
		return -1;
	out[0] = 0;
	if (form < PSD_TIME_DATE || form > PSD_TIME_ISO_MS || !sane(utc))
		return -1;
	t = (time_t)floor(utc);
	if (!(local ? localtime_r(&t, &tm) : gmtime_r(&t, &tm)))
		return -1;
	len = form_text(form, &tm, out, n);
	if (len == 0) {
		out[0] = 0;
		return -1;
	}
	if (form == PSD_TIME_ISO_MS) {
		int ms = (int)floor((utc - (double)t) * 1000);
		int k = snprintf(out + len, n - len, ".%03d", ms > 999 ? 999 : ms);
		if (k < 0 || (size_t)k >= n - len) {
			out[0] = 0;
			return -1;
		}
		len += (size_t)k;
	}
	if (z) {
		if (len + 2 > n) {
			out[0] = 0;
			return -1;
		}
		out[len] = 'Z';
		out[len + 1] = 0;
	}
	return 0;
}

int psd_time_utc_text(double utc, int form, char *out, size_t n)
{
	return text(utc, form, 0, out, n);
}

int psd_time_local_text(double utc, int form, char *out, size_t n)
{
	return text(utc, form, 1, out, n);
}
