/* SPDX-License-Identifier: ISC */
/* The sample log's writer thread (daemon/dbwriter.c) against real SQLite
 * locks (python3's sqlite3 in a child): samples queued while another
 * process holds the write lock are held, the cause names that process,
 * and they are all written, in order, once it lets go; past the bound the
 * oldest are dropped and counted in the record; a waiting writer (a
 * simulated clock) loses nothing while the database works and drops
 * (counted) rather than hang while it fails; events and MQTT cursors are
 * written in order with the samples; a writer killed while it holds
 * samples leaves their count in a state file beside the database, which
 * the next writer records as a "log gap" (keeping the file until it can). */
#include <math.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <sqlite3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include <cmocka.h>

#include "db.h"
#include "dbwriter.h"

static char path[64];
static struct psd_db *owner;   /* the daemon's own connection: the schema, the lock file */

static void unlink_all(void)
{
	char f[96];
	const char *ext[] = { "", "-wal", "-shm", ".lock", ".held" };
	for (size_t i = 0; i < 5; i++) {
		snprintf(f, sizeof f, "%s%s", path, ext[i]);
		unlink(f);
	}
}

static int setup(void **state)
{
	char err[256];
	int fd;
	(void)state;
	snprintf(path, sizeof path, "/tmp/test_dbwriter.XXXXXX");
	if ((fd = mkstemp(path)) < 0)
		return -1;
	close(fd);
	unlink(path);
	owner = psd_db_open(path, err, sizeof err);
	return owner ? 0 : -1;
}

static int teardown(void **state)
{
	(void)state;
	psd_db_close(owner);
	unlink_all();
	return 0;
}

static long long scalar(const char *sql)
{
	sqlite3 *h;
	sqlite3_stmt *st;
	long long v = -1;
	assert_int_equal(sqlite3_open_v2(path, &h, SQLITE_OPEN_READONLY, NULL), SQLITE_OK);
	assert_int_equal(sqlite3_prepare_v2(h, sql, -1, &st, NULL), SQLITE_OK);
	if (sqlite3_step(st) == SQLITE_ROW)
		v = sqlite3_column_int64(st, 0);
	sqlite3_finalize(st);
	sqlite3_close(h);
	return v;
}

static void add(struct psd_dbwriter *w, int i)
{
	struct psd_sample s = { (double)i, (double)i, 1.5, 0.5, 300, NAN, 0.1, 200, "daylight_mean", 2.0, NULL, "office",
	                        1.7e9 + i, NULL, -1, NAN };
	psd_dbwriter_sample(w, &s);
}

static void sleep_ms(int ms)
{
	struct timespec ts = { ms / 1000, (long)(ms % 1000) * 1000000L };
	nanosleep(&ts, NULL);
}

/* Another process (python3's sqlite3) holding BEGIN IMMEDIATE until it is
 * told to stop (a byte on its stdin); returns its pid once the lock is
 * taken. */
static pid_t hold_lock(int *stop_fd)
{
	static const char script[] = "import sqlite3, sys\n"
	                             "c = sqlite3.connect(sys.argv[1], isolation_level=None)\n"
	                             "c.execute('BEGIN IMMEDIATE')\n"
	                             "sys.stdout.write('r'); sys.stdout.flush()\n"
	                             "sys.stdin.read(1)\n"
	                             "c.execute('COMMIT')\n";
	int ready[2], stop[2];
	char c;
	pid_t pid;
	assert_int_equal(pipe(ready), 0);
	assert_int_equal(pipe(stop), 0);
	pid = fork();
	assert_true(pid >= 0);
	if (pid == 0) {
		dup2(stop[0], 0);
		dup2(ready[1], 1);
		close(ready[0]);
		close(stop[1]);
		execl("/usr/bin/python3", "python3", "-c", script, path, (char *)NULL);
		_exit(127);
	}
	close(ready[1]);
	close(stop[0]);
	if (read(ready[0], &c, 1) != 1)
		skip();   /* no python3: the lock cannot be held */
	close(ready[0]);
	*stop_fd = stop[1];
	return pid;
}

