/* SPDX-License-Identifier: ISC */
/* psscene: precompute a space's simulated task-sensor ratios from fisheye
 * renders at the sensor and at the task, for each daylight and electric
 * condition of a scene file; write the results file psensd runs on.
 *   psscene [-o results] [-C cachedir | -N] [-q] scene
 * See psscene(1) and psscene(5). */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"
#include "cache.h"
#include "dcset.h"
#include "gridmtx.h"
#include "integrate.h"
#include "picture.h"
#include "render.h"
#include "results.h"
#include "scene.h"
#include "sensor.h"
#include "filter.h"
#include "sum.h"
#include "view.h"
#include "weather.h"
#include "year.h"
#include "weights.h"

#define LUX_PER_WM2 179.0

struct run {
	const struct ps_scene *sc;
	struct ps_sensor sensor, cosine;
	char sensor_id[200];       /* what identifies the sensor in cache keys */
	double rgb[3];
	const char *cache;         /* NULL: no cache */
	struct ps_weights w;       /* the last weight map, reused while its key matches */
	int have_w;
	int done, total, reused, computed, rendered;
	int tty, quiet;
	char hashes[4096];         /* every input hash, for the scene hash */
};

static void progress(struct run *r, const char *label, const char *what)
{
	int width = 30, filled;
	r->done++;
	if (!r->tty || r->quiet)
		return;
	filled = r->total ? width * r->done / r->total : width;
	fprintf(stderr, "\rpsscene: [%.*s%*s] %d/%d %-12s %-6s", filled,
	        "==============================", width - filled, "", r->done, r->total, label, what);
	if (r->done == r->total)
		fputc('\n', stderr);
	fflush(stderr);
}

static int file_exists(const char *path)
{
	struct stat st;
	return stat(path, &st) == 0;
}

/* Render a missing picture when the scene says how and rpict is here. */
static int ensure_picture(struct run *r, const struct ps_condition *c, const char *pic,
                          int task, struct ps_err *e)
{
	char rpict[4096];
	const struct ps_marks_place *at = task ? &r->sc->task_at : &r->sc->sensor_at;
	double field = task ? 180.0 : ps_render_field(ps_sensor_extent(&r->sensor));
	char **argv;
	int rc;
	if (file_exists(pic))
		return 0;
	if (!c->octree || !at->have) {
		return ps_err_set(e, PS_EMISSING, "%s: condition %s: %s picture %s is missing%s", r->sc->path,
		                  c->label, task ? "task" : "sensor", pic,
		                  c->octree ? "; give the [sensor]/[task] position to render it"
		                         : "; render it (see psscene(1)) or name an octree to render from");
	}
	if (ps_render_find("rpict", rpict, sizeof rpict) != 0)
		return ps_err_set(e, PS_EMISSING, "%s: condition %s: %s picture %s is missing and rpict "
		                  "(Radiance) is not on PATH; render it with: rpict -vta -vp %g %g %g "
		                  "-vd %g %g %g -vu %g %g %g -vh %g -vv %g -x %d -y %d %s > %s",
		                  r->sc->path, c->label, task ? "task" : "sensor", pic, at->pos[0], at->pos[1],
		                  at->pos[2], at->dir[0], at->dir[1], at->dir[2], at->up[0], at->up[1],
		                  at->up[2], field, field, r->sc->resolution, r->sc->resolution, c->octree, pic);
	argv = ps_render_argv(rpict, at->pos, at->dir, at->up, field, r->sc->resolution,
	                      r->sc->render_options, c->octree);
	if (!argv)
		return ps_err_set(e, PS_ENOMEM, "out of memory");
	if (!r->quiet)
		fprintf(stderr, "%spsscene: rendering %s (-vta -vh %g) with %s\n", r->tty ? "\n" : "",
		        pic, field, rpict);
	rc = ps_render_run(argv, pic, e);
	ps_render_free_argv(argv);
	if (rc == 0)
		r->rendered++;
	return rc;
}

