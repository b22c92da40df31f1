/* SPDX-License-Identifier: ISC */
/* Where the signal comes from: each pixel's share of the response sums to 1
 * and matches ps_integrate; and under a uniform sky of radiance the shares
 * of a box room's surfaces seen by an ideal cosine sensor are their
 * configuration factors, which Lambert's contour formula gives exactly:
 * F = (1 / 2 pi) sum_i gamma_i (n . (R_i x R_i+1) / |R_i x R_i+1|). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "integrate.h"
#include "picture.h"
#include "radgeom.h"
#include "regions.h"
#include "sensor.h"
#include "share.h"
#include "sum.h"
#include "view.h"
#include "weights.h"

static const double coef[3] = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B };

static void load_view(const struct ps_picture *pic, struct ps_view *v)
{
	struct ps_err e;
	ps_view_default(v);
	assert_non_null(pic->view);
	assert_int_equal(ps_view_parse(v, pic->view, "pic", &e), 0);
	assert_int_equal(ps_view_check_fisheye(v, "pic", &e), 0);
}

static void shares_of_the_example_render(void **state)
{
	const char *top = getenv("TOP");
	char path[600];
	struct ps_picture pic;
	struct ps_view v;
	struct ps_sensor s, uni;
	struct ps_weights w, sa;
	struct ps_response r;
	struct ps_share sh;
	struct ps_regions reg;
	struct ps_radgeom g;
	struct ps_region_share *rs;
	struct ps_sum sum;
	struct ps_err e;
	(void)state;
	snprintf(path, sizeof path, "%s/config/example/ofb/img/day_0318_sensor_256.hdr", top ? top : ".");
	assert_int_equal(ps_picture_read(&pic, path, &e), 0);
	load_view(&pic, &v);
	snprintf(path, sizeof path, "%s/config/example/ofb/sensors/cosine.sen", top ? top : ".");
	assert_int_equal(ps_sensor_open(&s, path, &e), 0);
	assert_int_equal(ps_sensor_set_reading(&s, PS_READ_LINEAR, &e), 0);
	assert_int_equal(ps_sensor_builtin(&uni, PS_SENS_UNIFORM, &e), 0);
	assert_int_equal(ps_weights_build(&w, &s, 30, &v, pic.width, pic.height, PS_W_EXACT, &e), 0);
	assert_int_equal(ps_weights_build(&sa, &uni, 0, &v, pic.width, pic.height, PS_W_EXACT, &e), 0);
	assert_int_equal(ps_integrate(&w, &pic, coef, &r, &e), 0);
	assert_int_equal(ps_share_compute(&sh, &w, &pic, coef, &e), 0);
	assert_true(fabs(sh.response - r.response) <= 1e-12 * r.response);
	ps_sum_init(&sum);
	for (size_t p = 0; p < (size_t)pic.width * (size_t)pic.height; p++)
		ps_sum_add(&sum, sh.share[p]);
	assert_true(fabs(ps_sum_get(&sum) - 1) < 1e-12);
	/* the brightest pixel's share is what psens reports */
	{
		double best = 0;
		for (size_t p = 0; p < (size_t)pic.width * (size_t)pic.height; p++)
			best = fmax(best, sh.share[p]);
		assert_true(fabs(best - r.brightest_share) < 1e-12);
	}
	/* regions from the geometry, and sectors: each set sums to 1 */
	ps_radgeom_init(&g);
	snprintf(path, sizeof path, "%s/config/example/ofb/radiance/room.rad", top ? top : ".");
	assert_int_equal(ps_radgeom_read(&g, path, &e), 0);
	for (int kind = 0; kind < 2; kind++) {
		double tot = 0, tsa = 0;
		if (kind == 0)
			assert_int_equal(ps_regions_geometry(&reg, &g, PS_GROUP_AUTO, &v, pic.width,
			                                     pic.height, 2, &e), 0);
		else
			assert_int_equal(ps_regions_sectors(&reg, &v, pic.width, pic.height, 2, &e), 0);
		assert_int_equal(ps_share_regions(&sh, &reg, &sa, &pic, &rs, &e), 0);
		for (int i = 0; i < reg.nlabels; i++) {
			tot += rs[i].share;
			tsa += rs[i].solid_angle;
			if (i)
				assert_true(rs[i].share <= rs[i - 1].share);
		}
		assert_true(fabs(tot - 1) < 1e-12);
		assert_true(fabs(tsa - sa.solid_angle) < 1e-9 * sa.solid_angle);
		if (kind == 0) {
			/* the glazing sees the bright sky: it leads */
			assert_string_equal(reg.label[rs[0].label], "window");
			assert_true(rs[0].share > 0.4);
		}
		free(rs);
		ps_regions_free(&reg);
	}
	ps_radgeom_free(&g);
	ps_share_free(&sh);
	ps_weights_free(&w);
	ps_weights_free(&sa);
	ps_sensor_free(&s);
	ps_sensor_free(&uni);
	ps_picture_free(&pic);
}

