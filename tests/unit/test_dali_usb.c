/* SPDX-License-Identifier: ISC */
/* The DALI USB driver through the driver.h table, with real libusb against the
 * emulated Tridonic interface and its ballasts (tests/emu, libumockdev), and
 * the same cases again against the emulated hasseb DALI Master (transport
 * hasseb: no echo, DTR0 as a frame of its own, sequence numbers 1-255):
 * the transport's bytes against the worked examples of doc/hardware.md,
 * finding and claiming the interface, levels on the ballasts, query answers,
 * fades, the physical minimum, the safe level, faults, unplug and replug,
 * the choice between two interfaces and the bus's frame rate; for the hasseb,
 * also its sequence numbers and the frames of another master. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#if defined(PS_WITH_USB) && defined(PS_WITH_UMOCKDEV)
#include <poll.h>
#include <time.h>

#include "control.h"
#include "dali.h"
#include "dali_emu.h"
#include "helpers/dali_preload.h"
#include "helpers/test_opts.h"
#include "dali_transport.h"
#include "dali_usb.h"
#include "driver.h"
#include "registry.h"
#include "usb_tridonic.h"
#include "time.h"

/* ---- transport bytes ----------------------------------------------------------- */

static void tridonic_send_report(void **state)
{
	uint8_t out[64], want[64] = { 0 };
	(void)state;
	/* doc/hardware.md section 1: DAPC short 5 level 200 seq 0x2A -> 12 2A 00 03 00 00 0A C8 00... */
	assert_int_equal(ps_usb_tridonic.encode_send(out, sizeof out, 0x2A, 0x0AC8, 0, -1), 64);
	memcpy(want, (uint8_t[]){ 0x12, 0x2A, 0x00, 0x03, 0x00, 0x00, 0x0A, 0xC8 }, 8);
	assert_memory_equal(out, want, 64);
	/* python-dali's log: DAPC short 21 level 1, seq 0xD6 */
	assert_int_equal(ps_usb_tridonic.encode_send(out, sizeof out, 0xD6, 0x2A01, 0, -1), 64);
	assert_memory_equal(out, ((uint8_t[]){ 0x12, 0xD6, 0x00, 0x03, 0x00, 0x00, 0x2A, 0x01, 0x00 }), 9);
	/* send twice with DTR0 first: flags 0x20 | 0x10, DTR0 in byte 8 */
	assert_int_equal(ps_usb_tridonic.encode_send(out, sizeof out, 7, 0xFF2C, 1, 229), 64);
	assert_memory_equal(out, ((uint8_t[]){ 0x12, 7, 0x30, 0x03, 0, 0, 0xFF, 0x2C, 229 }), 9);
	assert_int_equal(ps_usb_tridonic.encode_send(out, 63, 7, 0xFF2C, 1, -1), -1);   /* too small */
	assert_int_equal(ps_usb_tridonic.encode_send(out, 64, 256, 0xFF2C, 1, -1), -1);
	/* sequence numbers run 1..255 and skip 0 */
	assert_int_equal(ps_usb_tridonic.next_seq(255), 1);
	assert_int_equal(ps_usb_tridonic.next_seq(0), 1);
	assert_int_equal(ps_usb_tridonic.next_seq(41), 42);
}

static void tridonic_reports(void **state)
{
	struct ps_dali_reply r;
	uint8_t in[64] = { 0 };
	(void)state;
	/* python-dali's log: 12 73 00 00 2A 01 00 F5 D6, then 12 71 00 00 00 00 00 8A D6 */
	memcpy(in, (uint8_t[]){ 0x12, 0x73, 0, 0, 0x2A, 0x01, 0x00, 0xF5, 0xD6 }, 9);
	ps_usb_tridonic.decode(in, 64, &r);
	assert_int_equal(r.event, PS_DALI_EV_ECHO);
	assert_int_equal(r.seq, 0xD6);
	assert_int_equal(r.value, 0x2A01);
	memcpy(in, (uint8_t[]){ 0x12, 0x71, 0, 0, 0, 0, 0x00, 0x8A, 0xD6 }, 9);
	ps_usb_tridonic.decode(in, 64, &r);
	assert_int_equal(r.event, PS_DALI_EV_NO_ANSWER);
	assert_int_equal(r.seq, 0xD6);
	memcpy(in, (uint8_t[]){ 0x12, 0x72, 0, 0, 0, 0xC8, 0x00, 0x8A, 0x05 }, 9);
	ps_usb_tridonic.decode(in, 64, &r);
	assert_int_equal(r.event, PS_DALI_EV_ANSWER);
	assert_int_equal(r.value, 200);
	assert_int_equal(r.seq, 5);
	memcpy(in, (uint8_t[]){ 0x12, 0x77, 0, 0, 0, 3, 0, 0, 9 }, 9);       /* framing error */
	ps_usb_tridonic.decode(in, 64, &r);
	assert_int_equal(r.event, PS_DALI_EV_BUS_ERROR);
	assert_int_equal(r.value, 3);
	in[5] = 4;                                                            /* bus ok: news only */
	ps_usb_tridonic.decode(in, 64, &r);
	assert_int_equal(r.event, PS_DALI_EV_IGNORE);
	memcpy(in, (uint8_t[]){ 0x11, 0x73, 0, 0, 0xFF, 0x05, 0, 0, 0 }, 9);  /* another master */
	ps_usb_tridonic.decode(in, 64, &r);
	assert_int_equal(r.event, PS_DALI_EV_OBSERVED);
	assert_int_equal(r.seq, -1);
	assert_int_equal(r.value, 0xFF05);
	ps_usb_tridonic.decode(in, 8, &r);                                   /* short */
	assert_int_equal(r.event, PS_DALI_EV_MALFORMED);
	in[0] = 0x12;
	in[1] = 0x7E;                                                         /* no such type */
	ps_usb_tridonic.decode(in, 64, &r);
	assert_int_equal(r.event, PS_DALI_EV_MALFORMED);
	in[0] = 0x99;
	ps_usb_tridonic.decode(in, 64, &r);
	assert_int_equal(r.event, PS_DALI_EV_MALFORMED);
}

/* ---- the emulator and a device on it ---------------------------------------------- */

static double fade_clock;   /* the ballasts' clock: tests move fades along */
static double clock_ahead;  /* the driver's clock: the monotonic one plus this (a test moves it on) */

static double tnow(void)
{
	return psd_time_mono() + clock_ahead;
}

static double get_fade_clock(void *user)
{
	(void)user;
	return fade_clock;
}

struct fx {
	struct psemu *emu;
	struct ps_dev dev;
	struct ps_test_opts o;
	struct ps_point pt[4];
	struct ps_opt po[4];
	struct ps_opts popts[4];
	int open;
	int model;   /* enum psemu_model of the emulated interfaces */
	const char *transport;   /* the transport key open_dev adds (NULL: the model's own) */
};

static int setup_n(void **state, int nifaces, int model)
{
	static struct fx f;
	char err[256];
	memset(&f, 0, sizeof f);
	f.model = model;
	f.emu = psemu_new(err, sizeof err);
	if (!f.emu)
		fail_msg("%s", err);
	for (int i = 0; i < nifaces; i++)
		if (psemu_add_model(f.emu, model, i + 1, i ? "B2" : "A1", 4, err, sizeof err) != i)
			fail_msg("%s", err);
	fade_clock = 1000;
	clock_ahead = 0;
	psemu_set_clock(f.emu, get_fade_clock, NULL);
	*state = &f;
	return 0;
}