/* Response of one picture to the sensor (or the cosine at the task), through
 * the cache.  out[0] = response, out[1] = brightest pixel's share. */
static int integrate(struct run *r, const char *path, int task, double out[2], struct ps_err *e)
{
	char hash[65], key[1024];
	const double *coef = task ? (const double[3]){ PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B }
	                          : r->rgb;
	const struct ps_sensor *s = task ? &r->cosine : &r->sensor;
	struct ps_picture pic;
	struct ps_view view;
	struct ps_response resp;
	char wkey[512], where[4200];
	if (ps_cache_hash_file(path, hash, e) != 0)
		return -1;
	snprintf(key, sizeof key, "v1 %s %s rot=%.17g reading=%s rgb=%.17g,%.17g,%.17g exact", hash,
	         task ? "builtin:cosine" : r->sensor_id, task ? 0.0 : r->sc->rotation,
	         ps_sensor_reading_name(s->reading), coef[0], coef[1], coef[2]);
	{
		size_t n = strlen(r->hashes);
		snprintf(r->hashes + n, sizeof r->hashes - n, "%.16s", hash);
	}
	if (r->cache && ps_cache_get(r->cache, key, out, 2)) {
		r->reused++;
		return 0;
	}
	if (ps_picture_read(&pic, path, e) != 0)
		return -1;
	snprintf(where, sizeof where, "%s: VIEW", path);
	ps_view_default(&view);
	if (!pic.view) {
		ps_view_default_fisheye(&view);
		if (!r->quiet)
			fprintf(stderr, "psscene: warning: %s has no VIEW=; assuming -vta -vh 180 -vv 180\n", path);
	} else if (ps_view_parse(&view, pic.view, where, e) != 0) {
		ps_picture_free(&pic);
		return -1;
	}
	if (ps_view_check_fisheye(&view, where, e) != 0) {
		ps_picture_free(&pic);
		return -1;
	}
	/* weight maps are shared by every picture of the same view and size */
	ps_weights_key(s, task ? 0.0 : r->sc->rotation, &view, pic.width, pic.height, PS_W_EXACT,
	               wkey, sizeof wkey);
	if (!r->have_w || strcmp(wkey, r->w.key) != 0) {
		ps_weights_free(&r->w);
		r->have_w = ps_weights_build(&r->w, s, task ? 0.0 : r->sc->rotation, &view, pic.width,
		                             pic.height, PS_W_EXACT, e) == 0;
		if (!r->have_w) {
			ps_picture_free(&pic);
			return -1;
		}
	}
	if (ps_integrate(&r->w, &pic, coef, &resp, e) != 0) {
		ps_picture_free(&pic);
		return -1;
	}
	if (!r->quiet && r->w.coverage < 1 - 1e-9)
		fprintf(stderr, "psscene: warning: %s holds %.2f %% of the sensitivity\n", path,
		        100 * r->w.coverage);
	ps_picture_free(&pic);
	out[0] = resp.response;
	out[1] = resp.brightest_share;
	r->computed++;
	if (r->cache) {
		struct ps_err ce;
		if (ps_cache_put(r->cache, key, out, 2, &ce) != 0 && !r->quiet)
			fprintf(stderr, "psscene: warning: cache not written: %s\n", ce.msg);
	}
	return 0;
}

static void fmt_time(double tod, char *buf, size_t len)
{
	if (tod < 0)
		snprintf(buf, len, "-");
	else
		snprintf(buf, len, "%02d:%02d", (int)(tod / 3600), (int)fmod(tod / 60, 60));
}

