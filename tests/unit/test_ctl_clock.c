/* SPDX-License-Identifier: ISC */
/* The control protocol's word splitter and the daemon's clock. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
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
	assert_int_equal(psd_ctl_split(line, argv, err, sizeof err), 4);
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
	assert_int_equal(psd_ctl_split(ctl, argv, err, sizeof err), -1);
	assert_string_equal(err, "control character 0x1b at byte 6");
	assert_int_equal(psd_ctl_split(many, argv, err, sizeof err), -1);
	assert_string_equal(err, "more than 8 words");
	assert_int_equal(psd_ctl_split(empty, argv, err, sizeof err), 0);
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

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(split_words),
		cmocka_unit_test(split_refuses),
		cmocka_unit_test(simulated_clock_jumps),
		cmocka_unit_test(real_clock_speed),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
