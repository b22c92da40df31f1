/* SPDX-License-Identifier: ISC */
#include "annual.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "canvas.h"
#include "config.h"
#include "dali.h"
#include "dated.h"
#include "falsecolor.h"
#include "roomsetup.h"
#include "sum.h"
#include "time.h"

#define DAYS PSD_ANNUAL_MAX_DAYS   /* the pictures' stride */
#define ROWS 144   /* 10-minute rows */

static double clamp(double x, double lo, double hi)
{
	return x < lo ? lo : x > hi ? hi : x;
}

/* one run's state, for the room's callbacks */
struct run {
	const struct ps_results *r;
	const struct psd_annual_opt *o;
	struct psd_annual *a;
	struct psd_control c;
	struct ps_sum em[3], e2[3];
	int m, doy;
	double mean_ratio, dated, prev;
	double dated_at[12][24];   /* psd_dated_ratio by month and hour (it depends on nothing else) */
};

static double law(void *ctx, double t, double volts)
{
	struct run *u = ctx;
	u->prev = u->c.level;
	if (!(t >= u->o->occ_start && t < u->o->occ_end)) {
		u->c.level = 0;   /* nobody there: the lights off, as a vacancy sensor does */
		u->c.pending_dir = 0;
		return 0;
	}
	u->dated = isfinite(t) ? u->dated_at[u->m][psd_dated_hour(t)] : NAN;
	u->c.daylight_ratio = u->o->dated && u->dated > 0 ? u->dated : u->mean_ratio;
	{
		double level = psd_control_step(&u->c, volts, t);
		/* a DALI output sends the nearest arc power level */
		return u->o->dali && level > 0 ? ps_dali_level_to_fraction(ps_dali_fraction_to_level(level)) : level;
	}
}

double psd_annual_weather_step(const struct ps_results *r)
{
	double step = 0;
	for (size_t i = 1; r->have_year && i < r->year.n; i++) {
		const struct ps_year_hour *a = &r->year.h[i - 1], *b = &r->year.h[i];
		double d = 3600.0 * (b->hour - a->hour);
		if (a->month == b->month && a->day == b->day && d > 0.5 && (step == 0 || d < step))
			step = d;
	}
	return step;
}

double psd_annual_power(const struct psd_annual_opt *o, double y)
{
	double lo = o->light_min, pm = o->power_at_min;
	if (!(y > 0))
		return 0.0;
	if (pm < 0 || !(lo > 0) || lo >= 1)
		return y;
	if (y < lo)
		return y * pm / lo;
	return pm + (1 - pm) * (y - lo) / (1 - lo);
}

/* the in-hour measurement's two passes: the sub-hourly year's occupied
 * steps' daylight kept, then the hourly year's compared with it step by
 * step (both runs step the same days at the same period) */
struct inhour_acc {
	const struct psd_annual_opt *o;
	float *dl;
	size_t n, cap, at;
	int second, overflow;
	double sum_sub, sum_hourly, sq, nsq;
};

static void inhour_step(void *ctx, int doy, double t, double level, double output, double truth, double dl)
{
	struct inhour_acc *k = ctx;
	(void)doy;
	(void)level;
	(void)output;
	(void)truth;
	if (!(t >= k->o->occ_start && t < k->o->occ_end))
		return;
	if (!k->second) {
		if (k->n == k->cap) {
			k->overflow = 1;
			return;
		}
		k->dl[k->n++] = (float)dl;
		k->sum_sub += dl;
		return;
	}
	if (k->at >= k->n) {
		k->overflow = 1;
		return;
	}
	k->sum_hourly += dl;
	if (k->dl[k->at] >= 50) {
		double e = dl / k->dl[k->at] - 1;
		k->sq += e * e;
		k->nsq++;
	}
	k->at++;
}

/* the results' steps at the hours' middles (h + 0.5), into y (its tables
 * recomputed); 0 when there are none */