static void print_table(const struct ps_scene *sc, const struct ps_results *res, int cosine_sensor)
{
	printf("scene: %s (%s)\n", sc->name, sc->path);
	printf("sensor: %s, %s reading, rotation %g, R G B %.6f %.6f %.6f\n", res->sensitivity,
	       res->reading, res->rotation, res->rgb[0], res->rgb[1], res->rgb[2]);
	printf("\n%-10s %-9s %-5s %-5s %14s %10s %10s %13s %9s\n", "condition", "kind", "date", "time",
	       "sensor resp.", cosine_sensor ? "sensor lx" : "", "task lx", "lx per resp.",
	       cosine_sensor ? "task/sens" : "");
	for (size_t i = 0; i < res->ncond; i++) {
		const struct ps_result_cond *c = &res->cond[i];
		char t[16];
		fmt_time(c->tod_s, t, sizeof t);
		if (!c->computed) {
			printf("%-10s %-9s %-5s %-5s %14s (optional; pictures missing)\n", c->label,
			       c->kind ? "electric" : "daylight", *c->date ? c->date : "-", t, "-");
			continue;
		}
		printf("%-10s %-9s %-5s %-5s %14.6g ", c->label, c->kind ? "electric" : "daylight",
		       *c->date ? c->date : "-", t, c->sensor_response);
		if (cosine_sensor)
			printf("%10.1f ", LUX_PER_WM2 * c->sensor_response);
		else
			printf("%10s ", "");
		printf("%10.1f %13.2f", c->task_lux, c->ratio);
		if (cosine_sensor)
			printf(" %9.3f", c->ratio / LUX_PER_WM2);
		printf("\n");
	}
	printf("\nsummary (ratios in task lux per unit of sensor response%s):\n",
	       cosine_sensor ? "; lux/lux in brackets" : "");
	if (!isnan(res->daylight_ratio_mean)) {
		printf("  daylight ratio      %.2f", res->daylight_ratio_mean);
		if (cosine_sensor)
			printf(" (%.3f)", res->daylight_ratio_mean / LUX_PER_WM2);
		printf(", spread %.2f %% (sd), %.2f to %.2f\n",
		       100 * res->daylight_ratio_sd / res->daylight_ratio_mean, res->daylight_ratio_min,
		       res->daylight_ratio_max);
	}
	if (!isnan(res->electric_ratio)) {
		printf("  electric ratio      %.2f", res->electric_ratio);
		if (cosine_sensor)
			printf(" (%.3f)", res->electric_ratio / LUX_PER_WM2);
		printf("\n");
	}
	if (!isnan(res->task_sensor_ratio))
		printf("  task-sensor ratio   %.3f  (electric over daylight ratio, as the paper's Table 1)\n",
		       res->task_sensor_ratio);
	if (sc->nref && cosine_sensor) {
		printf("\nbeside other figures (reported, not tuned to):\n");
		printf("  %-28s %10s", "quantity", "psscene");
		for (size_t k = 0; k < sc->nref; k++)
			printf(" %16.16s", sc->ref[k].label);
		printf("\n");
#define ROW(name, ours, field, fmt)                                                      \
	do {                                                                                 \
		printf("  %-28s " fmt, name, ours);                                              \
		for (size_t k = 0; k < sc->nref; k++)                                            \
			if (isnan(sc->ref[k].field))                                                 \
				printf(" %16s", "-");                                                    \
			else                                                                         \
				printf(" %16.4g", sc->ref[k].field);                                     \
		printf("\n");                                                                    \
	} while (0)
		ROW("daylight task/sensor (lx/lx)", res->daylight_ratio_mean / LUX_PER_WM2, daylight_ratio, "%10.3f");
		ROW("electric task/sensor (lx/lx)", res->electric_ratio / LUX_PER_WM2, electric_ratio, "%10.3f");
		ROW("task-sensor ratio", res->task_sensor_ratio, task_sensor_ratio, "%10.3f");
		ROW("electric task lux", res->electric_task_lux, electric_task_lux, "%10.1f");
		ROW("electric sensor lux", LUX_PER_WM2 * res->electric_sensor_response, electric_sensor_lux,
		    "%10.1f");
#undef ROW
	}
}

/* Error against run time of other renders of a condition: against the
 * condition's converged reference when the scene gives one, else against the
 * condition's own pictures. */
