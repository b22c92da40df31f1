/* SPDX-License-Identifier: ISC */
/* psemu-run: host emulated DALI USB interfaces in this process and run a
 * program as a child, whose real libusb reaches them through umockdev
 * (doc/emulation.md 2.4).  Run with libumockdev-preload.so.0 preloaded:
 *
 *   LD_PRELOAD=libumockdev-preload.so.0 psemu-run [-i PORT:SERIAL:N[:MODEL] [-b SPEC]...]...
 *       [-c FIFO] [-s STATEFILE] [-u FILE] [-t SECONDS] -- PROGRAM ARGS...
 *
 * -i adds an interface at USB port 1-PORT with N ballasts (default 1:A1:4),
 *    in slots 0..N-1 at short addresses 0..N-1; MODEL tridonic (the default,
 *    17b5:0020) or hasseb (the hasseb DALI Master, 04cc:0802).
 * -b sets up one ballast of the last interface:
 *      SLOT:short=A|none,random=0xR,draw=0xR,reply=MS,groups=0xG,phys=N,dead=N
 *    (any of the keys; draw: what its next RANDOMISE draws; reply: its
 *    settling time in ms; dead: it stops answering after N answers).
 * -u writes the testbed's UMOCKDEV_DIR to FILE, so that another program
 *    (run with the preload and that UMOCKDEV_DIR) reaches the same devices.
 * -c names a control FIFO, one command a line:
 *      unplug I | replug I | fault I none|noanswer|garbled|malformed|unplug|other|stale COUNT | dump
 *    (other: another master's frame on the bus before ours; stale: a report
 *    for the previous sequence number instead of ours)
 * -s: after each command and at the end, the ballasts' state is written there
 *     (psemu_dump lines), atomically.
 * -t: kill the child after this many seconds (default 60).
 * Exit status: the child's; 124 on the time limit; 77 without the preload. */
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include <glib.h>

#include "dali_emu.h"

static struct psemu *emu;
static const char *state_path;

static void write_state(void)
{
	char buf[16384], tmp[4200];
	FILE *fp;
	if (!state_path)
		return;
	psemu_dump(emu, buf, sizeof buf);
	snprintf(tmp, sizeof tmp, "%s.tmp", state_path);
	fp = fopen(tmp, "w");
	if (!fp)
		return;
	fputs(buf, fp);
	fclose(fp);
	rename(tmp, state_path);
}

static int fault_kind(const char *s)
{
	static const char *const names[] = { "none", "noanswer", "garbled", "malformed", "unplug", "other", "stale", NULL };
	for (int i = 0; names[i]; i++)
		if (strcmp(s, names[i]) == 0)
			return i;
	return -1;
}

static gpointer control(gpointer path)
{
	/* O_RDWR: a read-only open of a FIFO would block inside the preload
	 * while it holds umockdev's lock (doc/emulation.md pitfall 5) */
	int fd = open(path, O_RDWR | O_CLOEXEC);
	FILE *fp = fd >= 0 ? fdopen(fd, "r") : NULL;
	char line[256], err[256], kind[32];
	int i, n;
	if (!fp)
		return NULL;
	while (fgets(line, sizeof line, fp)) {
		if (sscanf(line, "unplug %d", &i) == 1) {
			if (psemu_unplug(emu, i) != 0)
				fprintf(stderr, "psemu-run: unplug %d: not plugged\n", i);
		} else if (sscanf(line, "replug %d", &i) == 1) {
			if (psemu_replug(emu, i, err, sizeof err) != 0)
				fprintf(stderr, "psemu-run: %s\n", err);
		} else if (sscanf(line, "fault %d %31s %d", &i, kind, &n) == 3 && fault_kind(kind) >= 0) {
			psemu_fault(emu, i, fault_kind(kind), n);
		} else if (strncmp(line, "dump", 4) != 0) {
			fprintf(stderr, "psemu-run: unknown command: %s", line);
		}
		write_state();
	}
	fclose(fp);
	return NULL;
}

/* -b SLOT:key=value,... on interface iface; 0 or -1 */
static int ballast_spec(int iface, const char *spec)
{
	char buf[256], *save = NULL;
	int slot, n = 0, short_addr = -2, dead = -2, phys = 0;
	unsigned random_addr = 0x1000000, draw = 0x1000000, groups = 0x10000;
	double reply = 0;
	struct psemu_ballast b;
	if (sscanf(spec, "%d:%n", &slot, &n) != 1 || psemu_ballast(emu, iface, slot, &b) != 0)
		return -1;
	snprintf(buf, sizeof buf, "%s", spec + n);
	for (char *kv = strtok_r(buf, ",", &save); kv; kv = strtok_r(NULL, ",", &save)) {
		char *eq = strchr(kv, '='), *end;
		unsigned long v;
		if (!eq)
			return -1;
		*eq++ = 0;
		if (strcmp(kv, "short") == 0 && strcmp(eq, "none") == 0) {
			short_addr = -1;
			continue;
		}
		if (strcmp(kv, "reply") == 0) {
			reply = strtod(eq, &end);
			if (*end)
				return -1;
			continue;
		}
		v = strtoul(eq, &end, 0);
		if (*end || end == eq)
			return -1;
		if (strcmp(kv, "short") == 0) short_addr = (int)v;
		else if (strcmp(kv, "random") == 0) random_addr = (unsigned)v;
		else if (strcmp(kv, "draw") == 0) draw = (unsigned)v;
		else if (strcmp(kv, "groups") == 0) groups = (unsigned)v;
		else if (strcmp(kv, "phys") == 0) phys = (int)v;
		else if (strcmp(kv, "dead") == 0) dead = (int)v;
		else return -1;
	}
	if (psemu_ballast_identity(emu, iface, slot, short_addr != -2 ? short_addr : b.short_addr,
	                           random_addr <= 0xFFFFFF ? random_addr : b.random, reply > 0 ? reply : b.reply_ms) != 0)
		return -1;
	if (draw <= 0xFFFFFF && psemu_ballast_randoms(emu, iface, slot, &draw, 1) != 0)
		return -1;
	if ((groups <= 0xFFFF || phys) &&
	    psemu_ballast_setup(emu, iface, slot, groups <= 0xFFFF ? groups : b.groups, phys ? phys : b.phys_min) != 0)
		return -1;
	if (dead != -2 && psemu_ballast_dead_after(emu, iface, slot, dead) != 0)
		return -1;
	return 0;
}