/* Lambert: configuration factor from a differential area at the origin with
 * unit normal n to the polygon q (in front of it). */
static double lambert(const double q[][3], int nv, const double n[3])
{
	double f = 0;
	for (int i = 0; i < nv; i++) {
		const double *a = q[i], *b = q[(i + 1) % nv];
		double c[3] = { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0] };
		double lc = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
		double gamma = atan2(lc, a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
		if (lc > 0)
			f += gamma * (n[0] * c[0] + n[1] * c[1] + n[2] * c[2]) / lc;
	}
	return fabs(f) / (2 * M_PI);
}

static void cosine_shares_are_configuration_factors(void **state)
{
	/* a 3.7 x 4.57 x 2.68 room, the sensor at (1.85, 2.285, 2.2) looking
	 * down; uniform radiance everywhere */
	const double A = 3.7, B = 4.57, C = 2.68, P[3] = { 1.85, 2.285, 2.2 }, n[3] = { 0, 0, -1 };
	const int N = 256;
	char text[2048];
	const char *head = "#?RADIANCE\nVIEW= -vta -vp 1.85 2.285 2.2 -vd 0 0 -1 -vu 0 1 0 -vh 180 -vv 180\n"
	                   "FORMAT=32-bit_rle_rgbe\n\n-Y 256 +X 256\n";
	size_t hl = strlen(head);
	uint8_t *buf = malloc(hl + (size_t)N * N * 4);
	struct ps_picture pic;
	struct ps_view v;
	struct ps_sensor cosine, uni;
	struct ps_weights w, sa;
	struct ps_share sh;
	struct ps_regions reg;
	struct ps_radgeom g;
	struct ps_region_share *rs;
	struct ps_err e;
	double worst = 0, sum = 0;
	(void)state;
	assert_non_null(buf);
	memcpy(buf, head, hl);
	for (size_t i = 0; i < (size_t)N * N; i++) {
		uint8_t px[4] = { 128, 128, 128, 129 };
		memcpy(buf + hl + 4 * i, px, 4);
	}
	assert_int_equal(ps_picture_read_mem(&pic, buf, hl + (size_t)N * N * 4, "uniform", &e), 0);
	free(buf);
	load_view(&pic, &v);
	{
		/* the six walls: corners as 0/1 of each size */
		static const char *const name[6] = { "floor", "ceiling", "wall_x0", "wall_x1",
		                                     "wall_y0", "wall_y1" };
		static const int idx[6][4][3] = {
			{ { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 } },
			{ { 0, 0, 1 }, { 0, 1, 1 }, { 1, 1, 1 }, { 1, 0, 1 } },
			{ { 0, 0, 0 }, { 0, 1, 0 }, { 0, 1, 1 }, { 0, 0, 1 } },
			{ { 1, 0, 0 }, { 1, 0, 1 }, { 1, 1, 1 }, { 1, 1, 0 } },
			{ { 0, 0, 0 }, { 0, 0, 1 }, { 1, 0, 1 }, { 1, 0, 0 } },
			{ { 0, 1, 0 }, { 1, 1, 0 }, { 1, 1, 1 }, { 0, 1, 1 } },
		};
		const double size[3] = { A, B, C };
		size_t at = 0;
		for (int f = 0; f < 6; f++) {
			at += (size_t)snprintf(text + at, sizeof text - at, "m polygon %s 0 0 12", name[f]);
			for (int k = 0; k < 4; k++)
				for (int j = 0; j < 3; j++)
					at += (size_t)snprintf(text + at, sizeof text - at, " %g",
					                       idx[f][k][j] * size[j]);
			at += (size_t)snprintf(text + at, sizeof text - at, "\n");
		}
	}
	ps_radgeom_init(&g);
	assert_int_equal(ps_radgeom_parse(&g, text, strlen(text), "box", &e), 0);
	assert_int_equal(g.npoly, 6);
	assert_int_equal(ps_sensor_builtin(&cosine, PS_SENS_COSINE, &e), 0);
	assert_int_equal(ps_sensor_builtin(&uni, PS_SENS_UNIFORM, &e), 0);
	assert_int_equal(ps_weights_build(&w, &cosine, 0, &v, N, N, PS_W_EXACT, &e), 0);
	assert_int_equal(ps_weights_build(&sa, &uni, 0, &v, N, N, PS_W_EXACT, &e), 0);
	assert_int_equal(ps_share_compute(&sh, &w, &pic, coef, &e), 0);
	assert_int_equal(ps_regions_geometry(&reg, &g, PS_GROUP_NAME, &v, N, N, 4, &e), 0);
	assert_int_equal(ps_share_regions(&sh, &reg, &sa, &pic, &rs, &e), 0);
	for (int i = 0; i < reg.nlabels; i++) {
		const char *name = reg.label[rs[i].label];
		double q[4][3], exact;
		/* each surface's part below the sensor's plane, relative to P */
		if (strcmp(name, "ceiling") == 0) {
			assert_true(rs[i].share == 0);
			continue;
		} else if (strcmp(name, "floor") == 0) {
			double f[4][3] = { { 0, 0, 0 }, { A, 0, 0 }, { A, B, 0 }, { 0, B, 0 } };
			memcpy(q, f, sizeof q);
		} else {
			int x = name[5] == 'x', hi = name[6] == '1';
			double c = hi ? (x ? A : B) : 0, len = x ? B : A;
			for (int k = 0; k < 4; k++) {
				double along = k == 1 || k == 2 ? len : 0, z = k >= 2 ? P[2] : 0;
				q[k][0] = x ? c : along;
				q[k][1] = x ? along : c;
				q[k][2] = z;
			}
		}
		for (int k = 0; k < 4; k++)
			for (int j = 0; j < 3; j++)
				q[k][j] -= P[j];
		exact = lambert((const double (*)[3])q, 4, n);
		sum += exact;
		worst = fmax(worst, fabs(rs[i].share - exact));
	}
	print_message("cosine shares against configuration factors, 256 x 256, 4 x 4 rays: "
	              "worst %.2e (absolute)\n", worst);
	assert_true(fabs(sum - 1) < 1e-12);   /* the analytic factors close the hemisphere */
	assert_true(worst < 5e-5);   /* measured 9.4e-6 */
	free(rs);
	ps_regions_free(&reg);
	ps_radgeom_free(&g);
	ps_share_free(&sh);
	ps_weights_free(&w);
	ps_weights_free(&sa);
	ps_sensor_free(&cosine);
	ps_sensor_free(&uni);
	ps_picture_free(&pic);
}

static void zero_response_refused(void **state)
{
	const char *head = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 2\n";
	uint8_t buf[64] = { 0 };
	struct ps_picture pic;
	struct ps_view v;
	struct ps_sensor cosine;
	struct ps_weights w;
	struct ps_share sh;
	struct ps_err e;
	(void)state;
	memcpy(buf, head, strlen(head));
	assert_int_equal(ps_picture_read_mem(&pic, buf, strlen(head) + 16, "black", &e), 0);
	ps_view_default_fisheye(&v);
	assert_int_equal(ps_sensor_builtin(&cosine, PS_SENS_COSINE, &e), 0);
	assert_int_equal(ps_weights_build(&w, &cosine, 0, &v, 2, 2, PS_W_EXACT, &e), 0);
	assert_int_equal(ps_share_compute(&sh, &w, &pic, coef, &e), -1);
	assert_non_null(strstr(e.msg, "response is 0"));
	ps_weights_free(&w);
	ps_sensor_free(&cosine);
	ps_picture_free(&pic);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(shares_of_the_example_render),
		cmocka_unit_test(cosine_shares_are_configuration_factors),
		cmocka_unit_test(zero_response_refused),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