static int print_variants(struct run *r, const struct ps_scene *sc, const struct ps_results *res,
                          struct ps_err *e)
{
	for (size_t k = 0; k < sc->ncond; k++) {
		const struct ps_condition *c = &sc->cond[k];
		const struct ps_result_cond *rc = &res->cond[k];
		double rs = isnan(c->ref_sensor) ? rc->sensor_response : c->ref_sensor;
		double rt = isnan(c->ref_task) ? rc->task_irradiance : c->ref_task;
		int header = 0;
		if (!rc->computed)
			continue;
		for (size_t i = 0; i < sc->nvar; i++) {
			const struct ps_variant *v = &sc->var[i];
			double sv[2], tv[2], ratio, rratio = rt / rs;
			char secs[32];
			if (strcmp(v->of, c->label) != 0)
				continue;
			if (!header) {
				printf("\nrenders of %s: error against %s\n", c->label,
				       isnan(c->ref_sensor) ? "its own pictures" : "the converged reference");
				printf("  %-14s %10s %12s %12s %10s %10s\n", "variant", "render s", "sensor",
				       "task W/m2", "ratio", "ratio err");
				printf("  %-14s %10s %12.6g %12.6g %10.4g\n", "reference", "", rs, rt, rratio);
				header = 1;
			}
			if (integrate(r, v->sensor_pic, 0, sv, e) != 0 || integrate(r, v->task_pic, 1, tv, e) != 0)
				return -1;
			ratio = tv[0] / sv[0];
			if (isnan(v->render_seconds))
				snprintf(secs, sizeof secs, "-");
			else
				snprintf(secs, sizeof secs, "%.1f", v->render_seconds);
			printf("  %-14s %10s %12.6g %12.6g %10.4g %+9.2f%%\n", v->label, secs, sv[0], tv[0],
			       ratio, 100 * (ratio / rratio - 1));
		}
	}
	return 0;
}

/* The task's row from a work-plane grid (gridmtx.h): the mean of the rows
 * task_points names (all when it names none); a mean of rows is a row, so
 * the year's task is exactly the points' mean illuminance. */
static int grid_row(const struct ps_dcspec *d, struct ps_dcset_row *row, struct ps_err *e)
{
	struct ps_gridmtx g;
	int n = 0;
	memset(row, 0, sizeof *row);
	if (ps_gridmtx_read(&g, d->task_matrix, e) != 0)
		return -1;
	if (d->mf && g.mf != d->mf) {
		ps_gridmtx_free(&g);
		return ps_err_set(e, PS_EFORMAT, "%s: %d columns (MF %d) where the scene says MF %d", d->task_matrix,
		                  g.npatch, g.mf, d->mf);
	}
	row->c = calloc((size_t)g.npatch * 3, sizeof *row->c);
	if (!row->c) {
		ps_gridmtx_free(&g);
		return ps_err_set(e, PS_ENOMEM, "out of memory");
	}
	for (int i = 0; i < g.npoints; i++) {
		int want = !d->task_points;
		const char *q = d->task_points;
		while (q && *q && !want) {
			char *end;
			want = strtol(q, &end, 10) == i + 1;
			q = *end ? end + 1 : end;
		}
		if (!want)
			continue;
		for (int k = 0; k < g.npatch * 3; k++)
			row->c[k] += g.c[(size_t)i * (size_t)g.npatch * 3 + (size_t)k];
		n++;
	}
	{
		/* every named row must be in the grid */
		const char *q = d->task_points;
		while (q && *q) {
			char *end;
			long i = strtol(q, &end, 10);
			if (i > g.npoints) {
				int np = g.npoints;
				ps_gridmtx_free(&g);
				ps_dcset_row_free(row);
				return ps_err_set(e, PS_ERANGE, "%s: task_points names row %ld of %d", d->task_matrix, i, np);
			}
			q = *end ? end + 1 : end;
		}
	}
	for (int k = 0; k < g.npatch * 3; k++)
		row->c[k] /= n;
	row->mf = g.mf;
	row->n = g.npatch;
	row->coverage = 1.0;
	ps_gridmtx_free(&g);
	return 0;
}

/* The daylight-coefficient rows of both views (the scene's
 * [daylight_coefficients]): the sensor's with its sensitivity, rotation and
 * colour coefficients, the task's with a cosine. */
