/* SPDX-License-Identifier: ISC */
/* The sky: the daylight-coefficient route against the continuous Perez sky,
 * its error against MF and its run time.
 *
 * A sensor faces up under an unobstructed sky.  Its coefficient pictures are
 * exact (ps_dcpic: each patch's own region of a 256 x 256 180-degree fisheye
 * with radiance 1), integrated by psens with the sensor's exact weights; the
 * route's signal is the sum over patches of coefficient x patch radiance
 * (the sky vector as gendaymtx makes it, normalised with the exact sine).
 * The exact signal integrates the continuous sky (normalised to the same
 * diffuse illuminance) times the sensitivity by adaptive quadrature (its
 * own error estimate printed), plus the sun as a point.
 *   err sky:     the diffuse sky alone (patch sampling and the pictures' pixels)
 *   err +sun:    with the sun (spread over 4 patches against a point)
 *   exact coefficients: each coefficient the quadrature of the sensitivity
 *                over the patch: what is left is the sky's own discretisation
 *                (the pictures' pixel error removed)
 * Sensors: the ideal cosine, and a cone (sensitivity 1 to 29 degrees, 0 from
 * 31).  Hours from Radiance's test.wea (Mountain View). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "dcpic.h"
#include "integrate.h"
#include "patches.h"
#include "quad.h"
#include "sensor.h"
#include "sky.h"
#include "view.h"
#include "weather.h"
#include "weights.h"
#include "time.h"

#define RES 256

static const double rgbcoef[3] = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B };

struct sens_ctx {
	const struct ps_sensor *s;
	double f[3][3];       /* the view's frame */
};

/* sensitivity in a world direction */
static double sens_weight(const double d[3], void *p)
{
	const struct sens_ctx *c = p;
	double x = d[0] * c->f[0][0] + d[1] * c->f[0][1] + d[2] * c->f[0][2];
	double y = d[0] * c->f[1][0] + d[1] * c->f[1][1] + d[2] * c->f[1][2];
	double z = d[0] * c->f[2][0] + d[1] * c->f[2][1] + d[2] * c->f[2][2];
	return ps_sensor_value(c->s, acos(fmax(-1, fmin(1, z))), atan2(y, x));
}

/* for the view used here (up, north at the top) the sensor's polar angle is
 * the zenith angle and its azimuth the compass azimuth east of north */
struct patch_ctx {
	const struct ps_sensor *s;
};

static double patch_f(double alt, double azi, void *p)
{
	const struct patch_ctx *c = p;
	return ps_sensor_value(c->s, M_PI / 2 - alt, azi) * cos(alt);
}

/* the exact coefficient: the sensitivity integrated over the patch */
static double patch_exact(const struct ps_patches *P, int i, const struct ps_sensor *s)
{
	struct patch_ctx c = { s };
	struct ps_quad2_spec q;
	struct ps_quad r;
	double b[4], xb[256], yb[256];
	int nx = 0, ny = 0;
	ps_patches_bounds(P, i, b);
	for (int k = 0; k <= s->nt && nx < 256; k++)
		xb[nx++] = M_PI / 2 - s->tb[k];
	for (int k = 0; k <= s->np && ny < 256; k++)
		for (int w = -1; w <= 1 && ny < 256; w++)
			yb[ny++] = s->pb[k] + 2 * M_PI * w;
	q.x0 = b[0];
	q.x1 = b[1];
	q.xb = xb;
	q.nxb = nx;
	q.y0 = b[2];
	q.y1 = b[3];
	q.yb = yb;
	q.nyb = ny;
	q.abstol = 1e-15;
	q.reltol = 1e-11;
	q.max_intervals = 200;
	ps_quad_2d(patch_f, &c, &q, &r);
	return r.value;
}

struct hour {
	const char *name;
	int month, day;
	double hour;
};

