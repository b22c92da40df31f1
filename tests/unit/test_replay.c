/* SPDX-License-Identifier: ISC */
/* Replay files: columns by name in any order, fault rows skipped, located
 * errors. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "replay.h"

static void columns_by_name(void **state)
{
	const char *t = "# exported\n"
	                "daylight_lux,x,tod_s,daylight_v,fault\n"
	                "100,a,3600,0.5,\n"
	                ",b,3660,,\"open circuit, 0 V\"\n"
	                "200,c,3720,1.0,\n";
	struct ps_room_daypoint *d;
	size_t n;
	char err[256];
	(void)state;
	assert_int_equal(ps_replay_parse(t, strlen(t), "r.csv", 0.5, 0, &d, &n, err, sizeof err), 0);
	assert_int_equal(n, 2);   /* the fault row has no daylight */
	assert_true(d[0].t == 3600 && d[0].sensor == 1.0 && d[0].task_lux == 100);
	assert_true(d[1].t == 3720 && d[1].sensor == 2.0 && d[1].task_lux == 200);
	free(d);
	/* without daylight_lux: from the ratio */
	t = "tod_s,daylight_v\n0,1\n10,2\n";
	assert_int_equal(ps_replay_parse(t, strlen(t), "r.csv", 1, 300, &d, &n, err, sizeof err), 0);
	assert_true(d[1].task_lux == 600);
	free(d);
}

static void located_errors(void **state)
{
	static const struct {
		const char *text, *want;
	} bad[] = {
		{ "t,sensor_v\n1,2\n", "r.csv:1: the header needs columns tod_s and daylight_v" },
		{ "tod_s,daylight_v\n10,1\n5,1\n", "r.csv:3: tod_s 5 does not follow 10" },
		{ "tod_s,daylight_v\n10,x\n", "r.csv:2: daylight_v 'x' is not a voltage" },
		{ "tod_s,daylight_v\n99999,1\n", "r.csv:2: tod_s '99999' is not seconds of a day" },
		{ "tod_s,daylight_v,daylight_lux\n10,1,-3\n", "r.csv:2: daylight_lux '-3' is not an illuminance" },
		{ "tod_s,daylight_v\n10,1\n", "fewer than two rows" },
		{ "tod_s,daylight_v\n10\n", "r.csv:2: 1 fields" },
		{ "", "no header line" },
	};
	struct ps_room_daypoint *d;
	size_t n;
	char err[256];
	(void)state;
	for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
		assert_int_equal(ps_replay_parse(bad[k].text, strlen(bad[k].text), "r.csv", 1, 1, &d, &n,
		                                 err, sizeof err), -1);
		if (!strstr(err, bad[k].want))
			fail_msg("case %zu: '%s' lacks '%s'", k, err, bad[k].want);
		assert_null(d);
	}
	{
		const char *t = "tod_s,daylight_v\n0,1\n10,2\n";
		assert_int_equal(ps_replay_parse(t, strlen(t), "r.csv", 1, 0, &d, &n, err, sizeof err), -1);
		assert_non_null(strstr(err, "no daylight_lux and no replay_ratio"));
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(columns_by_name),
		cmocka_unit_test(located_errors),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
