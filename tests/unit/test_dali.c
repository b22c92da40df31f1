/* SPDX-License-Identifier: ISC */
/* The DALI layer (drivers/dali.c): the logarithmic curve against the formula
 * of IEC 62386-102 and the published table, its round trip at every level,
 * nearest-level rounding against a brute-force search, frames against the
 * worked examples of doc/hardware.md, address parsing and fade times. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "dali.h"

static void curve_endpoints_and_table(void **state)
{
	/* level, percent as published (zencontrol table, logicmachine "229 = 50.53 %") */
	static const struct { int n; double pct, tol; } tab[] = {
		{ 1, 0.10, 0.005 }, { 85, 0.99, 0.005 }, { 86, 1.02, 0.005 }, { 127, 3.12, 0.005 },
		{ 170, 10.1, 0.05 }, { 195, 20.0, 0.05 }, { 200, 22.9, 0.05 }, { 210, 30.0, 0.5 } /* published as "30 %" */,
		{ 228, 49.2, 0.05 }, { 229, 50.53, 0.005 }, { 235, 59.5, 0.05 }, { 241, 70.1, 0.05 },
		{ 246, 80.4, 0.05 }, { 250, 89.7, 0.05 }, { 254, 100.0, 1e-12 },
	};
	(void)state;
	assert_true(fabs(ps_dali_level_to_fraction(1) - 0.001) < 1e-17);
	assert_true(fabs(ps_dali_level_to_fraction(254) - 1.0) < 1e-15);
	assert_true(ps_dali_level_to_fraction(0) == 0.0);
	assert_true(isnan(ps_dali_level_to_fraction(PS_DALI_MASK)));
	for (size_t i = 0; i < sizeof tab / sizeof tab[0]; i++) {
		double pct = 100 * ps_dali_level_to_fraction(tab[i].n);
		if (fabs(pct - tab[i].pct) > tab[i].tol)
			fail_msg("level %d: %.4f %%, published %.2f %%", tab[i].n, pct, tab[i].pct);
	}
}

static void every_step_is_the_same_ratio(void **state)
{
	double r = pow(10.0, 3.0 / 253.0);   /* 2.77 % per step */
	(void)state;
	for (int n = 1; n < 254; n++) {
		double q = ps_dali_level_to_fraction(n + 1) / ps_dali_level_to_fraction(n);
		assert_true(fabs(q / r - 1) < 1e-13);
	}
}

static void round_trip_at_every_level(void **state)
{
	(void)state;
	for (int n = 0; n <= 254; n++) {
		int back = ps_dali_fraction_to_level(ps_dali_level_to_fraction(n));
		if (back != n)
			fail_msg("level %d -> %.17g -> level %d", n, ps_dali_level_to_fraction(n), back);
	}
}

/* the level is the nearest in ratio: just below the geometric midpoint of two
 * levels gives the lower, just above gives the upper */
static void rounding_at_the_geometric_midpoints(void **state)
{
	(void)state;
	for (int n = 1; n < 254; n++) {
		double mid = sqrt(ps_dali_level_to_fraction(n) * ps_dali_level_to_fraction(n + 1));
		assert_int_equal(ps_dali_fraction_to_level(mid * (1 - 1e-9)), n);
		assert_int_equal(ps_dali_fraction_to_level(mid * (1 + 1e-9)), n + 1);
	}
}

static void nearest_level_against_brute_force(void **state)
{
	uint64_t x = 88172645463325252ull;
	(void)state;
	for (int k = 0; k < 20000; k++) {
		double u, f, best = INFINITY;
		int arg = -1, got;
		x ^= x << 13; x ^= x >> 7; x ^= x << 17;
		u = (double)(x >> 11) / 9007199254740992.0;
		f = pow(10.0, -3 + 3 * u);             /* 0.1 % to 100 %, log-uniform */
		for (int n = 1; n <= 254; n++) {
			double e = fabs(log(ps_dali_level_to_fraction(n) / f));
			if (e < best) {
				best = e;
				arg = n;
			}
		}
		got = ps_dali_fraction_to_level(f);
		/* worst ratio error is half a step: 10^(1.5/253) - 1 = 1.38 % */
		assert_int_equal(got, arg);
		assert_true(fabs(ps_dali_level_to_fraction(got) / f - 1) <= pow(10.0, 1.5 / 253) - 1 + 1e-12);
	}
}

