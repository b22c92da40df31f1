/* SPDX-License-Identifier: ISC */
/* The cell reading's route from the solid-angle map (sim/weights/cellmap.c)
 * against the exact edge route (ps_weights_build) pixel by pixel: a sensor
 * that changes with azimuth, both fisheye projections, even sizes (the
 * zenith on a pixel corner) and odd ones (the zenith inside a pixel),
 * rotations that put a ray along a pixel edge, a view shifted off the
 * centre (the solid-angle map then full, not mirrored), and a table whose
 * cells are smaller than a pixel.  Every weight within 1e-12 of the largest
 * (two routes each exact to the cancellation of a pixel's four edge
 * integrals; 3e-12 on the hemispherical projection, see tolerance), the totals within 1e-12 of each other and of the table's
 * integral over the sphere where the picture sees all of it.  Then the
 * route through the weight cache (the solid-angle map stored once, found
 * again; the result the same) and which sensors the route takes.
 * The linear reading the same way (from the solid angles and the pixels'
 * moments), on the angular projection where the moments' route runs and
 * on the hemispherical where every pixel takes the edge route; through the
 * cache cold, warm and without one. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <unistd.h>
#include <cmocka.h>

#include "cellmap.h"
#include "sensor.h"
#include "view.h"
#include "wcache.h"
#include "weights.h"

static const char table_text[] = "Elevation field 90\n"
                                 "degrees 0 45 90 135 180 225 270 315\n"
                                 "0 1 1 1 1 1 1 1 1\n"
                                 "20 0.95 0.9 0.7 0.6 0.8 0.9 0.85 0.9\n"
                                 "40 0.8 0.6 0.4 0.3 0.5 0.7 0.7 0.75\n"
                                 "60 0.5 0.3 0.2 0.1 0.2 0.4 0.45 0.5\n"
                                 "80 0.1 0.05 0.02 0.01 0.03 0.08 0.1 0.1\n"
                                 "90 0 0 0 0 0 0 0 0\n";

static void load_text(struct ps_sensor *s, const char *text, size_t len, int reading)
{
	struct ps_err e;
	if (ps_sensor_parse(s, text, len, "table", &e) != 0 || ps_sensor_set_reading(s, reading, &e) != 0)
		fail_msg("%s", e.msg);
}

static void load(struct ps_sensor *s, int reading)
{
	load_text(s, table_text, sizeof table_text - 1, reading);
}

/* A table of 1 degree by 0.5 degree cells to 12 degrees (smaller than a
 * pixel of a 64 x 64 picture, 2.8 degrees), values changing in both. */
static char *fine_table(size_t *len)
{
	size_t cap = 1 << 20, n = 0;
	char *t = malloc(cap);
	assert_non_null(t);
	n += (size_t)snprintf(t + n, cap - n, "Elevation field 12\ndegrees");
	for (int j = 0; j < 720; j++)
		n += (size_t)snprintf(t + n, cap - n, " %g", 0.5 * j);
	for (int i = 0; i <= 12; i++) {
		n += (size_t)snprintf(t + n, cap - n, "\n%d", i);
		for (int j = 0; j < 720; j++)
			n += (size_t)snprintf(t + n, cap - n, " %.6f",
			                      i == 12 ? 0.0 : 1.0 + 0.5 * sin(3 * j * M_PI / 360) * cos(0.1 * i) + 0.01 * i);
	}
	n += (size_t)snprintf(t + n, cap - n, "\n");
	*len = n;
	return t;
}

/* The uniform sensor's exact map: the solid angles. */
static void omega_map_wh(struct ps_weights *om, const struct ps_view *v, int nw, int nh, int compact)
{
	struct ps_sensor u;
	struct ps_err e;
	if (ps_sensor_builtin(&u, PS_SENS_UNIFORM, &e) != 0 ||
	    ps_weights_build_ex(om, &u, 0.0, v, nw, nh, PS_W_EXACT, compact ? PS_WB_COMPACT : 0, &e) != 0)
		fail_msg("%s", e.msg);
	ps_sensor_free(&u);
}

