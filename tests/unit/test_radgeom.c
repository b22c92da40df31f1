/* SPDX-License-Identifier: ISC */
/* The Radiance geometry reader, the ray caster and the region labeller,
 * against analytic answers: the solid angle of each wall of a box room
 * (Van Oosterom and Strackee's formula for a triangle's solid angle), the
 * solid angle of polar-angle sectors, and the example office's files. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "radgeom.h"
#include "regions.h"
#include "sensor.h"
#include "view.h"
#include "weights.h"

static int parse(struct ps_radgeom *g, const char *text, struct ps_err *e)
{
	ps_radgeom_init(g);
	return ps_radgeom_parse(g, text, strlen(text), "t.rad", e);
}

static void polygons_and_skips(void **state)
{
	struct ps_radgeom g;
	struct ps_err e;
	(void)state;
	assert_int_equal(parse(&g, "# a comment\nvoid plastic white 0 0 5 .5 .5 .5 0 0\n"
	                          "white polygon floor\n0\n0\n12 0 0 0  1 0 0  1 1 0  0 1 0\n"
	                          "void alias grey white\n"
	                          "skyfunc glow sky_glow 0 0 4 1 1 1 0\n"
	                          "sky_glow source sky 0 0 4 0 0 1 180\n"
	                          "white polygon sliver 0 0 9 0 0 0 1 1 1 2 2 2\n", &e), 0);
	assert_int_equal(g.npoly, 1);
	assert_string_equal(g.poly[0].name, "floor");
	assert_string_equal(g.poly[0].material, "white");
	assert_int_equal(g.poly[0].line, 3);
	assert_int_equal(g.skipped, 4);     /* plastic, alias, glow, source */
	assert_int_equal(g.degenerate, 1);  /* the collinear sliver */
	assert_true(fabs(fabs(g.poly[0].n[2]) - 1) < 1e-15);
	ps_radgeom_free(&g);
}

static void genbox_and_xform(void **state)
{
	struct ps_radgeom g;
	struct ps_err e;
	double org[3] = { 1.5, 0.5, 10 }, down[3] = { 0, 0, -1 }, t;
	long hit;
	(void)state;
	/* a 1 x 2 x 3 box turned 90 degrees about z (x -> y, y -> -x), then
	 * moved by (2, 0, 0): it spans x 0..2, y 0..1, z 0..3; then scaled by 2
	 * about the origin in a second xform: x 0..4, y 0..2, z 0..6 */
	assert_int_equal(parse(&g, "!genbox m b 1 2 3 | xform -rz 90 -t 2 0 0 \\\n | xform -s 2\n"
	                          "!genbox m c 1 1 1 -i | xform -m other -mz\n", &e), 0);
	assert_int_equal(g.npoly, 12);
	assert_string_equal(g.poly[0].name, "b.1540");
	assert_string_equal(g.poly[5].name, "b.6457");
	assert_string_equal(g.poly[6].material, "other");
	assert_int_equal(g.poly[6].line, 3);   /* the continued line counts */
	for (int k = 0; k < 3; k++) {
		double lo = INFINITY, hi = -INFINITY;
		for (int i = 0; i < 6; i++) {
			lo = fmin(lo, g.poly[i].lo[k]);
			hi = fmax(hi, g.poly[i].hi[k]);
		}
		assert_true(fabs(lo - 0) < 1e-12);
		assert_true(fabs(hi - (k == 0 ? 4 : k == 1 ? 2 : 6)) < 1e-12);
	}
	/* mirrored in z: the second box spans z -1..0 */
	assert_true(fabs(g.poly[6].lo[2] + 1) < 1e-12 || fabs(g.poly[8].lo[2] + 1) < 1e-12);
	/* straight down from above: the top face b.6457 at z = 6, distance 4 */
	hit = ps_radgeom_trace(&g, org, down, &t);
	assert_int_equal(hit, 5);
	assert_true(fabs(t - 4) < 1e-12);
	/* from inside, upwards along a long direction vector: t scales */
	org[2] = 1;
	down[2] = 2;
	hit = ps_radgeom_trace(&g, org, down, &t);
	assert_int_equal(hit, 5);
	assert_true(fabs(t - 2.5) < 1e-12);
	/* away from everything */
	org[0] = 100;
	assert_int_equal(ps_radgeom_trace(&g, org, down, &t), -1);
	ps_radgeom_free(&g);
}

