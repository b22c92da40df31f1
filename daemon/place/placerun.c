/* SPDX-License-Identifier: ISC */
#include "placerun.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "placeset.h"
#include "placeyear.h"

static void day_close(struct watch *w)
{
	if (w->day_seen) {
		w->days++;
		if (!w->day_fail)
			w->days_pass++;
	}
	w->day_seen = w->day_fail = 0;
	w->last_dir = 0;
	w->last_swing_t = -1e30;
}

static void step_hook(void *ctx, int doy, double t, double level, double output, double truth, double dl)
{
	struct watch *w = ctx;
	const struct psd_annual_opt *o = w->o;
	const struct psd_control *c = w->c;
	double h = o->period / 3600.0;
	(void)level;
	if (doy != w->day) {
		day_close(w);
		w->day = doy;
		w->last_out = output;
	}
	if (w->hour_power) {
		int hr = (doy - 1) * 24 + (int)(t / 3600.0);
		if (hr >= 0 && hr < 8784) {
			w->hour_power[hr] += psd_annual_power(o, output);
			w->hour_level[hr] += output;
			w->hour_steps[hr] += 1;
		}
	}
	if (!(t >= o->occ_start && t < o->occ_end)) {
		w->last_out = output;
		return;
	}
	w->day_seen = 1;
	if (truth < c->target_lux)
		w->deficit_lxh += (c->target_lux - truth) * h;
	{
		double ideal = o->ideal ? o->ideal(o->task_ctx, doy, t, c->target_lux) : (c->target_lux - dl) / c->elec_task_lux;
		ideal = ideal < c->min_level ? c->min_level : ideal > 1 ? 1 : ideal;
		if (output > ideal + 0.01)
			w->over_h += h;
	}
	/* full daylight: with daylight at 150 % of the target, power at most 35 % */
	if (dl >= 1.5 * c->target_lux && psd_annual_power(o, output) > 0.35)
		w->day_fail = 1;
	/* low daylight: with daylight below 10 % of the target, the task at 90 % */
	if (dl < 0.1 * c->target_lux && truth < 0.9 * c->target_lux && t - o->period >= o->occ_start)
		w->day_fail = 1;
	/* cycling: swings of more than 0.05 against the last one's direction no
	 * closer together than the zone's delay */
	if (fabs(output - w->last_out) > 0.05 && t - o->period >= o->occ_start) {
		int dir = output > w->last_out ? 1 : -1;
		if (w->last_dir && dir != w->last_dir && t - w->last_swing_t < c->delay)
			w->day_fail = 1;
		w->last_dir = dir;
		w->last_swing_t = t;
	}
	w->last_out = output;
}

/* The ctl psensd's engine makes for a zone from results (engine.c's zone
 * set-up, and -Y's automatic switching thresholds). */
static void law_for(const struct search *s, const struct ps_results *r, int alg, struct psd_control *c)
{
	*c = s->zc->ctl;
	c->daylight_ratio = r->daylight_ratio_mean;
	c->elec_sensor = r->electric_sensor_response;
	c->elec_task_lux = r->electric_task_lux;
	c->level = 1.0;
	c->pending_since = -1;
	c->algorithm = alg;
	if (alg == PSD_ALG_SWITCHING && c->s_off >= 1e9) {
		double full = c->sensor_gain * c->elec_sensor;
		double need = c->sensor_gain * c->target_lux / r->year.mean_ratio;
		c->s_on = need;
		c->s_off = full + need;
	}
}

/* the task/sensor ratio's spread (sd / mean, %) by sky class over the
 * hours with 50 lx or more at the task */
static void spread(const struct ps_results *r, struct combo *k)
{
	double n[PS_SKY_NCLASS] = { 0 }, m[PS_SKY_NCLASS] = { 0 }, q[PS_SKY_NCLASS] = { 0 };
	for (size_t i = 0; i < r->year.n; i++) {
		const struct ps_year_hour *h = &r->year.h[i];
		if (h->task_lux >= 50 && h->sensor > 0) {
			double x = h->task_lux / h->sensor;
			n[h->sky_class]++;
			m[h->sky_class] += x;
			q[h->sky_class] += x * x;
		}
	}
	k->spread_max = 0;
	for (int c = 0; c < PS_SKY_NCLASS; c++) {
		double mean = n[c] ? m[c] / n[c] : NAN, var = n[c] ? q[c] / n[c] - mean * mean : NAN;
		k->spread[c] = n[c] > 1 && mean > 0 ? 100 * sqrt(var > 0 ? var : 0) / mean : NAN;
		if (isfinite(k->spread[c]) && k->spread[c] > k->spread_max)
			k->spread_max = k->spread[c];
	}
}

