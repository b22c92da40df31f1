/* SPDX-License-Identifier: ISC */
/* psensctl export's time arguments (daemon/sampleout.c) against epochs
 * computed apart (Python's calendar.timegm), in UTC and in a zone an hour
 * east (a POSIX TZ string: no time zone database needed). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <time.h>
#include <unistd.h>

#include <cmocka.h>
#include <sqlite3.h>

#include "sampleout.h"

static void zone(const char *tz)
{
	setenv("TZ", tz, 1);
	tzset();
}

static void iso_and_epoch(void **state)
{
	double t;
	(void)state;
	zone("UTC0");
	assert_int_equal(psd_sampleout_time_parse("2026-03-18T12:05:30Z", &t), 0);
	assert_true(t == 1773835530.0);
	assert_int_equal(psd_sampleout_time_parse("2026-03-18T12:05:30", &t), 0);
	assert_true(t == 1773835530.0);
	assert_int_equal(psd_sampleout_time_parse("2026-03-18 12:05", &t), 0);
	assert_true(t == 1773835500.0);
	assert_int_equal(psd_sampleout_time_parse("2026-03-18", &t), 0);
	assert_true(t == 1773792000.0);
	assert_int_equal(psd_sampleout_time_parse("1773835530.25", &t), 0);
	assert_true(t == 1773835530.25);
	/* an hour east of UTC: local 13:05:30 is 12:05:30Z; Z stays UTC */
	zone("CET-1");
	assert_int_equal(psd_sampleout_time_parse("2026-03-18T13:05:30", &t), 0);
	assert_true(t == 1773835530.0);
	assert_int_equal(psd_sampleout_time_parse("2026-03-18T12:05:30Z", &t), 0);
	assert_true(t == 1773835530.0);
	zone("UTC0");
}

static void refused(void **state)
{
	static const char *const bad[] = { "", "yesterday", "12:05", "2026-13-01", "2026-03-18T25:00",
	                                   "2026-03-18T12:05:30+02", "2026-03-18X", "-5", "1e308", "nan",
	                                   "2026-03-18T12", NULL };
	double t;
	(void)state;
	for (int i = 0; bad[i]; i++)
		assert_int_equal(psd_sampleout_time_parse(bad[i], &t), -1);
}

static void iso_out(void **state)
{
	char out[32];
	(void)state;
	zone("UTC0");
	psd_sampleout_time_iso(1773835530.4, out);
	assert_string_equal(out, "2026-03-18T12:05:30");
	zone("CET-1");
	psd_sampleout_time_iso(1773835530.4, out);
	assert_string_equal(out, "2026-03-18T13:05:30");
	psd_sampleout_time_iso(NAN, out);
	assert_string_equal(out, "-");
	psd_sampleout_time_iso(1e300, out);
	assert_string_equal(out, "-");
	zone("UTC0");
}

static void count_row(void *user, const struct psd_sample *s)
{
	(void)s;
	++*(int *)user;
}

/* A log from before schema 4, read without migrating it (psensctl opens it
 * read-only): its samples come out without a time, and a time range
 * matches none of them, instead of "no such column: utc". */
static void old_log(void **state)
{
	char path[] = "/tmp/psout.XXXXXX", db[64], err[256];
	sqlite3 *h;
	int n = 0;
	(void)state;
	assert_non_null(mkdtemp(path));
	snprintf(db, sizeof db, "%s/v3.db", path);
	assert_int_equal(sqlite3_open(db, &h), SQLITE_OK);
	assert_int_equal(sqlite3_exec(h, "CREATE TABLE samples(t REAL NOT NULL, tod_s REAL, sensor_v REAL, output REAL,"
	                                 " est_task_lux REAL, task_lux REAL, daylight_v REAL, daylight_lux REAL,"
	                                 " condition TEXT, ratio REAL, fault TEXT, zone TEXT);"
	                                 "INSERT INTO samples(t, tod_s, sensor_v, output, zone) VALUES"
	                                 " (21600, 21600, 0.5, 0.4, 'office'), (21660, 21660, 0.6, 0.3, 'office');",
	                                 NULL, NULL, NULL), SQLITE_OK);
	sqlite3_close(h);
	assert_int_equal(psd_db_select(db, "office", NAN, NAN, 0, count_row, &n, err, sizeof err), 0);
	assert_int_equal(n, 2);
	n = 0;
	assert_int_equal(psd_db_select(db, "office", 0, NAN, 0, count_row, &n, err, sizeof err), 0);
	assert_int_equal(n, 0);
	n = 0;
	assert_int_equal(psd_db_select(db, NULL, NAN, NAN, 1, count_row, &n, err, sizeof err), 0);
	assert_int_equal(n, 1);
	unlink(db);
	rmdir(path);
}

/* The CSV export: each column's unit in its name, no column repeating
 * another (the clock's seconds beside tod_s), the output as logged (a
 * fraction, so named), the measured task lux and the simulated room's
 * truth each in its own named column, occupancy 1, 0 or empty (no input),
 * every number round-tripping, nothing before the first row is asked for. */
static void csv_form(void **state)
{
	char buf[1024];
	FILE *fp = fmemopen(buf, sizeof buf, "w");
	struct psd_sampleout o;
	struct psd_sample s = { 43260.5, 43260.5, 3.6878, 0.1, 1842.4, 1820.2, 3.6331, 1715.9, "daylight_mean", 236.15,
	                        NULL, "office", 1773835530, NULL, 1, 1817.25 };
	(void)state;
	assert_non_null(fp);
	zone("UTC0");
	psd_sampleout_begin(&o, fp, PSD_OUT_CSV);
	assert_int_equal(ftell(fp), 0);
	psd_sampleout_row(&o, &s);
	s.occupied = 0;
	psd_sampleout_row(&o, &s);
	s.occupied = -1;
	s.true_task_lux = NAN;
	psd_sampleout_row(&o, &s);
	assert_int_equal(psd_sampleout_end(&o), 0);
	fclose(fp);
	assert_string_equal(buf, "zone,time_local,utc_s,tod_s,sensor_v,output_fraction,est_task_lux,task_lux,daylight_v,"
	                         "daylight_lux,condition,ratio_lux_per_unit,fault,occupied,simulated_true_task_lux\n"
	                         "office,2026-03-18T12:05:30,1773835530,43260.5,3.6878,0.1,1842.4,1820.2,3.6331,1715.9,"
	                         "daylight_mean,236.15,,1,1817.25\n"
	                         "office,2026-03-18T12:05:30,1773835530,43260.5,3.6878,0.1,1842.4,1820.2,3.6331,1715.9,"
	                         "daylight_mean,236.15,,0,1817.25\n"
	                         "office,2026-03-18T12:05:30,1773835530,43260.5,3.6878,0.1,1842.4,1820.2,3.6331,1715.9,"
	                         "daylight_mean,236.15,,,\n");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(iso_and_epoch),
		cmocka_unit_test(refused),
		cmocka_unit_test(iso_out),
		cmocka_unit_test(old_log),
		cmocka_unit_test(csv_form),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
