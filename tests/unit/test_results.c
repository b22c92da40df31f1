/* The results file psensd reads: what psscene writes reads back, summaries
 * follow from the conditions, and other versions are refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <unistd.h>
#include <cmocka.h>

#include "results.h"
#include "scene.h"

static void round_trip_and_summary(void **state)
{
	struct ps_results r, back;
	struct ps_err e;
	struct ps_result_cond c[4] = {
		{ "d1", PS_COND_DAYLIGHT, "03-18", 54000, 1, 5.0, 6.0, 1074.0, 200.0, 0.01 },
		{ "d2", PS_COND_DAYLIGHT, "04-16", 54000, 1, 5.0, 6.0, 1074.0, 220.0, 0.01 },
		{ "opt", PS_COND_DAYLIGHT, "", 3600, 0, NAN, NAN, NAN, NAN, NAN },
		{ "e", PS_COND_ELECTRIC, "", -1, 1, 1.0, 7.0, 1253.0, 1050.0, 0.0 },
	};
	char path[] = "/tmp/psresXXXXXX";
	int fd = mkstemp(path);
	(void)state;
	close(fd);
	memset(&r, 0, sizeof r);
	r.scene = "x.scene";
	r.scene_hash = "abc";
	r.sensitivity = "builtin:cosine";
	r.reading = "linear";
	r.rgb[0] = 0.2;
	r.rgb[1] = 0.7;
	r.rgb[2] = 0.1;
	r.cond = c;
	r.ncond = 4;
	ps_results_summarise(&r);
	assert_true(r.daylight_ratio_mean == 210.0);
	assert_true(r.daylight_ratio_min == 200.0 && r.daylight_ratio_max == 220.0);
	assert_true(fabs(r.daylight_ratio_sd - sqrt(200.0)) < 1e-12);
	assert_true(r.electric_ratio == 1050.0);
	assert_true(r.task_sensor_ratio == 5.0);
	assert_int_equal(ps_results_write(&r, path, &e), 0);
	assert_int_equal(ps_results_read(&back, path, &e), 0);
	assert_int_equal(back.ncond, 4);
	assert_string_equal(back.cond[0].label, "d1");
	assert_true(back.cond[1].ratio == 220.0);
	assert_int_equal(back.cond[2].computed, 0);
	assert_true(isnan(back.cond[2].ratio));
	assert_int_equal(back.cond[3].kind, PS_COND_ELECTRIC);
	assert_true(back.task_sensor_ratio == 5.0);
	assert_true(back.rgb[1] == 0.7);
	ps_results_free(&back);
	/* the same text from memory reads the same (the fuzz target's way in) */
	{
		FILE *fp = fopen(path, "r");
		char text[8192];
		size_t n;
		assert_non_null(fp);
		n = fread(text, 1, sizeof text - 1, fp);
		fclose(fp);
		text[n] = '\0';
		assert_int_equal(ps_results_parse(&back, text, path, &e), 0);
		assert_int_equal(back.ncond, 4);
		assert_true(back.cond[1].ratio == 220.0);
		assert_true(back.task_sensor_ratio == 5.0);
		ps_results_free(&back);
		assert_non_null(strstr(text, "[psresults]"));
		strstr(text, "[psresults]")[9] = 'z';   /* no [psresults] section: named as the file */
		assert_int_equal(ps_results_parse(&back, text, "mem.results", &e), -1);
		assert_non_null(strstr(e.msg, "mem.results"));
	}
	unlink(path);
}

static void other_versions_and_garbage(void **state)
{
	struct ps_results r;
	struct ps_err e;
	char path[] = "/tmp/psresXXXXXX";
	int fd = mkstemp(path);
	FILE *fp;
	(void)state;
	close(fd);
	fp = fopen(path, "w");
	fputs("[psresults]\nversion = 2\n", fp);
	fclose(fp);
	assert_int_equal(ps_results_read(&r, path, &e), -1);
	assert_non_null(strstr(e.msg, ":2: results version 2, this psensd reads 1"));
	fp = fopen(path, "w");
	fputs("[psresults]\nversion = 1\nrgb = 1 1 1\nrotation = 0\n[condition a]\nkind = daylight\n"
	      "tod_s = x\n", fp);
	fclose(fp);
	assert_int_equal(ps_results_read(&r, path, &e), -1);
	assert_non_null(strstr(e.msg, ":7: tod_s: 'x' is not a number"));
	fp = fopen(path, "w");
	fputs("hello\n", fp);
	fclose(fp);
	assert_int_equal(ps_results_read(&r, path, &e), -1);
	unlink(path);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(round_trip_and_summary),
		cmocka_unit_test(other_versions_and_garbage),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
