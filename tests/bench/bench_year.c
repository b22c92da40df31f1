/* SPDX-License-Identifier: ISC */
/* The year through daylight-coefficient rows: run time of the precompute
 * (weights and coefficients) and of the year (8760 skies through the rows)
 * against MF, for an upward cosine sensor under an open sky (exact
 * coefficient pictures, ps_dcpic, 128 x 128) and the example office's
 * rfluxmtx pictures (MF 1, read from disk), with the example's year
 * (config/example/ofb/weather/sf-tmy3.wea: San Francisco's TMY3 year,
 * NREL; see its README).  Goal: the year's series for one zone at MF 4 in at
 * most 1 s once the coefficients are integrated.  The sensor and task rows
 * share the sky vectors, so a second view costs only its dot products. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "dcpic.h"
#include "dcset.h"
#include "integrate.h"
#include "patches.h"
#include "sensor.h"
#include "sky.h"
#include "view.h"
#include "weather.h"
#include "weights.h"
#include "year.h"
#include "time.h"

#define RES 128

static const double V[3] = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B };

static int top_path(char *buf, size_t n, const char *rel)
{
	const char *top = getenv("TOP");
	return snprintf(buf, n, "%s/%s", top ? top : ".", rel) < (int)n ? 0 : -1;
}

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return x < y ? -1 : x > y;
}

int main(void)
{
	static const int mfs[] = { 1, 2, 4, 6 };
	struct ps_weather w;
	struct ps_sensor cos;
	struct ps_view v;
	struct ps_sky_opt o;
	struct ps_err e;
	char path[4096];
	top_path(path, sizeof path, "config/example/ofb/weather/sf-tmy3.wea");
	if (ps_weather_read(&w, path, 0, &e) != 0 || ps_sensor_builtin(&cos, PS_SENS_COSINE, &e) != 0) {
		fprintf(stderr, "bench_year: %s\n", e.msg);
		return 1;
	}
	ps_view_default(&v);
	ps_view_parse(&v, "-vta -vp 0 0 0 -vd 0 0 1 -vu 0 1 0 -vh 180 -vv 180", "bench", &e);
	ps_sky_opt_default(&o);
	printf("the year (%zu steps of %s) through coefficient rows, upward cosine, open sky,\n"
	       "exact pictures %d x %d (ms; year = both rows, every hour with light)\n", w.n, path,
	       RES, RES);
	printf("%4s %8s %10s %12s %10s %10s %12s %14s\n", "MF", "patches", "weights", "coefficients",
	       "year", "per hour", "mean ratio", "task lx-hours");
	for (size_t k = 0; k < sizeof mfs / sizeof *mfs; k++) {
		struct ps_patches P;
		struct ps_weights wt;
		struct ps_dcset_row row;
		struct ps_year y;
		int *map = malloc(RES * RES * sizeof *map);
		double *c, t0, t1, t2, t3;
		struct { double s; } sum = { 0 };
		static const double red[3] = { 1, 0, 0 };
		ps_patches_init(&P, mfs[k], &e);
		t0 = psd_time_mono();
		ps_weights_build(&wt, &cos, 0.0, &v, RES, RES, PS_W_EXACT, &e);
		t1 = psd_time_mono();
		ps_dcpic_map(&P, &v, RES, RES, map, &e);
		c = malloc((size_t)P.n * sizeof *c);
		ps_dcpic_coefficients(&wt, map, P.n, red, c, &e);
		memset(&row, 0, sizeof row);
		row.mf = mfs[k];
		row.n = P.n;
		row.c = malloc((size_t)P.n * 3 * sizeof *row.c);
		for (int p = 0; p < P.n; p++)
			row.c[3 * p] = row.c[3 * p + 1] = row.c[3 * p + 2] = c[p];
		t2 = psd_time_mono();
		if (ps_year_run(&row, V, &row, &w, &o, &y, &e) != 0) {
			fprintf(stderr, "bench_year: %s\n", e.msg);
			return 1;
		}
		t3 = psd_time_mono();
		for (size_t i = 0; i < y.n; i++)
			sum.s += y.h[i].task_lux;
		printf("%4d %8d %10.1f %12.1f %10.1f %10.4f %12.2f %14.4g\n", mfs[k], P.n,
		       1e3 * (t1 - t0), 1e3 * (t2 - t1), 1e3 * (t3 - t2), 1e3 * (t3 - t2) / (double)y.n,
		       y.mean_ratio, sum.s);
		ps_year_free(&y);
		ps_dcset_row_free(&row);
		free(c);
		free(map);
		ps_weights_free(&wt);
		ps_patches_free(&P);
	}
	{
		struct ps_dcset_row s, t;
		struct ps_year y;
		struct ps_view sv, tv;
		char sp[4096], tp[4096];
		double t0, t1, t2;
		top_path(sp, sizeof sp, "config/example/ofb/dc/sensor/dc_%03d.hdr");
		top_path(tp, sizeof tp, "config/example/ofb/dc/task/dc_%03d.hdr");
		ps_view_default(&sv);
		ps_view_default(&tv);
		ps_view_parse(&sv, "-vta -vp 1.85 2.285 2.2 -vd 0 0 -1 -vu 0 1 0 -vh 180 -vv 180", "b", &e);
		ps_view_parse(&tv, "-vta -vp 1.85 2.285 0.762 -vd 0 0 1 -vu 0 1 0 -vh 180 -vv 180", "b", &e);
		t0 = psd_time_mono();
		if (ps_dcset_row(sp, &sv, 1, &cos, 0.0, &s, &e) != 0 ||
		    ps_dcset_row(tp, &tv, 1, &cos, 0.0, &t, &e) != 0) {
			fprintf(stderr, "bench_year: %s\n", e.msg);
			return 1;
		}
		t1 = psd_time_mono();
		ps_year_run(&s, V, &t, &w, &o, &y, &e);
		t2 = psd_time_mono();
		printf("\nthe example office (rfluxmtx pictures, MF 1, 2 x 146 of 64 x 64 read from disk):\n"
		       "  precompute (read, weights once per view, integrate) %.1f ms; the year %.1f ms "
		       "(%zu hours with light, %.2f us an hour)\n",
		       1e3 * (t1 - t0), 1e3 * (t2 - t1), y.n, 1e6 * (t2 - t1) / (double)y.n);
		{
			/* how much an hour's task daylight hangs on how the sun is
			 * shared at MF 1: the sun in its nearest patch against the four
			 * nearest (gendaymtx's way), occupied hours with 50 lx or more */
			struct ps_sky_opt o1 = o;
			struct ps_year y1;
			double *d = malloc(y.n * sizeof *d), s4 = 0, s1 = 0, worst = 0;
			size_t m = 0;
			o1.nsun = 1;
			if (!d || ps_year_run(&s, V, &t, &w, &o1, &y1, &e) != 0 || y1.n != y.n) {
				fprintf(stderr, "bench_year: the sun in one patch: %s\n", e.msg);
				free(d);
				return 1;
			}
			for (size_t i = 0; i < y.n; i++) {
				if (y.h[i].hour < 8 || y.h[i].hour > 18 || y.h[i].task_lux < 50)
					continue;
				s4 += y.h[i].task_lux;
				s1 += y1.h[i].task_lux;
				d[m] = fabs(y1.h[i].task_lux / y.h[i].task_lux - 1);
				if (d[m] > worst)
					worst = d[m];
				m++;
			}
			qsort(d, m, sizeof *d, cmp_double);
			printf("  the sun in its nearest patch against the four nearest (MF 1), %zu occupied hours with 50 lx\n"
			       "  or more at the task: hours' task daylight differ by up to %.0f %% (95th percentile %.1f %%,\n"
			       "  median %.1f %%); the sum over them by %+.2f %%\n",
			       m, 100 * worst, m ? 100 * d[(size_t)(0.95 * (double)(m - 1))] : NAN,
			       m ? 100 * d[(m - 1) / 2] : NAN, 100 * (s1 / s4 - 1));
			free(d);
			ps_year_free(&y1);
		}
		ps_year_free(&y);
		ps_dcset_row_free(&s);
		ps_dcset_row_free(&t);
	}
	ps_sensor_free(&cos);
	ps_weather_free(&w);
	return 0;
}
