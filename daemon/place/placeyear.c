/* SPDX-License-Identifier: ISC */
#include "placeyear.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dcset.h"
#include "roomsetup.h"
#include "integrate.h"
#include "patches.h"
#include "scene.h"
#include "sky.h"

static const double V[3] = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B };

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return x < y ? -1 : x > y;
}

/* The grid's figure of the points' lux v[n]: min, mean, pNN (the NN-th
 * percentile, nearest rank) or points:i,j,... (the mean of those rows,
 * from 1). */
double psd_placeyear_stat(const char *stat, const double *v, int n, double *scratch)
{
	double sum = 0;
	if (!strcmp(stat, "min")) {
		double m = v[0];
		for (int i = 1; i < n; i++)
			m = v[i] < m ? v[i] : m;
		return m;
	}
	if (!strcmp(stat, "mean")) {
		for (int i = 0; i < n; i++)
			sum += v[i];
		return sum / n;
	}
	if (stat[0] == 'p' && stat[1] != 'o') {
		double q = atof(stat + 1) / 100.0;
		int k = (int)ceil(q * n) - 1;
		memcpy(scratch, v, (size_t)n * sizeof *v);
		qsort(scratch, (size_t)n, sizeof *scratch, cmp_double);
		return scratch[k < 0 ? 0 : k >= n ? n - 1 : k];
	}
	{
		/* points:i,j */
		const char *p = strchr(stat, ':') + 1;
		int cnt = 0;
		while (*p) {
			char *end;
			long i = strtol(p, &end, 10);
			sum += v[i - 1];
			cnt++;
			p = *end == ',' ? end + 1 : end;
		}
		return sum / cnt;
	}
}

/* 0, or -1 with err: stat names a figure of an n-point grid */
int psd_placeyear_check(const char *stat, int n, char *err, size_t errlen)
{
	if (!strcmp(stat, "min") || !strcmp(stat, "mean"))
		return 0;
	if (stat[0] == 'p' && stat[1] != 'o') {
		char *end;
		double q = strtod(stat + 1, &end);
		if (end != stat + 1 && !*end && q >= 0 && q <= 100)
			return 0;
	} else if (!strncmp(stat, "points:", 7) && stat[7]) {
		const char *p = stat + 7;
		while (*p) {
			char *end;
			long i = strtol(p, &end, 10);
			if (end == p || i < 1 || i > n || (*end && *end != ','))
				return snprintf(err, errlen, "-t %s: a point is a row of the grid, 1 to %d", stat, n), -1;
			p = *end == ',' ? end + 1 : end;
		}
		return 0;
	}
	return snprintf(err, errlen, "-t %s: the grid's figure is min, mean, pNN (a percentile) or points:i,j,...",
	                stat), -1;
}

/* 1: the figure stat is not linear in the points (min, pNN): the task is
 * judged point by point (psd_placeyear_task) */
static int exact_figure(const char *stat)
{
	return !strcmp(stat, "min") || (stat[0] == 'p' && stat[1] != 'o');
}

static int ideal_table(struct search *s);

/* day of year (from 1) of a date of the weather's year */
static int doy_of(int month, int day, int leap)
{
	static const int start[12] = { 0, 31, 59, 90, 120, 151, 181, 212, 243, 273, 304, 334 };
	return start[month - 1] + day + (leap && month > 2);
}