static size_t hourly_points(const struct ps_results *r, struct ps_year *y)
{
	*y = r->year;
	y->n = 0;
	y->h = malloc((r->year.n ? r->year.n : 1) * sizeof *y->h);
	if (!y->h)
		return 0;
	for (size_t i = 0; i < r->year.n; i++) {
		double f = r->year.h[i].hour - floor(r->year.h[i].hour);
		if (fabs(f - 0.5) < 1e-3)
			y->h[y->n++] = r->year.h[i];
	}
	ps_year_tabulate(y);
	return y->n;
}

int psd_annual_inhour(const struct ps_results *r, const struct psd_control *ctl,
                      const struct psd_annual_opt *o, struct psd_annual_inhour *b)
{
	struct psd_annual_opt q = *o;
	struct inhour_acc k = { .o = o };
	struct ps_results hr = *r;
	struct psd_annual sub;
	double step = psd_annual_weather_step(r);
	int rc = -3;
	memset(b, 0, sizeof *b);
	if (!(step > 0 && step < 3599) || !(o->period > 0))
		return -1;
	if (hourly_points(r, &hr.year) == 0) {
		rc = hr.year.h ? -1 : -2;
		free(hr.year.h);
		return rc;
	}
	b->hours = (double)hr.year.n;
	k.cap = (size_t)(PSD_ANNUAL_MAX_DAYS * ((o->occ_end - o->occ_start) / o->period + 2));
	k.dl = malloc(k.cap * sizeof *k.dl);
	if (!k.dl) {
		free(hr.year.h);
		return -2;
	}
	q.task_img = q.level_img = NULL;
	q.no_estimate = 1;
	q.occupied_only = 0;
	q.step = inhour_step;
	q.step_ctx = &k;
	if (psd_annual_run(r, ctl, &q, &sub) == 0) {
		k.second = 1;
		if (psd_annual_run(&hr, ctl, &q, &b->hourly) == 0 && !k.overflow && k.at == k.n && k.sum_sub > 0) {
			b->task_sum = k.sum_hourly / k.sum_sub - 1;
			b->task_n = k.nsq;
			b->task_rms = k.nsq > 0 ? sqrt(k.sq / k.nsq) : NAN;
			rc = 0;
		}
	}
	free(k.dl);
	free(hr.year.h);
	return rc;
}

static double task_of(void *ctx, double t, double lamp)
{
	struct run *u = ctx;
	return u->o->task(u->o->task_ctx, u->doy, t, lamp);
}

/* the room need not be looked at outside the occupied hours */
static int lean(const struct psd_annual_opt *o)
{
	return o->occupied_only && o->no_estimate && !o->task_img;
}