static int dc_rows(struct run *r, struct ps_dcset_row *srow, struct ps_dcset_row *trow, struct ps_err *e)
{
	const struct ps_dcspec *d = &r->sc->dc;
	if (ps_dcset_row(d->sensor_pattern, &d->sensor_view, d->mf, &r->sensor, r->sc->rotation, srow,
	                 e) != 0)
		return -1;
	if ((d->task_matrix ? grid_row(d, trow, e) : ps_dcset_row(d->task_pattern, &d->task_view, d->mf, &r->cosine,
	                                                          0.0, trow, e)) != 0) {
		ps_dcset_row_free(srow);
		return -1;
	}
	if (srow->n != trow->n) {
		ps_err_set(e, PS_EFORMAT, "%s: %d patches (MF %d), but %s has %d (MF %d): one subdivision for "
		           "both views", d->sensor_pattern, srow->n, srow->mf,
		           d->task_matrix ? d->task_matrix : d->task_pattern, trow->n, trow->mf);
		ps_dcset_row_free(srow);
		ps_dcset_row_free(trow);
		return -1;
	}
	if (!r->quiet && srow->coverage < 1 - 1e-9)
		fprintf(stderr, "psscene: warning: %s holds %.2f %% of the sensitivity\n",
		        d->sensor_pattern, 100 * srow->coverage);
	return 0;
}

static void print_dc(const struct run *r, const struct ps_dcset_row *srow, const struct ps_dcset_row *trow,
                     double seconds)
{
	static const double grey[3] = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B };
	double *one = malloc((size_t)srow->n * 3 * sizeof *one), s, t;
	int zero = 0;
	if (!one)
		return;
	for (int i = 0; i < 3 * srow->n; i++)
		one[i] = 1.0;
	for (int p = 0; p < srow->n; p++)
		zero += srow->c[3 * p] == 0 && srow->c[3 * p + 1] == 0 && srow->c[3 * p + 2] == 0 &&
		        trow->c[3 * p] == 0 && trow->c[3 * p + 1] == 0 && trow->c[3 * p + 2] == 0;
	s = ps_dcset_row_apply(srow, r->rgb, one);
	t = ps_dcset_row_apply(trow, grey, one);
	printf("\ndaylight coefficients: MF %d, %d patches of %d x %d (sensor) and %d x %d (task), "
	       "%d zero in both views; %.2f s\n", srow->mf, srow->n, srow->width, srow->height,
	       trow->width, trow->height, zero, seconds);
	printf("  uniform sky and ground of radiance 1: sensor response %.6g, task %.6g W/m2 "
	       "(%.1f lx), ratio %.2f\n", s, t, LUX_PER_WM2 * t, s > 0 ? LUX_PER_WM2 * t / s : NAN);
	free(one);
}

static double seconds_since(const struct timespec *t0)
{
	struct timespec t1;
	clock_gettime(CLOCK_MONOTONIC, &t1);
	return (double)(t1.tv_sec - t0->tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0->tv_nsec);
}

/* The year of the scene's weather file through the two rows. */
static int run_year(const struct run *r, const struct ps_dcset_row *srow, const struct ps_dcset_row *trow,
                    struct ps_results *res, double *secs, struct ps_err *e)
{
	const struct ps_dcspec *d = &r->sc->dc;
	struct ps_weather w;
	struct ps_sky_opt o;
	struct timespec t0;
	int rc;
	clock_gettime(CLOCK_MONOTONIC, &t0);
	if (ps_weather_read(&w, d->weather, d->weather_illum ? PS_WX_EPW_ILLUM : 0, e) != 0)
		return -1;
	ps_sky_opt_default(&o);
	memcpy(o.ground, d->ground, sizeof o.ground);
	rc = ps_year_run(srow, r->rgb, trow, &w, &o, &res->year, e);
	ps_weather_free(&w);
	if (rc != 0)
		return -1;
	res->have_year = 1;
	res->weather = strdup(d->weather);
	res->year_mf = srow->mf;
	*secs = seconds_since(&t0);
	return res->weather ? 0 : ps_err_set(e, PS_ENOMEM, "out of memory");
}