static void omega_map(struct ps_weights *om, const struct ps_view *v, int n, int compact)
{
	omega_map_wh(om, v, n, n, compact);
}

/* fast against exact: the same layout, every weight, the totals */
static void same_as_exact_tol(const struct ps_weights *fast, const struct ps_weights *ex,
                              const char *what, double tol)
{
	double wmax = 0, dmax = 0;
	assert_int_equal(fast->nruns, ex->nruns);
	assert_int_equal(fast->nw, ex->nw);
	assert_int_equal(fast->npix, ex->npix);
	assert_int_equal(fast->mirror, 0);
	for (size_t k = 0; k < ex->nruns; k++) {
		assert_int_equal(fast->runs[k].row, ex->runs[k].row);
		assert_int_equal(fast->runs[k].x0, ex->runs[k].x0);
		assert_int_equal(fast->runs[k].n, ex->runs[k].n);
		assert_int_equal(fast->runs[k].off, ex->runs[k].off);
	}
	for (size_t i = 0; i < ex->nw; i++)
		wmax = fmax(wmax, fabs(ex->w[i]));
	assert_true(wmax > 0);
	for (size_t i = 0; i < ex->nw; i++)
		dmax = fmax(dmax, fabs(fast->w[i] - ex->w[i]));
	if (dmax > tol * wmax)
		fail_msg("%s: a weight differs by %.3g of the largest", what, dmax / wmax);
	if (fabs(fast->sens_sum / ex->sens_sum - 1) > 1e-12)
		fail_msg("%s: total %.17g, exact route's %.17g", what, fast->sens_sum, ex->sens_sum);
	assert_true(fabs(fast->sens_full - ex->sens_full) <= 1e-15 * ex->sens_full);
	assert_true(fabs(fast->solid_angle - ex->solid_angle) <= 1e-15 * ex->solid_angle);
	assert_true(fabs(fast->coverage - ex->coverage) <= 1e-12);
}

static void same_as_exact(const struct ps_weights *fast, const struct ps_weights *ex, const char *what)
{
	same_as_exact_tol(fast, ex, what, 1e-12);
}

/* The hemispherical projection: the exact route itself errs by up to 2e-12
 * of the largest weight on the pixels along azimuth 180 degrees (edges
 * across atan2's cut: the general route, its pieces' cancellation), where
 * the fast route gives the cell's value times the solid angle to the last
 * digit (ratio 0.2 or 0.4 exactly); 3e-12 there. */
static double tolerance(const struct ps_view *v)
{
	return v->type == PS_VT_HEMI ? 3e-12 : 1e-12;
}

static void compare_wh(const struct ps_sensor *s, double rot, const struct ps_view *v, int nw,
                       int nh, int compact, const char *what)
{
	struct ps_weights om, fast, ex;
	struct ps_err e;
	char name[160];
	omega_map_wh(&om, v, nw, nh, compact);
	if (ps_cellmap_build(&fast, s, rot, v, nw, nh, &om, &e) != 0)
		fail_msg("%s", e.msg);
	if (ps_weights_build(&ex, s, rot, v, nw, nh, PS_W_EXACT, &e) != 0)
		fail_msg("%s", e.msg);
	snprintf(name, sizeof name, "%s, %d x %d, rotation %g, type %c, vs %g", what, nw, nh, rot,
	         v->type, v->vs);
	same_as_exact_tol(&fast, &ex, name, tolerance(v));
	ps_weights_free(&fast);
	ps_weights_free(&ex);
	ps_weights_free(&om);
}

static void compare(const struct ps_sensor *s, double rot, const struct ps_view *v, int n,
                    int compact, const char *what)
{
	compare_wh(s, rot, v, n, n, compact, what);
}

