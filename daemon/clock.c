/* SPDX-License-Identifier: ISC */
#include "clock.h"

#include <math.h>
#include <stdio.h>

#include "time.h"

void psd_clock_real(struct psd_clock *c, double origin, double speed)
{
	c->simulated = 0;
	c->origin = origin;
	c->speed = speed > 0 ? speed : 1;
	c->now = origin;
	c->epoch0 = NAN;
	c->mono0 = psd_time_mono();
}

void psd_clock_simulated(struct psd_clock *c, double origin)
{
	c->simulated = 1;
	c->origin = origin;
	c->speed = 1;
	c->now = origin;
	c->mono0 = 0;
	c->epoch0 = NAN;
}

double psd_clock_now(struct psd_clock *c)
{
	if (c->simulated)
		return c->now;
	c->now = c->origin + c->speed * (psd_time_mono() - c->mono0);
	return c->now;
}

int psd_clock_wait_ms(struct psd_clock *c, double deadline, int max_ms)
{
	double ms;
	if (c->simulated)
		return 0;
	if (isinf(deadline) && deadline > 0)
		return max_ms;
	ms = ceil((deadline - psd_clock_now(c)) / c->speed * 1000.0);
	if (ms <= 0)
		return 0;
	return ms > max_ms ? max_ms : (int)ms;
}

void psd_clock_advance(struct psd_clock *c, double deadline)
{
	if (c->simulated && deadline > c->now && isfinite(deadline))
		c->now = deadline;
}

double psd_clock_local_tod(void)
{
	double now = psd_time_wall();
	struct tm tm;
	if (psd_time_local(now, &tm) != 0)
		return psd_clock_tod(now);
	return tm.tm_hour * 3600.0 + tm.tm_min * 60.0 + tm.tm_sec + (now - floor(now));
}

double psd_clock_tod(double t)
{
	double tod = fmod(t, 86400.0);
	return tod < 0 ? tod + 86400.0 : tod;
}

double psd_clock_dst_shift(double utc)
{
	time_t t;
	struct tm tm;
	if (!isfinite(utc))
		return 0;
	t = (time_t)floor(utc);
	tzset();   /* sets timezone: seconds west of UTC in standard time */
	if (!localtime_r(&t, &tm) || tm.tm_isdst <= 0)
		return 0;
	return (double)(tm.tm_gmtoff + timezone);
}

double psd_clock_dst_shift_day(const char *mmdd, double midnight_utc)
{
	if (!isfinite(midnight_utc)) {
		time_t now = time(NULL);
		struct tm tm;
		int m, d;
		if (!mmdd || sscanf(mmdd, "%d-%d", &m, &d) != 2 || !localtime_r(&now, &tm) ||
		    psd_clock_midnight(tm.tm_year + 1900, m, d, &midnight_utc) != 0)
			return 0;
	}
	return psd_clock_dst_shift(midnight_utc + 43200);
}

void psd_clock_hhmm(double t, char out[8])
{
	int m = (int)floor(psd_clock_tod(t) / 60 + 1e-9);
	snprintf(out, 8, "%02d:%02d", (m / 60) % 24, m % 60);
}

int psd_clock_midnight(int year, int month, int day, double *epoch)
{
	struct tm tm = { 0 };
	time_t t;
	if (year < 1970 || year > 9999 || month < 1 || month > 12 || day < 1 || day > 31)
		return -1;
	tm.tm_year = year - 1900;
	tm.tm_mon = month - 1;
	tm.tm_mday = day;
	tm.tm_isdst = -1;
	t = mktime(&tm);
	/* mktime normalises 02-30 to 03-02: that is no date */
	if (t == (time_t)-1 || tm.tm_mday != day || tm.tm_mon != month - 1)
		return -1;
	*epoch = (double)t;
	return 0;
}

int psd_clock_parse_date(const char *s, double *epoch)
{
	int y, m, d, n = 0;
	if (!s || sscanf(s, "%4d-%2d-%2d%n", &y, &m, &d, &n) != 3 || s[n])
		return -1;
	return psd_clock_midnight(y, m, d, epoch);
}

void psd_clock_stamp(double epoch0, double t, char *out, size_t n)
{
	if (!isfinite(epoch0) || !isfinite(t)) {
		char hm[8];
		psd_clock_hhmm(t, hm);
		snprintf(out, n, "%s", hm);
		return;
	}
	if (psd_time_local_text(epoch0 + t + 1e-6, PSD_TIME_MINUTE, out, n) != 0)
		snprintf(out, n, "?");
}

void psd_clock_duration(double s, char *out, size_t n)
{
	long m = lround(s / 60);
	if (!(s >= 0) || !isfinite(s))
		snprintf(out, n, "?");
	else if (s < 60)
		snprintf(out, n, "%.0f s", s);
	else if (m < 60)
		snprintf(out, n, "%ld min", m);
	else
		snprintf(out, n, "%ld h %ld min", m / 60, m % 60);
}
