/* SPDX-License-Identifier: ISC */
#include "roomsetup.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "driver.h"
#include "room.h"
#include "scene.h"

int psd_roomsetup_day_of_year(const char *mmdd)
{
	static const int start[12] = { 0, 31, 59, 90, 120, 151, 181, 212, 243, 273, 304, 334 };
	/* February 29 is a day a leap year's weather plays (else the 28th's) */
	static const int days[12] = { 31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31 };
	int m, d, n = 0;
	if (!mmdd || sscanf(mmdd, "%d-%d%n", &m, &d, &n) != 2 || mmdd[n] || m < 1 || m > 12 || d < 1 ||
	    d > days[m - 1])
		return -1;
	return start[m - 1] + d;
}

static double shape(double t, double sunrise, double sunset)
{
	if (t <= sunrise || t >= sunset)
		return 0.0;
	return sin(M_PI * (t - sunrise) / (sunset - sunrise));
}

/* month and day of day-of-year doy (non-leap) */
static void month_day(int doy, int *m, int *d)
{
	static const int start[13] = { 0, 31, 59, 90, 120, 151, 181, 212, 243, 273, 304, 334, 365 };
	int k = 0;
	while (k < 11 && doy > start[k + 1])
		k++;
	*m = k + 1;
	*d = doy - start[k];
}

int psd_roomsetup_has_feb29(const struct ps_results *r)
{
	if (r->have_year && r->year.leap)
		return 1;   /* the weather file said so, even if the 29th is dark */
	for (size_t i = 0; r->have_year && i < r->year.n; i++)
		if (r->year.h[i].month == 2 && r->year.h[i].day == 29)
			return 1;
		else if (r->year.h[i].month > 2)
			break;   /* file order */
	return 0;
}

static int from_date(const struct ps_results *r, int m, int d, struct ps_room_daypoint *day,
                     struct ps_room_params *p);

int psd_roomsetup_from_year(const struct ps_results *r, int doy, struct ps_room_daypoint *day,
                       struct ps_room_params *p)
{
	int m, d;
	if (doy < 1 || doy > 366) {
		memset(p, 0, sizeof *p);
		return -1;
	}
	month_day(doy > 365 ? 365 : doy, &m, &d);
	return from_date(r, m, d, day, p);
}

/* A day of the results' year for a calendar date (month 1-12, day 1-31):
 * February 29 of a leap year's file plays its own hours. */
static int from_date(const struct ps_results *r, int m, int d, struct ps_room_daypoint *day,
                     struct ps_room_params *p)
{
	size_t lo = 0, hi, n = 0;
	memset(p, 0, sizeof *p);
	if (!r->have_year || isnan(r->electric_sensor_response) || m < 1 || m > 12 || d < 1 || d > 31)
		return -1;
	/* the hours are in file order: find the date's run (the first hour not
	 * before the date, by bisection: a year plays every day) */
	hi = r->year.n;
	while (lo < hi) {
		size_t mid = lo + (hi - lo) / 2;
		const struct ps_year_hour *h = &r->year.h[mid];
		if (h->month < m || (h->month == m && h->day < d))
			lo = mid + 1;
		else
			hi = mid;
	}
	hi = lo;
	while (hi < r->year.n && r->year.h[hi].month == m && r->year.h[hi].day == d)
		hi++;
	if (hi > lo) {
		/* dark a step before the first step with light and after the last:
		 * an hour, or the file's step when it is shorter */
		double first = 3600.0 * r->year.h[lo].hour, last = 3600.0 * r->year.h[hi - 1].hour;
		double step = 3600.0;
		if (hi - lo > 1) {
			double s1 = 3600.0 * (r->year.h[lo + 1].hour - r->year.h[lo].hour);
			if (s1 > 0 && s1 < step)
				step = s1;
		}
		day[n++] = (struct ps_room_daypoint){ fmax(0.0, first - step), 0.0, 0.0, 0.0 };
		for (size_t i = lo; i < hi && n < PSD_YEAR_DAY_POINTS - 1; i++) {
			double t = 3600.0 * r->year.h[i].hour;
			if (t <= day[n - 1].t)
				continue;   /* an hour at midnight's edge: keep the order strict */
			day[n++] = (struct ps_room_daypoint){ t, r->year.h[i].sensor, r->year.h[i].task_lux,
			                                          r->year.h[i].horiz_lux };
		}
		if (last + step > day[n - 1].t && n < PSD_YEAR_DAY_POINTS)
			day[n++] = (struct ps_room_daypoint){ fmin(86400.0, last + step), 0.0, 0.0, 0.0 };
	}
	p->daylight = day;
	p->ndaylight = n;
	p->elec_sensor = r->electric_sensor_response;
	p->elec_task_lux = r->electric_task_lux;
	return 0;
}

/* Build a day of daylight for day-of-year doy from the results' daylight
 * conditions, into day[PSD_DAY_POINTS], and the electric responses into p.
 * The scene gives daylight at a few dates and times; between them this
 * assumes a clear sky: each condition's value is scaled over the day by
 * sin(pi (t - sunrise) / (sunset - sunrise)), relative to its own time, and
 * conditions at other dates are interpolated linearly in day of year.
 * Returns -1 when the results have no electric or no daylight condition. */
static int from_results(const struct ps_results *r, int doy, double sunrise, double sunset,
                        struct ps_room_daypoint *day, struct ps_room_params *p)
{

