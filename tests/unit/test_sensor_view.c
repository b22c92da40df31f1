/* SPDX-License-Identifier: ISC */
/* Sensitivity files and view options: what they accept, and a located error
 * for everything else. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "sensor.h"
#include "view.h"

#define DEG (M_PI / 180.0)

static void good_tables(void **state)
{
	struct ps_sensor s;
	struct ps_err e;
	const char *t = "Elevation angles of the photometer\n"
	                "degrees\t0\t90\t180\t270\r\n"
	                "0\t1\t1\t1\t1\n"
	                "\n"
	                "45 0.5 0.25  0.5 1\n"
	                "90\t0 0 0 0\n";
	(void)state;
	assert_int_equal(ps_sensor_parse(&s, t, strlen(t), "a.sen", &e), 0);
	assert_int_equal(s.ntheta, 3);
	assert_int_equal(s.nphi, 4);
	assert_true(s.total == 4 + 2.25);
	/* linear reading: exact table values at the table's points ... */
	assert_true(fabs(ps_sensor_value(&s, 45 * DEG, 90 * DEG) - 0.25) < 1e-15);
	/* ... and bilinear between them, wrapping from 270 to 360 */
	assert_true(fabs(ps_sensor_value(&s, 45 * DEG, 315 * DEG) - 0.75) < 1e-14);
	assert_true(fabs(ps_sensor_value(&s, 22.5 * DEG, 90 * DEG) - 0.625) < 1e-14);
	assert_true(ps_sensor_value(&s, 91 * DEG, 0) == 0.0);
	/* cell reading: each value holds to the midpoints; phi cells wrap */
	assert_int_equal(ps_sensor_set_reading(&s, PS_READ_CELL, &e), 0);
	assert_true(ps_sensor_value(&s, 40 * DEG, 100 * DEG) == 0.25);
	assert_true(ps_sensor_value(&s, 40 * DEG, 350 * DEG) == 0.5);
	assert_true(ps_sensor_value(&s, 40 * DEG, 314 * DEG) == 1.0 && ps_sensor_value(&s, 40 * DEG, 316 * DEG) == 0.5);
	assert_true(ps_sensor_value(&s, 22.4 * DEG, 100 * DEG) == 1.0);
	/* the last cell ends at 1.5 * 90 - 0.5 * 45 = 112.5 */
	assert_true(fabs(s.theta_end - 112.5 * DEG) < 1e-15);
	ps_sensor_free(&s);
}

static void located_errors(void **state)
{
	static const struct {
		const char *text, *want;
	} cases[] = {
		{ "", "a.sen:0: empty sensitivity table" },
		{ "azimuths 0 90 180 270\n", "a.sen:1: first line must be 'degrees'" },
		{ "degrees 10 90 180 270\n0 1 1 1 1\n", "a.sen:1: azimuths must start at 0" },
		{ "degrees 0 90 90 270\n", "a.sen:1: azimuth 90 does not increase" },
		{ "degrees 0 90 180\n", "a.sen:1: azimuths must reach at least 270" },
		{ "degrees 0 90 180 360\n", "a.sen:1: azimuths must reach at least 270 and stay below 360" },
		{ "degrees 0 90 180 270\n0 1 1 1 1\n10 1 x 1 1\n", "a.sen:3: 'x' is not a number" },
		{ "degrees 0 90 180 270\n0 1 1 1 1\n10 1 nan 1 1\n", "a.sen:3: 'nan' is not a finite number" },
		{ "degrees 0 90 180 270\n0 1 1 1 1\n10 1 -1 1 1\n", "a.sen:3: negative sensitivity -1" },
		{ "degrees 0 90 180 270\n0 1 1 1 1\n10 1 1 1\n", "a.sen:3: row has 4 values" },
		{ "degrees 0 90 180 270\n5 1 1 1 1\n", "a.sen:2: polar angle 5 must be 0" },
		{ "degrees 0 90 180 270\n0 1 1 1 1\n20 1 1 1 1\n10 1 1 1 1\n", "a.sen:4: polar angle 10 does not increase" },
		{ "degrees 0 90 180 270\n0 1 1 1 1\n190 1 1 1 1\n", "a.sen:3: polar angle 190 is beyond 180" },
		{ "degrees 0 90 180 270\n0 1 1 1 1\n", "needs at least two polar angle rows" },
		{ "degrees 0 90 180 270\n0 0 0 0 0\n9 0 0 0 0\n", "every sensitivity is zero" },
	};
	(void)state;
	for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
		struct ps_sensor s;
		struct ps_err e;
		assert_int_equal(ps_sensor_parse(&s, cases[k].text, strlen(cases[k].text), "a.sen", &e), -1);
		if (!strstr(e.msg, cases[k].want))
			fail_msg("case %zu: '%s' lacks '%s'", k, e.msg, cases[k].want);
	}
	{
		struct ps_sensor s;
		struct ps_err e;
		assert_int_equal(ps_sensor_read(&s, "/nonexistent.sen", &e), -1);
		assert_non_null(strstr(e.msg, "/nonexistent.sen: No such file"));
	}
}

