/* SPDX-License-Identifier: ISC */
/* An LD_PRELOAD fixture that hosts the emulated GPIO chip (vgpio.c) inside
 * an unmodified program, psensd in the system tests: line descriptors are
 * only valid in the process that made them (doc/emulation.md 3.2).
 *
 *   LD_PRELOAD=libumockdev-preload.so.0:libvgpio_fixture.so
 *   VGPIO_TARGET=psensd     host the chip only in this program (LD_PRELOAD is inherited)
 *   VGPIO_LINES=16          lines on gpiochip0
 *   VGPIO_INIT=6=1,7=0      initial input levels
 *   VGPIO_CTL=FIFO          commands, one a line:
 *        set L V | press L PRESSED BOUNCES HOLD_MS | rate L HZ |
 *        tsl230 L HZ S2 S3 (a TSL230R: HZ at /1, divided as its pins say) | dump
 *   VGPIO_STATE=FILE        vgpio_dump() written there (atomically) after each
 *                           command and every 50 ms while anything changes */
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <glib.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "vgpio.h"

extern char *program_invocation_short_name;
static struct vgpio *chip;

/* Every thread of the process starts with every signal blocked.  The
 * emulator's threads are not only the ones made in fixture_init: umockdev
 * and GLib start more later (a client connecting when the program reopens
 * the chip), from whatever thread, and one that took a SIGHUP meant for
 * the program's signalfd would die of it (420's reload test, about one
 * run in three).  The program's own threads lose nothing: a daemon blocks
 * its signals in every thread and reads them in one. */
int pthread_create(pthread_t *th, const pthread_attr_t *attr, void *(*fn)(void *), void *arg)
{
	static int (*real)(pthread_t *, const pthread_attr_t *, void *(*)(void *), void *);
	sigset_t all, old;
	int rc;
	if (!real) {
		void *sym = dlsym(RTLD_NEXT, "pthread_create");
		memcpy(&real, &sym, sizeof real);
	}
	if (!real)
		return EAGAIN;
	sigfillset(&all);
	pthread_sigmask(SIG_BLOCK, &all, &old);
	rc = real(th, attr, fn, arg);
	pthread_sigmask(SIG_SETMASK, &old, NULL);
	return rc;
}
static int stopping;
static GThread *state_thread;

static void write_state(void)
{
	const char *path = getenv("VGPIO_STATE");
	char buf[8192], tmp[4200];
	FILE *fp;
	if (!path || !chip)
		return;
	vgpio_dump(chip, buf, sizeof buf);
	snprintf(tmp, sizeof tmp, "%s.tmp", path);
	/* the real path: the preload redirects only /dev, /sys and /proc */
	if (!(fp = fopen(tmp, "w")))
		return;
	fputs(buf, fp);
	fclose(fp);
	rename(tmp, path);
}

static gpointer control(gpointer path)
{
	/* O_RDWR: a read-only open of a FIFO blocks inside the preload's open()
	 * while it holds umockdev's path lock (doc/emulation.md pitfall 5) */
	int fd = open(path, O_RDWR | O_CLOEXEC);
	FILE *f = fd >= 0 ? fdopen(fd, "r") : NULL;
	char line[160];
	g_free(path);
	if (!f)
		return NULL;
	while (fgets(line, sizeof line, f)) {
		unsigned l, v, b, ms;
		double hz;
		if (sscanf(line, "set %u %u", &l, &v) == 2)
			vgpio_set(chip, l, (int)v);
		else if (sscanf(line, "press %u %u %u %u", &l, &v, &b, &ms) == 4)
			vgpio_press(chip, l, (int)v, (int)b, (int)ms);
		else if (sscanf(line, "tsl230 %u %lf %u %u", &l, &hz, &b, &ms) == 4)
			vgpio_tsl230(chip, l, hz, b, ms);
		else if (sscanf(line, "rate %u %lf", &l, &hz) == 2)
			vgpio_rate(chip, l, hz);
		write_state();
	}
	return NULL;
}

static gpointer state_loop(gpointer unused)
{
	struct timespec t = { 0, 50 * 1000 * 1000 };
	(void)unused;
	while (!__atomic_load_n(&stopping, __ATOMIC_ACQUIRE)) {
		write_state();
		nanosleep(&t, NULL);
	}
	return NULL;
}

static void fixture_start(const char *ctl, const char *init, const char *lines);

__attribute__((constructor)) static void fixture_init(void)
{
	const char *target = getenv("VGPIO_TARGET"), *ctl = getenv("VGPIO_CTL"), *init = getenv("VGPIO_INIT");
	const char *lines = getenv("VGPIO_LINES");
	sigset_t all, old;
	if (target && strcmp(target, program_invocation_short_name) != 0)
		return;
	/* the emulator's threads (umockdev's worker, ours) take no signals: the
	 * program under test blocks its own only later, in main, and a SIGTERM
	 * delivered to one of these would kill it before its handler runs */
	sigfillset(&all);
	pthread_sigmask(SIG_BLOCK, &all, &old);
	fixture_start(ctl, init, lines);
	/* ... and the program's main thread keeps the signals it reads from
	 * its signalfd (HUP, INT, TERM) blocked from here on, not only from
	 * its own sigprocmask in main.  umockdev 0.17 (Debian 12) keeps the
	 * mask it saves around every trapped call (open, fopen, rename,
	 * statfs, ...) in one global, before taking its lock: two threads in
	 * trapped calls at once can each leave with the other's mask
	 * (umockdev#252 upstream, fixed in July 2024).  Our state
	 * thread writes a file every 50 ms; if the main thread was in a
	 * trapped call with its start-up mask, empty, the state thread could
	 * leave with that empty mask and later take the test's SIGHUP and die
	 * of it (420: exit 129 at the reload, 2 runs in 8).  With these three
	 * blocked in every thread from the start, any mask a thread is left
	 * with still blocks them. */
	sigaddset(&old, SIGHUP);
	sigaddset(&old, SIGINT);
	sigaddset(&old, SIGTERM);
	pthread_sigmask(SIG_SETMASK, &old, NULL);
}

static void fixture_start(const char *ctl, const char *init, const char *lines)
{
	if (!(chip = vgpio_new("gpiochip0", lines ? (unsigned)atoi(lines) : 16)))
		return;
	if (init) {
		char **kv = g_strsplit(init, ",", -1);
		for (char **p = kv; *p; p++) {
			unsigned l, v;
			if (sscanf(*p, "%u=%u", &l, &v) == 2)
				vgpio_set(chip, l, (int)v);
		}
		g_strfreev(kv);
	}
	if (ctl) {
		mkfifo(ctl, 0600);
		g_thread_unref(g_thread_new("vgpio-ctl", control, g_strdup(ctl)));
	}
	if (getenv("VGPIO_STATE"))
		state_thread = g_thread_new("vgpio-state", state_loop, NULL);
}

__attribute__((destructor)) static void fixture_fini(void)
{
	__atomic_store_n(&stopping, 1, __ATOMIC_RELEASE);
	if (state_thread)
		g_thread_join(state_thread);
	write_state();
	vgpio_free(chip);
	chip = NULL;
}
