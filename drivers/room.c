/* SPDX-License-Identifier: ISC */
/* The virtual room (see room.h). */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "ballast.h"
#include "driver.h"
#include "room.h"

struct ps_room {
	struct ps_room_params p;
	struct ps_room_daypoint *day;
	struct ps_room_fault_window *faults;
	struct ps_ballast ballast;
	uint64_t rng;         /* splitmix64 state: reproducible noise */
	double last_volts;    /* for the stuck sensor */
	int have_last;
	size_t *hint;         /* the day's point last looked up (time moves on: the next
	                         look-up starts there); points at hint_at */
	size_t hint_at;
};

static uint64_t splitmix64(uint64_t *s)
{
	uint64_t z = (*s += 0x9e3779b97f4a7c15ULL);
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
	return z ^ (z >> 31);
}

/* standard normal by Box-Muller */
static double gauss(uint64_t *s)
{
	double u1 = ((splitmix64(s) >> 11) + 1.0) * 0x1p-53, u2 = (splitmix64(s) >> 11) * 0x1p-53;
	return sqrt(-2.0 * log(u1)) * cos(2 * M_PI * u2);
}

double ps_room_tod(double now)
{
	double t;
	if (now >= 0 && now < 86400.0)
		return now;   /* fmod's answer, without the call */
	t = fmod(now, 86400.0);
	return t < 0 ? t + 86400.0 : t;
}

struct ps_room *ps_room_new(const struct ps_room_params *p, double t0)
{
	struct ps_room *r = calloc(1, sizeof *r);
	if (!r)
		return NULL;
	r->p = *p;
	if (p->ndaylight) {
		r->day = malloc(p->ndaylight * sizeof *r->day);
		if (!r->day)
			goto fail;
		memcpy(r->day, p->daylight, p->ndaylight * sizeof *r->day);
	}
	if (p->nfaults) {
		r->faults = malloc(p->nfaults * sizeof *r->faults);
		if (!r->faults)
			goto fail;
		memcpy(r->faults, p->faults, p->nfaults * sizeof *r->faults);
	}
	r->p.daylight = r->day;
	r->p.faults = r->faults;
	r->hint = &r->hint_at;
	r->rng = p->seed;
	ps_ballast_init(&r->ballast, &p->ballast, t0, 1.0);
	return r;
fail:
	free(r->day);
	free(r);
	errno = ENOMEM;
	return NULL;
}

void ps_room_free(struct ps_room *r)
{
	if (!r)
		return;
	free(r->day);
	free(r->faults);
	free(r);
}

int ps_room_fault(const struct ps_room *r, double now)
{
	double tod = ps_room_tod(now);
	for (size_t i = 0; i < r->p.nfaults; i++) {
		const struct ps_room_fault_window *f = &r->faults[i];
		/* a window whose end is before its start crosses midnight */
		int in = f->start <= f->end ? (tod >= f->start && tod < f->end)
		                            : (tod >= f->start || tod < f->end);
		if (in)
			return f->kind;
	}
	return PS_ROOM_FAULT_NONE;
}

/* The day's three numbers at now, linear between its points (zero outside). */
static void day_at(const struct ps_room *r, double now, double *s, double *l, double *g)
{
	double tod = ps_room_tod(now);
	const struct ps_room_daypoint *d = r->day;
	size_t n = r->p.ndaylight;
	*s = *l = *g = 0;
	if (n && tod >= d[0].t && tod <= d[n - 1].t) {
		/* the last point at or before tod (binary search: replays hold a
		 * point per logged period) */
		size_t lo = 0, hi = n - 1, i = *r->hint;
		/* the last point at or before tod: the one looked up last, or the
		 * next, when it is (the day's points are in order) */
		if (i + 1 < n && d[i + 1].t <= tod && (i + 2 == n || d[i + 2].t > tod))
			lo = hi = i + 1;
		else if (i < n && d[i].t <= tod && (i + 1 == n || d[i + 1].t > tod))
			lo = hi = i;
		while (lo < hi) {
			size_t mid = (lo + hi + 1) / 2;
			if (d[mid].t <= tod)
				lo = mid;
			else
				hi = mid - 1;
		}
		i = *r->hint = lo;
		if (i + 1 < n && d[i + 1].t > d[i].t) {
			double w = (tod - d[i].t) / (d[i + 1].t - d[i].t);
			*s = d[i].sensor + w * (d[i + 1].sensor - d[i].sensor);
			*l = d[i].task_lux + w * (d[i + 1].task_lux - d[i].task_lux);
			*g = d[i].rooftop_lux + w * (d[i + 1].rooftop_lux - d[i].rooftop_lux);
		} else {
			*s = d[i].sensor;
			*l = d[i].task_lux;
			*g = d[i].rooftop_lux;
		}
	} else if (n && isnan(d[0].rooftop_lux))
		*g = NAN;
}

