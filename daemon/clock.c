/* SPDX-License-Identifier: ISC */
#include "clock.h"

#include <math.h>
#include <stdio.h>

void psd_clock_real(struct psd_clock *c, double origin, double speed)
{
	c->simulated = 0;
	c->origin = origin;
	c->speed = speed > 0 ? speed : 1;
	c->now = origin;
	clock_gettime(CLOCK_MONOTONIC, &c->mono0);
}

void psd_clock_simulated(struct psd_clock *c, double origin)
{
	c->simulated = 1;
	c->origin = origin;
	c->speed = 1;
	c->now = origin;
	c->mono0.tv_sec = c->mono0.tv_nsec = 0;
}

double psd_clock_now(struct psd_clock *c)
{
	struct timespec t;
	if (c->simulated)
		return c->now;
	clock_gettime(CLOCK_MONOTONIC, &t);
	c->now = c->origin + c->speed * ((double)(t.tv_sec - c->mono0.tv_sec) +
	                                 1e-9 * (double)(t.tv_nsec - c->mono0.tv_nsec));
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
	struct timespec ts;
	struct tm tm;
	clock_gettime(CLOCK_REALTIME, &ts);
	localtime_r(&ts.tv_sec, &tm);
	return tm.tm_hour * 3600.0 + tm.tm_min * 60.0 + tm.tm_sec + ts.tv_nsec * 1e-9;
}

double psd_clock_tod(double t)
{
	double tod = fmod(t, 86400.0);
	return tod < 0 ? tod + 86400.0 : tod;
}

void psd_clock_hhmm(double t, char out[8])
{
	int m = (int)floor(psd_clock_tod(t) / 60 + 1e-9);
	snprintf(out, 8, "%02d:%02d", (m / 60) % 24, m % 60);
}
