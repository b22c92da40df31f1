/* SPDX-License-Identifier: ISC */
/* The front ends' table (daemon/frontend.c), on rows of its own: every row
 * the configuration wants starts in the table's order; at a failed start
 * the rows after it never start and every one started before it is stopped
 * by psd_frontend_stop, in the reverse order, once; each running front end's
 * descriptors land in the poll set one after another, the soonest turn one
 * wants sets the timeout, and the service after poll() gives each its own
 * descriptors back (NULL when it has none); a reload reaches every row, a
 * stopped one with no state; status only the running ones. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "errbuf.h"
#include "frontend.h"

/* One fake front end: what it does, and what was done to it. */
struct fake {
	char name;
	int wanted, fails, nfd, wait;   /* wait: its wait_ms, -1 none */
	const struct pollfd *got;       /* service: the descriptors it was given */
	int got_n, serviced, reloaded_running, status;
};

static struct fake fakes[5];
static char calls[256];   /* "+A" a start, "-A" a stop, in order */

static void called(char sign, const struct fake *f)
{
	size_t n = strlen(calls);
	snprintf(calls + n, sizeof calls - n, "%c%c", sign, f->name);
}

static void *begin(struct fake *f, char *err, size_t errlen)
{
	called('+', f);
	if (f->fails) {
		psd_errbuf(err, errlen, "%c cannot start", f->name);
		return NULL;
	}
	return f;
}

static int pollfds(void *fe, struct pollfd *fds, int max)
{
	struct fake *f = fe;
	for (int i = 0; i < f->nfd && i < max; i++)
		fds[i] = (struct pollfd){ .fd = 100 * (f->name - 'A' + 1) + i, .events = POLLIN };
	return f->nfd < max ? f->nfd : max;
}

static int wait_ms(const void *fe)
{
	return ((const struct fake *)fe)->wait;
}

static void service(void *fe, const struct pollfd *fds, int n, double now)
{
	struct fake *f = fe;
	(void)now;
	f->got = fds;
	f->got_n = n;
	f->serviced++;
}

static void reload(void *fe, const struct psd_config *cf)
{
	(void)cf;
	if (fe)
		((struct fake *)fe)->reloaded_running++;
}

static void status(const void *fe, struct json_object *o)
{
	(void)o;
	((struct fake *)(uintptr_t)fe)->status++;
}

static void stop(void *fe)
{
	called('-', fe);
}

/* The rows differ only in their fake; a row its fake does not want is one
 * the configuration leaves out. */
#define ROW(i)                                                                            \
	static int wanted_##i(const struct psd_config *cf)                                \
	{                                                                                 \
		(void)cf;                                                                 \
		return fakes[i].wanted;                                                   \
	}                                                                                 \
	static void *start_##i(const struct psd_frontend_env *env, char *err, size_t n)   \
	{                                                                                 \
		(void)env;                                                                \
		return begin(&fakes[i], err, n);                                          \
	}                                                                                 \
	static const struct psd_frontend row_##i = { .name = "fake",                      \
		                                     .refused = "a fake cannot start",    \
		                                     .wanted = wanted_##i,                \
		                                     .start = start_##i,                  \
		                                     .pollfds = pollfds,                  \
		                                     .wait_ms = wait_ms,                  \
		                                     .service = service,                  \
		                                     .reload = reload,                    \
		                                     .status = status,                    \
		                                     .stop = stop };
ROW(0)
ROW(1)
ROW(2)
ROW(3)
ROW(4)

static const struct psd_frontend *const rows[] = { &row_0, &row_1, &row_2, &row_3, &row_4, NULL };

static int setup(void **state)
{
	(void)state;
	memset(fakes, 0, sizeof fakes);
	for (int i = 0; i < 5; i++)
		fakes[i] = (struct fake){ .name = (char)('A' + i), .wanted = 1, .wait = -1 };
	calls[0] = 0;
	return 0;
}