static void release_lock(pid_t pid, int stop_fd)
{
	int status;
	assert_int_equal(write(stop_fd, "s", 1), 1);
	close(stop_fd);
	assert_int_equal(waitpid(pid, &status, 0), pid);
	assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 0);
}

/* Wait up to 5 s for the writer to report the fault. */
static void wait_degraded(struct psd_dbwriter *w, struct psd_dbwriter_stats *st)
{
	for (int i = 0; i < 500; i++) {
		psd_dbwriter_stats(w, st);
		if (st->degraded)
			return;
		sleep_ms(10);
	}
	fail_msg("the writer did not report the lock");
}

static void all_written(void **state)
{
	char err[256];
	struct psd_dbwriter *w = psd_dbwriter_open(path, 0, 0, err, sizeof err);
	(void)state;
	assert_non_null(w);
	for (int i = 0; i < 1000; i++)
		add(w, i);
	assert_int_equal(psd_dbwriter_sync(w, 10), 0);
	assert_int_equal(psd_dbwriter_committed(w), 1000);
	psd_dbwriter_close(w, 1);
	assert_int_equal(scalar("SELECT count(*) FROM samples"), 1000);
	/* in order: rowid order is t order */
	assert_int_equal(scalar("SELECT count(*) FROM samples a JOIN samples b ON b.rowid = a.rowid + 1 WHERE b.t <> a.t + 1"),
	                 0);
	assert_int_equal(scalar("SELECT max(t) FROM samples"), 999);
}

static void lock_held_then_released(void **state)
{
	char err[256];
	struct psd_dbwriter *w = psd_dbwriter_open(path, 0, 0, err, sizeof err);
	struct psd_dbwriter_stats st;
	char want[64];
	int stop;
	pid_t pid;
	(void)state;
	assert_non_null(w);
	add(w, 0);
	assert_int_equal(psd_dbwriter_sync(w, 10), 0);
	pid = hold_lock(&stop);
	for (int i = 1; i <= 100; i++)
		add(w, i);
	wait_degraded(w, &st);
	snprintf(want, sizeof want, "locked by pid %ld", (long)pid);
	assert_non_null(strstr(st.cause, want));
	assert_int_equal(st.held, 100);
	assert_int_equal(st.dropped, 0);
	assert_int_equal(psd_dbwriter_committed(w), 1);
	assert_int_equal(scalar("SELECT count(*) FROM samples"), 1);
	release_lock(pid, stop);
	/* the back-off is at most 5 s */
	assert_int_equal(psd_dbwriter_sync(w, 10), 0);
	psd_dbwriter_stats(w, &st);
	assert_int_equal(st.degraded, 0);
	assert_int_equal(st.held, 0);
	assert_true(st.errors >= 1);
	assert_int_equal(psd_dbwriter_committed(w), 101);
	psd_dbwriter_close(w, 1);
	assert_int_equal(scalar("SELECT count(*) FROM samples"), 101);
	assert_int_equal(scalar("SELECT count(*) FROM events WHERE kind = 'log gap'"), 0);
}

/* The state file's count, 0 when there is none. */
static unsigned long held_in(const char *file)
{
	unsigned long c = 0;
	FILE *f = fopen(file, "r");
	if (f) {
		if (fscanf(f, "held %lu", &c) != 1)
			c = 0;
		fclose(f);
	}
	return c;
}

static void slurp(const char *file, char *buf, size_t n)
{
	FILE *f = fopen(file, "r");
	size_t got;
	assert_non_null(f);
	got = fread(buf, 1, n - 1, f);
	buf[got] = 0;
	fclose(f);
}