int psd_placeyear_hours(struct search *s, const struct ps_gridmtx *g, char *err, size_t errlen)
{
	struct ps_weather w;
	struct ps_patches P;
	struct ps_sky_opt so;
	struct ps_err e;
	struct hours *H = &s->hrs;
	double *lux = malloc((size_t)g->npoints * 2 * sizeof *lux);
	if (!lux)
		return snprintf(err, errlen, "out of memory"), -1;
	if (ps_weather_read(&w, s->o->weather, 0, &e) != 0) {
		free(lux);
		return snprintf(err, errlen, "%s", e.msg), -1;
	}
	if (ps_patches_init(&P, g->mf, &e) != 0) {
		free(lux);
		ps_weather_free(&w);
		return snprintf(err, errlen, "%s", e.msg), -1;
	}
	ps_sky_opt_default(&so);
	H->npatch = P.n;
	H->npoints = g->npoints;
	if (exact_figure(s->o->stat) && !(H->pt_day = malloc((w.n ? w.n : 1) * (size_t)g->npoints * sizeof *H->pt_day))) {
		free(lux);
		ps_weather_free(&w);
		ps_patches_free(&P);
		return snprintf(err, errlen, "out of memory for %zu hours", w.n), -1;
	}
	H->h = calloc(w.n ? w.n : 1, sizeof *H->h);
	H->sky = malloc((w.n ? w.n : 1) * (size_t)P.n * 3 * sizeof *H->sky);
	H->task = malloc((w.n ? w.n : 1) * sizeof *H->task);
	if (!H->h || !H->sky || !H->task) {
		free(lux);
		ps_weather_free(&w);
		ps_patches_free(&P);
		return snprintf(err, errlen, "out of memory for %zu hours", w.n), -1;
	}
	H->site = w.site;
	H->leap = w.leap;
	for (size_t i = 0; i < w.n; i++) {
		struct ps_sky sk;
		struct ps_year_hour *k;
		double *sky = H->sky + H->n * (size_t)P.n * 3;
		if (ps_sky_step(&sk, &w, i, &so, &e) != 0) {
			free(lux);
			ps_weather_free(&w);
			ps_patches_free(&P);
			return snprintf(err, errlen, "%s", e.msg), -1;
		}
		if (sk.dark)
			continue;
		ps_sky_vector(&sk, &P, PS_SKY_ALL, sky);
		k = &H->h[H->n];
		k->month = w.step[i].month;
		k->day = w.step[i].day;
		k->hour = w.step[i].hour;
		k->epsilon = sk.model.epsilon;
		k->sky_class = ps_year_class(sk.model.epsilon);
		k->horiz_lux = sk.model.dif_lux + (sk.sun_alt > 0 ? sk.model.dir_lux * sin(sk.sun_alt) : 0.0);
		for (int pt = 0; pt < g->npoints; pt++) {
			struct ps_dcset_row row;
			ps_gridmtx_row(g, pt, &row);
			lux[pt] = PS_YEAR_LUX_PER_WM2 * ps_dcset_row_apply(&row, V, sky);
		}
		H->task[H->n] = psd_placeyear_stat(s->o->stat, lux, g->npoints, lux + g->npoints);
		if (H->pt_day)
			memcpy(H->pt_day + H->n * (size_t)g->npoints, lux, (size_t)g->npoints * sizeof *lux);
		H->n++;
	}
	{
		/* the hours of each day (file order); a leap year as the annual run plays it */
		int leap = H->leap, d = 1;
		for (size_t i = 0; i < H->n; i++)
			leap |= H->h[i].month == 2 && H->h[i].day == 29;
		H->day_first[1] = 0;
		for (size_t i = 0; i <= H->n; i++) {
			int di = i < H->n ? doy_of(H->h[i].month, H->h[i].day, leap) : 367;
			while (d < di && d < 367)
				H->day_first[++d] = i;
		}
	}
	free(lux);
	ps_weather_free(&w);
	ps_patches_free(&P);
	if (ideal_table(s) != 0)
		return snprintf(err, errlen, "out of memory for the year's steps"), -1;
	return 0;
}

/* The year's sensor signals of rows rows[0 .. nrow - 1] (each npatch x 3,
 * per channel), row j weighed by its sensor's colour weights wts[j], into
 * sig[j * hours + i]: eight rows at a time (eight sums
 * in flight) over a tile of hours (which stays in cache for every block
 * of rows), each row's sum taken in the one order (patch, then channel)
 * and each term as (w[c] x row) x sky, so a row's signals are the same
 * whatever rows it goes with. */