/* Run combination k's law on results r (its row's); w (may be NULL)
 * gathers the hours. */
static int run_law(const struct search *s, struct combo *k, const struct ps_results *r, struct watch *wx)
{
	struct psd_control c;
	struct psd_annual_opt o = s->ao;
	struct watch w0, *w = wx ? wx : &w0;
	if (!wx)
		memset(&w0, 0, sizeof w0);
	struct psd_placeyear_task tk;
	int rc = 0;
	law_for(s, r, s->o->laws[k->law], &c);
	if (s->hrs.pt_day) {
		/* the grid's figure point by point: its daylight and electric
		 * light are not a figure's sum */
		if (psd_placeyear_task_init(&tk, s) != 0) {
			k->fail = 1;
			return -1;
		}
		o.task = psd_placeyear_task;
		o.ideal = psd_placeyear_ideal;
		o.task_ctx = &tk;
	}
	w->o = &o;
	w->c = &c;
	w->day = 0;
	w->last_swing_t = -1e30;
	o.step = step_hook;
	o.occupied_only = !w->hour_power;   /* the hook looks at the occupied steps only */
	o.step_ctx = w;
	if (psd_annual_run(r, &c, &o, &k->a) != 0) {
		k->fail = 1;
		rc = -1;
	}
	if (s->hrs.pt_day)
		psd_placeyear_task_free(&tk);
	if (rc)
		return rc;
	day_close(w);
	k->deficit_lxh = w->deficit_lxh;
	k->over_h = w->over_h;
	k->days = w->days;
	k->days_pass = w->days_pass;
	return 0;
}

/* Run the laws of combinations k[0 .. n-1], which share one row whose
 * year's signals are sig. */
static int row_of_signals(const struct search *s, struct combo *k, int n, const double *sig, double elec,
                          struct watch *wx)
{
	struct ps_results r;
	int rc = 0;
	double sum;
	if (psd_placeyear_results_of(s, sig, elec, &s->sens[k[0].sens], &r, &sum) != 0)
		return -1;
	for (int i = 0; i < n; i++) {
		k[i].sensor_sum = sum;
		spread(&r, &k[i]);
		if (run_law(s, &k[i], &r, wx) != 0)
			rc = -1;
	}
	psd_placeyear_release(&r);
	return rc;
}

/* Run the laws of combinations k[0 .. n-1], which share one row. */
int psd_placerun_row(const struct search *s, struct combo *k, int n, const double *row, double elec, struct watch *wx)
{
	double *sig = malloc((s->hrs.n ? s->hrs.n : 1) * sizeof *sig);
	const double *w = s->o->coef[k[0].sens];
	int rc = -1;
	if (sig && psd_placeyear_signals(s, &row, &w, 1, sig) == 0)
		rc = row_of_signals(s, k, n, sig, elec, wx);
	free(sig);
	return rc;
}

const double *psd_placerun_row_of(const struct search *s, const struct combo *k)
{
	const struct pose *p = &s->poses[k->pose];
	size_t rk = (size_t)k->rot * (size_t)s->o->nsens + (size_t)k->sens;
	return p->row + rk * (size_t)s->npatch * 3;
}

double psd_placerun_elec_of(const struct search *s, const struct combo *k)
{
	return s->poses[k->pose].elec[(size_t)k->rot * (size_t)s->o->nsens + (size_t)k->sens];
}

/* rows a worker takes at once: their signals are made together */
#define WORK_ROWS 32

static void *worker(void *arg)
{
	struct search *s = arg;
	size_t nl = (size_t)s->o->nlaws;
	double *sig = malloc(WORK_ROWS * (s->hrs.n ? s->hrs.n : 1) * sizeof *sig);
	for (;;) {
		size_t i;
		int nr, bad = 0;
		const double *rows[WORK_ROWS], *wts[WORK_ROWS];
		pthread_mutex_lock(&s->lock);
		i = s->next;
		s->next += WORK_ROWS * nl;
		pthread_mutex_unlock(&s->lock);
		if (i >= s->nc)
			break;
		nr = (int)((s->nc - i) / nl < WORK_ROWS ? (s->nc - i) / nl : WORK_ROWS);
		for (int j = 0; j < nr; j++) {
			rows[j] = psd_placerun_row_of(s, &s->c[i + j * nl]);
			wts[j] = s->o->coef[s->c[i + j * nl].sens];
		}
		if (!sig || psd_placeyear_signals(s, rows, wts, nr, sig) != 0)
			bad = nr;
		for (int j = 0; j < nr && !bad; j++) {
			struct combo *k = &s->c[i + j * nl];
			if (row_of_signals(s, k, (int)nl, sig + (size_t)j * s->hrs.n, psd_placerun_elec_of(s, k), NULL) != 0)
				bad++;
		}
		if (bad) {
			pthread_mutex_lock(&s->lock);
			s->failed += bad;
			pthread_mutex_unlock(&s->lock);
		}
	}
	free(sig);
	return NULL;
}