/* A writer killed holding 50 samples (a child that ends without closing
 * it, as SIGKILL would): the state file says 50, the oldest's clock time
 * and UTC, the newest's UTC and the child's pid.  A writer opened while
 * the lock is still held cannot record it and keeps the file (a clean
 * close too); once the lock goes the next one records a "log gap" with
 * the count and the file goes.  A malformed file is removed, nothing
 * recorded. */
static void killed_holding(void **state)
{
	char err[256], held[96], want[160], got[256], like[320];
	struct psd_dbwriter *w;
	int stop, status;
	pid_t pid, child;
	(void)state;
	snprintf(held, sizeof held, "%s.held", path);
	pid = hold_lock(&stop);
	child = fork();
	assert_true(child >= 0);
	if (child == 0) {
		if (!(w = psd_dbwriter_open(path, 0, 0, err, sizeof err)))
			_exit(2);
		for (int i = 1; i <= 50; i++)
			add(w, i);
		for (int i = 0; i < 500 && held_in(held) != 50; i++)
			sleep_ms(10);
		_exit(held_in(held) == 50 ? 0 : 3);
	}
	assert_int_equal(waitpid(child, &status, 0), child);
	assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 0);
	snprintf(want, sizeof want, "held 50\nclock 1.000\nutc 1700000001.000\nlast_utc 1700000050.000\npid %ld\n",
	         (long)child);
	slurp(held, got, sizeof got);
	assert_string_equal(got, want);

	/* still locked: the loss cannot be recorded, the file stays */
	w = psd_dbwriter_open(path, 0, 0, err, sizeof err);
	assert_non_null(w);
	assert_int_equal(psd_dbwriter_sync(w, 0.5), -1);
	psd_dbwriter_close(w, 0.2);
	slurp(held, got, sizeof got);
	assert_string_equal(got, want);

	release_lock(pid, stop);
	w = psd_dbwriter_open(path, 0, 0, err, sizeof err);
	assert_non_null(w);
	assert_int_equal(psd_dbwriter_sync(w, 10), 0);
	assert_int_equal(access(held, F_OK), -1);
	psd_dbwriter_close(w, 1);
	snprintf(like, sizeof like, "SELECT count(*) FROM events WHERE kind = 'log gap' AND text LIKE "
	         "'50 samples lost: psensd (pid %ld) %%2023-11-14 22:13:21 UTC to 2023-11-14 22:14:10 UTC'", (long)child);
	assert_int_equal(scalar(like), 1);
	assert_int_equal(scalar("SELECT count(*) FROM samples"), 0);

	/* malformed: removed, nothing recorded */
	{
		FILE *f = fopen(held, "w");
		assert_non_null(f);
		fputs("held 12\nclock x\n", f);
		fclose(f);
	}
	w = psd_dbwriter_open(path, 0, 0, err, sizeof err);
	assert_non_null(w);
	assert_int_equal(psd_dbwriter_sync(w, 10), 0);
	psd_dbwriter_close(w, 1);
	assert_int_equal(access(held, F_OK), -1);
	assert_int_equal(scalar("SELECT count(*) FROM events WHERE kind = 'log gap'"), 1);
}

static void past_the_bound(void **state)
{
	char err[256];
	struct psd_dbwriter *w = psd_dbwriter_open(path, 16, 0, err, sizeof err);
	struct psd_dbwriter_stats st;
	int stop;
	pid_t pid;
	(void)state;
	assert_non_null(w);
	pid = hold_lock(&stop);
	add(w, 0);
	wait_degraded(w, &st);
	for (int i = 1; i < 40; i++)
		add(w, i);
	psd_dbwriter_stats(w, &st);
	assert_int_equal(st.held, 16);
	assert_int_equal(st.dropped, 24);
	release_lock(pid, stop);
	assert_int_equal(psd_dbwriter_sync(w, 10), 0);
	psd_dbwriter_close(w, 1);
	/* the newest 16 are kept, the gap is in the record */
	assert_int_equal(scalar("SELECT count(*) FROM samples"), 16);
	assert_int_equal(scalar("SELECT min(t) FROM samples"), 24);
	assert_int_equal(scalar("SELECT max(t) FROM samples"), 39);
	assert_int_equal(scalar("SELECT count(*) FROM events WHERE kind = 'log gap' AND text LIKE '24 samples dropped%'"),
	                 1);
}

