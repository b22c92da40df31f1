/* SPDX-License-Identifier: ISC */
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
	fputs("[psresults]\nversion = 3\n", fp);
	fclose(fp);
	assert_int_equal(ps_results_read(&r, path, &e), -1);
	assert_non_null(strstr(e.msg, ":2: results version 3, this psensd reads 1 to 2"));
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

/* version 2 carries the year; version 1 files (no year) still read */
static void year_round_trip(void **state)
{
	struct ps_results r, back;
	struct ps_err e;
	struct ps_year_hour h[3] = {
		{ 1, 1, 8.5, 2.0, 400.0, PS_SKY_OVERCAST, 1.1, 5000.0, NAN, NAN },
		{ 1, 2, 8.5, 2.0, 600.0, PS_SKY_OVERCAST, 1.2, NAN, NAN, NAN },   /* a file before the column */
		{ 7, 4, 12.5, 10.0, 2000.0, PS_SKY_CLEAR, 6.0, 98765.5, NAN, NAN },
	};
	char path[] = "/tmp/psresXXXXXX";
	int fd = mkstemp(path);
	FILE *fp;
	(void)state;
	close(fd);
	memset(&r, 0, sizeof r);
	r.scene = "x.scene";
	r.reading = "linear";
	r.have_year = 1;
	r.weather = "w.wea";
	r.year_mf = 1;
	r.year.h = h;
	r.year.n = 3;
	r.year.steps = 10;
	r.year.dark = 7;
	r.year.patches = r.year.used = 146;
	r.year.have_site = 1;
	r.year.leap = 1;
	r.year.site = (struct ps_site){ .lat = 37.7, .lon = -122.2, .tz = -8 };
	ps_year_tabulate(&r.year);
	assert_true(r.year.ratio[0][8][PS_SKY_OVERCAST] == 250.0);   /* (400 + 600) / 4 */
	assert_true(r.year.ratio[6][12][PS_SKY_CLEAR] == 200.0);
	assert_true(isnan(r.year.ratio[6][12][PS_SKY_OVERCAST]));
	assert_true(r.year.mean_ratio == 3000.0 / 14.0);
	ps_results_summarise(&r);
	assert_int_equal(ps_results_write(&r, path, &e), 0);
	assert_int_equal(ps_results_read(&back, path, &e), 0);
	assert_int_equal(back.version, 2);
	assert_int_equal(back.have_year, 1);
	assert_string_equal(back.weather, "w.wea");
	assert_int_equal(back.year.n, 3);
	assert_int_equal(back.year.dark, 7);
	assert_true(back.year.h[2].task_lux == 2000.0 && back.year.h[2].hour == 12.5);
	/* the rooftop column and the site */
	assert_true(back.year.h[0].horiz_lux == 5000.0 && back.year.h[2].horiz_lux == 98765.5);
	assert_true(isnan(back.year.h[1].horiz_lux));
	assert_int_equal(back.year.have_site, 1);
	assert_int_equal(back.year.leap, 1);
	assert_true(back.year.site.lat == 37.7 && back.year.site.lon == -122.2 && back.year.site.tz == -8);
	assert_true(back.year.ratio[0][8][PS_SKY_OVERCAST] == 250.0);
	assert_true(back.year.mean_ratio == 3000.0 / 14.0);
	ps_results_free(&back);
	/* a bad hour: file:line */
	fp = fopen(path, "w");
	fputs("[psresults]\nversion = 2\nrgb = 1 1 1\nrotation = 0\n[year]\nhours = 2\n"
	      "mean_ratio = 1\n[year_hours]\nh1 = 1 1 8.5 2 400 2 1.1\nh2 = 13 1 8.5 2 400 2 1.1\n", fp);
	fclose(fp);
	assert_int_equal(ps_results_read(&back, path, &e), -1);
	assert_non_null(strstr(e.msg, ":10: h2: '13 1 8.5 2 400 2 1.1' is not month day hour"));
	fp = fopen(path, "w");
	fputs("[psresults]\nversion = 2\nrgb = 1 1 1\nrotation = 0\n[year]\nhours = 3\n"
	      "mean_ratio = 1\n[year_hours]\nh1 = 1 1 8.5 2 400 2 1.1\n", fp);
	fclose(fp);
	assert_int_equal(ps_results_read(&back, path, &e), -1);
	assert_non_null(strstr(e.msg, ":5: [year] says hours = 3, [year_hours] has 1"));
	/* an eighth field that is no illuminance, and a ninth */
	fp = fopen(path, "w");
	fputs("[psresults]\nversion = 2\nrgb = 1 1 1\nrotation = 0\n[year]\nhours = 2\n"
	      "mean_ratio = 1\n[year_hours]\nh1 = 1 1 8.5 2 400 2 1.1 -5\nh2 = 1 1 9.5 2 400 2 1.1 7 8\n", fp);
	fclose(fp);
	assert_int_equal(ps_results_read(&back, path, &e), -1);
	assert_non_null(strstr(e.msg, ":9: h1: '1 1 8.5 2 400 2 1.1 -5' is not month day hour"));
	fp = fopen(path, "w");
	fputs("[psresults]\nversion = 2\nrgb = 1 1 1\nrotation = 0\n[year]\nhours = 1\n"
	      "mean_ratio = 1\n[year_hours]\nh1 = 1 1 9.5 2 400 2 1.1 7 8\n", fp);
	fclose(fp);
	assert_int_equal(ps_results_read(&back, path, &e), -1);
	assert_non_null(strstr(e.msg, ":9: h1: '1 1 9.5 2 400 2 1.1 7 8' is not month day hour"));
	/* the sun in its nearest patch: sensor and task, both on every hour, or none */
	fp = fopen(path, "w");
	fputs("[psresults]\nversion = 2\nrgb = 1 1 1\nrotation = 0\n[year]\nhours = 2\n"
	      "mean_ratio = 1\n[year_hours]\nh1 = 1 1 8.5 2 400 2 1.1 7 3 600\nh2 = 1 1 9.5 2 400 2 1.1 7 1 200\n", fp);
	fclose(fp);
	assert_int_equal(ps_results_read(&back, path, &e), 0);
	assert_int_equal(back.year.have_alt, 1);
	assert_true(back.year.h[0].sensor_alt == 3 && back.year.h[0].task_alt == 600 &&
	            back.year.h[1].sensor_alt == 1 && back.year.h[1].task_alt == 200);
	assert_int_equal(ps_results_write(&back, path, &e), 0);
	ps_results_free(&back);
	assert_int_equal(ps_results_read(&back, path, &e), 0);
	assert_true(back.year.have_alt == 1 && back.year.h[1].task_alt == 200);
	ps_results_free(&back);
	fp = fopen(path, "w");
	fputs("[psresults]\nversion = 2\nrgb = 1 1 1\nrotation = 0\n[year]\nhours = 2\n"
	      "mean_ratio = 1\n[year_hours]\nh1 = 1 1 8.5 2 400 2 1.1 7 3 600\nh2 = 1 1 9.5 2 400 2 1.1 7\n", fp);
	fclose(fp);
	assert_int_equal(ps_results_read(&back, path, &e), 0);
	assert_int_equal(back.year.have_alt, 0);   /* not every hour: no alternative year */
	ps_results_free(&back);
	fp = fopen(path, "w");
	fputs("[psresults]\nversion = 2\nrgb = 1 1 1\nrotation = 0\n[year]\nhours = 1\n"
	      "mean_ratio = 1\n[year_hours]\nh1 = 1 1 9.5 2 400 2 1.1 7 3 600 9\n", fp);
	fclose(fp);
	assert_int_equal(ps_results_read(&back, path, &e), -1);
	assert_non_null(strstr(e.msg, ":9: h1: '1 1 9.5 2 400 2 1.1 7 3 600 9' is not month day hour"));
	/* version 1: no year */
	fp = fopen(path, "w");
	fputs("[psresults]\nversion = 1\nrgb = 1 1 1\nrotation = 0\n[condition a]\nkind = daylight\n"
	      "tod_s = 1\nsensor_response = 1\ntask_irradiance = 1\ntask_lux = 179\nratio = 179\n"
	      "brightest_share = 0\n", fp);
	fclose(fp);
	assert_int_equal(ps_results_read(&back, path, &e), 0);
	assert_int_equal(back.version, 1);
	assert_int_equal(back.have_year, 0);
	assert_true(back.daylight_ratio_mean == 179.0);
	ps_results_free(&back);
	unlink(path);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(round_trip_and_summary),
		cmocka_unit_test(other_versions_and_garbage),
		cmocka_unit_test(year_round_trip),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