int main(void)
{
	static const int mfs[4] = { 1, 2, 4, 6 };
	static const struct hour hours[3] = {
		{ "clear", 6, 21, 12.5 }, { "intermediate", 3, 21, 12.5 }, { "overcast", 3, 21, 13.5 }
	};
	static const char cone_text[] = "Elevation field 31\ndegrees 0 90 180 270\n0 1 1 1 1\n29 1 1 1 1\n31 0 0 0 0\n";
	struct ps_sensor sens[2];
	const char *sname[2] = { "cosine", "cone 30" };
	struct ps_weather w;
	struct ps_view v;
	struct ps_err e;
	struct ps_sky_opt o;
	struct ps_sky sky[3];
	double exact_sky[2][3], exact_sun[2][3], quad_err[2][3], quad_ms[2][3];
	size_t hi[3];
	double err[4][2][3][4], times[4][5];   /* [mf][sensor][hour][kind]; times: map, coef, vector, signal, weights */
	double f[3][3];
	const char *top = getenv("TOP");
	char path[4096];

	snprintf(path, sizeof path, "%s/tests/data/gendaymtx/test.wea", top ? top : ".");
	if (ps_weather_read(&w, path, 0, &e) != 0 || ps_sensor_builtin(&sens[0], PS_SENS_COSINE, &e) != 0 ||
	    ps_sensor_parse(&sens[1], cone_text, strlen(cone_text), "cone30", &e) != 0) {
		fprintf(stderr, "bench_sky: %s\n", e.msg);
		return 1;
	}
	ps_sky_opt_default(&o);
	o.exact_sine = 1;
	ps_view_default_fisheye(&v);
	v.vd[2] = 1.0;   /* up, north (+Y) at the top */
	ps_dcpic_frame(&v, f);
	for (int h = 0; h < 3; h++) {
		hi[h] = w.n;
		for (size_t i = 0; i < w.n; i++)
			if (w.step[i].month == hours[h].month && w.step[i].day == hours[h].day &&
			    w.step[i].hour == hours[h].hour)
				hi[h] = i;
		if (hi[h] == w.n || ps_sky_step(&sky[h], &w, hi[h], &o, &e) != 0 ||
		    ps_sky_normalise(&sky[h], 1e-12, &e) != 0) {
			fprintf(stderr, "bench_sky: hour %s: %s\n", hours[h].name, hi[h] == w.n ? "missing" : e.msg);
			return 1;
		}
	}
	/* the exact signals */
	for (int k = 0; k < 2; k++) {
		struct sens_ctx c = { &sens[k], { { 0 } } };
		double zb[64], ab[64];
		int nz = 0, na = 0;
		memcpy(c.f, f, sizeof f);
		for (int q = 0; q <= sens[k].nt && nz < 64; q++)
			zb[nz++] = sens[k].tb[q];
		for (int q = 0; q <= sens[k].np && na < 64; q++)
			ab[na++] = sens[k].pb[q];
		for (int h = 0; h < 3; h++) {
			struct ps_quad r;
			double sd[3], srgb[3], t0 = psd_time_mono();
			if (ps_sky_integrate(&sky[h], rgbcoef, sens_weight, &c, zb, nz, ab, na, 1e-10, &r, &e) != 0) {
				fprintf(stderr, "bench_sky: %s\n", e.msg);
				return 1;
			}
			quad_ms[k][h] = 1e3 * (psd_time_mono() - t0);
			exact_sky[k][h] = r.value;
			quad_err[k][h] = r.error / fabs(r.value);
			ps_sky_sun(&sky[h], sd, srgb);
			exact_sun[k][h] = sd[2] > 0 ? sens_weight(sd, &c) *
			                                  (rgbcoef[0] * srgb[0] + rgbcoef[1] * srgb[1] + rgbcoef[2] * srgb[2])
			                            : 0.0;
		}
	}
	for (int m = 0; m < 4; m++) {
		struct ps_patches P;
		int *map;
		double *coef, *exact, *vd, *vs, t0;
		if (ps_patches_init(&P, mfs[m], &e) != 0)
			return 1;
		map = malloc((size_t)RES * RES * sizeof *map);
		coef = malloc((size_t)P.n * sizeof *coef);
		exact = malloc((size_t)P.n * sizeof *exact);
		vd = malloc((size_t)P.n * 3 * sizeof *vd);
		vs = malloc((size_t)P.n * 3 * sizeof *vs);
		t0 = psd_time_mono();
		if (ps_dcpic_map(&P, &v, RES, RES, map, &e) != 0)
			return 1;
		times[m][0] = psd_time_mono() - t0;
		times[m][1] = times[m][4] = 0;
		for (int k = 0; k < 2; k++) {
			struct ps_weights wt;
			t0 = psd_time_mono();
			if (ps_weights_build(&wt, &sens[k], 0, &v, RES, RES, PS_W_EXACT, &e) != 0) {
				fprintf(stderr, "bench_sky: %s\n", e.msg);
				return 1;
			}
			times[m][4] += psd_time_mono() - t0;
			t0 = psd_time_mono();
			if (ps_dcpic_coefficients(&wt, map, P.n, rgbcoef, coef, &e) != 0) {
				fprintf(stderr, "bench_sky: %s\n", e.msg);
				return 1;
			}
			times[m][1] += psd_time_mono() - t0;
			ps_weights_free(&wt);
			exact[0] = 0;
			for (int i = 1; i < P.n; i++)
				exact[i] = patch_exact(&P, i, &sens[k]);
			for (int h = 0; h < 3; h++) {
				double route_d = 0, route_s = 0, route_x = 0, route_xs = 0;
				int reps = 200;
				t0 = psd_time_mono();
				for (int r = 0; r < reps; r++) {
					ps_sky_vector(&sky[h], &P, PS_SKY_DIFFUSE, vd);
					ps_sky_vector(&sky[h], &P, PS_SKY_SUN, vs);
				}
				times[m][2] = (psd_time_mono() - t0) / (2 * reps);
				t0 = psd_time_mono();
				for (int r = 0; r < reps; r++) {
					route_d = route_s = route_x = route_xs = 0;
					for (int i = 0; i < P.n; i++) {
						double ld = rgbcoef[0] * vd[3 * i] + rgbcoef[1] * vd[3 * i + 1] +
						            rgbcoef[2] * vd[3 * i + 2];
						double ls = rgbcoef[0] * vs[3 * i] + rgbcoef[1] * vs[3 * i + 1] +
						            rgbcoef[2] * vs[3 * i + 2];
						route_d += coef[i] * ld;
						route_s += coef[i] * ls;
						route_x += exact[i] * ld;
						route_xs += exact[i] * ls;
					}
				}
				times[m][3] = (psd_time_mono() - t0) / reps / 3;
				/* the coefficients' colour weights sum to 1: a grey patch's coefficient */
				err[m][k][h][0] = route_d / exact_sky[k][h] - 1;
				err[m][k][h][1] = (route_d + route_s) / (exact_sky[k][h] + exact_sun[k][h]) - 1;
				err[m][k][h][2] = route_x / exact_sky[k][h] - 1;
				err[m][k][h][3] = (route_x + route_xs) / (exact_sky[k][h] + exact_sun[k][h]) - 1;
			}
		}
		free(map);
		free(coef);
		free(exact);
		free(vd);
		free(vs);
		ps_patches_free(&P);
	}
	printf("daylight-coefficient route against the continuous Perez sky: sensor facing up, %d x %d\n"
	       "exact coefficient pictures, psens's exact weights; errors relative to the quadrature\n\n",
	       RES, RES);
	printf("  %-8s %-12s %-5s %6s  %12s  %9s  %9s |      %-20s  %s\n", "", "", "", "sun", "", "",
	       "", "coefficient pictures", "exact coefficients");
	printf("  %-8s %-12s %-5s %6s  %12s  %9s  %9s |  MF   err sky   err +sun    err sky   err +sun\n",
	       "sensor", "sky", "date", "alt", "exact signal", "quad. err", "quad. ms");
	for (int k = 0; k < 2; k++)
		for (int h = 0; h < 3; h++)
			for (int m = 0; m < 4; m++) {
				if (m == 0)
					printf("  %-8s %-12s %2d/%-2d %6.1f  %12.5g  %9.1e  %9.1f |", sname[k],
					       hours[h].name, hours[h].month, hours[h].day, sky[h].sun_alt * 180 / M_PI,
					       exact_sky[k][h] + exact_sun[k][h], quad_err[k][h], quad_ms[k][h]);
				else
					printf("  %-8s %-12s %5s %6s  %12s  %9s  %9s |", "", "", "", "", "", "", "");
				printf("  %2d  %+8.2e  %+8.2e  %+8.2e  %+8.2e\n", mfs[m], err[m][k][h][0],
				       err[m][k][h][1], err[m][k][h][2], err[m][k][h][3]);
			}
	printf("\nrun time (the coefficients once per sensor; then per hour a sky vector and a sum)\n"
	       "  MF  patches  patch map ms  weights ms  pictures+integration ms  per patch us"
	       "  sky vector us  signal us\n");
	for (int m = 0; m < 4; m++)
		printf("  %2d  %7d  %12.1f  %10.1f  %23.1f  %12.1f  %13.1f  %9.2f\n", mfs[m],
		       ps_patches_count(mfs[m]), 1e3 * times[m][0], 1e3 * times[m][4] / 2,
		       1e3 * times[m][1] / 2, 1e6 * times[m][1] / (2.0 * ps_patches_count(mfs[m])),
		       1e6 * times[m][2], 1e6 * times[m][3]);
	printf("  (weights and pictures: per sensor; the exact signal's quadrature is in the table above)\n");
	ps_sensor_free(&sens[0]);
	ps_sensor_free(&sens[1]);
	ps_weather_free(&w);
	return 0;
}