static void waiting_loses_nothing(void **state)
{
	char err[256];
	struct psd_dbwriter *w = psd_dbwriter_open(path, 16, 1, err, sizeof err);
	struct psd_dbwriter_stats st;
	(void)state;
	assert_non_null(w);
	for (int i = 0; i < 2000; i++)
		add(w, i);
	assert_int_equal(psd_dbwriter_sync(w, 30), 0);
	psd_dbwriter_stats(w, &st);
	assert_int_equal(st.dropped, 0);
	psd_dbwriter_close(w, 1);
	assert_int_equal(scalar("SELECT count(*) FROM samples"), 2000);
}

/* A waiting writer on a failing database drops and counts: a simulated
 * day on a locked or corrupt file never hangs. */
static void waiting_drops_when_failing(void **state)
{
	char err[256];
	struct psd_dbwriter *w = psd_dbwriter_open(path, 16, 1, err, sizeof err);
	struct psd_dbwriter_stats st;
	int stop;
	pid_t pid;
	(void)state;
	assert_non_null(w);
	pid = hold_lock(&stop);
	add(w, 0);
	wait_degraded(w, &st);
	for (int i = 1; i < 40; i++)
		add(w, i);
	psd_dbwriter_stats(w, &st);
	assert_int_equal(st.held, 16);
	assert_int_equal(st.dropped, 24);
	release_lock(pid, stop);
	assert_int_equal(psd_dbwriter_sync(w, 10), 0);
	psd_dbwriter_close(w, 1);
	assert_int_equal(scalar("SELECT count(*) FROM samples"), 16);
}

static void events_in_order_with_samples(void **state)
{
	char err[256];
	struct psd_dbwriter *w = psd_dbwriter_open(path, 0, 0, err, sizeof err);
	(void)state;
	assert_non_null(w);
	psd_dbwriter_set_epoch(w, 1.7e9);
	add(w, 1);
	psd_dbwriter_event(w, 2, "office", "fault", "sensor reads 12 V");
	psd_dbwriter_event(w, 3, NULL, "start", NULL);
	psd_dbwriter_cursor(w, "site1", 1);
	psd_dbwriter_cursor(w, "site1", 9007199254740991LL);   /* 2^53 - 1: exact */
	psd_dbwriter_close(w, 5);
	assert_int_equal(scalar("SELECT sample FROM mqtt_cursor WHERE site = 'site1'"), 9007199254740991LL);
	assert_int_equal(scalar("SELECT count(*) FROM events WHERE kind = 'fault' AND zone = 'office' AND"
	                        " text = 'sensor reads 12 V' AND utc = 1700000002"), 1);
	assert_int_equal(scalar("SELECT count(*) FROM events WHERE kind = 'start' AND zone IS NULL AND text IS NULL"), 1);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test_setup_teardown(all_written, setup, teardown),
		cmocka_unit_test_setup_teardown(lock_held_then_released, setup, teardown),
		cmocka_unit_test_setup_teardown(killed_holding, setup, teardown),
		cmocka_unit_test_setup_teardown(past_the_bound, setup, teardown),
		cmocka_unit_test_setup_teardown(waiting_loses_nothing, setup, teardown),
		cmocka_unit_test_setup_teardown(waiting_drops_when_failing, setup, teardown),
		cmocka_unit_test_setup_teardown(events_in_order_with_samples, setup, teardown),
	};
	signal(SIGPIPE, SIG_IGN);
	return cmocka_run_group_tests(tests, NULL, NULL);
}