static void equals_exact_route(void **state)
{
	static const int sizes[] = { 64, 101, 256 };
	static const double rots[] = { 10.0, 0.0, 22.5 };   /* 0 and 22.5: rays on pixel edges and diagonals */
	struct ps_sensor s;
	(void)state;
	load(&s, PS_READ_CELL);
	for (int t = 0; t < 2; t++)
		for (int k = 0; k < 3; k++) {
			struct ps_view v;
			ps_view_default_fisheye(&v);
			v.type = t ? PS_VT_HEMI : PS_VT_ANGULAR;
			compare(&s, rots[k], &v, sizes[k], 1, "8 x 6 cell table");
		}
	ps_sensor_free(&s);
}

static void totals_are_the_integral(void **state)
{
	struct ps_sensor s;
	struct ps_view v;
	struct ps_weights om, w;
	struct ps_err e;
	(void)state;
	load(&s, PS_READ_CELL);   /* ends at 95 degrees: the 180-degree picture's corners see it all */
	ps_view_default_fisheye(&v);
	omega_map(&om, &v, 300, 1);
	if (ps_cellmap_build(&w, &s, 10.0, &v, 300, 300, &om, &e) != 0)
		fail_msg("%s", e.msg);
	if (fabs(w.sens_sum / ps_sensor_integral(&s) - 1) > 1e-12)
		fail_msg("total %.17g, integral %.17g", w.sens_sum, ps_sensor_integral(&s));
	ps_weights_free(&w);
	ps_weights_free(&om);
	ps_sensor_free(&s);
}

static void shifted_view_full_omega(void **state)
{
	struct ps_sensor s;
	struct ps_view v;
	(void)state;
	load(&s, PS_READ_CELL);
	ps_view_default_fisheye(&v);
	v.vs = 0.1;
	v.vl = -0.05;
	compare(&s, 30.0, &v, 90, 1, "shifted view");
	ps_sensor_free(&s);
}

static void cells_smaller_than_pixels(void **state)
{
	struct ps_sensor s;
	size_t len;
	char *t = fine_table(&len);
	(void)state;
	load_text(&s, t, len, PS_READ_CELL);
	free(t);
	for (int n = 63; n <= 64; n++) {
		struct ps_view v;
		ps_view_default_fisheye(&v);
		compare(&s, 5.0, &v, n, 1, "0.5 x 1 degree cells");
	}
	ps_sensor_free(&s);
}

/* The linear reading: the moments' route against the exact edge route. */
static void linear_equals_exact_route(void **state)
{
	static const int sizes[] = { 64, 101, 256, 512, 401 };
	static const double rots[] = { 10.0, 0.0, 22.5, 7.0, 45.0 };
	struct ps_sensor s;
	(void)state;
	load(&s, PS_READ_LINEAR);
	for (int k = 0; k < 5; k++) {
		struct ps_view v;
		ps_view_default_fisheye(&v);
		compare(&s, rots[k], &v, sizes[k], 1, "8 x 6 linear table");
	}
	{
		struct ps_view v;   /* not square: mirrored in x and y, not in the diagonal */
		ps_view_default_fisheye(&v);
		compare_wh(&s, 15.0, &v, 320, 257, 1, "8 x 6 linear table");
		v.vv = 120.0;   /* square, a narrower field up: no diagonal either */
		compare_wh(&s, 15.0, &v, 300, 300, 1, "8 x 6 linear table, -vv 120");
	}
	{
		struct ps_view v;   /* the hemispherical projection: every pixel by its edges */
		ps_view_default_fisheye(&v);
		v.type = PS_VT_HEMI;
		compare(&s, 10.0, &v, 101, 1, "8 x 6 linear table");
	}
	ps_sensor_free(&s);
}