static void seen(void *ctx, double t, double level, double output, double truth, double dl, double roof)
{
	struct run *u = ctx;
	const struct psd_annual_opt *o = u->o;
	struct psd_annual *a = u->a;
	struct psd_control *c = &u->c;
	int m = u->m;
	a->steps++;
	if (lean(o) && !(t >= o->occ_start && t < o->occ_end))
		return;   /* a lean step: the room was not looked at */
	if (o->step)
		o->step(o->step_ctx, u->doy, t, level, output, truth, dl);
	if (o->task_img) {
		int row = (int)(t / 600.0);
		if (row < ROWS && fmod(t, 600.0) < o->period) {
			o->task_img[row * DAYS + u->doy - 1] = (float)truth;
			o->level_img[row * DAYS + u->doy - 1] = (float)level;
		}
	}
	if (!(t >= o->occ_start && t < o->occ_end))
		return;
	{
		double h = o->period / 3600.0;
		double want = o->ideal ? o->ideal(o->task_ctx, u->doy, t, c->target_lux)
		                       : (c->target_lux - dl) / c->elec_task_lux;
		double ideal_level = clamp(want, c->min_level, 1.0), ideal = psd_annual_power(o, ideal_level);
		double power = psd_annual_power(o, output);
		a->occ_h += h;
		a->light_h += output * h;
		a->energy_h += power * h;
		a->ideal_h += ideal * h;
		a->month[m].occ_h += h;
		a->month[m].light_h += output * h;
		a->month[m].energy_h += power * h;
		a->month[m].ideal_h += ideal * h;
		if (truth < 0.999 * c->target_lux && power < ideal) {
			a->short_h += h;
			a->short_lxh += (c->target_lux - truth) * h;
			a->short_saved_h += (ideal - power) * h;
		}
		if (truth < 0.9 * c->target_lux) {
			a->below_h += h;
			a->month[m].below_h += h;
		}
		/* over-dimmed is a question of light: the level against the
		 * ideal's level, not its power */
		if (level < ideal_level - 0.01 && truth < c->target_lux) {
			a->overdim_h += h;
			a->month[m].overdim_h += h;
		}
		/* the switch-on at arrival is not a dimming change */
		if (fabs(level - u->prev) > 0.005 && t - o->period >= o->occ_start)
			a->changes++;
	}
	if (dl >= 50 && !o->no_estimate) {
		/* the law's daylight estimate with each ratio */
		double resp = c->daylight_volts / c->sensor_gain;
		double typical = u->dated > 0 ? u->dated : u->mean_ratio, q = NAN;
		int cls = psd_dated_rooftop_class(u->r, u->doy, t, roof);
		double est[3];
		if (cls >= 0)
			q = psd_dated_ratio_class(u->r, m + 1, t, cls);
		est[0] = u->mean_ratio * resp;
		est[1] = typical * resp;
		est[2] = (q > 0 ? q : typical) * resp;   /* the live estimate with a rooftop sensor */
		for (int k = 0; k < 3; k++) {
			double err = est[k] / dl - 1;
			ps_sum_add(&u->em[k], err);
			ps_sum_add(&u->e2[k], err * err);
		}
		a->est_n++;
	}
}

int psd_annual_run(const struct ps_results *r, const struct psd_control *ctl,
                   const struct psd_annual_opt *o, struct psd_annual *a)
{
	static const int mdays[12] = { 31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31 };
	struct run u;
	int feb29;
	double t0;
	memset(a, 0, sizeof *a);
	if (!r->have_year || isnan(r->electric_sensor_response) || o->period <= 0)
		return -1;
	t0 = psd_time_mono();
	memset(&u, 0, sizeof u);
	u.r = r;
	u.o = o;
	u.a = a;
	u.c = *ctl;
	for (int k = 0; k < 3; k++) {
		ps_sum_init(&u.em[k]);
		ps_sum_init(&u.e2[k]);
	}
	u.c.elec_sensor = r->electric_sensor_response;
	u.c.elec_task_lux = r->electric_task_lux;
	/* a year without light has no ratio: any will do, there is no daylight */
	u.mean_ratio = r->year.mean_ratio > 0 ? r->year.mean_ratio
	               : ctl->daylight_ratio > 0 ? ctl->daylight_ratio : 1.0;
	u.c.daylight_ratio = u.mean_ratio;
	for (int m = 0; m < 12; m++)
		for (int h = 0; h < 24; h++)
			u.dated_at[m][h] = psd_dated_ratio(r, m + 1, 3600.0 * h, NULL);
	u.c.level = 0.0;
	u.c.pending_since = -1;
	/* every date of the year, February 29 when the weather file has it */
	feb29 = psd_roomsetup_has_feb29(r);
	u.doy = 0;
	for (u.m = 0; u.m < 12; u.m++)
		for (int d = 1; d <= mdays[u.m] + (u.m == 1 && feb29); d++) {
			struct psd_roomsetup_play q = {
				.month = u.m + 1, .mday = d, .gain = u.c.sensor_gain, .period = o->period,
				.level0 = u.c.level, .ballast = o->ballast, .law = law, .seen = seen, .ctx = &u,
				.lean = lean(o), .busy_from = o->occ_start, .busy_to = o->occ_end,
				.task = o->task ? task_of : NULL,
			};
			double before = a->light_h;
			u.doy++;
			if (psd_roomsetup_play_day(r, &q) != 0)
				return -1;
			a->day_light_h[u.doy - 1] = a->light_h - before;
		}
	a->days = u.doy;
	a->kwh = a->energy_h * o->watts / 1000.0;
	a->savings = a->occ_h > 0 ? 1 - a->energy_h / a->occ_h : NAN;
	a->ideal_savings = a->occ_h > 0 ? 1 - a->ideal_h / a->occ_h : NAN;
	a->effectiveness = a->ideal_savings > 0 ? a->savings / a->ideal_savings : NAN;
	a->effectiveness_at_target = a->ideal_savings > 0
	        ? (1 - (a->energy_h + a->short_saved_h) / a->occ_h) / a->ideal_savings : NAN;
	a->changes_per_h = a->occ_h > 0 ? a->changes / a->occ_h : NAN;
	a->est_rooftop = r->year.have_site && r->year.n > 0 && !isnan(r->year.h[0].horiz_lux);
	for (int k = 0; k < 3; k++) {
		a->est_mean[k] = a->est_n ? 100 * ps_sum_get(&u.em[k]) / a->est_n : NAN;
		a->est_rms[k] = a->est_n ? 100 * sqrt(ps_sum_get(&u.e2[k]) / a->est_n) : NAN;
	}
	a->seconds = psd_time_mono() - t0;
	return 0;
}