#define SIG_BLOCK 8
#define SIG_TILE 64
typedef double sig_v2 __attribute__((vector_size(16)));
int psd_placeyear_signals(const struct search *s, const double *const *rows, const double *const *wts, int nrow,
                          double *sig)
{
	const struct hours *H = &s->hrs;
	size_t m = (size_t)H->npatch * 3;
	int nblock = (nrow + SIG_BLOCK - 1) / SIG_BLOCK;
	/* block b's rows interleaved: rv[(b m + k) SIG_BLOCK + j], row j's term k */
	double *rv = aligned_alloc(sizeof(sig_v2), (size_t)(nblock > 0 ? nblock : 1) * SIG_BLOCK * m * sizeof *rv);
	if (!rv)
		return -1;
	for (int j = 0; j < nblock * SIG_BLOCK; j++) {
		const double *row = rows[j < nrow ? j : 0], *w = wts[j < nrow ? j : 0];
		double *r = rv + (size_t)(j / SIG_BLOCK) * SIG_BLOCK * m + j % SIG_BLOCK;
		for (size_t k = 0; k < m; k++)
			r[k * SIG_BLOCK] = w[k % 3] * row[k];
	}
	for (size_t i0 = 0; i0 < H->n; i0 += SIG_TILE) {
		size_t i1 = H->n - i0 < SIG_TILE ? H->n : i0 + SIG_TILE;
		for (int b0 = 0; b0 < nblock; b0++) {
			const double *r = rv + (size_t)b0 * SIG_BLOCK * m;
			int nb = nrow - b0 * SIG_BLOCK < SIG_BLOCK ? nrow - b0 * SIG_BLOCK : SIG_BLOCK;
			for (size_t i = i0; i < i1; i++) {
				const double *sky = H->sky + i * m;
				/* two rows a lane pair (gcc's and clang's vector extension):
				 * each lane one row's sum, in its own order */
				sig_v2 a0 = { 0, 0 }, a1 = { 0, 0 }, a2 = { 0, 0 }, a3 = { 0, 0 };
				double v[SIG_BLOCK];
				for (size_t k = 0; k < m; k++) {
					const sig_v2 *rk = (const sig_v2 *)(r + k * SIG_BLOCK);
					sig_v2 x = { sky[k], sky[k] };
					a0 += rk[0] * x;
					a1 += rk[1] * x;
					a2 += rk[2] * x;
					a3 += rk[3] * x;
				}
				memcpy(v, &a0, sizeof a0);
				memcpy(v + 2, &a1, sizeof a1);
				memcpy(v + 4, &a2, sizeof a2);
				memcpy(v + 6, &a3, sizeof a3);
				for (int b = 0; b < nb; b++)
					sig[(size_t)(b0 * SIG_BLOCK + b) * H->n + i] = v[b];
			}
		}
	}
	free(rv);
	return 0;
}

/* The results psensd would read for one combination: the year's hours
 * with this sensor's signal, a daylight condition holding the year's mean
 * ratio (the year's mean signals, at noon of any day) and the electric one.  row: npatch x 3 per channel. */
int psd_placeyear_results(const struct search *s, const double *row, double elec, const struct ps_sensor *sens,
                          struct ps_results *r, double *sensor_sum)
{
	double *sig = malloc((s->hrs.n ? s->hrs.n : 1) * sizeof *sig);
	int rc;
	const double *w = s->o->coef[sens - s->sens];
	if (!sig || psd_placeyear_signals(s, &row, &w, 1, sig) != 0) {
		free(sig);
		memset(r, 0, sizeof *r);
		return -1;
	}
	rc = psd_placeyear_results_of(s, sig, elec, sens, r, sensor_sum);
	free(sig);
	return rc;
}

