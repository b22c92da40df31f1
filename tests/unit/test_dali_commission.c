/* SPDX-License-Identifier: ISC */
/* DALI commissioning (drivers/dali_commission.c) through the dali_usb
 * driver's command method, with real libusb against the emulated Tridonic
 * interface and its ballasts (tests/emu): the bus scan, the random-address
 * search with unaddressed ballasts, two that drew the same random address,
 * one that goes quiet mid-search, ballasts sharing a short address,
 * INITIALISE's 15-minute window, groups, identify, verify, abort and
 * unplug, and zones dimmed between the search's frames; the scan, the
 * search and a colliding pair again on the emulated hasseb DALI Master.
 * Every outcome is read from the emulator's ballasts, not from the code
 * under test. */
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

#include "dali.h"
#include "dali_commission.h"
#include "dali_emu.h"
#include "dali_usb.h"
#include "driver.h"
#include "registry.h"
#include "helpers/dali_preload.h"
#include "helpers/test_opts.h"
#include "time.h"

static double fade_clock;   /* the ballasts' clock (fades, INITIALISE's window) */
static double skew;         /* seconds added to the driver's clock: both jump together */

static double get_fade_clock(void *user)
{
	(void)user;
	return fade_clock;
}

static double now_s(void)
{
	return psd_time_mono() + skew;
}

struct fx {
	struct psemu *emu;
	struct ps_dev dev;
	struct ps_test_opts o;
	struct ps_point pt[4];
	struct ps_opt po[4];
	struct ps_opts popts[4];
	int open;
	int model;   /* enum psemu_model of the emulated interface */
	char out[32768];
};

static struct fx F;

/* an interface with n ballasts, all at short addresses 0..n-1 to begin with */
static int setup_model(void **state, int n, int model)
{
	char err[256];
	memset(&F, 0, sizeof F);
	F.model = model;
	F.emu = psemu_new(err, sizeof err);
	if (!F.emu)
		fail_msg("%s", err);
	if (psemu_add_model(F.emu, model, 1, "A1", n, err, sizeof err) != 0)
		fail_msg("%s", err);
	fade_clock = 1000;
	skew = 0;
	psemu_set_clock(F.emu, get_fade_clock, NULL);
	*state = &F;
	return 0;
}

static int setup_n(void **state, int n)
{
	return setup_model(state, n, PSEMU_TRIDONIC);
}

static int setup6_hasseb(void **state)
{
	return setup_model(state, 6, PSEMU_HASSEB);
}

static int setup6(void **state)
{
	return setup_n(state, 6);
}

static int setup10(void **state)
{
	return setup_n(state, 10);
}

static int setup64(void **state)
{
	return setup_n(state, 64);
}

static int teardown(void **state)
{
	struct fx *f = *state;
	if (f->open)
		f->dev.drv->close(&f->dev);
	psemu_free(f->emu);
	return 0;
}

/* open dali_usb with key, value, ..., NULL */
static void open_dev(struct fx *f, ...)
{
	va_list ap;
	const struct ps_opts *opts;
	memset(&f->dev, 0, sizeof f->dev);
	f->dev.drv = ps_registry_find("dali_usb");
	assert_non_null(f->dev.drv);
	assert_non_null(f->dev.drv->command);
	snprintf(f->dev.name, sizeof f->dev.name, "dali");
	va_start(ap, f);
	opts = ps_test_vopts(&f->o, "test.conf", 10, ap);
	va_end(ap);
	if (f->model == PSEMU_HASSEB) {
		assert_true(f->o.o.n < PS_TEST_OPTS_MAX);
		f->o.v[f->o.o.n] = (struct ps_opt){ "transport", "hasseb", 9, 0 };
		f->o.o.n++;
	}
	if (f->dev.drv->open(&f->dev, opts) != 0)
		fail_msg("open: %s", f->dev.err);
	f->open = 1;
}