static void print_year(const struct ps_results *res, double secs)
{
	const struct ps_year *y = &res->year;
	static const char *const mon[] = { "Jan", "Feb", "Mar", "Apr", "May", "Jun",
	                                   "Jul", "Aug", "Sep", "Oct", "Nov", "Dec" };
	printf("\nyear: %s\n  %zu steps, %zu with light, %zu dark skipped; %d of %d patches used; "
	       "%.3f s\n", res->weather, y->steps, y->n, y->dark, y->used, y->patches, secs);
	printf("  daylight ratio over the year %.2f (sum task lux / sum response)\n", y->mean_ratio);
	printf("  %-5s %6s %10s %10s %9s %9s %9s\n", "month", "hours", "task lx", "sensor",
	       "clear", "interm.", "overcast");
	for (int m = 0; m < 12; m++) {
		struct ps_sum ts, ss;
		double cls[PS_SKY_NCLASS];
		int n = 0;
		ps_sum_init(&ts);
		ps_sum_init(&ss);
		for (size_t i = 0; i < y->n; i++)
			if (y->h[i].month == m + 1) {
				ps_sum_add(&ts, y->h[i].task_lux);
				ps_sum_add(&ss, y->h[i].sensor);
				n++;
			}
		for (int c = 0; c < PS_SKY_NCLASS; c++) {
			struct ps_sum a, b;
			ps_sum_init(&a);
			ps_sum_init(&b);
			for (size_t i = 0; i < y->n; i++)
				if (y->h[i].month == m + 1 && y->h[i].sky_class == c) {
					ps_sum_add(&a, y->h[i].task_lux);
					ps_sum_add(&b, y->h[i].sensor);
				}
			cls[c] = ps_sum_get(&b) > 0 ? ps_sum_get(&a) / ps_sum_get(&b) : NAN;
		}
		printf("  %-5s %6d %10.0f %10.3f %9.2f %9.2f %9.2f\n", mon[m], n,
		       n ? ps_sum_get(&ts) / n : 0.0, n ? ps_sum_get(&ss) / n : 0.0, cls[0], cls[1], cls[2]);
	}
	printf("  (mean task lux and sensor response over the month's hours with light; the\n"
	       "  daylight ratio by sky class; the results file has it by hour as well)\n");
}

static void usage(FILE *fp)
{
	fprintf(fp, "usage: psscene [-o results] [-C cachedir | -N] [-q] scene\n"
	            "  -o FILE  results file (default: the scene's name with .results)\n"
	            "  -C DIR   cache directory (default: the scene's cache key, else\n"
	            "           $XDG_CACHE_HOME/psensd or ~/.cache/psensd)\n"
	            "  -N       no cache\n"
	            "  -q       quiet: no table, no progress\n"
	            "  -h, --help  this help;  -V, --version  the version\n");
}

/* An error before the run: said, and what was read freed. */
static int early_error(struct run *r, struct ps_scene *sc, const struct ps_err *e)
{
	fprintf(stderr, "psscene: %s\n", e->msg);
	ps_sensor_free(&r->sensor);
	ps_sensor_free(&r->cosine);
	ps_scene_free(sc);
	return 1;
}