int psd_placeyear_results_of(const struct search *s, const double *sig, double elec, const struct ps_sensor *sens,
                             struct ps_results *r, double *sensor_sum)
{
	const struct hours *H = &s->hrs;
	const double *w = s->o->coef[sens - s->sens];   /* the sensor's colour weights */
	double ssum = 0, tsum = 0;
	memset(r, 0, sizeof *r);
	r->version = PS_RESULTS_VERSION;
	r->year.h = malloc((H->n ? H->n : 1) * sizeof *r->year.h);
	r->cond = calloc(2, sizeof *r->cond);
	if (!r->year.h || !r->cond) {
		free(r->year.h);
		free(r->cond);
		return -1;
	}
	for (size_t i = 0; i < H->n; i++) {
		double v = sig[i];
		r->year.h[i] = H->h[i];
		r->year.h[i].sensor = v;
		r->year.h[i].task_lux = H->task[i];
		ssum += v;
		tsum += H->task[i];
	}
	*sensor_sum = ssum;
	r->year.n = H->n;
	r->year.patches = H->npatch;
	r->year.used = H->npatch;
	r->year.leap = H->leap;
	r->year.have_site = 1;
	r->year.site = H->site;
	ps_year_tabulate(&r->year);
	r->have_year = 1;
	r->year_mf = s->mf;
	r->weather = (char *)s->o->weather;
	r->sensitivity = sens->path;
	r->reading = (char *)"linear";
	memcpy(r->rgb, w, sizeof r->rgb);
	r->scene = (char *)s->o->cands;
	r->scene_hash = (char *)"";
	r->ncond = 2;
	r->cond[0] = (struct ps_result_cond){ .label = (char *)"year_mean", .kind = PS_COND_DAYLIGHT, .date = (char *)"", .tod_s = 43200,
	                                      .computed = 1, .sensor_response = H->n ? ssum / (double)H->n : 0,
	                                      .task_lux = H->n ? tsum / (double)H->n : 0 };
	r->cond[1] = (struct ps_result_cond){ .label = (char *)"elec", .kind = PS_COND_ELECTRIC, .date = (char *)"", .tod_s = -1,
	                                      .computed = 1, .sensor_response = elec, .task_lux = s->elec_task };
	for (int k = 0; k < 2; k++) {
		r->cond[k].task_irradiance = r->cond[k].task_lux / PS_YEAR_LUX_PER_WM2;
		r->cond[k].ratio = r->cond[k].sensor_response > 0 ? r->cond[k].task_lux / r->cond[k].sensor_response : NAN;
	}
	ps_results_summarise(r);
	return 0;
}

/* the k-th smallest (from 0) of v[0 .. n-1], reordering v */
static double kth(double *v, int n, int k)
{
	int lo = 0, hi = n - 1;
	while (lo < hi) {
		double pivot = v[(lo + hi) / 2];
		int i = lo, j = hi;
		while (i <= j) {
			while (v[i] < pivot)
				i++;
			while (v[j] > pivot)
				j--;
			if (i <= j) {
				double x = v[i];
				v[i++] = v[j];
				v[j--] = x;
			}
		}
		if (k <= j)
			hi = j;
		else if (k >= i)
			lo = i;
		else
			return v[k];
	}
	return v[k];
}

/* day of year doy's points as the room makes them (roomsetup's from_date):
 * the hours with light, dark a step before the first and after the last */