/* the poses' projections, a pose at a time from a shared counter */
struct proj_job {
	struct search *s;
	pthread_mutex_t lock;
	int next;
	int *rc;
	char (*err)[1024];
};

static void *project_run(void *arg)
{
	struct proj_job *j = arg;
	for (;;) {
		int i;
		pthread_mutex_lock(&j->lock);
		i = j->next++;
		pthread_mutex_unlock(&j->lock);
		if (i >= j->s->nposes)
			break;
		j->rc[i] = psd_placeset_project(j->s, &j->s->poses[i], j->err[i], sizeof j->err[i]);
	}
	return NULL;
}

int psd_placerun_project(struct search *s, char *err, size_t errlen)
{
	struct proj_job j = { .s = s, .next = 0 };
	pthread_t th[256];
	int n = 0, rc = 0;
	j.rc = calloc((size_t)(s->nposes > 0 ? s->nposes : 1), sizeof *j.rc);
	j.err = calloc((size_t)(s->nposes > 0 ? s->nposes : 1), sizeof *j.err);
	if (!j.rc || !j.err) {
		free(j.rc);
		free(j.err);
		return snprintf(err, errlen, "out of memory"), -1;
	}
	pthread_mutex_init(&j.lock, NULL);
	for (int i = 1; i < s->o->threads && i < 256 && i < s->nposes; i++)
		if (pthread_create(&th[n], NULL, project_run, &j) == 0)
			n++;
	project_run(&j);
	for (int i = 0; i < n; i++)
		pthread_join(th[i], NULL);
	pthread_mutex_destroy(&j.lock);
	/* the first pose that failed, in the candidates' order */
	for (int i = 0; i < s->nposes && !rc; i++)
		if (j.rc[i] != 0) {
			snprintf(err, errlen, "%s", j.err[i]);
			rc = -1;
		}
	free(j.rc);
	free(j.err);
	return rc;
}

void psd_placerun_all(struct search *s)
{
	pthread_t th[256];
	int n = 0;
	for (int i = 1; i < s->o->threads && i < 256; i++)
		if (pthread_create(&th[n], NULL, worker, s) == 0)
			n++;
	worker(s);
	for (int i = 0; i < n; i++)
		pthread_join(th[i], NULL);
}

/* qsort_r's comparison: the search is the context (its hours limit) */
static int rank_cmp(const void *a, const void *b, void *search)
{
	const struct combo *x = a, *y = b;
	const struct search *s = search;
	double lim = s->o->max_below;
	int ox = x->a.below_h <= lim, oy = y->a.below_h <= lim;
	if (x->fail != y->fail)
		return x->fail - y->fail;
	if (ox != oy)
		return oy - ox;
	if (ox) {
		if (x->a.energy_h != y->a.energy_h)
			return x->a.energy_h < y->a.energy_h ? -1 : 1;
	} else if (x->a.below_h != y->a.below_h)
		return x->a.below_h < y->a.below_h ? -1 : 1;
	if (x->deficit_lxh != y->deficit_lxh)
		return x->deficit_lxh < y->deficit_lxh ? -1 : 1;
	if (x->pose != y->pose)
		return x->pose - y->pose;
	if (x->rot != y->rot)
		return x->rot - y->rot;
	if (x->sens != y->sens)
		return x->sens - y->sens;
	return x->law - y->law;
}

/* the front between energy and under-lighting (deficit): no other is at
 * least as good in both and better in one */
static void pareto(struct search *s)
{
	for (size_t i = 0; i < s->nc; i++) {
		struct combo *x = &s->c[i];
		x->pareto = !x->fail;
		for (size_t j = 0; j < s->nc && x->pareto; j++) {
			const struct combo *y = &s->c[j];
			if (j != i && !y->fail && y->a.energy_h <= x->a.energy_h && y->deficit_lxh <= x->deficit_lxh &&
			    (y->a.energy_h < x->a.energy_h || y->deficit_lxh < x->deficit_lxh))
				x->pareto = 0;
		}
	}
}

double psd_placerun_rot_deg(const struct search *s, int r)
{
	return r * 360.0 / s->o->nrot;
}


void psd_placerun_rank(struct search *s)
{
	qsort_r(s->c, s->nc, sizeof *s->c, rank_cmp, s);
	pareto(s);
}