	/* daylight at full sun-up shape (shape = 1) for the chosen day: nearest
	 * conditions in day of year on either side, linear between them */
	double best_lo = -1e9, best_hi = 1e9, s_lo = 0, s_hi = 0, l_lo = 0, l_hi = 0;
	int found = 0;
	memset(p, 0, sizeof *p);
	for (size_t i = 0; i < r->ncond; i++) {
		const struct ps_result_cond *c = &r->cond[i];
		double sh, d;
		if (!c->computed || c->kind != PS_COND_DAYLIGHT)
			continue;
		sh = shape(c->tod_s, sunrise, sunset);
		if (sh <= 0.05)
			continue;   /* too near night to scale from */
		d = psd_roomsetup_day_of_year(c->date) >= 0 ? psd_roomsetup_day_of_year(c->date) : doy;
		if (d <= doy && d > best_lo) {
			best_lo = d;
			s_lo = c->sensor_response / sh;
			l_lo = c->task_lux / sh;
		}
		if (d >= doy && d < best_hi) {
			best_hi = d;
			s_hi = c->sensor_response / sh;
			l_hi = c->task_lux / sh;
		}
		found = 1;
	}
	if (!found || isnan(r->electric_sensor_response))
		return -1;
	if (best_lo < -1e8) {
		s_lo = s_hi;
		l_lo = l_hi;
		best_lo = best_hi;
	}
	if (best_hi > 1e8) {
		s_hi = s_lo;
		l_hi = l_lo;
		best_hi = best_lo;
	}
	{
		double w = best_hi > best_lo ? (doy - best_lo) / (best_hi - best_lo) : 0.0;
		double s = s_lo + w * (s_hi - s_lo), l = l_lo + w * (l_hi - l_lo);
		for (int k = 0; k < PSD_DAY_POINTS; k++) {
			double t = k * 900.0, sh = shape(t, sunrise, sunset);
			day[k] = (struct ps_room_daypoint){ t, s * sh, l * sh, NAN };
		}
	}
	p->daylight = day;
	p->ndaylight = PSD_DAY_POINTS;
	p->elec_sensor = r->electric_sensor_response;
	p->elec_task_lux = r->electric_task_lux;
	return 0;
}

/* One block: the parameters, then the day they point to. */
struct roomsetup {
	struct ps_room_params p;
	struct ps_room_daypoint day[PSD_YEAR_DAY_POINTS];   /* a day of the scene uses the first PSD_DAY_POINTS */
};

struct ps_room_params *psd_roomsetup_new(const struct ps_results *r, const char *date, double sunrise,
                                         double sunset)
{
	struct roomsetup *rs;
	int doy = psd_roomsetup_day_of_year(date);
	if (doy < 0 || !(rs = malloc(sizeof *rs)))
		return NULL;
	if (from_results(r, doy, sunrise, sunset, rs->day, &rs->p) != 0) {
		free(rs);
		return NULL;
	}
	return &rs->p;
}

int psd_roomsetup_play_day(const struct ps_results *r, const struct psd_roomsetup_play *q)
{
	struct ps_room_daypoint day[PSD_YEAR_DAY_POINTS];
	struct ps_room_params p;
	struct ps_room *room;
	int steps = (int)floor(86400.0 / q->period + 0.5);
	if (q->period <= 0 || from_date(r, q->month, q->mday, day, &p) != 0)
		return -1;
	p.gain = q->gain;
	p.ballast = (struct ps_ballast_params){ q->ballast.fade_rate, q->ballast.min_level, q->ballast.lag_tau,
	                                        q->ballast.off_below_min };
	if (!(room = ps_room_new(&p, 0.0)))
		return -1;
	ps_room_command(room, 0.0, q->level0);
	for (int s = 0; s < steps; s++) {
		double t = s * q->period, volts, level, dv, dl, g, e0, e1;
		struct ps_truth a;
		if (q->lean && !(t >= q->busy_from && t < q->busy_to)) {
			level = q->law(q->ctx, t, NAN);
			ps_room_command(room, t, level);
			q->seen(q->ctx, t, level, NAN, NAN, NAN, NAN);
			continue;
		}
		if (ps_room_sensor(room, t, &volts) != 0)
			volts = 0;
		level = q->law(q->ctx, t, volts);
		ps_room_command(room, t, level);
		ps_room_daylight(room, t, &dv, &dl);
		if (q->lean || ps_room_rooftop(room, t, &g) != 0)
			g = NAN;
		/* the desk just after the command (looked at on a copy: the room's
		 * clock stays at t), and the lamp's light over the step, the
		 * ballast's own integral: the room run on to the next step, where
		 * the next reading would take it (nothing happens in between) */
		ps_room_truth(room, t + 1e-3, &a);
		e0 = ps_room_energy(room, t);
		e1 = ps_room_energy(room, t + q->period);
		if (q->task)
			a.task_lux = q->task(q->ctx, t + 1e-3, a.output);
		q->seen(q->ctx, t, level, (e1 - e0) / q->period, a.task_lux, dl, g);
	}
	ps_room_free(room);
	return 0;
}

struct ps_room_params *psd_roomsetup_new_year(const struct ps_results *r, const char *date, double shift_s)
{
	struct roomsetup *rs;
	int m = 0, d = 0;
	if (psd_roomsetup_day_of_year(date) < 0 || sscanf(date, "%d-%d", &m, &d) != 2 || !(rs = malloc(sizeof *rs)))
		return NULL;
	/* February 29 of a year without one: the 28th */
	if (m == 2 && d == 29 && !psd_roomsetup_has_feb29(r))
		d = 28;
	if (from_date(r, m, d, rs->day, &rs->p) != 0) {
		free(rs);
		return NULL;
	}
	for (size_t i = 0; i < rs->p.ndaylight; i++)
		rs->day[i].t += shift_s;
	return &rs->p;
}

void psd_roomsetup_free(struct ps_room_params *p)
{
	free(p);   /* the first member of its block */
}