int main(int argc, char **argv)
{
	const char *out = NULL, *cache = NULL;
	int nocache = 0, opt, status = 0;
	char outbuf[4096], cachebuf[4096], shash[65], hash[65];
	struct ps_scene sc;
	struct ps_results res;
	struct run r;
	struct ps_err e;
	struct ps_dcset_row srow, trow;
	int have_dc = 0;
	double dc_seconds = 0, year_seconds = 0;

	memset(&r, 0, sizeof r);
	memset(&srow, 0, sizeof srow);
	memset(&trow, 0, sizeof trow);
	static const struct option longopts[] = { PS_CLI_LONGOPTS, { NULL, 0, NULL, 0 } };
	while ((opt = getopt_long(argc, argv, "o:C:NqhV", longopts, NULL)) != -1) {
		switch (opt) {
		case 'o': out = optarg; break;
		case 'C': cache = optarg; break;
		case 'N': nocache = 1; break;
		case 'q': r.quiet = 1; break;
		case 'h': usage(stdout); return 0;
		case 'V': return ps_cli_version("psscene");
		default: usage(stderr); return 2;
		}
	}
	if (optind != argc - 1) {
		usage(stderr);
		return 2;
	}
	if (ps_scene_read(&sc, argv[optind], &e) != 0) {
		fprintf(stderr, "psscene: %s\n", e.msg);
		return 1;
	}
	r.sc = &sc;
	if (!out) {
		const char *dot = strrchr(sc.path, '.');
		size_t n = dot && !strchr(dot, '/') ? (size_t)(dot - sc.path) : strlen(sc.path);
		snprintf(outbuf, sizeof outbuf, "%.*s.results", (int)n, sc.path);
		out = outbuf;
	}
	if (!nocache) {
		if (!cache && sc.cache_dir)
			cache = sc.cache_dir;
		if (!cache) {
			const char *x = getenv("XDG_CACHE_HOME"), *home = getenv("HOME");
			if (x && *x)
				snprintf(cachebuf, sizeof cachebuf, "%s/psensd", x);
			else
				snprintf(cachebuf, sizeof cachebuf, "%s/.cache/psensd", home ? home : "/tmp");
			cache = cachebuf;
		}
		r.cache = cache;
	}
	if (ps_sensor_open(&r.sensor, sc.sensitivity, &e) != 0 ||
	    ps_sensor_set_reading(&r.sensor, sc.reading, &e) != 0 ||
	    ps_sensor_builtin(&r.cosine, PS_SENS_COSINE, &e) != 0) {
		return early_error(&r, &sc, &e);
	}
	if (strncmp(sc.sensitivity, "builtin:", 8) == 0)
		snprintf(r.sensor_id, sizeof r.sensor_id, "%s", sc.sensitivity);
	else if (ps_cache_hash_file(sc.sensitivity, hash, &e) == 0)
		snprintf(r.sensor_id, sizeof r.sensor_id, "sensor:%s", hash);
	else {
		return early_error(&r, &sc, &e);
	}
	memcpy(r.rgb, sc.rgb, sizeof r.rgb);
	if (sc.filter && ps_filter_rgb(sc.filter, r.rgb, &e) != 0) {
		return early_error(&r, &sc, &e);
	}
	r.tty = isatty(2);
	r.total = (int)(2 * sc.ncond);
	memset(&res, 0, sizeof res);
	res.scene = strdup(sc.path);
	res.sensitivity = strdup(sc.sensitivity);
	res.reading = strdup(ps_sensor_reading_name(sc.reading));
	res.rotation = sc.rotation;
	memcpy(res.rgb, r.rgb, sizeof res.rgb);
	res.cond = calloc(sc.ncond, sizeof *res.cond);
	res.ncond = sc.ncond;
	for (size_t i = 0; i < sc.ncond && status == 0; i++) {
		const struct ps_condition *c = &sc.cond[i];
		struct ps_result_cond *rc = &res.cond[i];
		double sv[2], tv[2];
		int missing = 0;
		rc->label = strdup(c->label);
		rc->kind = c->kind;
		rc->date = strdup(c->date);
		rc->tod_s = c->tod_s;
		for (int task = 0; task < 2; task++)
			if (ensure_picture(&r, c, task ? c->task_pic : c->sensor_pic, task, &e) != 0) {
				if (c->optional && e.code == PS_EMISSING) {
					missing = 1;
					continue;
				}
				if (r.tty && !r.quiet)
					fputc('\n', stderr);
				fprintf(stderr, "psscene: %s\n", e.msg);
				status = 1;
				break;
			}
		if (status)
			break;
		if (missing) {
			if (!r.quiet)
				fprintf(stderr, "%spsscene: %s: pictures missing; optional condition left out\n",
				        r.tty ? "\n" : "", c->label);
			r.done += 2;
			continue;
		}
		if (integrate(&r, c->sensor_pic, 0, sv, &e) != 0 || (progress(&r, c->label, "sensor"), 0) ||
		    integrate(&r, c->task_pic, 1, tv, &e) != 0) {
			if (r.tty && !r.quiet)
				fputc('\n', stderr);
			fprintf(stderr, "psscene: condition %s: %s\n", c->label, e.msg);
			status = 1;
			break;
		}
		progress(&r, c->label, "task");
		rc->computed = 1;
		rc->sensor_response = sv[0];
		rc->brightest_share = sv[1];
		rc->task_irradiance = tv[0];
		rc->task_lux = LUX_PER_WM2 * tv[0];
		rc->ratio = sv[0] > 0 ? rc->task_lux / sv[0] : NAN;
		if (!(sv[0] > 0) || !isfinite(rc->ratio)) {
			if (r.tty && !r.quiet)
				fputc('\n', stderr);
			if (!(sv[0] > 0))
				fprintf(stderr, "psscene: condition %s: the sensor's response is %g (%s sees no "
				        "light where the sensor looks): no task-sensor ratio\n", c->label, sv[0],
				        c->sensor_pic);
			else
				fprintf(stderr, "psscene: condition %s: the task-sensor ratio is not finite "
				        "(task %g lx over sensor response %g)\n", c->label, rc->task_lux, sv[0]);
			status = 1;
			break;
		}
	}
	if (status == 0 && sc.dc.have) {
		struct timespec t0, t1;
		clock_gettime(CLOCK_MONOTONIC, &t0);
		if (dc_rows(&r, &srow, &trow, &e) != 0) {
			fprintf(stderr, "psscene: %s\n", e.msg);
			status = 1;
		} else {
			have_dc = 1;
			clock_gettime(CLOCK_MONOTONIC, &t1);
			dc_seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
			if (sc.dc.weather && run_year(&r, &srow, &trow, &res, &year_seconds, &e) != 0) {
				fprintf(stderr, "psscene: %s\n", e.msg);
				status = 1;
			}
		}
	}
	if (status == 0) {
		char all[8192];
		ps_results_summarise(&res);
		if (ps_cache_hash_file(sc.path, shash, &e) != 0) {
			fprintf(stderr, "psscene: %s\n", e.msg);
			status = 1;
			goto done;
		}
		snprintf(all, sizeof all, "%s|%s|%s|%.17g|%.17g,%.17g,%.17g", shash, r.sensor_id, r.hashes,
		         sc.rotation, r.rgb[0], r.rgb[1], r.rgb[2]);
		ps_cache_hash_string(all, hash);
		res.scene_hash = strdup(hash);
		if (ps_results_write(&res, out, &e) != 0) {
			fprintf(stderr, "psscene: %s\n", e.msg);
			status = 1;
		} else if (!r.quiet) {
			print_table(&sc, &res, r.sensor.kind == PS_SENS_COSINE ||
			                           (strstr(sc.sensitivity, "cosine") != NULL));
			if (have_dc)
				print_dc(&r, &srow, &trow, dc_seconds);
			if (res.have_year)
				print_year(&res, year_seconds);
			if (print_variants(&r, &sc, &res, &e) != 0) {
				fprintf(stderr, "psscene: %s\n", e.msg);
				status = 1;
			}
			printf("\n%d integrations: %d computed, %d reused from the cache%s%s; %d rendered\n",
			       r.computed + r.reused, r.computed, r.reused, r.cache ? " " : "",
			       r.cache ? r.cache : "", r.rendered);
			printf("results: %s\n", out);
		}
	}
done:
	ps_results_free(&res);
	ps_dcset_row_free(&srow);
	ps_dcset_row_free(&trow);
	ps_weights_free(&r.w);
	ps_sensor_free(&r.sensor);
	ps_sensor_free(&r.cosine);
	ps_scene_free(&sc);
	return status;
}
