/* SPDX-License-Identifier: ISC */
/* Mirrored weight maps (a sensor the same at every azimuth on a view not
 * shifted: only a quarter integrated) against the same map integrated
 * everywhere: a table of constant rows, and its twin with one value moved by
 * one unit in the last place (no longer symmetric to the code, the same
 * sensitivity to 16 digits).  The totals match the table's exact integral to
 * 1e-12 at square, oblong, even and odd sizes; every weight matches its
 * unmirrored value within 1e-10 of the largest weight.  (A single weight is
 * exact only to the cancellation of its four edge integrals: moving one
 * table value by one unit in the last place moves weights by up to 2e-12
 * of the largest at 256 x 256, mirrored or not; sums telescope and stay
 * exact.) */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "sensor.h"
#include "view.h"
#include "weights.h"

static void table(struct ps_sensor *s, double tweak)
{
	char text[1024];
	struct ps_err e;
	int n = snprintf(text, sizeof text,
	                 "Elevation field 90\ndegrees 0 90 180 270\n0 1 1 1 1\n30 0.9 0.9 0.9 0.9\n"
	                 "60 0.5 0.5 %.17g 0.5\n85 0.1 0.1 0.1 0.1\n90 0 0 0 0\n",
	                 tweak ? nextafter(0.5, 1.0) : 0.5);
	if (ps_sensor_parse(s, text, (size_t)n, "table", &e) != 0 ||
	    ps_sensor_set_reading(s, PS_READ_LINEAR, &e) != 0)
		fail_msg("%s", e.msg);
}

static void mirrored_equals_direct(void **state)
{
	static const int sizes[][2] = { { 1, 1 }, { 2, 2 }, { 3, 3 }, { 8, 5 }, { 33, 33 },
	                                { 64, 64 }, { 101, 77 }, { 256, 256 }, { 511, 512 } };
	struct ps_sensor sym, asym;
	struct ps_view v;
	struct ps_err e;
	(void)state;
	table(&sym, 0);
	table(&asym, 1);
	assert_true(asym.val[2 * 4 + 2] != sym.val[2 * 4 + 2]);
	ps_view_default_fisheye(&v);
	for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
		int w = sizes[k][0], h = sizes[k][1];
		struct ps_weights a, b;
		double exact = ps_sensor_integral(&sym), maxw = 0;
		assert_int_equal(ps_weights_build(&a, &sym, 0, &v, w, h, PS_W_EXACT, &e), 0);
		assert_int_equal(ps_weights_build(&b, &asym, 0, &v, w, h, PS_W_EXACT, &e), 0);
		assert_int_equal(a.nw, b.nw);
		assert_int_equal(a.nruns, b.nruns);
		for (size_t i = 0; i < b.nw; i++)
			maxw = fmax(maxw, b.w[i]);
		for (size_t i = 0; i < a.nw; i++)
			assert_true(fabs(a.w[i] - b.w[i]) <= 1e-10 * maxw);
		/* a square picture of a 180-degree fisheye holds the whole table */
		if (w == h) {
			assert_true(fabs(a.sens_sum / exact - 1) <= 1e-12);
			assert_true(fabs(b.sens_sum / exact - 1) <= 1e-12);
		}
		ps_weights_free(&a);
		ps_weights_free(&b);
	}
	ps_sensor_free(&sym);
	ps_sensor_free(&asym);
}

/* A shifted view is not symmetric: the map must not be mirrored. */
static void shifted_view_is_not_mirrored(void **state)
{
	struct ps_sensor sym, asym;
	struct ps_view v;
	struct ps_weights a, b;
	struct ps_err e;
	(void)state;
	table(&sym, 0);
	table(&asym, 1);
	ps_view_default_fisheye(&v);
	v.vs = 0.1;
	assert_int_equal(ps_weights_build(&a, &sym, 0, &v, 64, 64, PS_W_EXACT, &e), 0);
	assert_int_equal(ps_weights_build(&b, &asym, 0, &v, 64, 64, PS_W_EXACT, &e), 0);
	assert_int_equal(a.nw, b.nw);
	/* both integrated everywhere: equal to what rounding allows (see above;
	 * a mirrored shifted map would be wrong by whole pixels' weights) */
	{
		double maxw = 0;
		for (size_t i = 0; i < b.nw; i++)
			maxw = fmax(maxw, b.w[i]);
		for (size_t i = 0; i < a.nw; i++)
			assert_true(fabs(a.w[i] - b.w[i]) <= 1e-10 * maxw);
	}
	ps_weights_free(&a);
	ps_weights_free(&b);
	ps_sensor_free(&sym);
	ps_sensor_free(&asym);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(mirrored_equals_direct),
		cmocka_unit_test(shifted_view_is_not_mirrored),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
