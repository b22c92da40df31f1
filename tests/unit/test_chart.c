/* SPDX-License-Identifier: ISC */
/* The report's axes: round ticks for numbers (1, 2, 5 x 10^n) and times of
 * day (whole quarter hours, half hours, hours), checked against the ticks
 * a person would write by hand. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "chart.h"

static void expect_ticks(const struct psd_ticks *t, const double *want, int n)
{
	assert_int_equal(t->n, n);
	for (int i = 0; i < n; i++)
		assert_true(fabs(t->v[i] - want[i]) < 1e-9);
}

static void volts(void **state)
{
	/* the old report: 0.934, 1.87, 2.8 V */
	static const double want[] = { 0, 0.5, 1, 1.5, 2, 2.5 };
	struct psd_ticks t;
	char b[16];
	(void)state;
	assert_int_equal(psd_chart_ticks_num(0, 2.8, 8, &t), 0);
	expect_ticks(&t, want, 6);
	assert_true(fabs(t.step - 0.5) < 1e-12);
	psd_chart_tick_num_label(&t, t.v[1], b, sizeof b);
	assert_string_equal(b, "0.5");
	psd_chart_tick_num_label(&t, t.v[2], b, sizeof b);
	assert_string_equal(b, "1.0");
}

static void lux(void **state)
{
	static const double want[] = { 0, 500, 1000, 1500, 2000 };
	struct psd_ticks t;
	char b[16];
	(void)state;
	assert_int_equal(psd_chart_ticks_num(0, 2017, 6, &t), 0);
	expect_ticks(&t, want, 5);
	psd_chart_tick_num_label(&t, 1500, b, sizeof b);
	assert_string_equal(b, "1500");
	/* steps of 2 x 10^n: 0..9 with at most 6 ticks is 0, 2, 4, 6, 8 */
	assert_int_equal(psd_chart_ticks_num(0, 9, 6, &t), 0);
	assert_true(fabs(t.step - 2) < 1e-12);
	assert_int_equal(t.n, 5);
	/* a negative start and small numbers: -0.03..0.07 by 0.02 */
	assert_int_equal(psd_chart_ticks_num(-0.03, 0.07, 6, &t), 0);
	assert_true(fabs(t.step - 0.02) < 1e-12);
	assert_int_equal(t.decimals, 2);
	assert_true(fabs(t.v[0] + 0.02) < 1e-12);
}

static void round_range(void **state)
{
	double lo = 0, hi = 2.8;
	(void)state;
	psd_chart_ticks_round_range(&lo, &hi, 8);
	assert_true(fabs(lo) < 1e-12 && fabs(hi - 3) < 1e-12);
	lo = 0, hi = 2017;
	psd_chart_ticks_round_range(&lo, &hi, 6);
	assert_true(fabs(hi - 2500) < 1e-9);
}

static void times(void **state)
{
	/* the old report: 06:00, 09:29, 12:59 */
	struct psd_ticks t;
	char b[16];
	(void)state;
	assert_int_equal(psd_chart_ticks_time(6 * 3600, 13 * 3600, 8, &t), 0);
	assert_int_equal(t.n, 8);
	assert_true(fabs(t.step - 3600) < 1e-9);
	for (int i = 0; i < t.n; i++) {
		char want[8];
		snprintf(want, sizeof want, "%02d:00", 6 + i);
		psd_chart_tick_time_label(t.v[i], b, sizeof b);
		assert_string_equal(b, want);
	}
	/* 06:00..20:00 (the example day) with room for 8: every 2 hours */
	assert_int_equal(psd_chart_ticks_time(6 * 3600, 20 * 3600, 8, &t), 0);
	assert_true(fabs(t.step - 7200) < 1e-9);
	/* one hour: every 15 minutes */
	assert_int_equal(psd_chart_ticks_time(9 * 3600 + 100, 10 * 3600 + 100, 5, &t), 0);
	assert_true(fabs(t.step - 900) < 1e-9);
	psd_chart_tick_time_label(t.v[0], b, sizeof b);
	assert_string_equal(b, "09:15");
	/* two days: hh:mm of each day, whole 6 hours */
	assert_int_equal(psd_chart_ticks_time(6 * 3600, 30 * 3600 + 1000, 6, &t), 0);
	assert_true(fabs(t.step - 21600) < 1e-9);
	psd_chart_tick_time_label(t.v[3], b, sizeof b);
	assert_string_equal(b, "00:00");
	/* half hours */
	assert_int_equal(psd_chart_ticks_time(3600, 3 * 3600, 5, &t), 0);
	assert_true(fabs(t.step - 1800) < 1e-9);
}

static void bad_input(void **state)
{
	struct psd_ticks t;
	(void)state;
	assert_int_equal(psd_chart_ticks_num(NAN, 1, 5, &t), -1);
	assert_int_equal(psd_chart_ticks_num(2, 1, 5, &t), -1);
	assert_int_equal(psd_chart_ticks_time(0, INFINITY, 5, &t), -1);
	/* a flat series still gets a tick */
	assert_int_equal(psd_chart_ticks_num(3, 3, 5, &t), 0);
	assert_true(t.n >= 1);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(volts),
		cmocka_unit_test(lux),
		cmocka_unit_test(round_range),
		cmocka_unit_test(times),
		cmocka_unit_test(bad_input),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
