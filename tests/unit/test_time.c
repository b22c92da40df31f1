/* SPDX-License-Identifier: ISC */
/* The daemon's time module against known answers: the two clocks against
 * the kernel's, HH:MM at and past its edges (one rule: 00:00 to 23:59),
 * ISO 8601 UTC texts of instants whose dates are known (the Unix epoch,
 * 1e9 s = 2001-09-09T01:46:40Z), and local texts either side of both
 * daylight saving time changes of 2026 in Europe/Berlin (CET to CEST at
 * 01:00 UTC on 03-29, back at 01:00 UTC on 10-25), where a wrong offset or
 * a fixed one shows as a wrong hour. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

#include "time.h"

static void clocks_follow_the_kernel(void **state)
{
	struct timespec ts;
	double m0, m1, w;
	(void)state;
	m0 = psd_time_mono();
	clock_gettime(CLOCK_MONOTONIC, &ts);
	m1 = psd_time_mono();
	assert_true(m1 >= m0);
	assert_true(fabs((double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec - m0) < 1.0);
	w = psd_time_wall();
	assert_true(fabs(w - (double)time(NULL)) <= 1.0);
	/* the monotonic clock is not the date: boot time, not 1970 */
	assert_true(fabs(w - m0) > 1e8);
}

static void hhmm_rule(void **state)
{
	static const struct {
		const char *s;
		double want;   /* -1: refused */
	} cases[] = {
		{ "00:00", 0 },        { "23:59", 86340 },   { "7:05", 25500 },   { "07:05", 25500 },
		{ "12:30", 45000 },    { "24:00", -1 },      { "24:30", -1 },     { "23:60", -1 },
		{ "7:5", -1 },         { "", -1 },           { ":30", -1 },       { " 7:05", -1 },
		{ "07:05 ", -1 },      { "-1:00", -1 },      { "+7:05", -1 },     { "123:00", -1 },
		{ "12:345", -1 },      { "12-30", -1 },      { "12:3a", -1 },     { "99:99", -1 },
	};
	(void)state;
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		double t = -2;
		int rc = psd_time_hhmm(cases[i].s, &t);
		if (cases[i].want < 0) {
			assert_int_equal(rc, -1);
			assert_true(t == -2);   /* untouched when refused */
		} else {
			assert_int_equal(rc, 0);
			assert_true(t == cases[i].want);
		}
	}
}

static void hhmm_scan_stops_after_minutes(void **state)
{
	int h = -1, m = -1;
	(void)state;
	assert_int_equal(psd_time_hhmm_scan("12:30Z", &h, &m), 5);
	assert_int_equal(h, 12);
	assert_int_equal(m, 30);
	assert_int_equal(psd_time_hhmm_scan("9:30:15", &h, &m), 4);
	assert_int_equal(h, 9);
	assert_int_equal(m, 30);
	assert_int_equal(psd_time_hhmm_scan("24:00", &h, &m), -1);
	assert_int_equal(psd_time_hhmm_scan(NULL, &h, &m), -1);
}

static void utc_texts(void **state)
{
	char out[40];
	(void)state;
	assert_int_equal(psd_time_utc_text(0, PSD_TIME_ISO, out, sizeof out), 0);
	assert_string_equal(out, "1970-01-01T00:00:00Z");
	assert_int_equal(psd_time_utc_text(1e9, PSD_TIME_ISO, out, sizeof out), 0);
	assert_string_equal(out, "2001-09-09T01:46:40Z");
	assert_int_equal(psd_time_utc_text(1e9 + 0.25, PSD_TIME_ISO_MS, out, sizeof out), 0);
	assert_string_equal(out, "2001-09-09T01:46:40.250Z");
	/* truncated, never rounded up into the next second */
	assert_int_equal(psd_time_utc_text(1e9 + 0.9999, PSD_TIME_ISO_MS, out, sizeof out), 0);
	assert_string_equal(out, "2001-09-09T01:46:40.999Z");
	assert_int_equal(psd_time_utc_text(1e9 + 0.9999, PSD_TIME_SECOND, out, sizeof out), 0);
	assert_string_equal(out, "2001-09-09 01:46:40");
	assert_int_equal(psd_time_utc_text(1773835530.0, PSD_TIME_MINUTE, out, sizeof out), 0);
	assert_string_equal(out, "2026-03-18 12:05");
	assert_int_equal(psd_time_utc_text(1773835530.0, PSD_TIME_DATE, out, sizeof out), 0);
	assert_string_equal(out, "2026-03-18");
	/* before 1970: a second before the epoch */
	assert_int_equal(psd_time_utc_text(-1, PSD_TIME_ISO, out, sizeof out), 0);
	assert_string_equal(out, "1969-12-31T23:59:59Z");
}