int psd_annual_devices(const struct psd_config *cf, const struct psd_zone_conf *zc, struct psd_annual_opt *o,
                       char *what, size_t whatlen, char *err, size_t errlen)
{
	struct psd_roomsetup_ballast *b = &o->ballast;
	const struct psd_device_conf *dev = zc->ndim > 0 ? &cf->dev[cf->pt[zc->dim[0]].device] : NULL;
	const char *name = dev && dev->drv ? dev->drv->name : "";
	size_t len = 0;
	memset(b, 0, sizeof *b);
	o->dali = 0;
	if (!strcmp(name, "loopback")) {
		struct ps_opts_reader rd = { &dev->opts, dev->drv->options, PS_OPT_DEVICE, err, errlen, NULL };
		int off = 1;
		if (ps_opts_double(&rd, "fade_rate", &b->fade_rate) || ps_opts_double(&rd, "min_level", &b->min_level) ||
		    ps_opts_double(&rd, "lag_tau", &b->lag_tau) || ps_opts_choice(&rd, "off_below_min", &off))
			return -1;
		b->off_below_min = off;
		len = (size_t)snprintf(what, whatlen, "the loopback room's ballast: fade %g/s, minimum %g (%s), lamp lag %g s",
		                       b->fade_rate, b->min_level, off ? "off below" : "held", b->lag_tau);
	} else if (!strncmp(name, "dali", 4)) {
		o->dali = 1;
		b->min_level = ps_dali_level_to_fraction(1);
		b->off_below_min = 0;
		len = (size_t)snprintf(what, whatlen, "DALI: the logarithmic arc power levels, instant (fade not modelled)");
	} else {
		len = (size_t)snprintf(what, whatlen, "an instant ballast (%s)", *name ? name : "no dim point");
	}
	o->light_min = b->min_level;
	o->power_at_min = cf->power_at_min;
	o->watts = cf->lamp_watts;
	if (len < whatlen) {
		if (o->power_at_min < 0 || !(o->light_min > 0))
			snprintf(what + len, whatlen - len, "; power proportional to light");
		else
			snprintf(what + len, whatlen - len, "; power %.3g of full at %.3g light, linear to full", o->power_at_min,
			         o->light_min);
	}
	return 0;
}

/* The output panel's colour: off (unoccupied, or dimmed off) a light
 * grey apart from every lit level, which takes the task panel's colour
 * scale on the square root of the level, so the low levels a daylit room
 * dims to stay apart (a linear grey put 10 % and off within 20 of 255). */
