/* SPDX-License-Identifier: ISC */
/* The I/O thread of a blocking device (daemon/devio.c), against a fake
 * driver whose reads and writes block like a slow Modbus module: the
 * caller never waits, results come back through the eventfd, queued writes
 * keep only the newest value, failures carry errno and message, input
 * events reach the caller's thread, and a due time on the monotonic clock
 * is kept in real seconds however fast the room's clock runs. */
#include <errno.h>
#include <math.h>
#include <poll.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include <cmocka.h>

#include "devio.h"
#include "time.h"

/* The fake device: read blocks read_ms and gives 42; write blocks write_ms
 * and records the value (or fails with ENODEV when gone). */
struct fake {
	int read_ms, write_ms, gone;
	double written[16];
	atomic_int nwritten;      /* atomic: the test polls it while the thread writes */
	atomic_int nstarted;      /* writes begun (the value is on the wire) */
	int serviced;
	double mono_due;          /* > 0: service is due then on the monotonic clock */
	double service_now, service_mono;   /* the clocks the last service ran at */
};

static void sleep_ms(int ms)
{
	struct timespec ts = { ms / 1000, (long)(ms % 1000) * 1000000L };
	nanosleep(&ts, NULL);
}

static int fake_read(struct ps_dev *dev, struct ps_point *pt, double now, double mono, double *v)
{
	struct fake *f = dev->priv;
	(void)pt;
	(void)now;
	(void)mono;
	sleep_ms(f->read_ms);
	*v = 42;
	return 0;
}

static int fake_write(struct ps_dev *dev, struct ps_point *pt, double now, double mono, double v)
{
	struct fake *f = dev->priv;
	(void)pt;
	(void)now;
	(void)mono;
	atomic_fetch_add(&f->nstarted, 1);
	sleep_ms(f->write_ms);
	if (f->gone)
		return ps_dev_fail(dev, ENODEV, "fake %s: gone", dev->name);
	if (f->nwritten < 16) {
		f->written[f->nwritten] = v;
		atomic_fetch_add(&f->nwritten, 1);
	}
	return 0;
}

static double fake_deadline(struct ps_dev *dev, double *mono)
{
	struct fake *f = dev->priv;
	if (f->mono_due > 0) {
		*mono = f->serviced ? INFINITY : f->mono_due;
		return INFINITY;
	}
	return f->serviced ? INFINITY : -INFINITY;
}

static int fake_service(struct ps_dev *dev, double now, double mono)
{
	struct fake *f = dev->priv;
	f->service_now = now;
	f->service_mono = mono;
	f->serviced = 1;
	dev->on_event(dev->event_user, dev, NULL, now, 1.0);   /* an input changed */
	return 0;
}

static const struct ps_driver fake_driver = {
	.name = "fake", .summary = "test", .compiled_in = 1,
	.read = fake_read, .write = fake_write, .deadline = fake_deadline, .service = fake_service,
};

static int events;
static double event_value;
static void on_event(void *user, struct ps_dev *dev, struct ps_point *pt, double now, double value)
{
	(void)user;
	(void)dev;
	(void)pt;
	(void)now;
	events++;
	event_value = value;
}

struct rig {
	struct fake f;
	struct ps_dev dev;
	struct ps_point pts[2];
	struct psd_clock clock;
	struct psd_devio *io;
};

static void rig_start(struct rig *r, int read_ms, int write_ms, int service_due)
{
	memset(r, 0, sizeof *r);
	r->f.read_ms = read_ms;
	r->f.write_ms = write_ms;
	r->f.serviced = !service_due;   /* before the thread starts: it alone reads it then */
	r->dev.drv = &fake_driver;
	r->dev.priv = &r->f;
	r->dev.on_event = on_event;
	snprintf(r->dev.name, sizeof r->dev.name, "dev");
	snprintf(r->pts[0].name, sizeof r->pts[0].name, "p0");
	snprintf(r->pts[1].name, sizeof r->pts[1].name, "p1");
	psd_clock_real(&r->clock, 0, 1);
	r->io = psd_devio_start(&r->dev, r->pts, 2, &r->clock);
	assert_non_null(r->io);
}

/* Wait (at most 5 s) until *count reaches n: 1 when it did. */
static int wait_until(atomic_int *count, int n)
{
	for (int i = 0; i < 500 && atomic_load(count) < n; i++)
		sleep_ms(10);
	return atomic_load(count) >= n;
}

/* Wait (at most 2 s) for the thread to wake us, then drain. */
static int woken(struct rig *r)
{
	struct pollfd p = { psd_devio_fd(r->io), POLLIN, 0 };
	int n = poll(&p, 1, 2000);
	if (n == 1)
		psd_devio_drain(r->io);
	return n == 1;
}