static void edges_of_the_fraction_scale(void **state)
{
	(void)state;
	assert_int_equal(ps_dali_fraction_to_level(0), 0);
	assert_int_equal(ps_dali_fraction_to_level(-0.5), 0);
	assert_int_equal(ps_dali_fraction_to_level(NAN), 0);
	assert_int_equal(ps_dali_fraction_to_level(1e-9), 1);      /* on, at the lowest arc power */
	assert_int_equal(ps_dali_fraction_to_level(0.0009), 1);
	assert_int_equal(ps_dali_fraction_to_level(1), 254);
	assert_int_equal(ps_dali_fraction_to_level(7), 254);
	assert_int_equal(ps_dali_fraction_to_level(INFINITY), 254);
	assert_int_equal(ps_dali_fraction_to_level(0.5), 229);      /* 50.53 % is nearest */
	/* the physical minimum raises low levels and leaves off and MASK alone */
	assert_int_equal(ps_dali_clamp_physical_min(1, 85), 85);
	assert_int_equal(ps_dali_clamp_physical_min(84, 85), 85);
	assert_int_equal(ps_dali_clamp_physical_min(86, 85), 86);
	assert_int_equal(ps_dali_clamp_physical_min(0, 85), 0);
	assert_int_equal(ps_dali_clamp_physical_min(255, 85), 255);
	assert_int_equal(ps_dali_clamp_physical_min(5, 0), 5);
}

static void frames_of_the_worked_examples(void **state)
{
	struct ps_dali_addr s5 = { PS_DALI_SHORT, 5 }, g3 = { PS_DALI_GROUP, 3 },
	                    bc = { PS_DALI_BROADCAST, 0 }, s21 = { PS_DALI_SHORT, 21 };
	(void)state;
	assert_int_equal(ps_dali_dapc(&s5, 200), 0x0AC8);
	assert_int_equal(ps_dali_cmd(&s5, PS_DALI_QUERY_ACTUAL_LEVEL), 0x0BA0);
	assert_int_equal(ps_dali_dapc(&g3, 100), 0x8664);
	assert_int_equal(ps_dali_cmd(&bc, PS_DALI_OFF), 0xFF00);
	assert_int_equal(ps_dali_cmd(&bc, PS_DALI_RECALL_MAX), 0xFF05);
	assert_int_equal(ps_dali_dapc(&bc, 254), 0xFEFE);
	assert_int_equal(ps_dali_dapc(&s21, 1), 0x2A01);            /* python-dali's log */
	assert_int_equal(ps_dali_dtr0(0x7F), 0xA37F);
	assert_int_equal(ps_dali_dtr0(256), -1);
	assert_int_equal(ps_dali_dapc(&(struct ps_dali_addr){ PS_DALI_SHORT, 64 }, 1), -1);
	assert_int_equal(ps_dali_dapc(&(struct ps_dali_addr){ PS_DALI_GROUP, 16 }, 1), -1);
	assert_int_equal(ps_dali_dapc(&s5, 256), -1);
	/* group 15 and short 63 are the last of their kind */
	assert_int_equal(ps_dali_cmd(&(struct ps_dali_addr){ PS_DALI_GROUP, 15 }, 0), 0x9F00);
	assert_int_equal(ps_dali_dapc(&(struct ps_dali_addr){ PS_DALI_SHORT, 63 }, 0), 0x7E00);
}

static void frame_kinds(void **state)
{
	struct ps_dali_addr s5 = { PS_DALI_SHORT, 5 }, bc = { PS_DALI_BROADCAST, 0 };
	(void)state;
	assert_true(ps_dali_needs_twice((unsigned)ps_dali_cmd(&s5, PS_DALI_SET_FADE_TIME)));
	assert_true(ps_dali_needs_twice((unsigned)ps_dali_cmd(&bc, PS_DALI_SET_SYSTEM_FAILURE_LEVEL)));
	assert_false(ps_dali_needs_twice((unsigned)ps_dali_cmd(&s5, PS_DALI_RECALL_MAX)));
	assert_false(ps_dali_needs_twice((unsigned)ps_dali_dapc(&s5, 0x2E)));   /* a level, not a command */
	assert_false(ps_dali_needs_twice(0xA32E));                              /* DTR0 = 0x2E */
	assert_true(ps_dali_expects_answer((unsigned)ps_dali_cmd(&s5, PS_DALI_QUERY_ACTUAL_LEVEL)));
	assert_true(ps_dali_expects_answer((unsigned)ps_dali_cmd(&bc, PS_DALI_QUERY_STATUS)));
	assert_false(ps_dali_expects_answer((unsigned)ps_dali_dapc(&s5, 0xA0)));
	assert_false(ps_dali_expects_answer((unsigned)ps_dali_cmd(&s5, PS_DALI_OFF)));
	/* every address decodes back to itself */
	for (int kind = 0; kind < 3; kind++)
		for (int n = 0; n < (kind == 0 ? 64 : kind == 1 ? 16 : 1); n++) {
			struct ps_dali_addr a = { kind, n }, b;
			assert_int_equal(ps_dali_frame_addr((unsigned)ps_dali_dapc(&a, 17), &b), 0);
			assert_int_equal(b.kind, kind);
			assert_int_equal(b.n, n);
			assert_int_equal(ps_dali_frame_addr((unsigned)ps_dali_cmd(&a, 5), &b), 0);
			assert_int_equal(b.kind, kind);
		}
	{
		struct ps_dali_addr b;
		assert_int_equal(ps_dali_frame_addr(0xA37F, &b), -1);   /* special command */
		assert_int_equal(ps_dali_frame_addr(0xFD00, &b), -1);   /* broadcast unaddressed */
	}
}