static void level_rgb(double v, uint8_t rgb[3])
{
	if (!(v > 0)) {
		rgb[0] = rgb[1] = rgb[2] = 215;
		return;
	}
	ps_falsecolor_rgb8(sqrt(clamp(v, 0, 1)), rgb);
}

/* A legend's swatch: a 16 x 12 box with a black frame at x, y. */
static void swatch(struct ps_canvas *cv, int x, int y, const uint8_t rgb[3])
{
	static const uint8_t frame[3] = { 0, 0, 0 };
	for (int yy = -1; yy < 13; yy++)
		for (int xx = -1; xx < 17; xx++)
			ps_canvas_set(cv, x + xx, y + yy, 1, yy < 0 || yy > 11 || xx < 0 || xx > 15 ? frame : rgb);
}

/* A panel's hour axis (midnight at the bottom) and month axis beneath. */
static void axes(struct ps_canvas *cv, int left, int top, int ph, int z, const double ink[3])
{
	static const char *const mn[] = { "Jan", "Feb", "Mar", "Apr", "May", "Jun",
	                                  "Jul", "Aug", "Sep", "Oct", "Nov", "Dec" };
	static const int start[12] = { 0, 31, 59, 90, 120, 151, 181, 212, 243, 273, 304, 334 };
	char buf[16];
	for (int hr = 0; hr <= 24; hr += 6) {
		snprintf(buf, sizeof buf, "%02d:00", hr);
		ps_canvas_label(cv, left - 4, top + ph - hr * 6 * z, 10, 1, ink, 0, buf);
	}
	for (int mo = 0; mo < 12; mo++)
		ps_canvas_label(cv, left + (start[mo] + 15) * z, top + ph + 12, 10, 0, ink, 0, mn[mo]);
}

int psd_annual_png(const char *path, const float *task_img, const float *level_img, int days,
                   double target, const char *title, char *err, size_t errlen)
{
	static const uint8_t white[3] = { 255, 255, 255 };
	static const double ink[3] = { 0, 0, 0 };
	static const double levels[] = { 0, 0.1, 0.25, 0.5, 1 };
	const int z = 2, left = 50, top = 52, gap = 62, pw = days * z, ph = ROWS * z, lw = 230;
	const int top2 = top + ph + gap;
	struct ps_canvas cv;
	struct ps_err e;
	struct ps_falsecolor_scale sc = { 100 * target, 1, 3 };   /* 0.1 to 100 x target, log */
	int W = left + pw + lw, H = top2 + ph + 30;
	char buf[96];
	if (ps_canvas_init(&cv, W, H, white, &e) != 0)
		return snprintf(err, errlen, "%s", e.msg), -1;
	ps_canvas_begin(&cv);
	for (int row = 0; row < ROWS; row++)
		for (int d = 0; d < days; d++) {
			uint8_t rgb[3];
			int y = ROWS - 1 - row;   /* midnight at the bottom */
			double v = task_img[row * DAYS + d], f = ps_falsecolor_scale_fraction(&sc, v);
			ps_falsecolor_rgb8(clamp(f, 0, 1), rgb);
			ps_canvas_set(&cv, left + d * z, top + y * z, z, rgb);
			level_rgb(level_img[row * DAYS + d], rgb);
			ps_canvas_set(&cv, left + d * z, top2 + y * z, z, rgb);
		}
	for (int k = 0; k <= 3; k++) {
		uint8_t rgb[3];
		ps_falsecolor_rgb8(k / 3.0, rgb);
		swatch(&cv, left + pw + 8, top + 24 + 18 * k, rgb);
	}
	for (int k = 0; k < 5; k++) {
		uint8_t rgb[3];
		level_rgb(levels[k], rgb);
		swatch(&cv, left + pw + 8, top2 + 24 + 18 * k, rgb);
	}
	ps_canvas_end(&cv);
	ps_canvas_label(&cv, left, 14, 13, -1, ink, 0, title);
	ps_canvas_label(&cv, left, top - 8, 12, -1, ink, 0,
	                "true task illuminance (hour of day, standard time, against day of the year)");
	ps_canvas_label(&cv, left, top2 - 8, 12, -1, ink, 0, "light output (hour of day, standard time)");
	ps_canvas_label(&cv, left + pw + 8, top + 10, 11, -1, ink, 0, "task lux (log scale)");
	ps_canvas_label(&cv, left + pw + 8, top2 + 10, 11, -1, ink, 0, "% of full output (square-root scale)");
	for (int k = 0; k <= 3; k++) {
		snprintf(buf, sizeof buf, "%.0f lx%s", 0.1 * target * pow(10, k), k == 3 ? " and over" : "");
		ps_canvas_label(&cv, left + pw + 30, top + 30 + 18 * k, 11, -1, ink, 0, buf);
	}
	for (int k = 0; k < 5; k++) {
		if (k == 0)
			snprintf(buf, sizeof buf, "off (unoccupied, or dimmed off)");
		else
			snprintf(buf, sizeof buf, "%.0f %%", 100 * levels[k]);
		ps_canvas_label(&cv, left + pw + 30, top2 + 30 + 18 * k, 11, -1, ink, 0, buf);
	}
	axes(&cv, left, top, ph, z, ink);
	axes(&cv, left, top2, ph, z, ink);
	if (ps_canvas_save_png(&cv, path, &e) != 0) {
		ps_canvas_free(&cv);
		return snprintf(err, errlen, "%s", e.msg), -1;
	}
	ps_canvas_free(&cv);
	return 0;
}