static void linear_shifted_and_small_cells(void **state)
{
	struct ps_sensor s;
	struct ps_view v;
	size_t len;
	char *t;
	(void)state;
	load(&s, PS_READ_LINEAR);
	ps_view_default_fisheye(&v);
	v.vs = 0.1;
	v.vl = -0.05;
	compare(&s, 30.0, &v, 300, 1, "linear, shifted view");
	compare(&s, 30.0, &v, 301, 0, "linear, shifted view");
	ps_sensor_free(&s);
	t = fine_table(&len);
	load_text(&s, t, len, PS_READ_LINEAR);
	free(t);
	ps_view_default_fisheye(&v);
	for (int n = 63; n <= 64; n++)
		compare(&s, 5.0, &v, n, 1, "linear 0.5 x 1 degree cells");
	compare(&s, 5.0, &v, 400, 1, "linear 0.5 x 1 degree cells");
	ps_sensor_free(&s);
}

/* The linear table's total is its integral over the sphere (the table ends
 * at 90 degrees, inside the 180-degree picture). */
static void linear_total_is_the_integral(void **state)
{
	struct ps_sensor s;
	struct ps_view v;
	struct ps_weights om, w;
	struct ps_err e;
	(void)state;
	load(&s, PS_READ_LINEAR);
	ps_view_default_fisheye(&v);
	omega_map(&om, &v, 600, 1);
	if (ps_cellmap_build(&w, &s, 33.0, &v, 600, 600, &om, &e) != 0)
		fail_msg("%s", e.msg);
	if (fabs(w.sens_sum / ps_sensor_integral(&s) - 1) > 1e-12)
		fail_msg("total %.17g, integral %.17g", w.sens_sum, ps_sensor_integral(&s));
	ps_weights_free(&w);
	ps_weights_free(&om);
	ps_sensor_free(&s);
}

static void which_sensors(void **state)
{
	struct ps_sensor s, c;
	struct ps_err e;
	static const char sym[] = "Elevation field 90\ndegrees 0 90 180 270\n0 1 1 1 1\n45 0.5 0.5 0.5 0.5\n90 0 0 0 0\n";
	(void)state;
	load(&s, PS_READ_LINEAR);
	assert_int_equal(ps_cellmap_fits(&s, PS_W_EXACT), PS_CELLMAP_LINEAR);
	assert_int_equal(ps_sensor_set_reading(&s, PS_READ_CELL, &e), 0);
	assert_int_equal(ps_cellmap_fits(&s, PS_W_EXACT), PS_CELLMAP_CELL);
	assert_int_equal(ps_cellmap_fits(&s, PS_W_CENTRE), 0);
	ps_sensor_free(&s);
	load_text(&s, sym, sizeof sym - 1, PS_READ_CELL);   /* the same at every azimuth: mirrored instead */
	assert_int_equal(ps_cellmap_fits(&s, PS_W_EXACT), 0);
	assert_int_equal(ps_sensor_set_reading(&s, PS_READ_LINEAR, &e), 0);
	assert_int_equal(ps_cellmap_fits(&s, PS_W_EXACT), 0);
	ps_sensor_free(&s);
	assert_int_equal(ps_sensor_builtin(&c, PS_SENS_COSINE, &e), 0);
	assert_int_equal(ps_cellmap_fits(&c, PS_W_EXACT), 0);
	ps_sensor_free(&c);
}

static void wrong_omega_refused(void **state)
{
	struct ps_sensor s;
	struct ps_view v;
	struct ps_weights om, w;
	struct ps_err e;
	(void)state;
	load(&s, PS_READ_CELL);
	ps_view_default_fisheye(&v);
	omega_map(&om, &v, 32, 1);
	assert_int_equal(ps_cellmap_build(&w, &s, 0.0, &v, 33, 33, &om, &e), -1);
	assert_non_null(strstr(e.msg, "32 x 32"));
	ps_weights_free(&om);
	ps_sensor_free(&s);
}

