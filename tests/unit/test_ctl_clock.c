/* SPDX-License-Identifier: ISC */
/* The control protocol's word splitter, its growing reply and the daemon's
 * clock. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <cmocka.h>

#include "clock.h"
#include "ctlsock.h"

static void split_words(void **state)
{
	char line[] = "  override\toffice  0.5 60 ", err[128];
	char *argv[PSD_CTL_MAX_WORDS];
	(void)state;
	assert_int_equal(psd_ctlsock_split(line, argv, err, sizeof err), 4);
	assert_string_equal(argv[0], "override");
	assert_string_equal(argv[1], "office");
	assert_string_equal(argv[2], "0.5");
	assert_string_equal(argv[3], "60");
}

static void split_refuses(void **state)
{
	char ctl[] = "status\x1b[2J", many[] = "a b c d e f g h i", empty[] = " \t ", err[128];
	char *argv[PSD_CTL_MAX_WORDS];
	(void)state;
	assert_int_equal(psd_ctlsock_split(ctl, argv, err, sizeof err), -1);
	assert_string_equal(err, "control character 0x1b at byte 6");
	assert_int_equal(psd_ctlsock_split(many, argv, err, sizeof err), -1);
	assert_string_equal(err, "more than 8 words");
	assert_int_equal(psd_ctlsock_split(empty, argv, err, sizeof err), 0);
}

/* A reply grows to what it holds (200 kB, past any one buffer), is
 * replaced whole by a shorter one, and one of PSD_CTL_MAX_REPLY octets or
 * more becomes the error reply. */
static void reply_grows_to_its_limit(void **state)
{
	struct psd_ctl_reply r = { 0 };
	size_t n = 200000;
	char *big = malloc(PSD_CTL_MAX_REPLY + 1);
	(void)state;
	assert_non_null(big);
	memset(big, 'x', n);
	big[n] = '\0';
	assert_int_equal(psd_ctlsock_reply_set(&r, big), 0);
	assert_int_equal(strlen(r.text), n);
	assert_true(r.cap >= n + 1);
	assert_int_equal(psd_ctlsock_reply_set(&r, "{\"ok\":true}"), 0);
	assert_string_equal(r.text, "{\"ok\":true}");
	memset(big, 'x', PSD_CTL_MAX_REPLY - 1);
	big[PSD_CTL_MAX_REPLY - 1] = '\0';
	assert_int_equal(psd_ctlsock_reply_set(&r, big), 0);   /* the most: one octet short of the limit */
	assert_int_equal(strlen(r.text), PSD_CTL_MAX_REPLY - 1);
	big[PSD_CTL_MAX_REPLY - 1] = 'x';
	big[PSD_CTL_MAX_REPLY] = '\0';
	assert_int_equal(psd_ctlsock_reply_set(&r, big), -1);
	assert_string_equal(r.text, "{\"ok\":false,\"error\":\"reply too long\"}");
	psd_ctlsock_reply_free(&r);
	assert_null(r.text);
	free(big);
}

static void simulated_clock_jumps(void **state)
{
	struct psd_clock c;
	(void)state;
	psd_clock_simulated(&c, 6 * 3600.0);
	assert_true(psd_clock_now(&c) == 21600.0);
	assert_int_equal(psd_clock_wait_ms(&c, 1e9, 1000), 0);   /* never waits */
	psd_clock_advance(&c, 21660.0);
	assert_true(psd_clock_now(&c) == 21660.0);
	psd_clock_advance(&c, 100.0);                            /* never back */
	psd_clock_advance(&c, INFINITY);                         /* nor to infinity */
	assert_true(psd_clock_now(&c) == 21660.0);
}

static void real_clock_speed(void **state)
{
	struct psd_clock c;
	struct timespec pause = { 0, 20 * 1000 * 1000 };
	double t0, t1;
	(void)state;
	psd_clock_real(&c, 1000.0, 100.0);
	t0 = psd_clock_now(&c);
	nanosleep(&pause, NULL);
	t1 = psd_clock_now(&c);
	/* 20 ms of wall time at 100x is at least 2 clock seconds */
	assert_true(t0 >= 1000.0 && t0 < 1001.0);
	assert_true(t1 - t0 >= 2.0);
	/* a deadline 10 clock seconds ahead is 100 ms of wall time, capped by max */
	assert_in_range(psd_clock_wait_ms(&c, psd_clock_now(&c) + 10.0, 100000), 95, 100);
	assert_int_equal(psd_clock_wait_ms(&c, psd_clock_now(&c) + 10.0, 30), 30);
	assert_int_equal(psd_clock_wait_ms(&c, psd_clock_now(&c) - 1.0, 30), 0);
	assert_int_equal(psd_clock_wait_ms(&c, INFINITY, 250), 250);
	psd_clock_advance(&c, 1e9);   /* real time is not moved by hand */
	assert_true(psd_clock_now(&c) < 2000.0);
}