static void failed_start_stops_every_started_one_in_reverse(void **state)
{
	struct psd_frontend_set s = { .rows = rows };
	const struct psd_frontend_env env = { 0 };
	const struct psd_frontend *failed = NULL;
	char err[64] = "";
	(void)state;
	fakes[1].wanted = 0;   /* B not configured */
	fakes[3].fails = 1;    /* D cannot start: E never starts */
	assert_int_equal(psd_frontend_start(&s, &env, &failed, err, sizeof err), -1);
	assert_ptr_equal(failed, &row_3);
	assert_string_equal(err, "D cannot start");
	assert_string_equal(calls, "+A+C+D");
	psd_frontend_stop(&s);
	assert_string_equal(calls, "+A+C+D-C-A");
	psd_frontend_stop(&s);   /* a second stop finds none running */
	assert_string_equal(calls, "+A+C+D-C-A");
	for (int i = 0; i < 5; i++)
		assert_null(s.fe[i]);
}

static void the_poll_set_and_the_service(void **state)
{
	struct psd_frontend_set s = { .rows = rows };
	const struct psd_frontend_env env = { 0 };
	const struct psd_frontend *failed = NULL;
	struct pollfd fds[8];
	char err[64];
	int timeout = 1000;
	(void)state;
	fakes[0] = (struct fake){ .name = 'A', .wanted = 1, .nfd = 2, .wait = 50 };
	fakes[1] = (struct fake){ .name = 'B', .wanted = 1, .nfd = 0, .wait = 7 };
	fakes[2] = (struct fake){ .name = 'C', .wanted = 0, .nfd = 1, .wait = 1 };   /* not running */
	fakes[3] = (struct fake){ .name = 'D', .wanted = 1, .nfd = 1, .wait = -1 };
	fakes[4] = (struct fake){ .name = 'E', .wanted = 1, .nfd = 3, .wait = -1 };
	assert_int_equal(psd_frontend_start(&s, &env, &failed, err, sizeof err), 0);
	/* 7 slots left: A's 2, D's 1, and E's 3 of them */
	assert_int_equal(psd_frontend_pollfds(&s, fds, 7, &timeout), 6);
	assert_int_equal(timeout, 7);   /* B's, the soonest of the running ones */
	assert_int_equal(fds[0].fd, 100);
	assert_int_equal(fds[1].fd, 101);
	assert_int_equal(fds[2].fd, 400);
	assert_int_equal(fds[3].fd, 500);
	assert_int_equal(fds[5].fd, 502);
	fds[2].revents = POLLIN;
	psd_frontend_service(&s, fds, 0);
	assert_ptr_equal(fakes[0].got, fds);
	assert_int_equal(fakes[0].got_n, 2);
	assert_null(fakes[1].got);   /* no descriptor: a turn of its own */
	assert_int_equal(fakes[1].serviced, 1);
	assert_int_equal(fakes[2].serviced, 0);
	assert_ptr_equal(fakes[3].got, fds + 2);
	assert_int_equal(fakes[3].got->revents, POLLIN);
	assert_ptr_equal(fakes[4].got, fds + 3);
	assert_int_equal(fakes[4].got_n, 3);
	timeout = -1;   /* infinite: lowered all the same */
	psd_frontend_pollfds(&s, fds, 8, &timeout);
	assert_int_equal(timeout, 7);
	timeout = 3;   /* sooner than any: kept */
	psd_frontend_pollfds(&s, fds, 8, &timeout);
	assert_int_equal(timeout, 3);
	psd_frontend_stop(&s);
	assert_string_equal(calls, "+A+B+D+E-E-D-B-A");
}

static void reload_and_status(void **state)
{
	struct psd_frontend_set s = { .rows = rows };
	const struct psd_frontend_env env = { 0 };
	const struct psd_frontend *failed = NULL;
	char err[64];
	(void)state;
	fakes[2].wanted = 0;
	assert_int_equal(psd_frontend_start(&s, &env, &failed, err, sizeof err), 0);
	psd_frontend_reload(&s, NULL);
	psd_frontend_status(&s, NULL);
	for (int i = 0; i < 5; i++) {
		assert_int_equal(fakes[i].reloaded_running, i != 2);
		assert_int_equal(fakes[i].status, i != 2);
	}
	psd_frontend_stop(&s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test_setup(failed_start_stops_every_started_one_in_reverse, setup),
		cmocka_unit_test_setup(the_poll_set_and_the_service, setup),
		cmocka_unit_test_setup(reload_and_status, setup),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