void ps_room_daylight(const struct ps_room *r, double now, double *volts, double *lux)
{
	double s, g;
	day_at(r, now, &s, lux, &g);
	*volts = r->p.gain * s;
}

int ps_room_rooftop(struct ps_room *r, double now, double *lux)
{
	double s, l, g;
	day_at(r, now, &s, &l, &g);
	if (isnan(g) || r->p.ndaylight == 0) {
		errno = ENODATA;
		return -1;
	}
	*lux = g < 0 ? 0 : g;
	return 0;
}

void ps_room_command(struct ps_room *r, double now, double level)
{
	if (ps_room_fault(r, now) == PS_ROOM_FAULT_BALLAST) {
		ps_ballast_advance(&r->ballast, now);
		return;
	}
	ps_ballast_command(&r->ballast, now, level);
}

double ps_room_output(struct ps_room *r, double now)
{
	ps_ballast_advance(&r->ballast, now);
	return r->ballast.output;
}

double ps_room_energy(struct ps_room *r, double now)
{
	ps_ballast_advance(&r->ballast, now);
	return r->ballast.energy;
}

/* The truth is looked at, never lived through: the ballast is advanced on a
 * copy, so asking what the desk gets before the next step (psensd's
 * statistics) cannot move the room's own clock ahead, where a command
 * arriving in between (an override) would be applied late. */
double ps_room_true_task_lux(const struct ps_room *r, double now)
{
	struct ps_truth t;
	ps_room_truth(r, now, &t);
	return t.task_lux;
}

void ps_room_truth(const struct ps_room *r, double now, struct ps_truth *t)
{
	struct ps_ballast b = r->ballast;
	ps_room_daylight(r, now, &t->daylight_v, &t->daylight_lux);
	ps_ballast_advance(&b, now);
	t->output = b.output;
	t->energy = b.energy;
	t->task_lux = t->daylight_lux + b.output * r->p.elec_task_lux;
}

int ps_room_sensor(struct ps_room *r, double now, double *volts)
{
	double dv, dl, v;
	switch (ps_room_fault(r, now)) {
	case PS_ROOM_FAULT_DROP:
	case PS_ROOM_FAULT_LATE:
		errno = ETIMEDOUT;
		return -1;
	case PS_ROOM_FAULT_OPEN:
		*volts = 0.0;
		return 0;
	case PS_ROOM_FAULT_SATURATED:
		*volts = r->p.saturation;
		return 0;
	case PS_ROOM_FAULT_STUCK:
		if (r->have_last) {
			*volts = r->last_volts;
			return 0;
		}
		break;
	default:
		break;
	}
	ps_room_daylight(r, now, &dv, &dl);
	if (ps_room_fault(r, now) == PS_ROOM_FAULT_OBSTRUCT)
		dv *= 0.5;
	v = dv + r->p.gain * ps_room_output(r, now) * r->p.elec_sensor + r->p.offset;
	if (r->p.noise > 0)
		v += r->p.noise * gauss(&r->rng);
	if (r->p.saturation > 0 && v > r->p.saturation)
		v = r->p.saturation;
	if (v < 0)
		v = 0;
	r->last_volts = v;
	r->have_last = 1;
	*volts = v;
	return 0;
}

int ps_room_task(struct ps_room *r, double now, double *lux)
{
	double v = ps_room_true_task_lux(r, now);
	if (r->p.task_noise > 0)
		v += r->p.task_noise * gauss(&r->rng);
	*lux = v < 0 ? 0 : v;
	return 0;
}