static void texts_refused(void **state)
{
	char out[40], small[20];
	(void)state;
	assert_int_equal(psd_time_utc_text(NAN, PSD_TIME_ISO, out, sizeof out), -1);
	assert_string_equal(out, "");
	assert_int_equal(psd_time_utc_text(INFINITY, PSD_TIME_ISO, out, sizeof out), -1);
	assert_int_equal(psd_time_local_text(1e300, PSD_TIME_ISO, out, sizeof out), -1);
	assert_string_equal(out, "");
	/* "1970-01-01T00:00:00Z" is 20 characters: with its NUL it needs 21 */
	assert_int_equal(psd_time_utc_text(0, PSD_TIME_ISO, small, sizeof small), -1);
	assert_string_equal(small, "");
	assert_int_equal(psd_time_utc_text(0, PSD_TIME_ISO_MS, out, 24), -1);
	assert_int_equal(psd_time_utc_text(0, PSD_TIME_ISO_MS, out, 25), 0);
	assert_string_equal(out, "1970-01-01T00:00:00.000Z");
	assert_int_equal(psd_time_utc_text(0, 99, out, sizeof out), -1);
}

/* Local texts around Berlin's 2026 changes; tzdata's zone when installed,
 * else the same rule in POSIX form (the answers are the same). */
static void local_texts_across_dst(void **state)
{
	static const struct {
		double utc;
		const char *local;
	} cases[] = {
		{ 1774745999, "2026-03-29T01:59:59" },   /* 00:59:59 UTC, CET (+1) */
		{ 1774746000, "2026-03-29T03:00:00" },   /* 01:00:00 UTC, CEST (+2): 02:xx never happens */
		{ 1792889999, "2026-10-25T02:59:59" },   /* 00:59:59 UTC, CEST */
		{ 1792890000, "2026-10-25T02:00:00" },   /* 01:00:00 UTC, CET: 02:xx twice */
		{ 1773835530, "2026-03-18T13:05:30" },   /* winter: UTC + 1 */
	};
	char out[40];
	struct tm tm;
	(void)state;
	setenv("TZ", access("/usr/share/zoneinfo/Europe/Berlin", R_OK) == 0 ? "Europe/Berlin" : "CET-1CEST,M3.5.0,M10.5.0/3",
	       1);
	tzset();
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		assert_int_equal(psd_time_local_text(cases[i].utc, PSD_TIME_ISO, out, sizeof out), 0);
		assert_string_equal(out, cases[i].local);   /* local: no Z */
	}
	assert_int_equal(psd_time_local_text(1774746000, PSD_TIME_MINUTE, out, sizeof out), 0);
	assert_string_equal(out, "2026-03-29 03:00");
	assert_int_equal(psd_time_local(1792890000, &tm), 0);
	assert_int_equal(tm.tm_hour, 2);
	assert_int_equal(tm.tm_isdst, 0);
	assert_int_equal(psd_time_local(1792889999, &tm), 0);
	assert_int_equal(tm.tm_hour, 2);
	assert_int_equal(tm.tm_isdst, 1);
	assert_int_equal(psd_time_local(NAN, &tm), -1);
	unsetenv("TZ");
	tzset();
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(clocks_follow_the_kernel),
		cmocka_unit_test(hhmm_rule),
		cmocka_unit_test(hhmm_scan_stops_after_minutes),
		cmocka_unit_test(utc_texts),
		cmocka_unit_test(texts_refused),
		cmocka_unit_test(local_texts_across_dst),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