static void describe_frames(void **state)
{
	char buf[64];
	(void)state;
	ps_dali_describe(0x0AC8, buf, sizeof buf);
	assert_string_equal(buf, "short 5 DAPC 200");
	ps_dali_describe(0x8701, buf, sizeof buf);
	assert_string_equal(buf, "group 3 command 0x01");
	ps_dali_describe(0xFF05, buf, sizeof buf);
	assert_string_equal(buf, "broadcast RECALL MAX LEVEL");
	ps_dali_describe(0x0BA0, buf, sizeof buf);
	assert_string_equal(buf, "short 5 QUERY ACTUAL LEVEL");
	ps_dali_describe(0xA37F, buf, sizeof buf);
	assert_string_equal(buf, "DTR0 127");
}

static void parse_addresses(void **state)
{
	static const struct { const char *s; int ok, kind, n; } cases[] = {
		{ "5", 1, PS_DALI_SHORT, 5 }, { "short 63", 1, PS_DALI_SHORT, 63 }, { " 0", 1, PS_DALI_SHORT, 0 },
		{ "group 3", 1, PS_DALI_GROUP, 3 }, { "g15", 1, PS_DALI_GROUP, 15 },
		{ "broadcast", 1, PS_DALI_BROADCAST, 0 },
		{ "64", 0, 0, 0 }, { "group 16", 0, 0, 0 }, { "g", 0, 0, 0 }, { "", 0, 0, 0 },
		{ "5x", 0, 0, 0 }, { "-1", 0, 0, 0 }, { "short", 0, 0, 0 }, { "broadcastx", 0, 0, 0 },
		{ "99999999999999999999", 0, 0, 0 },
	};
	(void)state;
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		struct ps_dali_addr a;
		char err[128] = "";
		int r = ps_dali_addr_parse(cases[i].s, &a, err, sizeof err);
		if ((r == 0) != cases[i].ok)
			fail_msg("'%s': %s", cases[i].s, r ? err : "accepted");
		if (r == 0) {
			assert_int_equal(a.kind, cases[i].kind);
			assert_int_equal(a.n, cases[i].n);
		} else {
			assert_true(err[0] != 0);
		}
	}
}

static void fade_times(void **state)
{
	(void)state;
	/* T = 0.5 sqrt(2^n): the published values */
	assert_true(fabs(ps_dali_fade_time_seconds(1) - 0.7071) < 1e-4);
	assert_true(ps_dali_fade_time_seconds(4) == 2.0);
	assert_true(ps_dali_fade_time_seconds(8) == 8.0);
	assert_true(fabs(ps_dali_fade_time_seconds(15) - 90.51) < 0.01);
	assert_true(ps_dali_fade_time_seconds(0) == 0);
	for (int c = 1; c <= 15; c++)
		assert_int_equal(ps_dali_fade_time_code(ps_dali_fade_time_seconds(c)), c);
	assert_int_equal(ps_dali_fade_time_code(0), 0);
	assert_int_equal(ps_dali_fade_time_code(0.3), 0);
	assert_int_equal(ps_dali_fade_time_code(1e6), 15);
	/* nearest on the log scale: 2.9 s is nearer 2.83 (code 5) than 4.0 */
	assert_int_equal(ps_dali_fade_time_code(2.9), 5);
	assert_int_equal(ps_dali_fade_time_code(3.5), 6);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(curve_endpoints_and_table),
		cmocka_unit_test(every_step_is_the_same_ratio),
		cmocka_unit_test(round_trip_at_every_level),
		cmocka_unit_test(rounding_at_the_geometric_midpoints),
		cmocka_unit_test(nearest_level_against_brute_force),
		cmocka_unit_test(edges_of_the_fraction_scale),
		cmocka_unit_test(frames_of_the_worked_examples),
		cmocka_unit_test(frame_kinds),
		cmocka_unit_test(describe_frames),
		cmocka_unit_test(parse_addresses),
		cmocka_unit_test(fade_times),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