/* A table must cover the field it states; one that states none is taken
 * only when it cannot be a cut copy: it reaches the hemisphere or ends with
 * a zero response. */
static void field_coverage(void **state)
{
	static const struct {
		const char *text, *want;
	} refused[] = {
		/* states 90 but stops at 60: the step is 30, so 90 alone is missing */
		{ "Elevation field 90\ndegrees 0 90 180 270\n0 1 1 1 1\n30 0.9 0.9 0.9 0.9\n"
		  "60 0.5 0.5 0.5 0.5\n",
		  "a.sen:5: the table ends at polar angle 60 but line 1 states a field of 90: "
		  "the row for 90 degrees is missing" },
		/* stops at 4 of a 2-degree table stating 10: 6, 8 and 10 are missing */
		{ "Elevation field 10\ndegrees 0 90 180 270\n0 1 1 1 1\n2 1 1 1 1\n4 1 1 1 1\n",
		  "a.sen:5: the table ends at polar angle 4 but line 1 states a field of 10: "
		  "the rows for 6 to 10 degrees are missing (3 rows at the table's 2-degree step)" },
		{ "Elevation field 30\ndegrees 0 90 180 270\n0 1 1 1 1\n30 1 1 1 1\n40 0 0 0 0\n",
		  "a.sen:5: polar angle 40 is beyond the field of 30 stated on line 1" },
		{ "Elevation field 0\ndegrees 0 90 180 270\n0 1 1 1 1\n30 1 1 1 1\n",
		  "a.sen:1: the field 0 is not a polar angle above 0 and at most 180" },
		{ "Elevation field 200\ndegrees 0 90 180 270\n0 1 1 1 1\n30 1 1 1 1\n",
		  "a.sen:1: the field 200 is not a polar angle above 0 and at most 180" },
		{ "Elevation field 1e999\ndegrees 0 90 180 270\n0 1 1 1 1\n30 1 1 1 1\n",
		  "a.sen:1: the field 1e999 is not a polar angle above 0 and at most 180" },
		/* no statement, a non-zero end short of 90: a cut copy or a cone? */
		{ "degrees 0 90 180 270\n0 1 1 1 1\n2 1 1 1 1\n4 1 0.5 1 1\n",
		  "a.sen:4: the table ends at polar angle 4 with a non-zero response (1 at azimuth 0) "
		  "and states no field" },
	};
	static const struct {
		const char *text;
		double end_deg;
	} taken[] = {
		/* ends with response 0 at 60, no statement */
		{ "degrees 0 90 180 270\n0 1 1 1 1\n30 0.8 0.8 0.8 0.8\n60 0 0 0 0\n", 60 },
		/* a flat response to 90, no statement */
		{ "degrees 0 90 180 270\n0 1 1 1 1\n90 1 1 1 1\n", 90 },
		/* a wide sensor to 135 */
		{ "degrees 0 90 180 270\n0 1 1 1 1\n135 0.2 0.2 0.2 0.2\n", 135 },
		/* a cone whose response is still 0.1 at its stated edge */
		{ "Elevation field 30 (degrees)\ndegrees 0 90 180 270\n0 1 1 1 1\n30 0.1 0.1 0.1 0.1\n", 30 },
		{ "Elevation field: 60\ndegrees 0 90 180 270\n0 1 1 1 1\n60 0 0 0 0\n", 60 },
		/* a title without a statement, a complete table */
		{ "Elevation angles of the photometer\ndegrees 0 90 180 270\n0 1 1 1 1\n90 0 0 0 0\n", 90 },
	};
	(void)state;
	for (size_t k = 0; k < sizeof refused / sizeof *refused; k++) {
		struct ps_sensor s;
		struct ps_err e;
		assert_int_equal(ps_sensor_parse(&s, refused[k].text, strlen(refused[k].text), "a.sen", &e), -1);
		if (!strstr(e.msg, refused[k].want))
			fail_msg("refused %zu: '%s' lacks '%s'", k, e.msg, refused[k].want);
	}
	for (size_t k = 0; k < sizeof taken / sizeof *taken; k++) {
		struct ps_sensor s;
		struct ps_err e;
		if (ps_sensor_parse(&s, taken[k].text, strlen(taken[k].text), "a.sen", &e) != 0)
			fail_msg("taken %zu refused: %s", k, e.msg);
		assert_true(fabs(s.theta_end - taken[k].end_deg * DEG) < 1e-15);
		ps_sensor_free(&s);
	}
}