static double now_s(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + ts.tv_nsec / 1e9;
}

int main(int argc, char **argv)
{
	const char *ctl = NULL, *udir_file = NULL;
	char err[256], buf[16384];
	double limit = 60, end;
	int opt, nif = 0, status = 0, rc;
	pid_t pid;
	while ((opt = getopt(argc, argv, "i:b:c:s:u:t:")) != -1) {
		switch (opt) {
		case 'i': {
			int port, n, k = 0, model = PSEMU_TRIDONIC;
			char serial[64];
			if (!emu && !(emu = psemu_new(err, sizeof err))) {
				printf("psemu-run: %s\n", err);
				return 77;
			}
			err[0] = 0;
			if (sscanf(optarg, "%d:%63[^:]:%d%n", &port, serial, &n, &k) == 3 && strcmp(optarg + k, ":hasseb") == 0) {
				model = PSEMU_HASSEB;
				k = (int)strlen(optarg);
			} else if (sscanf(optarg, "%d:%63[^:]:%d%n", &port, serial, &n, &k) == 3 &&
			           strcmp(optarg + k, ":tridonic") == 0) {
				k = (int)strlen(optarg);
			}
			if (sscanf(optarg, "%d:%63[^:]:%d", &port, serial, &n) != 3 || optarg[k] ||
			    psemu_add_model(emu, model, port, serial, n, err, sizeof err) < 0) {
				fprintf(stderr, "psemu-run: -i %s: want PORT:SERIAL:N[:tridonic|:hasseb] (%s)\n", optarg, err);
				return 2;
			}
			nif++;
			break;
		}
		case 'b':
			if (!nif || ballast_spec(nif - 1, optarg) != 0) {
				fprintf(stderr, "psemu-run: -b %s: want SLOT:short=A|none,random=0xR,draw=0xR,reply=MS,"
				                "groups=0xG,phys=N,dead=N after an -i\n", optarg);
				return 2;
			}
			break;
		case 'c': ctl = optarg; break;
		case 'u': udir_file = optarg; break;
		case 's': state_path = optarg; break;
		case 't': limit = atof(optarg); break;
		default:
			fprintf(stderr, "usage: psemu-run [-i PORT:SERIAL:N[:MODEL] [-b SPEC]...]... [-c FIFO] [-s FILE] [-u FILE] [-t S] "
			                "-- PROG ARGS...\n");
			return 2;
		}
	}
	if (optind >= argc) {
		fprintf(stderr, "psemu-run: no program to run\n");
		return 2;
	}
	if (!emu && !(emu = psemu_new(err, sizeof err))) {
		printf("psemu-run: %s\n", err);
		return 77;
	}
	if (!nif && psemu_add(emu, 1, "A1", 4, err, sizeof err) < 0) {
		fprintf(stderr, "psemu-run: %s\n", err);
		return 1;
	}
	write_state();
	if (udir_file) {
		FILE *fp = fopen(udir_file, "w");
		const char *dir = getenv("UMOCKDEV_DIR");
		if (!fp || !dir || fprintf(fp, "%s\n", dir) < 0 || fclose(fp) != 0) {
			fprintf(stderr, "psemu-run: %s: cannot write the testbed's directory\n", udir_file);
			return 1;
		}
	}
	if (ctl) {
		if (mkfifo(ctl, 0600) != 0 && errno != EEXIST) {
			fprintf(stderr, "psemu-run: %s: %s\n", ctl, strerror(errno));
			return 1;
		}
		g_thread_unref(g_thread_new("psemu-ctl", control, (gpointer)ctl));
	}
	/* the child inherits LD_PRELOAD and UMOCKDEV_DIR: its libusb sees our devices */
	pid = fork();
	if (pid == 0) {
		execvp(argv[optind], argv + optind);
		fprintf(stderr, "psemu-run: %s: %s\n", argv[optind], strerror(errno));
		_exit(127);
	}
	if (pid < 0) {
		fprintf(stderr, "psemu-run: fork: %s\n", strerror(errno));
		return 1;
	}
	end = now_s() + limit;
	while ((rc = waitpid(pid, &status, WNOHANG)) == 0 && now_s() < end)
		g_usleep(10000);
	if (rc == 0) {
		kill(pid, SIGKILL);
		waitpid(pid, &status, 0);
		fprintf(stderr, "psemu-run: %s killed after %g s\n", argv[optind], limit);
		status = 124 << 8;
	}
	write_state();
	psemu_dump(emu, buf, sizeof buf);
	fputs(buf, stdout);
	psemu_free(emu);
	return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}