static void read_does_not_wait(void **state)
{
	struct rig r;
	double t0, v = 0;
	char err[256];
	(void)state;
	rig_start(&r, 200, 0, 0);
	t0 = psd_time_mono();
	assert_int_equal(psd_devio_ask(r.io, 0, 0), 1);   /* asked: come back */
	assert_int_equal(psd_devio_ask(r.io, 0, 0), 1);   /* still out: not asked twice */
	assert_int_equal(psd_devio_take(r.io, 0, 0.05, &v, err, sizeof err), -1);
	assert_int_equal(errno, ETIMEDOUT);
	assert_true(psd_time_mono() - t0 < 0.1);   /* the 200 ms read runs elsewhere */
	assert_non_null(strstr(err, "fake dev: p0: no reply for"));
	while (psd_devio_ask(r.io, 0, 0) != 0)
		assert_true(woken(&r));
	assert_true(psd_time_mono() - t0 >= 0.19);
	assert_int_equal(psd_devio_take(r.io, 0, 0, &v, err, sizeof err), 0);
	assert_true(v == 42);
	/* taken once: the next ask starts a new read */
	assert_int_equal(psd_devio_ask(r.io, 0, 0), 1);
	psd_devio_stop(r.io);   /* joins the read under way */
}

static void writes_keep_the_newest(void **state)
{
	struct rig r;
	char err[256];
	(void)state;
	rig_start(&r, 0, 300, 0);   /* 0.2 and 0.3 are queued while 0.1 takes 300 ms */
	assert_int_equal(psd_devio_write(r.io, 1, 0, 0.1, err, sizeof err), 0);
	/* until the first is on the wire (a loaded machine may take a while
	 * to run the thread: waited for, not assumed after a sleep) */
	assert_true(wait_until(&r.f.nstarted, 1));
	assert_int_equal(psd_devio_write(r.io, 1, 0, 0.2, err, sizeof err), 0);
	assert_int_equal(psd_devio_write(r.io, 1, 0, 0.3, err, sizeof err), 0);
	assert_true(wait_until(&r.f.nwritten, 2));
	sleep_ms(150);   /* room for a wrong third write to show */
	psd_devio_stop(r.io);
	assert_int_equal(r.f.nwritten, 2);   /* 0.2 was replaced before it was sent */
	assert_true(r.f.written[0] == 0.1);
	assert_true(r.f.written[1] == 0.3);
}

static void failed_write_is_reported(void **state)
{
	struct rig r;
	char err[256] = "";
	(void)state;
	rig_start(&r, 0, 10, 0);
	r.f.gone = 1;
	assert_int_equal(psd_devio_write(r.io, 0, 0, 1.0, err, sizeof err), 0);   /* nothing finished yet */
	assert_true(woken(&r));
	assert_int_equal(psd_devio_write(r.io, 0, 0, 1.0, err, sizeof err), -1);
	assert_int_equal(errno, ENODEV);
	assert_string_equal(err, "fake dev: gone");
	psd_devio_stop(r.io);
}

/* A driver's due time on the monotonic clock (a bus timeout) is met in
 * real seconds although the room's clock runs 10000 times faster: not
 * early (as if 0.1 s were 0.1 s of the room's clock, 10 us) and not late. */
static void mono_deadline_in_real_seconds(void **state)
{
	struct rig r;
	double t0;
	(void)state;
	memset(&r, 0, sizeof r);
	r.dev.drv = &fake_driver;
	r.dev.priv = &r.f;
	r.dev.on_event = on_event;
	snprintf(r.dev.name, sizeof r.dev.name, "dev");
	t0 = psd_time_mono();
	r.f.mono_due = t0 + 0.1;
	psd_clock_real(&r.clock, 0, 10000);
	r.io = psd_devio_start(&r.dev, r.pts, 2, &r.clock);
	assert_non_null(r.io);
	assert_true(woken(&r));   /* the service's event */
	psd_devio_stop(r.io);
	assert_int_equal(r.f.serviced, 1);
	assert_true(r.f.service_mono >= t0 + 0.1);   /* not before it was due */
	assert_true(r.f.service_mono < t0 + 1.0);    /* and not left waiting */
	/* the room's clock went on 10000 times faster meanwhile */
	assert_true(r.f.service_now >= 0.1 * 10000 * 0.9);
}

static void events_reach_the_caller(void **state)
{
	struct rig r;
	(void)state;
	events = 0;
	rig_start(&r, 0, 0, 1);   /* service is due at once; it reports an input */
	while (events == 0)
		assert_true(woken(&r));
	assert_int_equal(events, 1);
	assert_true(event_value == 1.0);
	psd_devio_stop(r.io);
	assert_ptr_equal(r.dev.on_event, on_event);   /* given back */
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(read_does_not_wait),
		cmocka_unit_test(writes_keep_the_newest),
		cmocka_unit_test(failed_write_is_reported),
		cmocka_unit_test(events_reach_the_caller),
		cmocka_unit_test(mono_deadline_in_real_seconds),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