static int cmp_double(const void *x, const void *y)
{
	double a = *(const double *)x, b = *(const double *)y;
	return a < b ? -1 : a > b;
}

int psd_annual_sunbar(const struct ps_results *r, const struct psd_control *ctl,
                      const struct psd_annual_opt *o, struct psd_annual_sunbar *b)
{
	struct ps_results q;
	struct psd_annual_opt oq = *o;
	struct ps_sum s0, s1;
	double *d, t0 = psd_time_mono();
	size_t m = 0;
	int rc;
	memset(b, 0, sizeof *b);
	if (!r->have_year || !r->year.have_alt || r->year.n == 0)
		return -1;
	q = *r;   /* the same results but for the hours (read only: not freed) */
	q.year.h = malloc(r->year.n * sizeof *q.year.h);
	d = malloc(r->year.n * sizeof *d);
	if (!q.year.h || !d) {
		free(q.year.h);
		free(d);
		return -1;
	}
	ps_sum_init(&s0);
	ps_sum_init(&s1);
	for (size_t i = 0; i < r->year.n; i++) {
		const struct ps_year_hour *k = &r->year.h[i];
		double t = 3600.0 * k->hour;
		q.year.h[i] = *k;
		q.year.h[i].sensor = k->sensor_alt;
		q.year.h[i].task_lux = k->task_alt;
		if (t >= o->occ_start && t < o->occ_end && k->task_lux >= 50) {
			ps_sum_add(&s0, k->task_lux);
			ps_sum_add(&s1, k->task_alt);
			d[m++] = fabs(k->task_alt / k->task_lux - 1);
		}
	}
	ps_year_tabulate(&q.year);
	oq.task_img = oq.level_img = NULL;
	oq.step = NULL;
	oq.no_estimate = 1;
	rc = psd_annual_run(&q, ctl, &oq, &b->alt);
	free(q.year.h);
	qsort(d, m, sizeof *d, cmp_double);
	b->hours = (double)m;
	b->task_max = m ? d[m - 1] : NAN;
	b->task_p95 = m ? d[(size_t)(0.95 * (double)(m - 1))] : NAN;
	b->task_median = m ? d[(m - 1) / 2] : NAN;
	b->task_sum = m ? ps_sum_get(&s1) / ps_sum_get(&s0) - 1 : NAN;
	free(d);
	b->seconds = psd_time_mono() - t0;
	return rc;
}
