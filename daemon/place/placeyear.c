/* SPDX-License-Identifier: ISC */
#include "placeyear.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dcset.h"
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
		H->n++;
	}
	free(lux);
	ps_weather_free(&w);
	ps_patches_free(&P);
	return 0;
}

/* The year's sensor signals of rows rows[0 .. nrow - 1] (each npatch x 3,
 * per channel) into sig[j * hours + i]: a block of rows at a time, each
 * row's sum taken in the one order (patch, then channel) and each term as
 * (V[c] x row) x sky, so a row's signals are the same in any block. */
#define SIG_BLOCK 4
int psd_placeyear_signals(const struct search *s, const double *const *rows, int nrow, double *sig)
{
	const struct hours *H = &s->hrs;
	size_t m = (size_t)H->npatch * 3;
	double *rv = malloc(SIG_BLOCK * m * sizeof *rv);
	if (!rv)
		return -1;
	for (int j0 = 0; j0 < nrow; j0 += SIG_BLOCK) {
		int nb = nrow - j0 < SIG_BLOCK ? nrow - j0 : SIG_BLOCK;
		for (int b = 0; b < SIG_BLOCK; b++) {
			const double *row = rows[j0 + (b < nb ? b : 0)];
			for (size_t k = 0; k < m; k++)
				rv[b * m + k] = V[k % 3] * row[k];
		}
		for (size_t i = 0; i < H->n; i++) {
			const double *sky = H->sky + i * m;
			const double *r0 = rv, *r1 = rv + m, *r2 = rv + 2 * m, *r3 = rv + 3 * m;
			double v0 = 0, v1 = 0, v2 = 0, v3 = 0;
			for (size_t k = 0; k < m; k++) {
				double x = sky[k];
				v0 += r0[k] * x;
				v1 += r1[k] * x;
				v2 += r2[k] * x;
				v3 += r3[k] * x;
			}
			{
				double v[SIG_BLOCK] = { v0, v1, v2, v3 };
				for (int b = 0; b < nb; b++)
					sig[(size_t)(j0 + b) * H->n + i] = v[b];
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
	if (!sig || psd_placeyear_signals(s, &row, 1, sig) != 0) {
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
	memcpy(r->rgb, V, sizeof r->rgb);
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

void psd_placeyear_release(struct ps_results *r)
{
	free(r->year.h);
	free(r->cond);
	memset(r, 0, sizeof *r);
}

