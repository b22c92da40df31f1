/* SPDX-License-Identifier: ISC */
/* dali-client: drive the dali_usb driver through its driver.h table, for the
 * system tests (a process apart from the emulator, as psensd will be).
 *
 *   dali-client [KEY=VALUE]... -- COMMAND...
 *
 * KEY=VALUE are the device options (serial=, port=, safe_level=, ...).
 * Commands, run in order, each printing one line:
 *   point N ROLE ADDRESS   add point N (dim or relay) at a DALI address
 *   set N FRACTION         write a light output
 *   get N                  read the actual level (QUERY ACTUAL LEVEL), waits up to 3 s
 *   idle S                 run the event loop until nothing is pending (fail after S s)
 *   down S | up S          run it until the interface is gone / back
 *   mark TEXT              print TEXT (a sign for the test script)
 * Exit 0 when every command succeeded, 1 at the first failure. */
#include <errno.h>
#include <math.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "dali.h"
#include "dali_usb.h"
#include "driver.h"
#include "registry.h"

static struct ps_dev dev;
static struct ps_point pts[8];
static struct ps_opt popt[8];
static struct ps_opts popts[8];

static double now_s(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + ts.tv_nsec / 1e9;
}

static int state_is(const char *what)
{
	struct ps_dali_usb_stats st;
	ps_dali_usb_stats(&dev, &st);
	if (strcmp(what, "idle") == 0)
		return st.connected && st.pending == 0;
	if (strcmp(what, "down") == 0)
		return !st.connected;
	return st.connected;
}

/* the daemon's loop in small: poll the driver's fd until its deadline */
static int run_until(const char *what, double limit)
{
	double end = now_s() + limit;
	for (;;) {
		double t = now_s(), dl, m;
		struct pollfd p = { dev.drv->fd(&dev), POLLIN | POLLOUT, 0 };
		dev.drv->service(&dev, t, t);
		if (state_is(what))
			return 0;
		if (t >= end)
			return -1;
		m = INFINITY;   /* the driver's due time on either clock (the same here) */
		dl = fmin(dev.drv->deadline(&dev, &m), m);
		poll(&p, p.fd >= 0, isinf(dl) ? 20 : (int)fmax(0, fmin(20, (dl - t) * 1000)));
	}
}

static int point_index(const char *s)
{
	int n = atoi(s);
	return n >= 0 && n < 8 && pts[n].priv ? n : -1;
}

int main(int argc, char **argv)
{
	static struct ps_opt o[16];
	struct ps_opts opts = { o, 0, "(command line)" };
	int i = 1;
	setvbuf(stdout, NULL, _IOLBF, 0);
	for (; i < argc && strcmp(argv[i], "--") != 0; i++) {
		char *eq = strchr(argv[i], '=');
		if (!eq || opts.n >= 16) {
			fprintf(stderr, "dali-client: '%s' is not KEY=VALUE\n", argv[i]);
			return 2;
		}
		*eq = 0;
		o[opts.n++] = (struct ps_opt){ argv[i], eq + 1, i, 0 };
	}
	dev.drv = ps_registry_find("dali_usb");
	snprintf(dev.name, sizeof dev.name, "dali");
	if (!dev.drv || dev.drv->open(&dev, &opts) != 0) {
		printf("open: %s\n", dev.drv ? dev.err : "no dali_usb driver");
		if (dev.drv)
			dev.drv->close(&dev);
		return 1;
	}
	for (i++; i < argc; i++) {
		const char *cmd = argv[i];
		int n, ok = 1;
		double v;
		if (strcmp(cmd, "point") == 0 && i + 3 < argc) {
			n = atoi(argv[i + 1]);
			if (n < 0 || n >= 8 || pts[n].priv) {
				printf("point %s: bad number\n", argv[i + 1]);
				ok = 0;
			} else {
				snprintf(pts[n].name, sizeof pts[n].name, "p%d", n);
				pts[n].role = ps_role_parse(argv[i + 2]);
				popt[n] = (struct ps_opt){ "address", argv[i + 3], i + 3, 0 };
				popts[n] = (struct ps_opts){ &popt[n], 1, "(command line)" };
				ok = dev.drv->add_point(&dev, &pts[n], &popts[n]) == 0;
				printf("point %d %s\n", n, ok ? "ok" : dev.err);
			}
			i += 3;
		} else if (strcmp(cmd, "set") == 0 && i + 2 < argc && (n = point_index(argv[i + 1])) >= 0) {
			ok = dev.drv->write(&dev, &pts[n], now_s(), now_s(), atof(argv[i + 2])) == 0;
			printf("set %d %s %s\n", n, argv[i + 2], ok ? "ok" : dev.err);
			i += 2;
		} else if (strcmp(cmd, "get") == 0 && i + 1 < argc && (n = point_index(argv[i + 1])) >= 0) {
			double end = now_s() + 3;
			int r;
			/* the first read queues the query; the answer comes with the loop
			 * (EAGAIN: a level written is not read back before it is on the bus) */
			while ((r = dev.drv->read(&dev, &pts[n], now_s(), now_s(), &v)) != 0 && (errno == ETIMEDOUT || errno == EAGAIN) && now_s() < end)
				run_until("idle", 1);
			if (r == 0)
				printf("get %d %.6f level %d\n", n, v, ps_dali_fraction_to_level(v));
			else
				printf("get %d failed: %s\n", n, dev.err);
			ok = r == 0;
			i += 1;
		} else if ((strcmp(cmd, "idle") == 0 || strcmp(cmd, "down") == 0 || strcmp(cmd, "up") == 0) &&
		           i + 1 < argc) {
			ok = run_until(cmd, atof(argv[i + 1])) == 0;
			printf("%s %s\n", cmd, ok ? "ok" : "timed out");
			i += 1;
		} else if (strcmp(cmd, "mark") == 0 && i + 1 < argc) {
			printf("mark %s\n", argv[++i]);
		} else {
			printf("dali-client: bad command at '%s'\n", cmd);
			ok = 0;
		}
		if (!ok) {
			dev.drv->close(&dev);
			return 1;
		}
	}
	dev.drv->close(&dev);
	return 0;
}