static void task_day(struct psd_placeyear_task *k, int doy)
{
	const struct hours *H = &k->s->hrs;
	size_t lo = doy >= 1 && doy <= 366 ? H->day_first[doy] : 0, hi = doy >= 1 && doy <= 366 ? H->day_first[doy + 1] : 0;
	int n = 0;
	k->doy = doy;
	if (hi > lo) {
		double first = 3600.0 * H->h[lo].hour, last = 3600.0 * H->h[hi - 1].hour, step = 3600.0;
		if (hi - lo > 1) {
			double s1 = 3600.0 * (H->h[lo + 1].hour - H->h[lo].hour);
			if (s1 > 0 && s1 < step)
				step = s1;
		}
		k->t[n] = fmax(0.0, first - step);
		k->at[n++] = -1;
		for (size_t i = lo; i < hi && n < PSD_YEAR_DAY_POINTS - 1; i++) {
			double t = 3600.0 * H->h[i].hour;
			if (t <= k->t[n - 1])
				continue;
			k->t[n] = t;
			k->at[n++] = (long)i;
		}
		if (last + step > k->t[n - 1] && n < PSD_YEAR_DAY_POINTS) {
			k->t[n] = fmin(86400.0, last + step);
			k->at[n++] = -1;
		}
	}
	k->n = n;
}

/* The points' daylight at time t of day doy: rows *a and *b (a dark point
 * reads zeros) and the weight *w to *b, each point a[p] + w (b[p] - a[p])
 * (the room's day_at: linear between the day's points) */
static void day_rows(struct psd_placeyear_task *k, int doy, double t, const double **a, const double **b, double *w)
{
	const struct hours *H = &k->s->hrs;
	size_t np = (size_t)H->npoints;
	double tod = t >= 0 && t < 86400.0 ? t : fmod(t, 86400.0);   /* the room's clock */
	*a = *b = k->zero;
	*w = 0;
	if (tod < 0)
		tod += 86400.0;
	if (doy != k->doy)
		task_day(k, doy);
	if (k->n && tod >= k->t[0] && tod <= k->t[k->n - 1]) {
		/* the last point at or before tod, and the weight to the next */
		int lo = 0, hi = k->n - 1;
		while (lo < hi) {
			int mid = (lo + hi + 1) / 2;
			if (k->t[mid] <= tod)
				lo = mid;
			else
				hi = mid - 1;
		}
		if (k->at[lo] >= 0)
			*a = *b = H->pt_day + (size_t)k->at[lo] * np;
		if (lo + 1 < k->n && k->t[lo + 1] > k->t[lo]) {
			*w = (tod - k->t[lo]) / (k->t[lo + 1] - k->t[lo]);
			*b = k->at[lo + 1] >= 0 ? H->pt_day + (size_t)k->at[lo + 1] * np : k->zero;
		}
	}
}

double psd_placeyear_task(void *ctx, int doy, double t, double lamp)
{
	struct psd_placeyear_task *k = ctx;
	const struct hours *H = &k->s->hrs;
	int np = H->npoints;
	const double *a, *b, *e = H->pt_elec;
	double w, *v = k->v;
	day_rows(k, doy, t, &a, &b, &w);
	if (k->q < 0) {
		double m = INFINITY;
		for (int p = 0; p < np; p++) {
			double x = a[p] + w * (b[p] - a[p]) + lamp * e[p];
			m = x < m ? x : m;
		}
		return m;
	}
	for (int p = 0; p < np; p++)
		v[p] = a[p] + w * (b[p] - a[p]) + lamp * e[p];
	return kth(v, np, k->q);
}

/* The ideal photocell's light output: the smallest at which the figure
 * reaches the target.  Point p reaches it from its threshold (target -
 * daylight_p) / electric_p on; a point without electric light (electric_p
 * 0 or less) at any output when its daylight reaches the target (threshold
 * -infinity), at none when not (+infinity).  The figure of rank q (from 0,
 * the minimum's 0) reaches the target when n - q points do: at the
 * (n - q)-th smallest threshold.  Unclamped (the caller clamps to the
 * law's range). */
static double ideal_of(struct psd_placeyear_task *k, int doy, double t, double target)
{
	const struct hours *H = &k->s->hrs;
	int np = H->npoints, q = k->q < 0 ? 0 : k->q;
	const double *a, *b, *e = H->pt_elec;
	double w, *v = k->v;
	day_rows(k, doy, t, &a, &b, &w);
	for (int p = 0; p < np; p++) {
		double d = a[p] + w * (b[p] - a[p]);
		v[p] = e[p] > 0 ? (target - d) / e[p] : d >= target ? -INFINITY : INFINITY;
	}
	return np > 0 ? kth(v, np, np - 1 - q) : -INFINITY;
}