static void refusals(void **state)
{
	static const struct { const char *text, *msg; } c[] = {
		{ "\n\nm sphere ball 0 0 4 0 0 0 1\n", "t.rad:3: sphere 'ball' is not handled" },
		{ "!gensky 3 21 12\n", "t.rad:1: command 'gensky' is not handled" },
		{ "# x\n!genbox m b 1 1 1 | xform -a 3 -t 1 0 0\n", "t.rad:2: xform option '-a' is not handled" },
		{ "!genbox m b 1 1 1 | xform -n x\n", "t.rad:1: xform option '-n'" },
		{ "!genbox m b 1 1 1 | sed s/a/b/\n", "t.rad:1: genbox piped to 'sed'" },
		{ "!genbox m b 1 1 1 -r 0.1\n", "t.rad:1: genbox takes" },
		{ "!genbox m b 1 x 1\n", "t.rad:1: genbox: 'x' is not a number" },
		{ "!genbox m b 1 1 1 | xform -t 1 0\n", "t.rad:1: xform -t needs 3 numbers" },
		{ "!genbox m b 1 1 1 | xform -rz\n", "t.rad:1: xform -rz needs an angle" },
		{ "m polygon p 0 0 6 0 0 0 1 1 1\n", "t.rad:1: polygon 'p' needs" },
		{ "m polygon p 0 0 9 0 0 0 1 0 0 1 1\n", "t.rad:1: polygon 'p' ends before its 9 arguments" },
		{ "m polygon p 0 0 9 0 0 0 1 0 0 1 1 zz\n", "t.rad:1: polygon 'p': 'zz' is not a number" },
		{ "m polygon p 0 0 999999999 0 0 0\n", "is not an argument count this input can hold" },
		{ "m polygon\n", "t.rad:1: the input ends inside a primitive" },
		{ "m plastic p 0 0\n", "t.rad:1: plastic 'p' ends before its argument counts" },
		{ "void alias x\n", "t.rad:1: alias 'x' has no original" },
	};
	(void)state;
	for (size_t i = 0; i < sizeof c / sizeof c[0]; i++) {
		struct ps_radgeom g;
		struct ps_err e;
		assert_int_equal(parse(&g, c[i].text, &e), -1);
		if (!strstr(e.msg, c[i].msg))
			fail_msg("case %zu: got '%s', want '%s'", i, e.msg, c[i].msg);
		ps_radgeom_free(&g);
	}
}

static void example_office(void **state)
{
	const char *top = getenv("TOP");
	char path[600];
	struct ps_radgeom g;
	struct ps_err e;
	char **lab;
	int nlab, *of;
	(void)state;
	ps_radgeom_init(&g);
	snprintf(path, sizeof path, "%s/config/example/ofb/radiance/room.rad", top ? top : ".");
	assert_int_equal(ps_radgeom_read(&g, path, &e), 0);
	/* 7 polygons and 5 boxes of 6 faces */
	assert_int_equal(g.npoly, 37);
	snprintf(path, sizeof path, "%s/config/example/ofb/radiance/materials.rad", top ? top : ".");
	assert_int_equal(ps_radgeom_read(&g, path, &e), 0);
	assert_int_equal(g.npoly, 37);
	assert_int_equal(ps_regions_groups(&g, PS_GROUP_AUTO, &lab, &nlab, &of, &e), 0);
	{
		static const char *const want[] = { "floor", "ceiling", "back_wall", "left_wall",
		                                    "right_wall", "window", "desk", "shelf", "ground" };
		assert_int_equal(nlab, 9);
		for (int i = 0; i < 9; i++)
			assert_string_equal(lab[i], want[i]);
		for (int i = 0; i < nlab; i++)
			free(lab[i]);
		free(lab);
		free(of);
	}
	assert_int_equal(ps_regions_groups(&g, PS_GROUP_NAME, &lab, &nlab, &of, &e), 0);
	assert_int_equal(nlab, 12);   /* desk_top, desk_leg_l, ..., shelf_2: faces merged */
	assert_string_equal(lab[of[7]], "desk_top");
	for (int i = 0; i < nlab; i++)
		free(lab[i]);
	free(lab);
	free(of);
	assert_int_equal(ps_regions_groups(&g, PS_GROUP_MATERIAL, &lab, &nlab, &of, &e), 0);
	assert_int_equal(nlab, 7);    /* floor, ceiling, wall, glass, desk, shelf, ground */
	for (int i = 0; i < nlab; i++)
		free(lab[i]);
	free(lab);
	free(of);
	ps_radgeom_free(&g);
}

/* ---- solid angles ---- */