static void views(void **state)
{
	struct ps_view v;
	struct ps_err e;
	(void)state;
	ps_view_default(&v);
	/* later options override earlier ones; other words are skipped */
	assert_int_equal(ps_view_parse(&v, "rpict -vtv -vh 30 -x 256 -vta -vp 1 2 3 -vd 0 0 -1 "
	                                   "-vu 0 1 0 -vh 180 -vv 170 -vs 0.1 -vl -0.2 -ab 3 oct",
	                               "t", &e), 0);
	assert_int_equal(v.type, PS_VT_ANGULAR);
	assert_true(v.vp[2] == 3 && v.vd[2] == -1 && v.vu[1] == 1);
	assert_true(v.vh == 180 && v.vv == 170 && v.vs == 0.1 && v.vl == -0.2);
	assert_int_equal(ps_view_check_fisheye(&v, "t", &e), 0);
	assert_int_equal(ps_view_parse(&v, "-vth -vh 200", "t", &e), 0);
	assert_int_equal(ps_view_check_fisheye(&v, "pic.hdr: VIEW", &e), -1);
	assert_non_null(strstr(e.msg, "pic.hdr: VIEW: -vh 200"));
	ps_view_default(&v);
	assert_int_equal(ps_view_check_fisheye(&v, "t", &e), -1);
	assert_non_null(strstr(e.msg, "-vtv is not a fisheye"));
	assert_int_equal(ps_view_parse(&v, "-vta -vp 1 2", "t", &e), -1);
	assert_non_null(strstr(e.msg, "-vp needs 3 numbers"));
	assert_int_equal(ps_view_parse(&v, "-vtx", "t", &e), -1);
	assert_int_equal(ps_view_parse(&v, "-vh abc", "t", &e), -1);
	assert_non_null(strstr(e.msg, "'abc' is not a number"));
	assert_int_equal(ps_view_parse(&v, "-vta -vd 0 0 0", "t", &e), 0);
	assert_int_equal(ps_view_check_fisheye(&v, "t", &e), -1);
	assert_non_null(strstr(e.msg, "-vd is a zero vector"));
	assert_int_equal(ps_view_parse(&v, "-vd 0 1 0 -vu 0 2 0", "t", &e), 0);
	assert_int_equal(ps_view_check_fisheye(&v, "t", &e), -1);
	assert_non_null(strstr(e.msg, "parallel"));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(good_tables),
		cmocka_unit_test(located_errors),
		cmocka_unit_test(field_coverage),
		cmocka_unit_test(views),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