/* Dates: a date's local midnight, stamps and durations, in a
 * fixed zone with daylight saving time (TZ set here, for this process). */
static void dates_and_stamps(void **state)
{
	double e, e2;
	char out[32];
	(void)state;
	setenv("TZ", "CET-1CEST,M3.5.0,M10.5.0/3", 1);   /* POSIX rule: no tzdata needed */
	tzset();
	assert_int_equal(psd_clock_midnight(2026, 3, 18, &e), 0);
	assert_true(e == 1773788400.0);   /* 2026-03-17 23:00 UTC: CET is UTC+1 */
	assert_int_equal(psd_clock_parse_date("2026-03-18", &e2), 0);
	assert_true(e2 == e);
	assert_int_equal(psd_clock_parse_date("2026-02-30", &e2), -1);
	assert_int_equal(psd_clock_parse_date("03-18", &e2), -1);
	assert_int_equal(psd_clock_parse_date("2026-03-18x", &e2), -1);
	psd_clock_stamp(e, 21 * 3600.0 + 5 * 60, out, sizeof out);
	assert_string_equal(out, "2026-03-18 21:05");
	/* 28 hours on: the next day, not 01:00 of the same one */
	psd_clock_stamp(e, 28 * 3600.0 + 58 * 60, out, sizeof out);
	assert_string_equal(out, "2026-03-19 04:58");
	psd_clock_stamp(NAN, 6 * 3600.0, out, sizeof out);
	assert_string_equal(out, "06:00");
	/* the night of the change to summer time is 23 hours long */
	assert_int_equal(psd_clock_midnight(2026, 3, 29, &e), 0);
	assert_int_equal(psd_clock_midnight(2026, 3, 30, &e2), 0);
	assert_true(e2 - e == 23 * 3600.0);
	psd_clock_duration(3 * 3600.0 + 58 * 60, out, sizeof out);
	assert_string_equal(out, "3 h 58 min");
	psd_clock_duration(12 * 60, out, sizeof out);
	assert_string_equal(out, "12 min");
	psd_clock_duration(45, out, sizeof out);
	assert_string_equal(out, "45 s");
	unsetenv("TZ");
	tzset();
}

/* Local minus standard time: the hour of summer time from the zone's own
 * rule (CEST from the last Sunday of March, 01:00 UTC, to the last Sunday
 * of October, 01:00 UTC), none in winter, in a zone without summer time or
 * without a date. */
static void summer_time_shift(void **state)
{
	double e;
	(void)state;
	setenv("TZ", "CET-1CEST,M3.5.0,M10.5.0/3", 1);
	tzset();
	assert_true(psd_clock_dst_shift(1782475200.0) == 3600);   /* 2026-06-26 12:00 UTC */
	assert_true(psd_clock_dst_shift(1768478400.0) == 0);      /* 2026-01-15 12:00 UTC */
	assert_true(psd_clock_dst_shift(1774745999.0) == 0);      /* 2026-03-29 00:59:59 UTC */
	assert_true(psd_clock_dst_shift(1774746000.0) == 3600);   /* 01:00 UTC: summer time */
	assert_true(psd_clock_dst_shift(NAN) == 0);
	assert_int_equal(psd_clock_midnight(2026, 6, 26, &e), 0);
	assert_true(psd_clock_dst_shift_day("06-26", e) == 3600);
	assert_true(psd_clock_dst_shift_day("12-01", NAN) == 0);   /* this year's 1 December */
	assert_true(psd_clock_dst_shift_day("07-01", NAN) == 3600);
	assert_true(psd_clock_dst_shift_day("nonsense", NAN) == 0);
	setenv("TZ", "JST-9", 1);   /* no summer time */
	tzset();
	assert_true(psd_clock_dst_shift(1782475200.0) == 0);
	setenv("TZ", "PST8PDT,M3.2.0,M11.1.0", 1);   /* standard 8 h west: the shift is still an hour */
	tzset();
	assert_true(psd_clock_dst_shift(1782475200.0) == 3600);
	unsetenv("TZ");
	tzset();
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(split_words),
		cmocka_unit_test(split_refuses),
		cmocka_unit_test(reply_grows_to_its_limit),
		cmocka_unit_test(simulated_clock_jumps),
		cmocka_unit_test(real_clock_speed),
		cmocka_unit_test(dates_and_stamps),
		cmocka_unit_test(summer_time_shift),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