/* Van Oosterom & Strackee (1983): the solid angle of triangle (a, b, c) seen from the origin */
static double tri_solid_angle(const double a[3], const double b[3], const double c[3])
{
	double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
	double lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
	double lc = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
	double bc[3] = { b[1] * c[2] - b[2] * c[1], b[2] * c[0] - b[0] * c[2], b[0] * c[1] - b[1] * c[0] };
	double num = a[0] * bc[0] + a[1] * bc[1] + a[2] * bc[2];
	double den = la * lb * lc + (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) * lc +
	             (a[0] * c[0] + a[1] * c[1] + a[2] * c[2]) * lb +
	             (b[0] * c[0] + b[1] * c[1] + b[2] * c[2]) * la;
	return fabs(2 * atan2(num, den));
}

/* the six walls of the box [0,A] x [0,B] x [0,C], as polygons and names */
static const char *const wall_name[6] = { "floor", "ceiling", "wall_x0", "wall_x1", "wall_y0", "wall_y1" };

static void box_corners(double A, double B, double C, int w, double q[4][3])
{
	static const int idx[6][4][3] = {
		{ { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 } },
		{ { 0, 0, 1 }, { 0, 1, 1 }, { 1, 1, 1 }, { 1, 0, 1 } },
		{ { 0, 0, 0 }, { 0, 1, 0 }, { 0, 1, 1 }, { 0, 0, 1 } },
		{ { 1, 0, 0 }, { 1, 0, 1 }, { 1, 1, 1 }, { 1, 1, 0 } },
		{ { 0, 0, 0 }, { 0, 0, 1 }, { 1, 0, 1 }, { 1, 0, 0 } },
		{ { 0, 1, 0 }, { 1, 1, 0 }, { 1, 1, 1 }, { 0, 1, 1 } },
	};
	double size[3] = { A, B, C };
	for (int i = 0; i < 4; i++)
		for (int k = 0; k < 3; k++)
			q[i][k] = idx[w][i][k] * size[k];
}

static double wall_solid_angle(double A, double B, double C, int w, const double p[3])
{
	double q[4][3];
	box_corners(A, B, C, w, q);
	for (int i = 0; i < 4; i++)
		for (int k = 0; k < 3; k++)
			q[i][k] -= p[k];
	return tri_solid_angle(q[0], q[1], q[2]) + tri_solid_angle(q[0], q[2], q[3]);
}

static void box_scene(double A, double B, double C, char *buf, size_t len)
{
	size_t n = 0;
	for (int w = 0; w < 6; w++) {
		double q[4][3];
		box_corners(A, B, C, w, q);
		n += (size_t)snprintf(buf + n, len - n, "m polygon %s 0 0 12", wall_name[w]);
		for (int i = 0; i < 4; i++)
			n += (size_t)snprintf(buf + n, len - n, " %.17g %.17g %.17g", q[i][0], q[i][1], q[i][2]);
		n += (size_t)snprintf(buf + n, len - n, "\n");
	}
}

/* Sum of pixel solid angle x fraction per label. */
static void region_solid_angles(const struct ps_regions *r, const struct ps_weights *sa, double *out)
{
	double *dense = calloc((size_t)r->width * (size_t)r->height, sizeof *dense);
	assert_non_null(dense);
	for (size_t k = 0; k < sa->nruns; k++)
		for (int i = 0; i < sa->runs[k].n; i++)
			dense[(size_t)sa->runs[k].row * (size_t)r->width + (size_t)(sa->runs[k].x0 + i)] =
			        sa->w[sa->runs[k].off + (size_t)i];
	for (int l = 0; l < r->nlabels; l++)
		out[l] = 0;
	for (size_t p = 0; p < (size_t)r->width * (size_t)r->height; p++)
		for (size_t k = r->off[p]; k < r->off[p + 1]; k++)
			out[r->part[k].label] += dense[p] * r->part[k].frac;
	free(dense);
}

static double box_worst(const double p[3], int n, int sub, double *total)
{
	double A = 3.7, B = 4.57, C = 2.68, got[8], worst = 0;
	char text[4096];
	struct ps_radgeom g;
	struct ps_regions r;
	struct ps_weights sa;
	struct ps_sensor uni;
	struct ps_view v;
	struct ps_err e;
	box_scene(A, B, C, text, sizeof text);
	assert_int_equal(parse(&g, text, &e), 0);
	assert_int_equal(g.npoly, 6);
	/* the whole sphere: an angular fisheye of 360 degrees, looking down */
	ps_view_default_fisheye(&v);
	v.vh = v.vv = 360;
	memcpy(v.vp, p, sizeof v.vp);
	assert_int_equal(ps_sensor_builtin(&uni, PS_SENS_UNIFORM, &e), 0);
	assert_int_equal(ps_weights_build(&sa, &uni, 0, &v, n, n, PS_W_EXACT, &e), 0);
	assert_int_equal(ps_regions_geometry(&r, &g, PS_GROUP_NAME, &v, n, n, sub, &e), 0);
	assert_int_equal(r.nlabels, 6);     /* no ray misses inside a closed box */
	region_solid_angles(&r, &sa, got);
	*total = 0;
	for (int w = 0; w < 6; w++) {
		double exact = wall_solid_angle(A, B, C, w, p);
		assert_string_equal(r.label[w], wall_name[w]);
		worst = fmax(worst, fabs(got[w] - exact) / exact);
		*total += got[w];
	}
	ps_regions_free(&r);
	ps_weights_free(&sa);
	ps_sensor_free(&uni);
	ps_radgeom_free(&g);
	return worst;
}