static int setup(void **state)
{
	return setup_n(state, 1, PSEMU_TRIDONIC);
}

static int setup_two(void **state)
{
	return setup_n(state, 2, PSEMU_TRIDONIC);
}

static int setup_hasseb(void **state)
{
	return setup_n(state, 1, PSEMU_HASSEB);
}

static int setup_two_hasseb(void **state)
{
	return setup_n(state, 2, PSEMU_HASSEB);
}

/* the hasseb, opened with transport = usb: chosen by its VID:PID */
static int setup_usb_hasseb(void **state)
{
	setup_n(state, 1, PSEMU_HASSEB);
	((struct fx *)*state)->transport = "usb";
	return 0;
}

/* a Tridonic interface (A1, port 1) and a hasseb (B2, port 2) plugged in */
static int setup_mixed(void **state)
{
	char err[256];
	struct fx *f;
	setup_n(state, 1, PSEMU_TRIDONIC);
	f = *state;
	if (psemu_add_model(f->emu, PSEMU_HASSEB, 2, "B2", 4, err, sizeof err) != 1)
		fail_msg("%s", err);
	return 0;
}

static const char *model_name(const struct fx *f)
{
	return f->model == PSEMU_HASSEB ? "hasseb" : "tridonic";
}

static int teardown(void **state)
{
	struct fx *f = *state;
	if (f->open)
		f->dev.drv->close(&f->dev);
	psemu_free(f->emu);
	return 0;
}

/* open dali_usb with key, value, ..., NULL (and transport = hasseb on the hasseb) */
static int open_dev(struct fx *f, ...)
{
	va_list ap;
	const struct ps_opts *opts;
	memset(&f->dev, 0, sizeof f->dev);
	f->dev.drv = ps_registry_find("dali_usb");
	assert_non_null(f->dev.drv);
	assert_true(f->dev.drv->compiled_in);
	snprintf(f->dev.name, sizeof f->dev.name, "dali");
	va_start(ap, f);
	opts = ps_test_vopts(&f->o, "test.conf", 10, ap);
	va_end(ap);
	if (f->model == PSEMU_HASSEB || f->transport) {
		assert_true(f->o.o.n < PS_TEST_OPTS_MAX);
		f->o.v[f->o.o.n] = (struct ps_opt){ "transport", f->transport ? f->transport : "hasseb", 9, 0 };
		f->o.o.n++;
	}
	if (f->dev.drv->open(&f->dev, opts) != 0) {
		int e = errno;
		f->dev.drv->close(&f->dev);
		errno = e;
		return -1;
	}
	f->open = 1;
	return 0;
}

static void add_point(struct fx *f, int i, int role, const char *addr)
{
	snprintf(f->pt[i].name, sizeof f->pt[i].name, "p%d", i);
	f->pt[i].role = role;
	f->po[i] = (struct ps_opt){ "address", addr, 20 + i, 0 };
	f->popts[i] = (struct ps_opts){ &f->po[i], 1, "test.conf" };
	if (f->dev.drv->add_point(&f->dev, &f->pt[i], &f->popts[i]) != 0)
		fail_msg("add_point %s: %s", addr, f->dev.err);
}

static struct ps_dali_usb_stats stats(struct fx *f)
{
	struct ps_dali_usb_stats st;
	assert_int_equal(ps_dali_usb_stats(&f->dev, &st), 0);
	return st;
}

static int is_idle(struct fx *f)
{
	struct ps_dali_usb_stats st = stats(f);
	return st.connected && st.pending == 0;
}

static int is_connected(struct fx *f)
{
	return stats(f).connected;
}

static int is_down(struct fx *f)
{
	return !stats(f).connected;
}

/* The daemon's loop in small: poll the driver's fd until its deadline, call
 * service(); until pred holds or the (real-time) limit passes. */
static int run_until(struct fx *f, int (*pred)(struct fx *), double limit)
{
	double end = tnow() + limit;
	for (;;) {
		double t = tnow(), dl, m;
		struct pollfd p = { f->dev.drv->fd(&f->dev), POLLIN | POLLOUT, 0 };
		int ms;
		f->dev.drv->service(&f->dev, t, t);
		if (pred(f))
			return 1;
		if (t >= end)
			return 0;
		m = INFINITY;   /* the driver's due time on either clock (the same here) */
		dl = fmin(f->dev.drv->deadline(&f->dev, &m), m);
		ms = isinf(dl) ? 20 : (int)fmax(0, fmin(20, (dl - t) * 1000));
		poll(&p, p.fd >= 0, ms);
	}
}

static struct psemu_ballast ballast(struct fx *f, int iface, int addr)
{
	struct psemu_ballast b;
	assert_int_equal(psemu_ballast(f->emu, iface, addr, &b), 0);
	return b;
}

static int dwrite(struct fx *f, int i, double v)
{
	return f->dev.drv->write(&f->dev, &f->pt[i], tnow(), tnow(), v);
}

static int dread(struct fx *f, int i, double *v)
{
	return f->dev.drv->read(&f->dev, &f->pt[i], tnow(), tnow(), v);
}

/* ---- the tests ----------------------------------------------------------------------- */

static void opens_detaches_and_claims(void **state)
{
	struct fx *f = *state;
	struct ps_dali_usb_stats st;
	assert_int_equal(open_dev(f, NULL), 0);
	st = stats(f);
	assert_int_equal(st.connected, 1);
	assert_int_equal(st.connects, 1);
	assert_true(f->dev.drv->fd(&f->dev) >= 0);
	/* nothing to do yet: no deadline */
	{
		double m = INFINITY;
		assert_true(isinf(f->dev.drv->deadline(&f->dev, &m)) && isinf(m));
	}
}