static void add_point(struct fx *f, int i, const char *addr)
{
	snprintf(f->pt[i].name, sizeof f->pt[i].name, "p%d", i);
	f->pt[i].role = PS_ROLE_DIM;
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

static const struct ps_dali_commission *job(struct fx *f)
{
	const struct ps_dali_commission *c = ps_dali_usb_job(&f->dev);
	assert_non_null(c);
	return c;
}

static int is_idle(struct fx *f)
{
	struct ps_dali_usb_stats st = stats(f);
	return st.connected && st.pending == 0 && !st.job_running;
}

static int job_ended(struct fx *f)
{
	return !stats(f).job_running;
}

static int is_connected(struct fx *f)
{
	return stats(f).connected;
}

/* the daemon's loop in small: poll the driver's fd until its deadline */
static int run_until(struct fx *f, int (*pred)(struct fx *), double limit)
{
	double end = now_s() + limit;
	for (;;) {
		double t = now_s(), dl, m;
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

/* a request as psensctl sends it after "dali DEVICE", with the first npts
 * points (a zone's outputs): 0 or -1 (errno, dev.err) */
static int request_pts(struct fx *f, const char *line, int npts)
{
	char buf[256], *w[8];
	int n = 0;
	struct ps_point *pts[4] = { &f->pt[0], &f->pt[1], &f->pt[2], &f->pt[3] };
	snprintf(buf, sizeof buf, "%s", line);
	for (char *s = strtok(buf, " "); s && n < 8; s = strtok(NULL, " "))
		w[n++] = s;
	return f->dev.drv->command(&f->dev, n, w, pts, npts, now_s(), now_s(), f->out, sizeof f->out);
}

static int request(struct fx *f, const char *line)
{
	return request_pts(f, line, 0);
}

static void run_job(struct fx *f, const char *line, double limit)
{
	if (request(f, line) != 0)
		fail_msg("%s: %s", line, f->dev.err);
	if (!run_until(f, job_ended, limit))
		fail_msg("%s: still running after %g s: %s", line, limit, job(f)->step);
}

static struct psemu_ballast ballast(struct fx *f, int slot)
{
	struct psemu_ballast b;
	assert_int_equal(psemu_ballast(f->emu, 0, slot, &b), 0);
	return b;
}

static struct psemu_stats emu_stats(struct fx *f)
{
	struct psemu_stats st;
	assert_int_equal(psemu_stats(f->emu, 0, &st), 0);
	return st;
}

static void identity(struct fx *f, int slot, int short_addr, unsigned random_addr, double reply_ms)
{
	assert_int_equal(psemu_ballast_identity(f->emu, 0, slot, short_addr, random_addr, reply_ms), 0);
}

static void draws(struct fx *f, int slot, unsigned value)
{
	assert_int_equal(psemu_ballast_randoms(f->emu, 0, slot, &value, 1), 0);
}

/* every present, living ballast has a short address, no two the same */
static void assert_unique_addresses(struct fx *f, int n, int skip_slot)
{
	uint64_t seen = 0;
	for (int s = 0; s < n; s++) {
		struct psemu_ballast b = ballast(f, s);
		if (s == skip_slot)
			continue;
		if (b.short_addr < 0)
			fail_msg("slot %d has no short address", s);
		if (seen & ((uint64_t)1 << b.short_addr))
			fail_msg("slot %d: short address %d given twice", s, b.short_addr);
		seen |= (uint64_t)1 << b.short_addr;
		assert_int_equal(b.init_state, PSEMU_INIT_DISABLED);   /* TERMINATE closed the search */
	}
}

/* ---- scan ------------------------------------------------------------------------------ */

static void scan_reads_every_setting(void **state)
{
	struct fx *f = *state;
	const struct ps_dali_commission *c;
	/* slots 0..2 at 0, 9, 17 with their own groups and minimums; 3 and 4 share
	 * 30 and answer out of step; 5 has no short address */
	identity(f, 1, 9, 0xFFFFFF, 8.0);
	identity(f, 2, 17, 0xFFFFFF, 8.0);
	identity(f, 3, 30, 0xFFFFFF, 6.0);
	identity(f, 4, 30, 0xFFFFFF, 9.5);
	identity(f, 5, -1, 0xFFFFFF, 8.0);
	psemu_ballast_setup(f->emu, 0, 0, 1u << 0 | 1u << 3, 85);
	psemu_ballast_setup(f->emu, 0, 1, 1u << 15, 120);
	psemu_ballast_setup(f->emu, 0, 2, 0, 1);
	open_dev(f, "frame_gap", "0", "fade_time", "2", NULL);
	add_point(f, 0, "9");
	assert_int_equal(f->dev.drv->write(&f->dev, &f->pt[0], now_s(), now_s(), 0.5), 0);
	assert_true(run_until(f, is_idle, 3));
	fade_clock += 5;   /* its 2 s fade to 229 is over */
	run_job(f, "scan", 20);
	c = job(f);
	assert_int_equal(c->state, PS_DALI_COMMISSION_DONE);
	assert_int_equal(c->scanned, 64);
	for (int s = 0; s < 3; s++) {
		struct psemu_ballast b = ballast(f, s);
		const struct ps_dali_gear *g = &c->gear[b.short_addr];
		assert_int_equal(g->present, 1);
		assert_int_equal(g->device_type, b.device_type);
		assert_int_equal(g->phys_min, b.phys_min);
		assert_int_equal(g->min_level, b.min_level);
		assert_int_equal(g->max_level, b.max_level);
		assert_int_equal(g->fade >> 4, b.fade_time);
		assert_int_equal(g->fade & 15, b.fade_rate);
		assert_int_equal(g->groups, (int)b.groups);
		assert_int_equal(g->sfl, b.sfl);
		assert_int_equal(g->power_on, b.power_on_level);
		assert_int_equal(g->actual, b.level);
	}
	/* the point's fade_time reached short 9 only: FADE TIME code 4 (2 s) */
	assert_int_equal(ballast(f, 1).fade_time, 4);
	assert_int_equal(ballast(f, 1).level, 229);
	assert_int_equal(c->gear[30].present, 2);       /* two ballasts, answers out of step */
	assert_int_equal(c->unaddressed, 1);
	for (int a = 0; a < 64; a++)
		if (a != 0 && a != 9 && a != 17 && a != 30)
			assert_int_equal(c->gear[a].present, 0);
	assert_non_null(strstr(f->out, "\"job\":\"scan\""));
}

/* A scan's first query answered too early (the hasseb's status 4): not a
 * garbled answer, so not read as "several gear answered" (present = 2) but
 * asked again; the scan finds the six ballasts at 0..5 and nothing else. */
static void an_answer_too_early_is_asked_again(void **state)
{
	struct fx *f = *state;
	const struct ps_dali_commission *c;
	open_dev(f, "frame_gap", "0", NULL);
	assert_true(run_until(f, is_idle, 3));
	psemu_fault(f->emu, 0, PSEMU_FAULT_EARLY, 1);
	run_job(f, "scan", 20);
	c = job(f);
	assert_int_equal(c->state, PS_DALI_COMMISSION_DONE);
	assert_int_equal(c->scanned, 64);
	for (int a = 0; a < 64; a++)
		assert_int_equal(c->gear[a].present, a < 6);
	assert_int_equal(c->unaddressed, 0);
	assert_int_equal(stats(f).retries, 1);
	assert_int_equal(stats(f).garbled, 1);
	assert_int_equal(stats(f).failed, 0);
}

/* ---- address ----------------------------------------------------------------------------- */

static void address_new_at_the_bus_rate(void **state)
{
	struct fx *f = *state;
	const struct ps_dali_commission *c;
	static const unsigned rnd[6] = { 0, 0, 0x800000, 0x123456, 0xFFFFFE, 0x000001 };
	struct psemu_stats es;
	double t0;
	/* slots 0 and 1 keep 0 and 2; four without an address draw these */
	identity(f, 1, 2, 0xFFFFFF, 8.0);
	for (int s = 2; s < 6; s++) {
		identity(f, s, -1, 0xFFFFFF, 8.0);
		draws(f, s, rnd[s]);
	}
	open_dev(f, NULL);   /* the real frame gap, 22 ms */
	t0 = now_s();
	run_job(f, "address new", 60);
	c = job(f);
	es = emu_stats(f);
	print_message("# 4 ballasts addressed in %.2f s, %lu transactions, %u on the bus (%.2f s of bus time)\n",
	              now_s() - t0, c->frames, es.bus_frames, es.bus_time);
	assert_int_equal(c->state, PS_DALI_COMMISSION_DONE);
	assert_int_equal(ballast(f, 0).short_addr, 0);
	assert_int_equal(ballast(f, 1).short_addr, 2);
	/* the lowest random address gets the lowest free short address */
	assert_int_equal(ballast(f, 5).short_addr, 1);
	assert_int_equal(ballast(f, 3).short_addr, 3);
	assert_int_equal(ballast(f, 2).short_addr, 4);
	assert_int_equal(ballast(f, 4).short_addr, 5);
	assert_unique_addresses(f, 6, -1);
	assert_int_equal(c->programmed, 4);
	assert_int_equal(c->nfound, 4);
	assert_int_equal(c->clashes, 0);
	assert_int_equal(es.early_compares, 0);       /* 100 ms after RANDOMISE */
	assert_int_equal(es.gap_violations, 0);       /* the bus's settling time */
	assert_int_equal(stats(f).failed, 0);
}

static void colliding_random_addresses_are_separated(void **state)
{
	struct fx *f = *state;
	const struct ps_dali_commission *c;
	/* slots 1 and 4 draw the same random address and answer 3 ms apart */
	for (int s = 0; s < 6; s++)
		identity(f, s, -1, 0xFFFFFF, s == 4 ? 9.5 : 6.5);
	draws(f, 0, 0x300000);
	draws(f, 1, 0x5A5A5A);
	draws(f, 2, 0x000100);
	draws(f, 3, 0xC00000);
	draws(f, 4, 0x5A5A5A);
	draws(f, 5, 0x7FFFFF);
	open_dev(f, "frame_gap", "0", NULL);
	run_job(f, "address", 60);
	c = job(f);
	assert_int_equal(c->state, PS_DALI_COMMISSION_DONE);
	assert_unique_addresses(f, 6, -1);
	assert_true(c->clashes >= 1);
	assert_int_equal(c->programmed, 6);
	assert_true(emu_stats(f).collisions >= 1);
	/* the two drew again (their own generators): distinct now */
	assert_int_not_equal(ballast(f, 1).random, ballast(f, 4).random);
}

static void twins_in_step_need_address_all(void **state)
{
	struct fx *f = *state;
	const struct ps_dali_commission *c;
	/* slots 2 and 3 drew the same address and answer in step: their two
	 * "yes" frames add up to one clean frame, so nothing on the bus shows
	 * there are two.  address new gives both the same short address... */
	for (int s = 0; s < 6; s++)
		identity(f, s, s < 2 ? s : -1, 0xFFFFFF, 8.0);
	draws(f, 2, 0x444444);
	draws(f, 3, 0x444444);
	draws(f, 4, 0x100000);
	draws(f, 5, 0xA00000);
	open_dev(f, "frame_gap", "0", NULL);
	run_job(f, "address new", 60);
	assert_int_equal(job(f)->state, PS_DALI_COMMISSION_DONE);
	assert_int_equal(ballast(f, 2).short_addr, ballast(f, 3).short_addr);
	/* ... and address all draws new random addresses for everybody: the
	 * twins come apart, the one found second gets a free address */
	run_job(f, "address all", 60);
	c = job(f);
	assert_int_equal(c->state, PS_DALI_COMMISSION_DONE);
	assert_unique_addresses(f, 6, -1);
	assert_int_equal(c->nfound, 6);
	assert_int_equal(c->kept, 5);
	assert_int_equal(c->programmed, 1);
	assert_int_equal(ballast(f, 0).short_addr, 0);
	assert_int_equal(ballast(f, 1).short_addr, 1);
}

static void a_ballast_going_quiet_mid_search(void **state)
{
	struct fx *f = *state;
	const struct ps_dali_commission *c;
	/* slot 2 has the lowest random address and stops answering after six
	 * backward frames (COMPARE at FFFFFF, 7FFFFF, 3FFFFF, 1FFFFF, 0FFFFF,
	 * 07FFFF): its binary search ends at 07FFFF, where nobody is */
	for (int s = 0; s < 6; s++)
		identity(f, s, -1, 0xFFFFFF, 8.0);
	draws(f, 0, 0x200000);
	draws(f, 1, 0x900000);
	draws(f, 2, 0x010000);
	draws(f, 3, 0x400000);
	draws(f, 4, 0xE00000);
	draws(f, 5, 0x600000);
	assert_int_equal(psemu_ballast_dead_after(f->emu, 0, 2, 6), 0);
	open_dev(f, "frame_gap", "0", NULL);
	run_job(f, "address", 60);
	c = job(f);
	assert_int_equal(c->state, PS_DALI_COMMISSION_DONE);
	assert_true(ballast(f, 2).dead);
	assert_int_equal(ballast(f, 2).short_addr, -1);
	assert_unique_addresses(f, 6, 2);
	assert_true(c->restarts >= 1);
	assert_int_equal(c->programmed, 5);
	print_message("# %s\n", c->msg);
}

static void shared_short_addresses_are_split(void **state)
{
	struct fx *f = *state;
	const struct ps_dali_commission *c;
	int a3, b3;
	/* slots 1 and 2 both at 3 (answers out of step), slot 3 at 10, slots 4
	 * and 5 without an address, slot 0 at 0 */
	identity(f, 1, 3, 0xFFFFFF, 6.0);
	identity(f, 2, 3, 0xFFFFFF, 10.0);
	identity(f, 3, 10, 0xFFFFFF, 8.0);
	identity(f, 4, -1, 0xFFFFFF, 8.0);
	identity(f, 5, -1, 0xFFFFFF, 8.0);
	draws(f, 1, 0x300000);
	draws(f, 2, 0x200000);
	draws(f, 4, 0x100000);
	draws(f, 5, 0x400000);
	open_dev(f, "frame_gap", "0", NULL);
	run_job(f, "address new", 60);
	c = job(f);
	assert_int_equal(c->state, PS_DALI_COMMISSION_DONE);
	assert_unique_addresses(f, 6, -1);
	assert_int_equal(ballast(f, 0).short_addr, 0);
	assert_int_equal(ballast(f, 3).short_addr, 10);
	/* the one of the pair found first (lower random address) keeps 3 */
	a3 = ballast(f, 2).short_addr;
	b3 = ballast(f, 1).short_addr;
	assert_int_equal(a3, 3);
	assert_int_not_equal(b3, 3);
	assert_int_equal(c->kept, 1);
	assert_int_equal(c->programmed, 3);
	/* slots 0 and 3 were never in the search (INITIALISE unaddressed + short 3) */
	assert_int_equal(ballast(f, 0).random, 0xFFFFFF);
	assert_int_equal(ballast(f, 3).random, 0xFFFFFF);
}

static void initialise_is_renewed_within_its_15_minutes(void **state)
{
	struct fx *f = *state;
	const struct ps_dali_commission *c;
	for (int s = 0; s < 10; s++)
		identity(f, s, -1, 0xFFFFFF, 8.0);
	open_dev(f, "frame_gap", "0", NULL);
	assert_int_equal(request(f, "address"), 0);
	/* time passes at three moments of the search, both for the ballasts'
	 * window and the driver: 700 s, then 110 s, then 500 s (1310 s in all,
	 * more than the 900 s one INITIALISE opens) */
	for (int k = 0; k < 3; k++) {
		static const double jump[3] = { 700, 110, 500 };
		int want = 2 + 3 * k;
		while (job(f)->nfound < want && job(f)->state == PS_DALI_COMMISSION_RUNNING)
			run_until(f, job_ended, 0.05);
		fade_clock += jump[k];
		skew += jump[k];
	}
	assert_true(run_until(f, job_ended, 60));
	c = job(f);
	assert_int_equal(c->state, PS_DALI_COMMISSION_DONE);
	assert_int_equal(c->inits, 2);
	assert_int_equal(c->programmed, 10);
	assert_unique_addresses(f, 10, -1);
}

static void zones_are_dimmed_between_search_frames(void **state)
{
	struct fx *f = *state;
	/* slot 0 keeps short 0 and is a zone's output; nine others are new */
	for (int s = 1; s < 10; s++)
		identity(f, s, -1, 0xFFFFFF, 8.0);
	open_dev(f, NULL);
	add_point(f, 0, "0");
	assert_int_equal(request(f, "address"), 0);
	assert_true(run_until(f, is_connected, 1));
	while (job(f)->nfound < 1)
		run_until(f, job_ended, 0.05);
	assert_int_equal(f->dev.drv->write(&f->dev, &f->pt[0], now_s(), now_s(), 0.1), 0);
	run_until(f, job_ended, 0.3);
	/* the zone's level is on its ballast while the search goes on */
	assert_int_equal(ballast(f, 0).level, 170);
	assert_int_equal(job(f)->state, PS_DALI_COMMISSION_RUNNING);
	assert_true(job(f)->nfound < 9);
	assert_true(run_until(f, job_ended, 60));
	assert_int_equal(job(f)->programmed, 9);
	assert_unique_addresses(f, 10, -1);
	assert_int_equal(emu_stats(f).gap_violations, 0);
}

static void sixty_four_ballasts(void **state)
{
	struct fx *f = *state;
	const struct ps_dali_commission *c;
	struct psemu_stats es;
	double t0;
	/* settling times spread over 5.5 to 10.5 ms, as gear from the field's
	 * makers: two "yes" at once are garbled, which the search uses */
	for (int s = 0; s < 64; s++)
		identity(f, s, -1, 0xFFFFFF, 5.5 + fmod(s * 0.37, 5.0));
	open_dev(f, "frame_gap", "0", NULL);
	t0 = now_s();
	run_job(f, "address", 120);
	c = job(f);
	es = emu_stats(f);
	print_message("# 64 ballasts: %lu transactions, %u frames on the bus, %.1f s of bus time (%.1f s here, no frame gap)\n",
	              c->frames, es.bus_frames, es.bus_time, now_s() - t0);
	assert_int_equal(c->state, PS_DALI_COMMISSION_DONE);
	assert_int_equal(c->programmed, 64);
	assert_unique_addresses(f, 64, -1);
	/* all 64 taken: a scan sees every one, none without an address */
	run_job(f, "scan", 60);
	assert_int_equal(job(f)->unaddressed, 0);
	for (int a = 0; a < 64; a++)
		assert_int_equal(job(f)->gear[a].present, 1);
}

static void nothing_to_address(void **state)
{
	struct fx *f = *state;
	open_dev(f, "frame_gap", "0", NULL);
	run_job(f, "address new", 20);
	assert_int_equal(job(f)->state, PS_DALI_COMMISSION_DONE);
	assert_int_equal(job(f)->inits, 0);   /* no search was opened */
	assert_non_null(strstr(job(f)->msg, "nothing to do"));
	for (int s = 0; s < 6; s++)
		assert_int_equal(ballast(f, s).short_addr, s);
}

/* ---- groups, identify, verify ------------------------------------------------------------- */

static void groups_are_added_and_removed(void **state)
{
	struct fx *f = *state;
	open_dev(f, "frame_gap", "0", NULL);
	run_job(f, "group 4 add 3", 5);
	assert_int_equal(job(f)->state, PS_DALI_COMMISSION_DONE);
	assert_int_equal(ballast(f, 4).groups, 1u << 3);
	run_job(f, "group 4 add 12", 5);
	assert_int_equal(ballast(f, 4).groups, 1u << 3 | 1u << 12);
	assert_int_equal(job(f)->groups_after, 1 << 3 | 1 << 12);
	run_job(f, "group 4 remove 3", 5);
	assert_int_equal(ballast(f, 4).groups, 1u << 12);
	assert_int_equal(ballast(f, 3).groups, 0u);   /* nobody else */
	run_job(f, "group broadcast add 7", 5);
	for (int s = 0; s < 6; s++)
		assert_true(ballast(f, s).groups & 1u << 7);
	/* nobody at 40: the check afterwards says so */
	run_job(f, "group 40 add 1", 5);
	assert_int_equal(job(f)->state, PS_DALI_COMMISSION_FAILED);
	assert_non_null(strstr(job(f)->msg, "no ballast answers"));
	/* bad requests start nothing and keep the last report */
	assert_int_equal(request(f, "group 4 add 16"), -1);
	assert_int_equal(errno, EINVAL);
	assert_int_equal(request(f, "group 4 move 1"), -1);
	assert_int_equal(request(f, "identify 64"), -1);
	assert_int_equal(request(f, "frobnicate"), -1);
	assert_non_null(strstr(f->dev.err, "usage"));
	assert_int_equal(job(f)->kind, PS_DALI_COMMISSION_GROUP);
}

static void identify_flashes_one_ballast_and_restores_it(void **state)
{
	struct fx *f = *state;
	unsigned before[6];
	open_dev(f, "frame_gap", "0", NULL);
	add_point(f, 0, "broadcast");
	add_point(f, 1, "1");
	assert_int_equal(f->dev.drv->write(&f->dev, &f->pt[0], now_s(), now_s(), 0.5), 0);
	assert_true(run_until(f, is_idle, 3));
	for (int s = 0; s < 6; s++)
		before[s] = ballast(f, s).level_changes;
	assert_int_equal(request(f, "identify 2 2"), 0);
	run_until(f, job_ended, 0.7);
	/* mid-flash: the broadcast point reaches slot 2, so its write waits; the
	 * point at short 1 does not, and goes at once */
	assert_int_equal(f->dev.drv->write(&f->dev, &f->pt[0], now_s(), now_s(), 0.3), 0);
	assert_int_equal(f->dev.drv->write(&f->dev, &f->pt[1], now_s(), now_s(), 0.1), 0);
	run_until(f, job_ended, 0.3);
	assert_int_equal(job(f)->state, PS_DALI_COMMISSION_RUNNING);
	assert_int_equal(ballast(f, 1).level, 170);
	assert_int_equal(ballast(f, 0).level, 229);
	assert_true(run_until(f, job_ended, 5));
	assert_int_equal(job(f)->state, PS_DALI_COMMISSION_DONE);
	assert_int_equal(job(f)->flashes, 2);
	/* 2 s at 0.5 s a half: MAX, MIN, MAX, MIN, back to 229, and the held 30 % */
	assert_int_equal(ballast(f, 2).level_changes - before[2], 6);
	/* the held write went out after: everybody on the broadcast at 30 % */
	assert_true(run_until(f, is_idle, 3));
	for (int s = 0; s < 6; s++)
		if (s != 2 && s != 1)
			assert_int_equal(ballast(f, s).level_changes, before[s] + 1);
	for (int s = 0; s < 6; s++)
		if (s != 1)
			assert_int_equal(ballast(f, s).level, ps_dali_fraction_to_level(0.3));
	/* nobody there */
	run_job(f, "identify 33", 3);
	assert_int_equal(job(f)->state, PS_DALI_COMMISSION_FAILED);
	assert_non_null(strstr(job(f)->msg, "no ballast answers at short address 33"));
}

static void verify_reports_who_follows(void **state)
{
	struct fx *f = *state;
	const struct ps_dali_commission *c;
	struct psemu_ballast b0;
	/* a zone: group 1 (slots 0 and 1; slot 0's minimum is 200) and short 3,
	 * which has gone dead; slot 2 is in group 2 */
	psemu_ballast_setup(f->emu, 0, 0, 1u << 1, 200);
	psemu_ballast_setup(f->emu, 0, 1, 1u << 1, 1);
	psemu_ballast_setup(f->emu, 0, 2, 1u << 2, 1);
	assert_int_equal(psemu_ballast_dead_after(f->emu, 0, 3, 0), 0);
	open_dev(f, "frame_gap", "0", "fade_time", "1", NULL);
	add_point(f, 0, "group 1");
	add_point(f, 1, "3");
	add_point(f, 2, "group 2");
	assert_int_equal(f->dev.drv->write(&f->dev, &f->pt[0], now_s(), now_s(), 0.5), 0);
	assert_int_equal(f->dev.drv->write(&f->dev, &f->pt[2], now_s(), now_s(), 0.5), 0);
	run_until(f, is_idle, 2);   /* short 3's frames fail: it is dead */
	fade_clock += 5;
	/* the zone's outputs are the first two points (as the daemon passes them) */
	assert_int_equal(request_pts(f, "verify office", 2), 0);
	while (job(f)->state == PS_DALI_COMMISSION_RUNNING) {
		double w;
		run_until(f, job_ended, 0.1);
		fade_clock += 0.1;     /* the ballasts' fades run on their clock */
		/* the wait is the fade of the gear that answered (1 s, and 0.3 s
		 * margin), not the dead one's unknown fade taken as 90.5 s */
		if (sscanf(job(f)->step, "verify: level %*d sent, waiting %lf s", &w) == 1)
			assert_true(fabs(w - 1.3) < 0.05);
	}
	c = job(f);
	b0 = ballast(f, 0);
	assert_int_equal(c->state, PS_DALI_COMMISSION_DONE);
	assert_int_equal(c->nvt, 2);
	assert_true(c->vt[0].members == (1u << 0 | 1u << 1));
	assert_true(c->vt[0].ok);
	/* slot 0 cannot go below its minimum: 10 % (170) gives 200 */
	assert_int_equal(c->got[0][0], 254);
	assert_int_equal(c->got[0][1], b0.min_level);
	assert_int_equal(c->got[1][1], 170);
	assert_true(c->vt[1].members == 1u << 3);
	assert_false(c->vt[1].ok);
	assert_int_equal(c->got[3][0], PS_DALI_NO_ANSWER);
	assert_false(c->ok);
	/* slot 2 (group 2, not in the zone) did not follow */
	assert_int_not_equal(c->got[2][1], 170);
	assert_non_null(strstr(f->out, "\"job\":\"verify\""));
}

/* ---- abort, unplug, one job at a time -------------------------------------------------------- */

static void abort_terminates_the_search(void **state)
{
	struct fx *f = *state;
	for (int s = 0; s < 10; s++)
		identity(f, s, -1, 0xFFFFFF, 8.0);
	open_dev(f, "frame_gap", "0", NULL);
	assert_int_equal(request(f, "address"), 0);
	while (job(f)->nfound < 2)
		run_until(f, job_ended, 0.05);
	assert_int_equal(request(f, "scan"), -1);     /* one job at a time */
	assert_int_equal(errno, EBUSY);
	assert_int_equal(request(f, "abort"), 0);
	assert_true(run_until(f, job_ended, 3));
	assert_int_equal(job(f)->state, PS_DALI_COMMISSION_ABORTED);
	for (int s = 0; s < 10; s++)
		assert_int_equal(ballast(f, s).init_state, PSEMU_INIT_DISABLED);
	assert_int_equal(request(f, "abort"), -1);
}

static void unplug_fails_the_job_and_the_driver_recovers(void **state)
{
	struct fx *f = *state;
	char err[256];
	open_dev(f, "frame_gap", "0", NULL);
	assert_int_equal(request(f, "scan"), 0);
	while (job(f)->scanned < 10)
		run_until(f, job_ended, 0.05);
	assert_int_equal(psemu_unplug(f->emu, 0), 0);
	assert_true(run_until(f, job_ended, 3));
	assert_int_equal(job(f)->state, PS_DALI_COMMISSION_FAILED);
	print_message("# %s\n", job(f)->msg);
	assert_non_null(strstr(job(f)->msg, "DALI USB interface: interface unplugged"));
	assert_int_equal(request(f, "scan"), -1);
	assert_int_equal(errno, ENODEV);
	assert_int_equal(psemu_replug(f->emu, 0, err, sizeof err), 0);
	assert_true(run_until(f, is_connected, 10));
	run_job(f, "scan", 20);
	assert_int_equal(job(f)->state, PS_DALI_COMMISSION_DONE);
	for (int a = 0; a < 6; a++)
		assert_int_equal(job(f)->gear[a].present, 1);
}

int main(int argc, char **argv)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test_setup_teardown(scan_reads_every_setting, setup6, teardown),
		cmocka_unit_test_setup_teardown(address_new_at_the_bus_rate, setup6, teardown),
		cmocka_unit_test_setup_teardown(colliding_random_addresses_are_separated, setup6, teardown),
		/* the same on the hasseb DALI Master */
		cmocka_unit_test_setup_teardown(scan_reads_every_setting, setup6_hasseb, teardown),
		cmocka_unit_test_setup_teardown(address_new_at_the_bus_rate, setup6_hasseb, teardown),
		cmocka_unit_test_setup_teardown(colliding_random_addresses_are_separated, setup6_hasseb, teardown),
		cmocka_unit_test_setup_teardown(an_answer_too_early_is_asked_again, setup6_hasseb, teardown),
		cmocka_unit_test_setup_teardown(twins_in_step_need_address_all, setup6, teardown),
		cmocka_unit_test_setup_teardown(a_ballast_going_quiet_mid_search, setup6, teardown),
		cmocka_unit_test_setup_teardown(shared_short_addresses_are_split, setup6, teardown),
		cmocka_unit_test_setup_teardown(initialise_is_renewed_within_its_15_minutes, setup10, teardown),
		cmocka_unit_test_setup_teardown(zones_are_dimmed_between_search_frames, setup10, teardown),
		cmocka_unit_test_setup_teardown(sixty_four_ballasts, setup64, teardown),
		cmocka_unit_test_setup_teardown(nothing_to_address, setup6, teardown),
		cmocka_unit_test_setup_teardown(groups_are_added_and_removed, setup6, teardown),
		cmocka_unit_test_setup_teardown(identify_flashes_one_ballast_and_restores_it, setup6, teardown),
		cmocka_unit_test_setup_teardown(verify_reports_who_follows, setup6, teardown),
		cmocka_unit_test_setup_teardown(abort_terminates_the_search, setup10, teardown),
		cmocka_unit_test_setup_teardown(unplug_fails_the_job_and_the_driver_recovers, setup6, teardown),
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