static void box_room_solid_angles(void **state)
{
	double centre[3] = { 1.85, 2.285, 1.34 }, sensor[3] = { 1.85, 2.285, 2.2 }, total;
	double w1, w4, w4s;
	(void)state;
	/* the exact walls add up to 4 pi */
	{
		double s = 0;
		for (int w = 0; w < 6; w++)
			s += wall_solid_angle(3.7, 4.57, 2.68, w, sensor);
		assert_true(fabs(s - 4 * M_PI) < 1e-12);
	}
	w1 = box_worst(centre, 256, 1, &total);
	assert_true(fabs(total - 4 * M_PI) < 1e-9);
	w4 = box_worst(centre, 256, 4, &total);
	w4s = box_worst(sensor, 256, 4, &total);
	print_message("box room, 256 x 256: worst wall error %.2e (1 ray a pixel), %.2e (4 x 4), "
	              "%.2e (4 x 4, from the sensor's point)\n", w1, w4, w4s);
	/* measured: 3.7e-3, 1.2e-4, 1.3e-4 */
	assert_true(w1 < 1e-2);
	assert_true(w4 < w1 / 10);
	assert_true(w4 < 5e-4);
	assert_true(w4s < 5e-4);
}

static void sector_solid_angles(void **state)
{
	struct ps_regions r;
	struct ps_weights sa;
	struct ps_sensor uni;
	struct ps_view v;
	struct ps_err e;
	double got[16], worst = 0;
	(void)state;
	ps_view_default_fisheye(&v);
	v.vh = v.vv = 360;
	assert_int_equal(ps_sensor_builtin(&uni, PS_SENS_UNIFORM, &e), 0);
	assert_int_equal(ps_weights_build(&sa, &uni, 0, &v, 256, 256, PS_W_EXACT, &e), 0);
	assert_int_equal(ps_regions_sectors(&r, &v, 256, 256, 4, &e), 0);
	assert_int_equal(r.nlabels, 16);
	assert_string_equal(r.label[0], "0-30\xc2\xb0 up");
	assert_string_equal(r.label[13], "beyond 90\xc2\xb0 left");
	region_solid_angles(&r, &sa, got);
	for (int b = 0; b < 4; b++) {
		/* a band from t0 to t1, a quarter of it: (pi / 2)(cos t0 - cos t1) */
		double t0 = b * 30 * M_PI / 180, t1 = b < 3 ? (b + 1) * 30 * M_PI / 180 : M_PI;
		double exact = M_PI / 2 * (cos(t0) - cos(t1));
		for (int q = 0; q < 4; q++)
			worst = fmax(worst, fabs(got[4 * b + q] - exact) / exact);
	}
	print_message("sectors, 256 x 256, 4 x 4 rays: worst error %.2e\n", worst);
	assert_true(worst < 1e-3);   /* measured 3.2e-4 */
	ps_regions_free(&r);
	ps_weights_free(&sa);
	ps_sensor_free(&uni);
}

static void not_a_fisheye(void **state)
{
	struct ps_regions r;
	struct ps_radgeom g;
	struct ps_view v;
	struct ps_err e;
	(void)state;
	ps_radgeom_init(&g);
	ps_view_default(&v);
	assert_int_equal(ps_regions_geometry(&r, &g, PS_GROUP_AUTO, &v, 8, 8, 1, &e), -1);
	assert_non_null(strstr(e.msg, "not a fisheye"));
	ps_view_default_fisheye(&v);
	assert_int_equal(ps_regions_sectors(&r, &v, 8, 8, 0, &e), -1);
	ps_radgeom_free(&g);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(polygons_and_skips),
		cmocka_unit_test(genbox_and_xform),
		cmocka_unit_test(refusals),
		cmocka_unit_test(example_office),
		cmocka_unit_test(box_room_solid_angles),
		cmocka_unit_test(sector_solid_angles),
		cmocka_unit_test(not_a_fisheye),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