/* From the year's table when it holds the step (it depends on nothing a
 * combination chooses), else made and kept (the year asks twice a step). */
double psd_placeyear_ideal(void *ctx, int doy, double t, double target)
{
	struct psd_placeyear_task *k = ctx;
	const struct hours *H = &k->s->hrs;
	if (H->ideal && target == H->ideal_target && doy >= 1 && doy <= 366) {
		double i = floor(t / H->ideal_period + 0.5);
		if (i >= 0 && i < (double)H->ideal_steps && (long)i * H->ideal_period == t) {
			double x = H->ideal[(size_t)(doy - 1) * (size_t)H->ideal_steps + (size_t)i];
			if (!isnan(x))
				return x;
		}
	}
	if (doy == k->ideal_doy && t == k->ideal_t && target == k->ideal_target)
		return k->ideal;
	k->ideal_doy = doy;
	k->ideal_t = t;
	k->ideal_target = target;
	k->ideal = ideal_of(k, doy, t, target);
	return k->ideal;
}

/* the year's table of the ideal output at the occupied steps (the annual
 * run's step times, s x period), when the grid's figure is taken point by
 * point and the table is not too large; 0, or -1: out of memory */
#define IDEAL_MAX_CELLS 4000000L
static int ideal_table(struct search *s)
{
	struct hours *H = &s->hrs;
	struct psd_placeyear_task k;
	double period = s->ao.period, target = s->zc->ctl.target_lux;
	long steps = period > 0 ? (long)floor(86400.0 / period + 0.5) : 0;
	if (!H->pt_day || steps <= 0 || steps > IDEAL_MAX_CELLS / 366)
		return 0;
	if (!(H->ideal = malloc((size_t)steps * 366 * sizeof *H->ideal)) || psd_placeyear_task_init(&k, s) != 0) {
		free(H->ideal);
		H->ideal = NULL;
		return -1;
	}
	for (int d = 1; d <= 366; d++)
		for (long i = 0; i < steps; i++) {
			double t = (int)i * period;
			H->ideal[(size_t)(d - 1) * (size_t)steps + (size_t)i] =
				t >= s->ao.occ_start && t < s->ao.occ_end ? ideal_of(&k, d, t, target) : NAN;
		}
	psd_placeyear_task_free(&k);
	H->ideal_steps = steps;
	H->ideal_period = period;
	H->ideal_target = target;
	return 0;
}

int psd_placeyear_task_init(struct psd_placeyear_task *k, const struct search *s)
{
	const char *stat = s->o->stat;
	memset(k, 0, sizeof *k);
	k->s = s;
	k->doy = -1;
	k->ideal_doy = -1;
	if (!strcmp(stat, "min"))
		k->q = -1;
	else {
		int n = s->hrs.npoints, q = (int)ceil(atof(stat + 1) / 100.0 * n) - 1;
		k->q = q < 0 ? 0 : q >= n ? n - 1 : q;
	}
	k->v = malloc((size_t)(s->hrs.npoints > 0 ? s->hrs.npoints : 1) * sizeof *k->v);
	k->zero = calloc((size_t)(s->hrs.npoints > 0 ? s->hrs.npoints : 1), sizeof *k->zero);
	if (!k->v || !k->zero) {
		psd_placeyear_task_free(k);
		return -1;
	}
	return 0;
}

void psd_placeyear_task_free(struct psd_placeyear_task *k)
{
	free(k->v);
	free(k->zero);
	k->v = k->zero = NULL;
}

void psd_placeyear_release(struct ps_results *r)
{
	free(r->year.h);
	free(r->cond);
	memset(r, 0, sizeof *r);
}