static void through_the_cache(void **state)
{
	struct ps_sensor s;
	struct ps_view v;
	struct ps_weights ex, w;
	struct ps_err e, warn;
	char dir[] = "/tmp/test_cellmapXXXXXX", cmd[128];
	int how;
	(void)state;
	assert_non_null(mkdtemp(dir));
	load(&s, PS_READ_CELL);
	ps_view_default_fisheye(&v);
	if (ps_weights_build(&ex, &s, 10.0, &v, 120, 120, PS_W_EXACT, &e) != 0)
		fail_msg("%s", e.msg);
	{
		struct ps_wcache_key k = { &s, 10.0, &v, 120, 120, PS_W_EXACT };
		struct ps_wcache_dir c = { dir, 0 };
		/* first: the solid angles built and stored */
		if (ps_wcache_get(&w, &k, &c, &how, &warn, &e) != 0)
			fail_msg("%s", e.msg);
		assert_int_equal(how, PS_WC_STORED);
		same_as_exact(&w, &ex, "cold cache");
		ps_weights_free(&w);
		/* then found again */
		if (ps_wcache_get(&w, &k, &c, &how, &warn, &e) != 0)
			fail_msg("%s", e.msg);
		assert_int_equal(how, PS_WC_HIT);
		same_as_exact(&w, &ex, "warm cache");
		ps_weights_free(&w);
		/* another rotation of the same sensor: the same solid angles */
		k.rotation_deg = 50.0;
		if (ps_wcache_get(&w, &k, &c, &how, &warn, &e) != 0)
			fail_msg("%s", e.msg);
		assert_int_equal(how, PS_WC_HIT);
		ps_weights_free(&w);
		/* no cache: built */
		if (ps_wcache_get(&w, &k, NULL, &how, &warn, &e) != 0)
			fail_msg("%s", e.msg);
		assert_int_equal(how, PS_WC_BUILT);
		ps_weights_free(&w);
	}
	ps_weights_free(&ex);
	ps_sensor_free(&s);
	snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
	assert_int_equal(system(cmd), 0);
}

/* The linear reading through the cache: its map stored, found again, and
 * built without a cache, each the exact route's to 1e-12. */
static void linear_through_the_cache(void **state)
{
	struct ps_sensor s;
	struct ps_view v;
	struct ps_weights ex, w;
	struct ps_err e, warn;
	char dir[] = "/tmp/test_cellmapXXXXXX", cmd[128];
	static const int want[3] = { PS_WC_STORED, PS_WC_HIT, PS_WC_BUILT };
	static const char *what[3] = { "linear, cold cache", "linear, warm cache", "linear, no cache" };
	(void)state;
	assert_non_null(mkdtemp(dir));
	load(&s, PS_READ_LINEAR);
	ps_view_default_fisheye(&v);
	if (ps_weights_build(&ex, &s, 12.0, &v, 301, 301, PS_W_EXACT, &e) != 0)
		fail_msg("%s", e.msg);
	for (int k = 0; k < 3; k++) {
		struct ps_wcache_key key = { &s, 12.0, &v, 301, 301, PS_W_EXACT };
		struct ps_wcache_dir c = { dir, 0 };
		int how;
		if (ps_wcache_get(&w, &key, k < 2 ? &c : NULL, &how, &warn, &e) != 0)
			fail_msg("%s", e.msg);
		assert_int_equal(how, want[k]);
		same_as_exact(&w, &ex, what[k]);
		ps_weights_free(&w);
	}
	ps_weights_free(&ex);
	ps_sensor_free(&s);
	snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
	assert_int_equal(system(cmd), 0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(equals_exact_route),
		cmocka_unit_test(totals_are_the_integral),
		cmocka_unit_test(shifted_view_full_omega),
		cmocka_unit_test(cells_smaller_than_pixels),
		cmocka_unit_test(linear_equals_exact_route),
		cmocka_unit_test(linear_shifted_and_small_cells),
		cmocka_unit_test(linear_total_is_the_integral),
		cmocka_unit_test(which_sensors),
		cmocka_unit_test(wrong_omega_refused),
		cmocka_unit_test(through_the_cache),
		cmocka_unit_test(linear_through_the_cache),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
