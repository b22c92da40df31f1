/* SPDX-License-Identifier: ISC */
/* DALI commissioning at the real bus rate: the emulated Tridonic interface
 * (tests/emu) with its bus timing on holds every report back until its
 * frames would have ended at 1200 bit/s (15.8 ms a forward frame, the
 * ballast's settling time and 9.2 ms a backward frame, 11.3 ms of silence
 * for no answer, 13.5 ms inside a send-twice), and the driver keeps its
 * frame gap (22 ms after each final report).  Times to scan the bus and to
 * address 6 and 64 new ballasts (settling times spread over 5.5 to
 * 10.5 ms, random addresses from each ballast's own generator), measured
 * on the wall clock.  BENCH_DALI_64=0 leaves out the 64 (about 3 minutes). */
#include <math.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#if defined(PS_WITH_USB) && defined(PS_WITH_UMOCKDEV)
#include "dali_commission.h"
#include "dali_emu.h"
#include "dali_usb.h"
#include "driver.h"
#include "registry.h"
#include "helpers/dali_preload.h"
#include "time.h"

static int job_running(struct ps_dev *dev)
{
	struct ps_dali_usb_stats st;
	ps_dali_usb_stats(dev, &st);
	return st.job_running;
}

/* the daemon's loop in small until the job ends */
static void run(struct ps_dev *dev)
{
	while (job_running(dev)) {
		double t = psd_time_mono(), dl, m;
		struct pollfd p = { dev->drv->fd(dev), POLLIN, 0 };
		dev->drv->service(dev, t, t);
		m = INFINITY;   /* the driver's due time on either clock (the same here) */
		dl = fmin(dev->drv->deadline(dev, &m), m);
		poll(&p, 1, isinf(dl) ? 20 : (int)fmax(0, fmin(20, (dl - t) * 1000)));
	}
}

static int job(struct ps_dev *dev, struct psemu *e, int n, const char *what)
{
	char out[32768], buf[32];
	const struct ps_dali_commission *c;
	struct psemu_stats before, after;
	char *words[1] = { buf };
	double t0 = psd_time_mono(), t;
	snprintf(buf, sizeof buf, "%s", what);
	psemu_stats(e, 0, &before);
	if (dev->drv->command(dev, 1, words, NULL, 0, t0, t0, out, sizeof out) != 0) {
		printf("bench_dali_commission: %s\n", dev->err);
		return 1;
	}
	run(dev);
	t = psd_time_mono() - t0;
	c = ps_dali_usb_job(dev);
	psemu_stats(e, 0, &after);
	printf("%8s %3d ballasts %7.1f s %6lu transactions %5.1f ms each, the bus busy %5.1f s of it\n", what, n, t,
	       c->frames, 1e3 * t / (double)c->frames, after.bus_time - before.bus_time);
	if (c->state != PS_DALI_COMMISSION_DONE || (strcmp(what, "address") == 0 && c->programmed != n)) {
		printf("bench_dali_commission: %s: %s\n", what, c->msg);
		return 1;
	}
	return 0;
}

/* n new ballasts addressed, then the bus scanned */
static int one(int n)
{
	char err[256];
	struct psemu *e = psemu_new(err, sizeof err);
	struct ps_dev dev = { 0 };
	struct ps_opts none = { NULL, 0, "bench" };
	int rc;
	if (!e || psemu_add(e, 1, "A1", n, err, sizeof err) != 0) {
		printf("bench_dali_commission: %s\n", err);
		return 1;
	}
	for (int s = 0; s < n; s++)
		psemu_ballast_identity(e, 0, s, -1, 0xFFFFFF, 5.5 + fmod(s * 0.37, 5.0));
	psemu_set_bus_timing(e, 1);
	dev.drv = ps_registry_find("dali_usb");
	snprintf(dev.name, sizeof dev.name, "dali");
	if (dev.drv->open(&dev, &none) != 0) {
		printf("bench_dali_commission: %s\n", dev.err);
		return 1;
	}
	rc = job(&dev, e, n, "address") || job(&dev, e, n, "scan");
	dev.drv->close(&dev);
	psemu_free(e);
	return rc;
}

int main(int argc, char **argv)
{
	const char *big = getenv("BENCH_DALI_64");
	(void)argc;
	ps_test_need_umockdev(argv);
	printf("DALI commissioning, emulated bus at 1200 bit/s, driver frame gap 22 ms (wall clock)\n");
	if (one(6))
		return 1;
	if (big && strcmp(big, "0") == 0)
		return 0;
	return one(64);
}

#else
int main(void)
{
	printf("bench_dali_commission: skipped (the DALI USB driver or umockdev is not built in)\n");
	return 0;
}
#endif