static void levels_reach_the_ballasts(void **state)
{
	struct fx *f = *state;
	static const double fr[] = { 1.0, 0.5, 0.1, 0.0123, 0.001, 0.0 };
	/* ballasts 2 and 3 are group 1 */
	psemu_ballast_setup(f->emu, 0, 2, 1u << 1, 1);
	psemu_ballast_setup(f->emu, 0, 3, 1u << 1, 1);
	assert_int_equal(open_dev(f, NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "0");
	add_point(f, 1, PS_ROLE_DIM, "group 1");
	add_point(f, 2, PS_ROLE_DIM, "short 1");
	for (size_t k = 0; k < sizeof fr / sizeof fr[0]; k++) {
		/* the level on the wire is the curve's inverse: 1 + (253/3)(log10(100 f) + 1) */
		int want = fr[k] > 0 ? (int)lround(1 + 253.0 / 3 * (log10(100 * fr[k]) + 1)) : 0;
		int want1 = fr[k] > 0 ? (int)lround(1 + 253.0 / 3 * (log10(100 * fr[k] / 2) + 1)) : 0;
		assert_int_equal(dwrite(f, 0, fr[k]), 0);
		assert_int_equal(dwrite(f, 1, fr[k]), 0);
		assert_int_equal(dwrite(f, 2, fr[k] / 2), 0);
		assert_true(run_until(f, is_idle, 3));
		assert_int_equal(ballast(f, 0, 0).level, want);
		assert_int_equal(ballast(f, 0, 2).level, want);
		assert_int_equal(ballast(f, 0, 3).level, want);
		assert_int_equal(ballast(f, 0, 1).level, fr[k] / 2 >= 0.001 ? want1 : fr[k] > 0 ? 1 : 0);
	}
	assert_int_equal(stats(f).failed, 0);
}

static void the_latest_write_wins_and_frames_keep_the_bus_rate(void **state)
{
	struct fx *f = *state;
	struct psemu_stats es;
	struct ps_dali_usb_stats st;
	assert_int_equal(open_dev(f, NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "0");
	add_point(f, 1, PS_ROLE_DIM, "1");
	/* a burst faster than the bus: only the last level of each point matters */
	for (int k = 1; k <= 40; k++) {
		assert_int_equal(dwrite(f, 0, k / 40.0), 0);
		assert_int_equal(dwrite(f, 1, 1 - k / 80.0), 0);
		f->dev.drv->service(&f->dev, psd_time_mono(), psd_time_mono());
	}
	assert_true(run_until(f, is_idle, 5));
	assert_int_equal(ballast(f, 0, 0).level, 254);
	assert_int_equal(ballast(f, 0, 1).level, ps_dali_fraction_to_level(0.5));
	/* frames start at least 21.2 ms (priority 5 settling) after the last final report */
	assert_int_equal(psemu_stats(f->emu, 0, &es), 0);
	st = stats(f);
	print_message("# %u SENDs for 80 writes, shortest gap %.1f ms\n", es.sends, 1e3 * es.min_gap);
	assert_int_equal(es.gap_violations, 0);
	assert_true(es.min_gap >= 0.0212);
	assert_true(es.sends < 80);
	assert_int_equal(st.frames, es.sends);
}

/* The read-back rule: an answer counts only if its query went out once the
 * last level change was on the bus and its fade (fade_time) had passed.
 * The driver's clock is moved on by hand, the ballasts' with it. */
static void query_answers_follow_the_fade(void **state)
{
	struct fx *f = *state;
	double v = -1;
	unsigned long frames;
	/* 2 s fade: FADE TIME code 4, sent as DTR0 + SET FADE TIME twice */
	assert_int_equal(open_dev(f, "fade_time", "2", NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "0");
	assert_int_equal(dwrite(f, 0, ps_dali_level_to_fraction(100)), 0);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(ballast(f, 0, 0).fade_time, 4);
	/* inside the first fade: not yet, and no query is sent mid-fade */
	frames = stats(f).frames;
	assert_int_equal(dread(f, 0, &v), -1);
	assert_int_equal(errno, EAGAIN);
	assert_int_equal(stats(f).frames, frames);
	/* 2.5 s on: the query read() asked for at the fade's end is answered */
	clock_ahead += 2.5;
	fade_clock += 2.5;
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(stats(f).frames, frames + 1);
	assert_int_equal(dread(f, 0, &v), 0);
	assert_int_equal(ps_dali_fraction_to_level(v), 100);
	assert_true(run_until(f, is_idle, 3));
	/* to 200: half way through the fade the gear is at 150, which is not
	 * taken for an answer */
	assert_int_equal(dwrite(f, 0, ps_dali_level_to_fraction(200)), 0);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(ballast(f, 0, 0).target, 200);
	fade_clock += 1.0;
	assert_int_equal(ballast(f, 0, 0).level, 150);
	assert_int_equal(dread(f, 0, &v), -1);
	assert_int_equal(errno, EAGAIN);
	/* past the fade (2.1 s after the DAPC): the driver queries by itself,
	 * the point being read back */
	clock_ahead += 2.1;
	fade_clock += 1.1;
	frames = stats(f).frames;
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(stats(f).frames, frames + 1);
	assert_int_equal(dread(f, 0, &v), 0);
	assert_true(fabs(v - ps_dali_level_to_fraction(200)) < 1e-15);
}

/* Without a fade: an answer to a query queued before a level change is the
 * level from before the command, never returned after it. */
static void a_query_before_the_command_is_stale(void **state)
{
	struct fx *f = *state;
	double v = -1;
	assert_int_equal(open_dev(f, NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "0");
	assert_int_equal(dwrite(f, 0, ps_dali_level_to_fraction(100)), 0);
	assert_true(run_until(f, is_idle, 3));
	/* the first read: no answer yet is "not yet", not a failure */
	assert_int_equal(dread(f, 0, &v), -1);
	assert_int_equal(errno, EAGAIN);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(dread(f, 0, &v), 0);   /* queues the next query */
	assert_int_equal(ps_dali_fraction_to_level(v), 100);
	/* the level changes behind that query: 100 is answered, then DAPC 150 */
	assert_int_equal(dwrite(f, 0, ps_dali_level_to_fraction(150)), 0);
	assert_int_equal(dread(f, 0, &v), -1);
	assert_int_equal(errno, EAGAIN);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(ballast(f, 0, 0).level, 150);
	/* the query sent after the DAPC answers: 150, not the 100 from before */
	assert_int_equal(dread(f, 0, &v), 0);
	assert_int_equal(ps_dali_fraction_to_level(v), 150);
	/* the same level again changes nothing: the answer stands */
	assert_int_equal(dwrite(f, 0, ps_dali_level_to_fraction(150)), 0);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(dread(f, 0, &v), 0);
	assert_int_equal(ps_dali_fraction_to_level(v), 150);
}

static void physical_minimum_is_respected(void **state)
{
	struct fx *f = *state;
	psemu_ballast_setup(f->emu, 0, 0, 0, 85);   /* 1 % lowest */
	assert_int_equal(open_dev(f, NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "0");
	assert_true(run_until(f, is_idle, 3));     /* QUERY PHYSICAL MINIMUM answered */
	assert_int_equal(dwrite(f, 0, 0.002), 0);   /* level 33 asked */
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(ballast(f, 0, 0).level, 85);
	assert_int_equal(stats(f).frames, 2);        /* one query, one DAPC 85 */
}

static void relay_points_switch(void **state)
{
	struct fx *f = *state;
	double v;
	assert_int_equal(open_dev(f, NULL), 0);
	add_point(f, 0, PS_ROLE_RELAY, "broadcast");
	assert_int_equal(dwrite(f, 0, 0), 0);
	assert_true(run_until(f, is_idle, 3));
	for (int a = 0; a < 4; a++)
		assert_int_equal(ballast(f, 0, a).level, 0);
	assert_int_equal(dwrite(f, 0, 1), 0);
	assert_true(run_until(f, is_idle, 3));
	for (int a = 0; a < 4; a++)
		assert_int_equal(ballast(f, 0, a).level, 254);
	/* all four answer 254 together: identical answers do not collide */
	f->dev.drv->read(&f->dev, &f->pt[0], psd_time_mono(), psd_time_mono(), &v);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(f->dev.drv->read(&f->dev, &f->pt[0], psd_time_mono(), psd_time_mono(), &v), 0);
	assert_true(v == 1.0);
}

static void broadcast_query_collides(void **state)
{
	struct fx *f = *state;
	double v;
	assert_int_equal(open_dev(f, "retries", "1", NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "0");
	add_point(f, 1, PS_ROLE_DIM, "broadcast");
	assert_int_equal(dwrite(f, 1, 1.0), 0);
	assert_int_equal(dwrite(f, 0, 0.5), 0);
	assert_true(run_until(f, is_idle, 3));
	/* four ballasts answer 229, 254, 254, 254 at once: a framing error */
	f->dev.drv->read(&f->dev, &f->pt[1], psd_time_mono(), psd_time_mono(), &v);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(f->dev.drv->read(&f->dev, &f->pt[1], psd_time_mono(), psd_time_mono(), &v), -1);
	assert_int_equal(errno, EPROTO);
	assert_non_null(strstr(f->dev.err, "garbled"));
	assert_non_null(strstr(f->dev.err, "broadcast QUERY ACTUAL LEVEL"));
	assert_int_equal(stats(f).retries, 1);
}

static void faults_are_retried(void **state)
{
	struct fx *f = *state;
	struct ps_dali_usb_stats st;
	assert_int_equal(open_dev(f, "timeout", "0.05", NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "0");
	psemu_fault(f->emu, 0, PSEMU_FAULT_NO_ANSWER, 1);
	assert_int_equal(dwrite(f, 0, 0.5), 0);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(ballast(f, 0, 0).level, 229);
	st = stats(f);
	assert_int_equal(st.timeouts, 1);
	assert_int_equal(st.retries, 1);
	psemu_fault(f->emu, 0, PSEMU_FAULT_GARBLED, 1);
	assert_int_equal(dwrite(f, 0, 0.25), 0);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(ballast(f, 0, 0).level, ps_dali_fraction_to_level(0.25));
	assert_int_equal(stats(f).retries, 2);
	psemu_fault(f->emu, 0, PSEMU_FAULT_MALFORMED, 1);
	assert_int_equal(dwrite(f, 0, 0.75), 0);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(ballast(f, 0, 0).level, ps_dali_fraction_to_level(0.75));
	st = stats(f);
	assert_int_equal(st.retries, 3);
	assert_int_equal(st.garbled, 2);
	assert_int_equal(st.failed, 0);
}

static void silence_fails_after_the_retries(void **state)
{
	struct fx *f = *state;
	assert_int_equal(open_dev(f, "timeout", "0.03", "retries", "2", NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "5");   /* nobody there: QUERY PHYSICAL MINIMUM gets no answer */
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(stats(f).frames, 1);
	psemu_fault(f->emu, 0, PSEMU_FAULT_NO_ANSWER, 3);
	assert_int_equal(dwrite(f, 0, 0.5), 0);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(stats(f).failed, 1);
	assert_int_equal(stats(f).frames, 4);
	assert_int_equal(stats(f).timeouts, 3);
	/* the failure is reported once, on the next call */
	assert_int_equal(dwrite(f, 0, 0.5), -1);
	assert_int_equal(errno, ETIMEDOUT);
	assert_non_null(strstr(f->dev.err, "short 5 DAPC 229"));
	assert_non_null(strstr(f->dev.err, "3 tries"));
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(dwrite(f, 0, 0.5), 0);
}

static void safe_level_unplug_and_replug(void **state)
{
	struct fx *f = *state;
	char err[256];
	int r;
	double t0;
	assert_int_equal(open_dev(f, "safe_level", "0.5", NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "broadcast");
	assert_int_equal(dwrite(f, 0, 0.1), 0);
	assert_true(run_until(f, is_idle, 3));
	for (int a = 0; a < 4; a++) {
		struct psemu_ballast b = ballast(f, 0, a);
		assert_int_equal(b.sfl, 229);            /* 50 % programmed as the system failure level */
		assert_int_equal(b.level, 170);          /* 10 % */
		assert_int_equal(b.config_writes, 1);
	}
	/* unplugged: the bus goes down with it and the gear goes to its SFL */
	assert_int_equal(psemu_unplug(f->emu, 0), 0);
	for (int a = 0; a < 4; a++)
		assert_int_equal(ballast(f, 0, a).level, 229);
	assert_true(run_until(f, is_down, 3));
	r = dwrite(f, 0, 0.2);
	assert_int_equal(r, -1);
	assert_int_equal(errno, ENODEV);
	assert_non_null(strstr(f->dev.err, "unplugged"));
	/* still gone: rescans fail, with backoff, and writes keep failing */
	assert_false(run_until(f, is_connected, 0.7));
	assert_int_equal(dwrite(f, 0, 0.3), -1);
	assert_int_equal(errno, ENODEV);
	assert_non_null(strstr(f->dev.err, f->transport ? "no DALI USB interface (tridonic 17b5:0020, hasseb 04cc:0802)"
	                                   : f->model == PSEMU_HASSEB ? "no hasseb DALI USB interface 04cc:0802"
	                                                              : "no tridonic DALI USB interface 17b5:0020"));
	/* the cause stays in front of the rescan's words: a log of this fault
	 * says what happened (500-fault-table greps the samples for it) */
	assert_non_null(strstr(f->dev.err, "interface unplugged; rescan: "));
	/* back: the driver finds it (new device number), and sends the last level */
	assert_int_equal(psemu_replug(f->emu, 0, err, sizeof err), 0);
	t0 = psd_time_mono();
	assert_true(run_until(f, is_idle, 10));
	print_message("# reconnected %.2f s after the replug\n", psd_time_mono() - t0);
	assert_int_equal(stats(f).connects, 2);
	for (int a = 0; a < 4; a++) {
		struct psemu_ballast b = ballast(f, 0, a);
		assert_int_equal(b.level, ps_dali_fraction_to_level(0.3));
		assert_int_equal(b.config_writes, 1);    /* SFL already right: not written again */
	}
	assert_int_equal(dwrite(f, 0, 0.4), 0);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(ballast(f, 0, 0).level, ps_dali_fraction_to_level(0.4));
}

static void unplug_in_the_middle_of_a_transfer(void **state)
{
	struct fx *f = *state;
	char err[256];
	assert_int_equal(open_dev(f, NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "2");
	assert_true(run_until(f, is_idle, 3));
	psemu_fault(f->emu, 0, PSEMU_FAULT_UNPLUG, 1);
	assert_int_equal(dwrite(f, 0, 0.6), 0);    /* the frame goes out, then the interface is gone */
	assert_true(run_until(f, is_down, 3));
	assert_int_equal(dwrite(f, 0, 0.7), -1);
	assert_int_equal(errno, ENODEV);
	/* seen first by the sending side, the loss is still called an unplug */
	assert_non_null(strstr(f->dev.err, "unplugged"));
	assert_int_equal(psemu_replug(f->emu, 0, err, sizeof err), 0);
	assert_true(run_until(f, is_idle, 10));
	assert_int_equal(ballast(f, 0, 2).level, ps_dali_fraction_to_level(0.7));
	assert_int_equal(stats(f).connects, 2);
}

static void absent_at_open_then_found(void **state)
{
	struct fx *f = *state;
	char err[256];
	assert_int_equal(psemu_unplug(f->emu, 0), 0);
	assert_int_equal(open_dev(f, NULL), 0);     /* open succeeds without the device */
	add_point(f, 0, PS_ROLE_DIM, "0");
	assert_int_equal(dwrite(f, 0, 0.5), -1);
	assert_int_equal(errno, ENODEV);
	assert_int_equal(psemu_replug(f->emu, 0, err, sizeof err), 0);
	assert_true(run_until(f, is_idle, 10));
	assert_int_equal(ballast(f, 0, 0).level, 229);
}

static void two_interfaces_need_a_choice(void **state)
{
	struct fx *f = *state;
	assert_int_equal(open_dev(f, NULL), -1);
	assert_int_equal(errno, EINVAL);
	assert_non_null(strstr(f->dev.err, f->model == PSEMU_HASSEB ? "2 hasseb interfaces found"
	                                                            : "2 tridonic interfaces found"));
	assert_int_equal(open_dev(f, "serial", "B2", NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "1");
	assert_int_equal(dwrite(f, 0, 0.5), 0);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(ballast(f, 1, 1).level, 229);
	assert_int_equal(ballast(f, 0, 1).level, 254);   /* the other bus is untouched */
	f->dev.drv->close(&f->dev);
	f->open = 0;
	assert_int_equal(open_dev(f, "port", "1-1", NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "1");
	assert_int_equal(dwrite(f, 0, 0.1), 0);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(ballast(f, 0, 1).level, 170);
	assert_int_equal(ballast(f, 1, 1).level, 229);
	f->dev.drv->close(&f->dev);
	f->open = 0;
	/* a serial nobody has: open succeeds, the device is absent */
	assert_int_equal(open_dev(f, "serial", "ZZ", NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "1");
	assert_int_equal(dwrite(f, 0, 0.1), -1);
	assert_int_equal(errno, ENODEV);
	assert_non_null(strstr(f->dev.err, "with serial ZZ"));
}

/* The interface belongs to whoever claimed it first: a second program (here
 * a second device on its own libusb context and connection) is refused by
 * usbfs with EBUSY and keeps retrying as for an absent interface. */
static void a_second_claim_is_refused(void **state)
{
	struct fx *f = *state;
	struct ps_dev other = { 0 };
	struct ps_point pt = { "other", PS_ROLE_DIM, NULL };
	struct ps_opt o = { "address", "1", 40, 0 };
	struct ps_opts po = { &o, 1, "other.conf" };
	struct ps_opt model = { "transport", model_name(f), 1, 0 };
	struct ps_opts none = { &model, 1, "other.conf" };
	assert_int_equal(open_dev(f, NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "1");
	other.drv = f->dev.drv;
	snprintf(other.name, sizeof other.name, "other");
	assert_int_equal(other.drv->open(&other, &none), 0);
	assert_int_equal(other.drv->add_point(&other, &pt, &po), 0);
	assert_int_equal(other.drv->write(&other, &pt, psd_time_mono(), psd_time_mono(), 0.1), -1);
	assert_int_equal(errno, ENODEV);
	assert_non_null(strstr(other.err, "cannot claim it"));
	assert_non_null(strstr(other.err, "busy"));
	/* the owner goes on */
	assert_int_equal(dwrite(f, 0, 0.5), 0);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(ballast(f, 0, 1).level, 229);
	/* released: the other one gets it at its next scan */
	f->dev.drv->close(&f->dev);
	f->open = 0;
	for (int i = 0; i < 100 && other.drv->write(&other, &pt, psd_time_mono(), psd_time_mono(), 0.1) != 0; i++) {
		other.drv->service(&other, psd_time_mono(), psd_time_mono());
		poll(NULL, 0, 50);
	}
	assert_int_equal(other.drv->write(&other, &pt, psd_time_mono(), psd_time_mono(), 0.1), 0);
	other.drv->close(&other);
}

static void bad_options_name_file_and_line(void **state)
{
	struct fx *f = *state;
	struct ps_point p = { "sensor", PS_ROLE_SENSOR, NULL };
	struct ps_opt o = { "address", "group 16", 33, 0 };
	struct ps_opts po = { &o, 1, "test.conf" };
	assert_int_equal(open_dev(f, "timeout", "-1", NULL), -1);
	assert_int_equal(errno, EINVAL);
	assert_non_null(strstr(f->dev.err, "test.conf:10: timeout"));
	assert_int_equal(open_dev(f, "port", "usb1", NULL), -1);
	assert_non_null(strstr(f->dev.err, "test.conf:10: port"));
	assert_int_equal(open_dev(f, "transport", "lunatone", NULL), -1);
	assert_non_null(strstr(f->dev.err, "test.conf:10: transport: 'lunatone' is not one of tridonic"));
	assert_int_equal(open_dev(f, NULL), 0);
	p.role = PS_ROLE_DIM;
	assert_int_equal(f->dev.drv->add_point(&f->dev, &p, &po), -1);
	assert_non_null(strstr(f->dev.err, "test.conf:33: address: 'group 16'"));
	/* a sensor is a DALI-2 control device's instance: a gear address on it
	 * is refused, naming the key it should have been */
	p.role = PS_ROLE_SENSOR;
	o.value = "1";
	assert_int_equal(f->dev.drv->add_point(&f->dev, &p, &po), -1);
	assert_non_null(strstr(f->dev.err, "test.conf:33: address is the gear's; a control device's is device_address"));
	/* a role the driver has no use for */
	p.role = PS_ROLE_TASK_LUX;
	assert_int_equal(f->dev.drv->add_point(&f->dev, &p, &po), -1);
	assert_non_null(strstr(f->dev.err, "dim and relay points and reads sensor and input points, not task"));
	p.role = PS_ROLE_DIM;
	assert_int_equal(f->dev.drv->add_point(&f->dev, &p, &po), 0);
	assert_int_equal(f->dev.drv->write(&f->dev, &p, psd_time_mono(), psd_time_mono(), 1.5), -1);
	assert_int_equal(errno, EINVAL);
}


/* The daemon's control over a simulated day, dimming the emulated ballasts:
 * the set-point law (daemon/control.c) reads a sensor whose signal comes
 * from the ballasts' real arc power levels, and its commands reach the gear
 * through libusb.  Analytic bound: with the lights quantised to DALI steps
 * (at most half a step, 1.38 %, off in ratio) the task illuminance misses the
 * target by at most 1.38 % of (electric task lux + the electric part of the
 * daylight estimate).  An hour without the interface puts the lights at the
 * safe level (the gear's system failure level while the bus is down). */
static double daylight_lux(double t)
{
	double x = (t - 6 * 3600.0) / (12.5 * 3600.0);
	return x > 0 && x < 1 ? 900 * sin(M_PI * x) : 0;
}

static void a_simulated_day_with_the_control_law(void **state)
{
	struct fx *f = *state;
	struct psd_control c = { 0 };
	const double ratio = 400, es = 0.8, ee = 600, gain = 0.5, step = 600;
	const double half_step = pow(10.0, 1.5 / 253) - 1;
	double used = 0, hours = 0, worst = 0;
	int dimmed = 0, outage_steps = 0;
	char err[256];
	c.algorithm = PSD_ALG_SETPOINT;
	c.target_lux = 500;
	c.min_level = 0.1;
	c.sensor_gain = gain;
	c.daylight_ratio = ratio;
	c.elec_sensor = es;
	c.elec_task_lux = ee;
	c.level = 1;
	assert_int_equal(open_dev(f, "safe_level", "1.0", NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "broadcast");
	assert_int_equal(dwrite(f, 0, 1.0), 0);
	assert_true(run_until(f, is_idle, 3));
	for (double t = 6 * 3600.0; t < 20 * 3600.0; t += step) {
		int outage = t >= 12 * 3600.0 && t < 13 * 3600.0;
		double ua = ps_dali_level_to_fraction(ballast(f, 0, 0).level);
		double d = daylight_lux(t), volts = gain * (d / ratio + ua * es), prev = c.level, level, task;
		if (outage && ballast(f, 0, 0).level != 0 && stats(f).connected)
			assert_int_equal(psemu_unplug(f->emu, 0), 0);
		if (!outage && !stats(f).connected) {
			assert_int_equal(psemu_replug(f->emu, 0, err, sizeof err), 0);
			assert_true(run_until(f, is_idle, 10));
		}
		level = psd_control_step(&c, volts, t);
		if (dwrite(f, 0, level) != 0) {
			/* the daemon's rule: any failure puts the lights at the safe level */
			assert_int_equal(errno, ENODEV);
			c.level = 1.0;
			dwrite(f, 0, 1.0);
			outage_steps++;
			for (int a = 0; a < 4; a++)
				assert_int_equal(ballast(f, 0, a).level, 254);
			continue;
		}
		assert_true(run_until(f, is_idle, 3));
		for (int a = 0; a < 4; a++)
			assert_int_equal(ballast(f, 0, a).level, ps_dali_fraction_to_level(level));
		ua = ps_dali_level_to_fraction(ballast(f, 0, 0).level);
		task = d + ua * ee;
		if (level > c.min_level && level < 1) {
			double bound = half_step * (ee * level + ratio * es * prev) + 1e-9;
			double miss = fabs(task - c.target_lux);
			dimmed++;
			if (miss > bound)
				fail_msg("%02d:%02d task %.2f lx, target %g, bound %.2f", (int)(t / 3600),
				         (int)fmod(t / 60, 60), task, c.target_lux, bound);
			if (miss > worst)
				worst = miss;
		} else {
			assert_true(task >= c.target_lux * (1 - half_step) - 1e-9);
		}
		used += ua * step / 3600;
		hours += step / 3600;
	}
	print_message("# day: %d dimmed periods, worst miss %.2f lx, energy %.1f %% of full, %d periods "
	              "without the interface\n", dimmed, worst, 100 * used / hours, outage_steps);
	assert_true(dimmed >= 30);   /* mornings and afternoons; at midday daylight alone is enough */
	assert_int_equal(outage_steps, 6);
	assert_int_equal(stats(f).connects, 2);
}

/* transport = usb with a Tridonic and a hasseb plugged in: a choice to
 * make, named with both; transport = hasseb, or usb with a serial, makes
 * it; with the Tridonic unplugged, usb takes the hasseb (its own framing:
 * the level reaches the hasseb's bus, not the other). */
static void usb_takes_either_interface(void **state)
{
	struct fx *f = *state;
	f->transport = "usb";
	assert_int_equal(open_dev(f, NULL), -1);
	assert_int_equal(errno, EINVAL);
	if (!strstr(f->dev.err, "2 DALI USB interfaces found (") || !strstr(f->dev.err, "tridonic at 1-1") ||
	    !strstr(f->dev.err, "hasseb at 1-2") || !strstr(f->dev.err, "choose one with transport ="))
		fail_msg("%s", f->dev.err);
	f->transport = "hasseb";
	assert_int_equal(open_dev(f, NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "1");
	assert_int_equal(dwrite(f, 0, 0.5), 0);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(ballast(f, 1, 1).level, 229);
	assert_int_equal(ballast(f, 0, 1).level, 254);
	f->dev.drv->close(&f->dev);
	f->open = 0;
	f->transport = "usb";
	assert_int_equal(open_dev(f, "serial", "A1", NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "1");
	assert_int_equal(dwrite(f, 0, 0.1), 0);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(ballast(f, 0, 1).level, 170);
	assert_int_equal(ballast(f, 1, 1).level, 229);
	f->dev.drv->close(&f->dev);
	f->open = 0;
	assert_int_equal(psemu_unplug(f->emu, 0), 0);
	assert_int_equal(open_dev(f, NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "1");
	assert_int_equal(dwrite(f, 0, 0.1), 0);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(ballast(f, 1, 1).level, 170);
	f->dev.drv->close(&f->dev);
	f->open = 0;
	/* neither plugged in: the message names both */
	assert_int_equal(psemu_unplug(f->emu, 1), 0);
	assert_int_equal(open_dev(f, NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "1");
	assert_int_equal(dwrite(f, 0, 0.5), -1);
	assert_int_equal(errno, ENODEV);
	assert_non_null(strstr(f->dev.err, "no DALI USB interface (tridonic 17b5:0020, hasseb 04cc:0802) found"));
}

/* ---- the hasseb DALI Master's own paths ---------------------------------------------- */

/* Its sequence numbers run 1..255 and never 0 (the emulator drops a report
 * with 0, which would then time out); every report is answered under the
 * number it was sent with.  The firmware-version request at connect takes
 * number 1, so after it and N SENDs the last one carries N mod 255 + 1. */
static void hasseb_sequence_numbers_wrap_past_255(void **state)
{
	struct fx *f = *state;
	struct psemu_stats es;
	struct ps_dali_usb_stats st;
	assert_int_equal(open_dev(f, "frame_gap", "0", NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "0");
	assert_true(run_until(f, is_idle, 3));
	for (int k = 0; k < 300; k++) {
		assert_int_equal(dwrite(f, 0, k % 2 ? 0.5 : 0.25), 0);
		assert_true(run_until(f, is_idle, 3));
	}
	assert_int_equal(ballast(f, 0, 0).level, ps_dali_fraction_to_level(0.5));
	assert_int_equal(psemu_stats(f->emu, 0, &es), 0);
	st = stats(f);
	print_message("# %s: %u SENDs, last sequence number %u\n", model_name(f), es.sends, es.last_seq);
	assert_int_equal(es.sends, 301);          /* QUERY PHYSICAL MINIMUM and 300 DAPC */
	assert_int_equal(st.frames, es.sends);
	assert_int_equal(es.rejected, 0);
	assert_int_equal(es.version_requests, 1);
	assert_int_equal(es.last_seq, 301 % 255 + 1);
	assert_int_equal(st.timeouts, 0);
	assert_int_equal(st.failed, 0);
}

/* No DTR0 prefix: FADE TIME 2 s is DTR0 = 4 as a transaction of its own,
 * then SET FADE TIME sent twice (10 ms apart, inside the ballast's 100 ms),
 * 13.5 ms or more after DTR0's report. */
static void hasseb_dtr0_is_a_frame_of_its_own(void **state)
{
	struct fx *f = *state;
	struct psemu_stats es;
	struct psemu_ballast b;
	assert_int_equal(open_dev(f, "fade_time", "2", NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "0");
	assert_int_equal(dwrite(f, 0, 0.5), 0);
	assert_true(run_until(f, is_idle, 3));
	b = ballast(f, 0, 0);
	assert_int_equal(b.fade_time, 4);
	assert_int_equal(b.config_writes, 1);
	assert_int_equal(b.target, 229);
	assert_int_equal(psemu_stats(f->emu, 0, &es), 0);
	/* QUERY PHYSICAL MINIMUM, DTR0, SET FADE TIME (twice in one report), DAPC */
	assert_int_equal(es.sends, 4);
	assert_int_equal(es.bus_frames, 5);
	assert_int_equal(stats(f).frames, 4);
	assert_int_equal(es.gap_violations, 0);
	assert_int_equal(es.rejected, 0);
	assert_int_equal(stats(f).failed, 0);
}

/* Another master's frame on the bus before ours: the hasseb reports its
 * bytes sniffed under sequence number 0, the Tridonic as traffic of
 * another master; neither is taken for the answer to our query. */
static void another_masters_frame_is_not_an_answer(void **state)
{
	struct fx *f = *state;
	struct ps_dali_usb_stats st;
	double v = -1;
	assert_int_equal(open_dev(f, NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "1");
	assert_int_equal(dwrite(f, 0, ps_dali_level_to_fraction(170)), 0);
	assert_true(run_until(f, is_idle, 3));
	fade_clock += 10;
	psemu_fault(f->emu, 0, PSEMU_FAULT_OTHER_MASTER, 2);
	f->dev.drv->read(&f->dev, &f->pt[0], psd_time_mono(), psd_time_mono(), &v);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(f->dev.drv->read(&f->dev, &f->pt[0], psd_time_mono(), psd_time_mono(), &v), 0);
	assert_int_equal(ps_dali_fraction_to_level(v), 170);
	st = stats(f);
	assert_int_equal(st.retries, 0);
	assert_int_equal(st.failed, 0);
	assert_int_equal(st.garbled, 0);
}

/* A report under the previous sequence number (a late one of the last
 * transaction) in place of the query's own: not taken for its answer; the
 * query times out and its retry reads the ballast. */
static void a_stale_report_is_not_an_answer(void **state)
{
	struct fx *f = *state;
	struct ps_dali_usb_stats st;
	double v = -1;
	assert_int_equal(open_dev(f, "timeout", "0.05", NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "1");
	assert_int_equal(dwrite(f, 0, ps_dali_level_to_fraction(170)), 0);
	assert_true(run_until(f, is_idle, 3));
	fade_clock += 10;
	psemu_fault(f->emu, 0, PSEMU_FAULT_STALE, 1);
	f->dev.drv->read(&f->dev, &f->pt[0], psd_time_mono(), psd_time_mono(), &v);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(f->dev.drv->read(&f->dev, &f->pt[0], psd_time_mono(), psd_time_mono(), &v), 0);
	assert_int_equal(ps_dali_fraction_to_level(v), 170);   /* not 0x55 = 85 */
	st = stats(f);
	assert_int_equal(st.stray, 1);
	assert_int_equal(st.timeouts, 1);
	assert_int_equal(st.retries, 1);
	assert_int_equal(st.failed, 0);
}

/* A backward frame that began before the settling time (the hasseb's status
 * 4) is not a valid answer (IEC 62386-101: 5.5 ms at the least), and
 * nothing says several ballasts answered: the query is sent again and the
 * retry reads the ballast.  Too early on every try (1 + 2 retries) fails the
 * read as a bad answer named "answer too early", not as a garbled one. */
static void hasseb_an_answer_too_early_is_not_an_answer(void **state)
{
	struct fx *f = *state;
	struct ps_dali_usb_stats st;
	double v = -1;
	assert_int_equal(open_dev(f, "retries", "2", NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "1");
	assert_int_equal(dwrite(f, 0, ps_dali_level_to_fraction(170)), 0);
	assert_true(run_until(f, is_idle, 3));
	fade_clock += 10;
	psemu_fault(f->emu, 0, PSEMU_FAULT_EARLY, 1);
	f->dev.drv->read(&f->dev, &f->pt[0], psd_time_mono(), psd_time_mono(), &v);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(f->dev.drv->read(&f->dev, &f->pt[0], psd_time_mono(), psd_time_mono(), &v), 0);
	assert_int_equal(ps_dali_fraction_to_level(v), 170);
	st = stats(f);
	assert_int_equal(st.retries, 1);
	assert_int_equal(st.garbled, 1);
	assert_int_equal(st.timeouts, 0);
	assert_int_equal(st.failed, 0);
	/* the read above queued the next query; then too early on all three tries */
	assert_true(run_until(f, is_idle, 3));
	psemu_fault(f->emu, 0, PSEMU_FAULT_EARLY, 3);
	f->dev.drv->read(&f->dev, &f->pt[0], psd_time_mono(), psd_time_mono(), &v);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(f->dev.drv->read(&f->dev, &f->pt[0], psd_time_mono(), psd_time_mono(), &v), -1);
	assert_int_equal(errno, EPROTO);
	assert_non_null(strstr(f->dev.err, "answer too early"));
	assert_non_null(strstr(f->dev.err, "3 tries"));
	st = stats(f);
	assert_int_equal(st.retries, 3);
	assert_int_equal(st.garbled, 4);
	assert_int_equal(st.failed, 1);
	/* the next query is answered again */
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(f->dev.drv->read(&f->dev, &f->pt[0], psd_time_mono(), psd_time_mono(), &v), 0);
	assert_int_equal(ps_dali_fraction_to_level(v), 170);
}

/* psensctl dali DEV status: the device's report (JSON) in f->out */
static const char *status_json(struct fx *f)
{
	static char out[8192];
	char buf[] = "status", *w[1] = { buf };
	if (f->dev.drv->command(&f->dev, 1, w, NULL, 0, psd_time_mono(), psd_time_mono(), out, sizeof out) != 0)
		fail_msg("status: %s", f->dev.err);
	return out;
}

/* The driver asks the hasseb for its firmware version once per connect
 * (no transaction waits for it); the version the emulated device is given,
 * 3.7, reaches the stats and the status report, and is asked again after a
 * replug (a swapped device may run another). */
static void hasseb_firmware_version_reaches_the_status(void **state)
{
	struct fx *f = *state;
	struct psemu_stats es;
	char err[256];
	assert_int_equal(psemu_hasseb_version(f->emu, 0, 3, 7), 0);
	assert_int_equal(open_dev(f, NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "0");
	assert_int_equal(dwrite(f, 0, 0.5), 0);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(stats(f).firmware, 3 << 8 | 7);
	assert_non_null(strstr(status_json(f), "\"firmware\":\"3.7\""));
	assert_int_equal(psemu_stats(f->emu, 0, &es), 0);
	assert_int_equal(es.version_requests, 1);
	assert_int_equal(es.rejected, 0);
	assert_int_equal(ballast(f, 0, 0).level, 229);
	/* replugged with other firmware: the new version, asked anew */
	assert_int_equal(psemu_unplug(f->emu, 0), 0);
	assert_true(run_until(f, is_down, 5));
	assert_int_equal(psemu_hasseb_version(f->emu, 0, 4, 12), 0);
	assert_int_equal(psemu_replug(f->emu, 0, err, sizeof err), 0);
	assert_true(run_until(f, is_connected, 5));
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(stats(f).firmware, 4 << 8 | 12);
	assert_non_null(strstr(status_json(f), "\"firmware\":\"4.12\""));
	assert_int_equal(psemu_stats(f->emu, 0, &es), 0);
	assert_int_equal(es.version_requests, 2);
}

/* The Tridonic has no version request here: none is sent, none reported. */
static void tridonic_firmware_version_is_unknown(void **state)
{
	struct fx *f = *state;
	assert_int_equal(open_dev(f, NULL), 0);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(stats(f).firmware, -1);
	assert_non_null(strstr(status_json(f), "\"firmware\":null"));
}

/* An unasked version report under the query's own sequence number, before
 * the transmission report: not the answer (the query reads the ballast,
 * with no retry and nothing stray), and the version is recorded. */
static void hasseb_an_unasked_version_report_is_not_an_answer(void **state)
{
	struct fx *f = *state;
	struct ps_dali_usb_stats st;
	double v = -1;
	assert_int_equal(open_dev(f, "timeout", "0.05", NULL), 0);
	add_point(f, 0, PS_ROLE_DIM, "1");
	assert_int_equal(dwrite(f, 0, ps_dali_level_to_fraction(170)), 0);
	assert_true(run_until(f, is_idle, 3));
	fade_clock += 10;
	assert_int_equal(psemu_hasseb_version(f->emu, 0, 9, 1), 0);
	psemu_fault(f->emu, 0, PSEMU_FAULT_VERSION, 1);
	f->dev.drv->read(&f->dev, &f->pt[0], psd_time_mono(), psd_time_mono(), &v);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(f->dev.drv->read(&f->dev, &f->pt[0], psd_time_mono(), psd_time_mono(), &v), 0);
	assert_int_equal(ps_dali_fraction_to_level(v), 170);   /* not 9 nor 1 */
	st = stats(f);
	assert_int_equal(st.firmware, 9 << 8 | 1);
	assert_int_equal(st.retries, 0);
	assert_int_equal(st.timeouts, 0);
	assert_int_equal(st.stray, 0);
	assert_int_equal(st.garbled, 0);
	/* in place of the transmission report: the query times out and its
	 * retry reads the ballast (first the query the read above queued) */
	assert_true(run_until(f, is_idle, 3));
	psemu_fault(f->emu, 0, PSEMU_FAULT_VERSION_ONLY, 1);
	f->dev.drv->read(&f->dev, &f->pt[0], psd_time_mono(), psd_time_mono(), &v);
	assert_true(run_until(f, is_idle, 3));
	assert_int_equal(f->dev.drv->read(&f->dev, &f->pt[0], psd_time_mono(), psd_time_mono(), &v), 0);
	assert_int_equal(ps_dali_fraction_to_level(v), 170);
	st = stats(f);
	assert_int_equal(st.timeouts, 1);
	assert_int_equal(st.retries, 1);
	assert_int_equal(st.failed, 0);
}

int main(int argc, char **argv)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(tridonic_send_report),
		cmocka_unit_test(tridonic_reports),
		cmocka_unit_test_setup_teardown(opens_detaches_and_claims, setup, teardown),
		cmocka_unit_test_setup_teardown(levels_reach_the_ballasts, setup, teardown),
		cmocka_unit_test_setup_teardown(the_latest_write_wins_and_frames_keep_the_bus_rate, setup, teardown),
		cmocka_unit_test_setup_teardown(query_answers_follow_the_fade, setup, teardown),
		cmocka_unit_test_setup_teardown(a_query_before_the_command_is_stale, setup, teardown),
		cmocka_unit_test_setup_teardown(physical_minimum_is_respected, setup, teardown),
		cmocka_unit_test_setup_teardown(relay_points_switch, setup, teardown),
		cmocka_unit_test_setup_teardown(broadcast_query_collides, setup, teardown),
		cmocka_unit_test_setup_teardown(faults_are_retried, setup, teardown),
		cmocka_unit_test_setup_teardown(silence_fails_after_the_retries, setup, teardown),
		cmocka_unit_test_setup_teardown(safe_level_unplug_and_replug, setup, teardown),
		cmocka_unit_test_setup_teardown(unplug_in_the_middle_of_a_transfer, setup, teardown),
		cmocka_unit_test_setup_teardown(absent_at_open_then_found, setup, teardown),
		cmocka_unit_test_setup_teardown(two_interfaces_need_a_choice, setup_two, teardown),
		cmocka_unit_test_setup_teardown(a_second_claim_is_refused, setup, teardown),
		cmocka_unit_test_setup_teardown(bad_options_name_file_and_line, setup, teardown),
		cmocka_unit_test_setup_teardown(a_simulated_day_with_the_control_law, setup, teardown),
		cmocka_unit_test_setup_teardown(another_masters_frame_is_not_an_answer, setup, teardown),
		cmocka_unit_test_setup_teardown(a_stale_report_is_not_an_answer, setup, teardown),
		/* the same cases on the hasseb DALI Master */
		cmocka_unit_test_setup_teardown(opens_detaches_and_claims, setup_hasseb, teardown),
		cmocka_unit_test_setup_teardown(levels_reach_the_ballasts, setup_hasseb, teardown),
		cmocka_unit_test_setup_teardown(the_latest_write_wins_and_frames_keep_the_bus_rate, setup_hasseb, teardown),
		cmocka_unit_test_setup_teardown(query_answers_follow_the_fade, setup_hasseb, teardown),
		cmocka_unit_test_setup_teardown(a_query_before_the_command_is_stale, setup_hasseb, teardown),
		cmocka_unit_test_setup_teardown(physical_minimum_is_respected, setup_hasseb, teardown),
		cmocka_unit_test_setup_teardown(relay_points_switch, setup_hasseb, teardown),
		cmocka_unit_test_setup_teardown(broadcast_query_collides, setup_hasseb, teardown),
		cmocka_unit_test_setup_teardown(faults_are_retried, setup_hasseb, teardown),
		cmocka_unit_test_setup_teardown(silence_fails_after_the_retries, setup_hasseb, teardown),
		cmocka_unit_test_setup_teardown(safe_level_unplug_and_replug, setup_hasseb, teardown),
		cmocka_unit_test_setup_teardown(unplug_in_the_middle_of_a_transfer, setup_hasseb, teardown),
		cmocka_unit_test_setup_teardown(absent_at_open_then_found, setup_hasseb, teardown),
		cmocka_unit_test_setup_teardown(two_interfaces_need_a_choice, setup_two_hasseb, teardown),
		cmocka_unit_test_setup_teardown(a_second_claim_is_refused, setup_hasseb, teardown),
		cmocka_unit_test_setup_teardown(a_simulated_day_with_the_control_law, setup_hasseb, teardown),
		/* transport = usb: the interface by its VID:PID */
		cmocka_unit_test_setup_teardown(usb_takes_either_interface, setup_mixed, teardown),
		cmocka_unit_test_setup_teardown(levels_reach_the_ballasts, setup_usb_hasseb, teardown),
		cmocka_unit_test_setup_teardown(safe_level_unplug_and_replug, setup_usb_hasseb, teardown),
		cmocka_unit_test_setup_teardown(hasseb_dtr0_is_a_frame_of_its_own, setup_usb_hasseb, teardown),
		cmocka_unit_test_setup_teardown(another_masters_frame_is_not_an_answer, setup_hasseb, teardown),
		cmocka_unit_test_setup_teardown(a_stale_report_is_not_an_answer, setup_hasseb, teardown),
		cmocka_unit_test_setup_teardown(hasseb_an_answer_too_early_is_not_an_answer, setup_hasseb, teardown),
		cmocka_unit_test_setup_teardown(hasseb_an_unasked_version_report_is_not_an_answer, setup_hasseb, teardown),
		cmocka_unit_test_setup_teardown(hasseb_firmware_version_reaches_the_status, setup_hasseb, teardown),
		cmocka_unit_test_setup_teardown(tridonic_firmware_version_is_unknown, setup, teardown),
		cmocka_unit_test_setup_teardown(hasseb_sequence_numbers_wrap_past_255, setup_hasseb, teardown),
		cmocka_unit_test_setup_teardown(hasseb_dtr0_is_a_frame_of_its_own, setup_hasseb, teardown),
	};
	(void)argc;
	ps_test_need_umockdev(argv);
	return cmocka_run_group_tests(tests, NULL, NULL);
}

#else
int main(void)
{
	printf("the DALI USB driver or umockdev was not built in (libusb-1.0, umockdev-1.0)\n");
	return 77;
}
#endif
