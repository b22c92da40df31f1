/* SPDX-License-Identifier: ISC */
/* psemu: the emulated DALI USB interface and its ballasts (see dali_emu.h).
 * The byte layouts are written here from the tables of doc/hardware.md, not
 * taken from the driver's codec, so the emulator checks the driver instead of
 * agreeing with it. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <umockdev.h>

#include "dali_emu.h"
#include "vusb.h"

#define REPORT 64
#define MAX_OLD 32
#define MAX_SCRIPTED 8
#define TWICE_WINDOW 0.1        /* send-twice: the second frame within 100 ms */
#define SETTLE_P5 0.0212        /* longest settling time before a forward frame */
#define INIT_WINDOW 900.0       /* INITIALISE: 15 minutes */
#define RANDOM_READY 0.1        /* RANDOMISE: the new address within 100 ms */
#define NO_RANDOM 0xFFFFFFu     /* random address after reset */
/* bus timing (doc/hardware.md section 2): 1200 bit/s, bit 833.3 us */
#define BIT (1.0 / 1200)
#define T_FORWARD (19 * BIT)    /* start bit, 16 bits, 2 stop bits: 15.83 ms */
#define T_BACKWARD (11 * BIT)   /* start bit, 8 bits, 2 stop bits: 9.17 ms */
#define T_NO_ANSWER (0.0105 + BIT)   /* the latest answer's start bit would be over */
#define T_IN_TX 0.0135          /* between the frames of one transaction (priority 1) */
#define IN_STEP_MS 0.0833       /* answers this close add up to one clean frame */
#define OTHER_FRAME 0x7F90u     /* another master's frame: QUERY STATUS to short address 63 */
#define STALE_ANSWER 0x55       /* the answer a stale report carries */

struct ballast {
	struct psemu_ballast s;
	double fade_t0, fade_dur;   /* running fade: start and duration */
	int fade_from;
	double init_until;          /* ballasts' clock: the initialisation window ends */
	double random_ready;        /* real time: the last RANDOMISE's address counts */
	unsigned random_prev;       /* what COMPARE sees before that */
	unsigned scripted[MAX_SCRIPTED];
	int nscripted;
	GRand *rng;
	int dead_after;             /* answers left before it goes dead, -1 never */
};

/* a report the bus timing holds back until its frames are over */
struct delayed {
	double due;                 /* real time */
	struct vusb *usb;
	uint8_t r[REPORT];
	size_t len;
};

struct iface {
	struct psemu *e;
	int model;                       /* enum psemu_model */
	int index, port, next_devnum;
	char serial[64];
	struct vusb *usb;                /* NULL while unplugged */
	struct vusb *old[MAX_OLD];       /* earlier plugs: their fds may still be open */
	int nold;
	struct ballast b[PSEMU_MAX_BALLASTS];
	int nballasts;
	int fault, fault_count;
	uint8_t fw_major, fw_minor;      /* hasseb: its firmware version */
	double last_final;               /* real time of the last final report, <0 none */
	unsigned prev_frame;             /* the previous frame on the bus, for send-twice */
	double prev_frame_t;
	int have_prev;
	struct psemu_stats st;
};

struct psemu {
	UMockdevTestbed *tb;
	GMutex lock;
	struct iface ifc[PSEMU_MAX_IFACES];
	int n;
	double (*clock)(void *);
	void *clock_user;
	int timing;                 /* bus timing on */
	GQueue later;               /* struct delayed, in order of due time */
	GCond later_cond;
	GThread *later_thread;
	int stop;
};

static double mono(void *user)
{
	(void)user;
	return (double)g_get_monotonic_time() / 1e6;
}

static double real_now(void)
{
	return (double)g_get_monotonic_time() / 1e6;
}

/* ---- ballasts ---------------------------------------------------------------- */

/* The reset values of IEC 62386-102 (RESET keeps the short address). */
static void ballast_defaults(struct ballast *b)
{
	b->s.level = b->s.target = 254;   /* power on level after mains on */
	b->s.min_level = b->s.phys_min = 1;
	b->s.max_level = 254;
	b->s.sfl = 254;
	b->s.power_on_level = 254;
	b->s.fade_time = 0;
	b->s.fade_rate = 7;
	b->s.groups = 0;
	b->s.random = b->random_prev = NO_RANDOM;
}

static void ballast_init(struct ballast *b, int present, int iface, int slot)
{
	if (b->rng)
		g_rand_free(b->rng);
	memset(b, 0, sizeof *b);
	b->s.present = present;
	b->s.short_addr = slot;
	b->s.device_type = 6;
	b->s.reply_ms = 8.0;
	b->s.search = 0xFFFFFF;
	b->dead_after = -1;
	b->random_ready = -1;
	/* one generator per ballast: runs are repeatable, ballasts differ */
	b->rng = g_rand_new_with_seed((guint32)(2654435761u * (unsigned)(iface * 100 + slot + 1)));
	ballast_defaults(b);
}

static unsigned next_random(struct ballast *b)
{
	if (b->nscripted > 0) {
		unsigned v = b->scripted[0];
		memmove(b->scripted, b->scripted + 1, sizeof b->scripted[0] * (size_t)--b->nscripted);
		return v & 0xFFFFFF;
	}
	return (unsigned)g_rand_int_range(b->rng, 0, 0xFFFFFF);   /* 0 .. 0xFFFFFE */
}

/* the initialisation window closes by itself after 15 minutes */
static void init_advance(struct ballast *b, double t)
{
	if (b->s.init_state != PSEMU_INIT_DISABLED && t >= b->init_until)
		b->s.init_state = PSEMU_INIT_DISABLED;
}

/* bring a fade up to time t: linear in arc power level steps */
static void ballast_advance(struct ballast *b, double t)
{
	double k;
	if (b->s.level == b->s.target)
		return;
	if (b->fade_dur <= 0 || t >= b->fade_t0 + b->fade_dur) {
		b->s.level = b->s.target;
		return;
	}
	k = (t - b->fade_t0) / b->fade_dur;
	if (k < 0)
		k = 0;
	{
		/* a fade to off runs down to the minimum and switches off at the end */
		int to = b->s.target == 0 ? b->s.min_level : b->s.target;
		b->s.level = b->fade_from + (int)((to - b->fade_from) * k + (to > b->fade_from ? 0.5 : -0.5));
	}
}

static int clamp_level(const struct ballast *b, int level)
{
	if (level == 0)
		return 0;
	if (level < b->s.min_level)
		return b->s.min_level;
	if (level > b->s.max_level)
		return b->s.max_level;
	return level;
}

static void go_to(struct ballast *b, double t, int level, int fade)
{
	ballast_advance(b, t);
	if (level != b->s.target)
		b->s.level_changes++;
	b->fade_from = b->s.level;
	b->s.target = level;
	b->fade_t0 = t;
	b->fade_dur = fade && b->s.fade_time > 0 ? 0.5 * pow(2.0, b->s.fade_time / 2.0) : 0;
	if (b->fade_dur == 0 || b->fade_from == 0)
		b->s.level = level;   /* from off, the lamp ignites at the target */
}

static int addressed(const struct ballast *b, unsigned frame)
{
	unsigned ab = frame >> 8;
	if (!b->s.present || b->s.dead)
		return 0;
	if (ab >= 0xFE)
		return 1;
	if (ab >= 0xFC)                          /* broadcast to gear without a short address */
		return b->s.short_addr < 0;
	if ((ab & 0x80) == 0)
		return (int)(ab >> 1) == b->s.short_addr;
	if ((ab & 0xE0) == 0x80)
		return (b->s.groups >> ((ab >> 1) & 0x0F)) & 1;
	return 0;
}

/* a short address as special commands carry it: 0AAAAAA1, -1 otherwise */
static int short_of(unsigned data)
{
	return (data & 0x81) == 0x01 ? (int)(data >> 1) : -1;
}

/* A special command (address byte 101xxxx1 or 110xxxx1) at ballast time t,
 * real time rt.  Returns the backward frame, -1 for none. */
static int ballast_special(struct iface *f, struct ballast *b, double t, double rt, unsigned frame, int twice)
{
	unsigned ab = frame >> 8, data = frame & 0xFF;
	int sel;
	init_advance(b, t);
	switch (ab) {
	case 0xA1:                                                       /* TERMINATE */
		b->s.init_state = PSEMU_INIT_DISABLED;
		return -1;
	case 0xA5:                                                       /* INITIALISE */
		sel = data == 0x00 || (data == 0xFF && b->s.short_addr < 0) ||
		      (short_of(data) >= 0 && short_of(data) == b->s.short_addr);
		if (twice && sel) {
			b->s.init_state = PSEMU_INIT_ENABLED;
			b->init_until = t + INIT_WINDOW;
		}
		return -1;
	}
	if (b->s.init_state == PSEMU_INIT_DISABLED)
		return -1;                           /* the rest only inside the window */
	switch (ab) {
	case 0xA7:                                                       /* RANDOMISE */
		if (twice) {
			b->random_prev = rt < b->random_ready ? b->random_prev : b->s.random;
			b->s.random = next_random(b);
			b->random_ready = rt + RANDOM_READY;
		}
		return -1;
	case 0xA9: {                                                     /* COMPARE */
		unsigned r = b->s.random;
		if (b->s.init_state != PSEMU_INIT_ENABLED)
			return -1;
		if (rt < b->random_ready) {
			f->st.early_compares++;
			r = b->random_prev;
		}
		return r <= b->s.search ? 0xFF : -1;
	}
	case 0xAB:                                                       /* WITHDRAW */
		if (b->s.init_state == PSEMU_INIT_ENABLED && b->s.random == b->s.search)
			b->s.init_state = PSEMU_INIT_WITHDRAWN;
		return -1;
	case 0xB1: b->s.search = (b->s.search & 0x00FFFF) | data << 16; return -1;
	case 0xB3: b->s.search = (b->s.search & 0xFF00FF) | data << 8; return -1;
	case 0xB5: b->s.search = (b->s.search & 0xFFFF00) | data; return -1;
	case 0xB7:                                                       /* PROGRAM SHORT ADDRESS */
		if (b->s.random == b->s.search && (data == 0xFF || short_of(data) >= 0)) {
			b->s.short_addr = data == 0xFF ? -1 : short_of(data);
			b->s.config_writes++;
		}
		return -1;
	case 0xB9:                                                       /* VERIFY SHORT ADDRESS */
		return short_of(data) >= 0 && short_of(data) == b->s.short_addr ? 0xFF : -1;
	case 0xBB:                                                       /* QUERY SHORT ADDRESS */
		if (b->s.random != b->s.search)
			return -1;
		return b->s.short_addr >= 0 ? b->s.short_addr << 1 | 1 : 0xFF;
	}
	return -1;
}

/* One forward frame reaches a ballast at time t.  Returns the backward frame,
 * -1 for none.  twice: this frame repeats the one just before it in time. */
static int ballast_frame(struct ballast *b, double t, unsigned frame, int twice)
{
	unsigned op = frame & 0xFF;
	ballast_advance(b, t);
	b->s.commands++;
	if (!(frame & 0x100)) {                  /* DAPC */
		if (op == 255)
			b->s.target = b->s.level;        /* MASK: stop a fade */
		else
			go_to(b, t, clamp_level(b, (int)op), 1);
		return -1;
	}
	if (op >= 0x20 && op <= 0x81) {          /* configuration: only when sent twice */
		if (!twice)
			return -1;
		b->s.config_writes++;
		switch (op) {
		case 0x20: {                          /* RESET: all but the short address */
			int pm = b->s.phys_min;
			ballast_defaults(b);
			b->s.phys_min = b->s.min_level = pm;
			break;
		}
		case 0x2A: b->s.max_level = b->s.dtr0 < b->s.min_level ? b->s.min_level : b->s.dtr0 > 254 ? 254 : b->s.dtr0; break;
		case 0x2B: b->s.min_level = b->s.dtr0 < b->s.phys_min ? b->s.phys_min : b->s.dtr0 > b->s.max_level ? b->s.max_level : b->s.dtr0; break;
		case 0x2C: b->s.sfl = b->s.dtr0; break;
		case 0x2D: b->s.power_on_level = b->s.dtr0; break;
		case 0x2E: b->s.fade_time = b->s.dtr0 > 15 ? 15 : b->s.dtr0; break;
		case 0x2F: b->s.fade_rate = b->s.dtr0 < 1 ? 1 : b->s.dtr0 > 15 ? 15 : b->s.dtr0; break;
		case 0x80:                            /* SET SHORT ADDRESS from DTR0 */
			if (b->s.dtr0 == 0xFF)
				b->s.short_addr = -1;
			else if (short_of((unsigned)b->s.dtr0) >= 0)
				b->s.short_addr = short_of((unsigned)b->s.dtr0);
			else
				b->s.config_writes--;
			break;
		default:
			if (op >= 0x60 && op <= 0x6F)
				b->s.groups |= 1u << (op & 0x0F);          /* ADD TO GROUP */
			else if (op >= 0x70 && op <= 0x7F)
				b->s.groups &= ~(1u << (op & 0x0F));       /* REMOVE FROM GROUP */
			else
				b->s.config_writes--;         /* IDENTIFY DEVICE and the rest: no EEPROM */
			break;
		}
		return -1;
	}
	switch (op) {
	case 0x00: go_to(b, t, 0, 0); return -1;                              /* OFF */
	case 0x05: go_to(b, t, b->s.max_level, 0); return -1;                 /* RECALL MAX */
	case 0x06: go_to(b, t, b->s.min_level, 0); return -1;                 /* RECALL MIN */
	case 0x90: return (b->s.level > 0 ? 0x04 : 0) | (b->s.level != b->s.target ? 0x10 : 0) |
	                  (b->s.short_addr < 0 ? 0x40 : 0);
	case 0x91: return 0xFF;
	case 0x92: return -1;                                                 /* lamp ok: "no" */
	case 0x96: return b->s.short_addr < 0 ? 0xFF : -1;                   /* MISSING SHORT ADDRESS */
	case 0x97: return 0x08;                                               /* VERSION: 2.0 */
	case 0x99: return b->s.device_type;
	case 0x9A: return b->s.phys_min;
	case 0xA0: return b->s.level;
	case 0xA1: return b->s.max_level;
	case 0xA2: return b->s.min_level;
	case 0xA3: return b->s.power_on_level;
	case 0xA4: return b->s.sfl;
	case 0xA5: return b->s.fade_time << 4 | b->s.fade_rate;
	case 0xC0: return (int)(b->s.groups & 0xFF);
	case 0xC1: return (int)(b->s.groups >> 8);
	case 0xC2: return (int)(b->s.random >> 16);
	case 0xC3: return (int)(b->s.random >> 8 & 0xFF);
	case 0xC4: return (int)(b->s.random & 0xFF);
	}
	return -1;
}

/* ---- the bus ----------------------------------------------------------------- */

#define NO_ANSWER (-1)
#define COLLISION (-2)

struct answer {
	int value;          /* backward frame, NO_ANSWER or COLLISION */
	double first_ms;    /* settling time of the earliest answer */
};

/* One answer more on the bus: the same value in step adds up, else a collision. */
static void answer_add(struct answer *a, int value, double ms, double *last_ms)
{
	if (a->value == NO_ANSWER) {
		a->value = value;
		a->first_ms = *last_ms = ms;
		return;
	}
	if (ms < a->first_ms)
		a->first_ms = ms;
	if (ms > *last_ms)
		*last_ms = ms;
	if (a->value != value || *last_ms - a->first_ms > IN_STEP_MS)
		a->value = COLLISION;   /* different bits, or the same bits out of step */
}

/* Put one forward frame on the bus: every ballast that it addresses acts. */
static struct answer bus_frame(struct iface *f, unsigned frame)
{
	double t = f->e->clock(f->e->clock_user), rt = real_now(), last_ms = 0;
	struct answer ans = { NO_ANSWER, 0 };
	unsigned ab = frame >> 8;
	/* send-twice is bus timing: the real clock, not the fade clock */
	int twice = f->have_prev && f->prev_frame == frame && rt - f->prev_frame_t <= TWICE_WINDOW;
	f->st.bus_frames++;
	f->st.last_frame = frame;
	if (ab == 0xA3) {                          /* DTR0: every ballast */
		for (int i = 0; i < f->nballasts; i++)
			if (!f->b[i].s.dead)
				f->b[i].s.dtr0 = (int)(frame & 0xFF);
	} else {
		int special = ab >= 0xA0 && ab <= 0xCB && (ab & 1);
		if (special)
			f->st.specials++;
		for (int i = 0; i < f->nballasts; i++) {
			struct ballast *b = &f->b[i];
			int a;
			if (special) {
				if (!b->s.present || b->s.dead)
					continue;
				a = ballast_special(f, b, t, rt, frame, twice);
			} else {
				if (!addressed(b, frame))
					continue;
				a = ballast_frame(b, t, frame, twice);
			}
			if (a < 0)
				continue;
			answer_add(&ans, a, b->s.reply_ms, &last_ms);
			if (b->dead_after > 0 && --b->dead_after == 0)
				b->s.dead = 1;   /* this was its last answer */
		}
	}
	/* a frame just repeated has been used up as a pair */
	f->have_prev = !twice;
	f->prev_frame = frame;
	f->prev_frame_t = rt;
	if (ans.value == COLLISION)
		f->st.collisions++;
	return ans;
}

static void bus_down(struct iface *f)
{
	double t = f->e->clock(f->e->clock_user);
	for (int i = 0; i < f->nballasts; i++) {
		struct ballast *b = &f->b[i];
		if (!b->s.present || b->s.dead)
			continue;
		ballast_advance(b, t);
		if (b->s.sfl != 255)
			go_to(b, t, clamp_level(b, b->s.sfl), 0);
	}
	f->have_prev = 0;
}

/* ---- the interface firmware ---------------------------------------------------- */

/* Queue a report due at real time `due`: at once without bus timing, else
 * by the delivery thread.  Caller holds the lock. */
static void queue_report(struct iface *f, const uint8_t *r, size_t len, double due)
{
	struct psemu *e = f->e;
	struct delayed *d;
	if (!f->usb)
		return;
	if (!e->timing) {
		vusb_queue_in(f->usb, r, len);
		return;
	}
	d = g_new(struct delayed, 1);
	d->due = due;
	d->usb = f->usb;
	d->len = len < sizeof d->r ? len : sizeof d->r;
	memcpy(d->r, r, d->len);
	g_queue_push_tail(&e->later, d);
	g_cond_signal(&e->later_cond);
}

/* A report of the Tridonic interface (doc/hardware.md section 1). */
static void report(struct iface *f, uint8_t mode, uint8_t type, unsigned frame, uint8_t seq, double due)
{
	uint8_t r[REPORT] = { 0 };
	r[0] = mode;
	r[1] = type;
	r[4] = (uint8_t)(frame >> 8);
	r[5] = (uint8_t)frame;
	r[6] = 0x00;
	r[7] = type == 0x73 ? 0xF5 : 0x8A;   /* the undocumented "interval" field */
	r[8] = seq;
	queue_report(f, r, sizeof r, due);
}

/* The delivery thread of the bus timing: each report when it is due. */
static gpointer deliver(gpointer user)
{
	struct psemu *e = user;
	g_mutex_lock(&e->lock);
	while (!e->stop) {
		struct delayed *d = g_queue_peek_head(&e->later);
		double now = real_now();
		if (!d) {
			g_cond_wait(&e->later_cond, &e->lock);
			continue;
		}
		if (d->due > now) {
			g_cond_wait_until(&e->later_cond, &e->lock, g_get_monotonic_time() +
			                  (gint64)((d->due - now) * 1e6) + 1);
			continue;
		}
		g_queue_pop_head(&e->later);
		/* an unplugged device drops it; freed devices are only freed after this thread */
		vusb_queue_in(d->usb, d->r, d->len);
		g_free(d);
	}
	g_mutex_unlock(&e->lock);
	return NULL;
}

/* A SEND arrived at `now`: count it, check the gap since the last final
 * report, and take the fault it meets.  Caller holds the lock. */
static int take_send(struct iface *f, double now)
{
	int fault = PSEMU_FAULT_NONE;
	f->st.sends++;
	if (f->last_final >= 0 && f->have_prev && f->prev_frame >> 8 == 0xA3) {
		/* the command after its DTR0, one transaction: priority 1's settling time */
		if (now - f->last_final < T_IN_TX)
			f->st.gap_violations++;
	} else if (f->last_final >= 0) {
		double gap = now - f->last_final;
		if (gap < f->st.min_gap)
			f->st.min_gap = gap;
		if (gap < SETTLE_P5)
			f->st.gap_violations++;
	}
	if (f->fault_count > 0) {
		fault = f->fault;
		f->fault_count--;
	}
	return fault;
}

/* Unplugged in the middle of a transaction; called with the lock, returns without it. */
static void unplug_now(struct iface *f)
{
	struct vusb *u = f->usb;
	if (f->nold < MAX_OLD)
		f->old[f->nold++] = u;
	f->usb = NULL;
	f->st.plugged = 0;
	bus_down(f);
	g_mutex_unlock(&f->e->lock);
	vusb_unplug(u);
}

static void firmware(struct vusb *dev, uint8_t ep, const uint8_t *p, size_t len, void *user)
{
	struct iface *f = user;
	struct psemu *e = f->e;
	double now = real_now(), t;
	struct answer ans;
	int fault = PSEMU_FAULT_NONE, twice, dtr0;
	unsigned frame;
	uint8_t seq;
	(void)ep;
	g_mutex_lock(&e->lock);
	if (dev != f->usb || !p || len != REPORT || p[0] != 0x12) {
		/* INIT and other commands are not used by the driver; ignore */
		g_mutex_unlock(&e->lock);
		return;
	}
	fault = take_send(f, now);
	seq = p[1];
	f->st.last_seq = seq;
	twice = (p[2] & 0x20) != 0;
	dtr0 = (p[2] & 0x10) ? p[8] : -1;
	frame = (unsigned)p[6] << 8 | p[7];
	if (p[3] != 0x03) {                      /* only 16-bit frames here */
		report(f, 0x12, 0x77, 3, seq, now);
		f->last_final = now;
		g_mutex_unlock(&e->lock);
		return;
	}
	if (fault == PSEMU_FAULT_MALFORMED) {
		uint8_t junk[REPORT];
		for (int i = 0; i < REPORT; i++)
			junk[i] = (uint8_t)(0x5A ^ (i * 37));
		junk[0] = 0x12;
		junk[1] = 0x7E;                      /* no such type */
		junk[8] = seq;
		vusb_queue_in(f->usb, junk, sizeof junk);
		g_mutex_unlock(&e->lock);
		return;
	}
	/* t: when each frame of the transaction ends on the bus */
	t = now;
	if (fault == PSEMU_FAULT_OTHER_MASTER) {
		bus_frame(f, OTHER_FRAME);
		t += T_FORWARD + T_NO_ANSWER + SETTLE_P5;
		report(f, 0x11, 0x73, OTHER_FRAME, 0, t);
	}
	if (dtr0 >= 0) {
		bus_frame(f, 0xA300u | (unsigned)dtr0);
		t += T_FORWARD;
		report(f, 0x12, 0x73, 0xA300u | (unsigned)dtr0, seq, t);
		t += T_IN_TX;
	}
	ans = bus_frame(f, frame);
	t += T_FORWARD;
	report(f, 0x12, 0x73, frame, seq, t);
	if (twice) {
		ans = bus_frame(f, frame);
		t += T_IN_TX + T_FORWARD;
		report(f, 0x12, 0x73, frame, seq, t);
	}
	t += ans.value == NO_ANSWER ? T_NO_ANSWER : ans.first_ms / 1000 + T_BACKWARD;
	f->st.bus_time += t - now;
	if (!e->timing)
		t = now;
	switch (fault) {
	case PSEMU_FAULT_NO_ANSWER:
		break;
	case PSEMU_FAULT_GARBLED:
		report(f, 0x12, 0x77, 3, seq, t);
		f->last_final = t;
		break;
	case PSEMU_FAULT_STALE:
		report(f, 0x12, 0x72, STALE_ANSWER, (uint8_t)(seq - 1), t);
		break;
	case PSEMU_FAULT_UNPLUG:
		unplug_now(f);
		return;
	default:
		if (ans.value == NO_ANSWER)
			report(f, 0x12, 0x71, 0, seq, t);
		else if (ans.value == COLLISION)
			report(f, 0x12, 0x77, 3, seq, t);
		else
			report(f, 0x12, 0x72, (unsigned)ans.value, seq, t);
		f->last_final = t;
		break;
	}
	g_mutex_unlock(&e->lock);
}

/* ---- the hasseb DALI Master's firmware ----------------------------------------- */

/* Written from the protocol table of doc/hardware.md section 1.2 (the maker's
 * "hasseb USB DALI Master protocol"), not from the driver's codec. */
#define HB_LEN 10
#define HB_PREAMBLE 0xAA
#define HB_SEND 0x07
#define HB_VERSION 0x02
#define HB_EP_OUT 0x01
enum { HB_NO_ANSWER = 1, HB_ANSWER = 2, HB_INVALID = 3, HB_TOO_EARLY = 4, HB_SNIFFED = 5 };

/* A firmware-version report: AA 02 seq major minor 0 0 0 0 0 */
static void hb_version(struct iface *f, uint8_t seq, double due)
{
	uint8_t r[HB_LEN] = { HB_PREAMBLE, HB_VERSION, seq, f->fw_major, f->fw_minor, 0, 0, 0, 0, 0 };
	queue_report(f, r, sizeof r, due);
}

/* A transmission report: AA 07 seq status length data 0 0 0 0 */
static void hb_report(struct iface *f, uint8_t seq, uint8_t status, int value, double due)
{
	uint8_t r[HB_LEN] = { HB_PREAMBLE, HB_SEND, seq, status, 0, 0, 0, 0, 0, 0 };
	if (value >= 0) {
		r[4] = 1;
		r[5] = (uint8_t)value;
	}
	queue_report(f, r, sizeof r, due);
}

static void hasseb_firmware(struct vusb *dev, uint8_t ep, const uint8_t *p, size_t len, void *user)
{
	struct iface *f = user;
	struct psemu *e = f->e;
	double now = real_now(), t;
	struct answer ans;
	int fault, bits, expect, delay_ms;
	unsigned frame;
	uint8_t seq;
	g_mutex_lock(&e->lock);
	if (dev != f->usb) {
		g_mutex_unlock(&e->lock);
		return;
	}
	if (ep != HB_EP_OUT || !p || len != HB_LEN || p[0] != HB_PREAMBLE || (p[1] != HB_SEND && p[1] != HB_VERSION) ||
	    p[2] == 0) {
		f->st.rejected++;   /* not the protocol: the device does nothing */
		g_mutex_unlock(&e->lock);
		return;
	}
	if (p[1] == HB_VERSION) {
		/* nothing on the bus: the report comes at once */
		f->st.version_requests++;
		hb_version(f, p[2], now);
		g_mutex_unlock(&e->lock);
		return;
	}
	fault = take_send(f, now);
	seq = p[2];
	f->st.last_seq = seq;
	bits = p[3];
	expect = p[4] != 0;
	delay_ms = p[6];
	frame = (unsigned)p[7] << 8 | p[8];
	if (bits != 16) {                        /* only 16-bit frames in this model */
		hb_report(f, seq, HB_INVALID, -1, now);
		f->last_final = now;
		g_mutex_unlock(&e->lock);
		return;
	}
	if (fault == PSEMU_FAULT_MALFORMED) {
		const uint8_t shortr[6] = { HB_PREAMBLE, HB_SEND, seq, HB_ANSWER, 1, 0x5A };
		vusb_queue_in(f->usb, shortr, sizeof shortr);
		g_mutex_unlock(&e->lock);
		return;
	}
	t = now;
	if (fault == PSEMU_FAULT_OTHER_MASTER) {
		/* sniffed bytes carry sequence number 0, one report per byte */
		bus_frame(f, OTHER_FRAME);
		t += T_FORWARD;
		hb_report(f, 0, HB_SNIFFED, (int)(OTHER_FRAME >> 8), t);
		hb_report(f, 0, HB_SNIFFED, (int)(OTHER_FRAME & 0xFF), t);
		t += T_NO_ANSWER + SETTLE_P5;
	}
	ans = bus_frame(f, frame);
	t += T_FORWARD;
	if (delay_ms) {
		/* the second frame delay_ms after the first: a pair for the
		 * ballasts only if it comes within their 100 ms */
		f->prev_frame_t -= T_FORWARD + delay_ms / 1000.0;
		ans = bus_frame(f, frame);
		t += delay_ms / 1000.0 + T_FORWARD;
	}
	if (!expect)
		ans.value = NO_ANSWER;              /* it does not listen for one */
	t += ans.value == NO_ANSWER ? T_NO_ANSWER : ans.first_ms / 1000 + T_BACKWARD;
	f->st.bus_time += t - now;
	if (!e->timing)
		t = now;
	if (fault == PSEMU_FAULT_VERSION || fault == PSEMU_FAULT_VERSION_ONLY)
		hb_version(f, seq, t);
	switch (fault) {
	case PSEMU_FAULT_NO_ANSWER:
	case PSEMU_FAULT_VERSION_ONLY:
		break;
	case PSEMU_FAULT_GARBLED:
		hb_report(f, seq, HB_INVALID, -1, t);
		f->last_final = t;
		break;
	case PSEMU_FAULT_EARLY:
		/* a backward frame began inside the settling time: the firmware
		 * does not take it for the answer (whatever the ballasts said) */
		hb_report(f, seq, HB_TOO_EARLY, -1, t);
		f->last_final = t;
		break;
	case PSEMU_FAULT_STALE:
		hb_report(f, seq == 1 ? 255 : (uint8_t)(seq - 1), HB_ANSWER, STALE_ANSWER, t);
		break;
	case PSEMU_FAULT_UNPLUG:
		unplug_now(f);
		return;
	default:
		if (ans.value == NO_ANSWER)
			hb_report(f, seq, HB_NO_ANSWER, -1, t);
		else if (ans.value == COLLISION)
			hb_report(f, seq, HB_INVALID, -1, t);
		else
			hb_report(f, seq, HB_ANSWER, ans.value, t);
		f->last_final = t;
		break;
	}
	g_mutex_unlock(&e->lock);
}

/* ---- public ------------------------------------------------------------------ */

struct psemu *psemu_new(char *err, size_t errlen)
{
	struct psemu *e;
	const char *pre = getenv("LD_PRELOAD");
	/* umockdev_in_mock_environment() caches its first answer: look at the
	 * environment instead (doc/emulation.md pitfall 2) */
	if (!pre || !strstr(pre, "libumockdev-preload")) {
		snprintf(err, errlen, "libumockdev-preload.so.0 is not preloaded");
		return NULL;
	}
	e = g_new0(struct psemu, 1);
	g_mutex_init(&e->lock);
	g_cond_init(&e->later_cond);
	g_queue_init(&e->later);
	e->clock = mono;
	e->tb = umockdev_testbed_new();
	if (!e->tb) {
		snprintf(err, errlen, "umockdev: cannot create a testbed");
		g_free(e);
		return NULL;
	}
	return e;
}

static int plug(struct iface *f, char *err, size_t errlen)
{
	struct vusb_desc d = { 0x17B5, 0x0020, f->port, f->next_devnum++, f->serial, REPORT, 0, NULL, NULL };
	struct vusb *u;
	if (f->model == PSEMU_HASSEB) {
		d.vid = 0x04CC;
		d.pid = 0x0802;
		d.ep_out = HB_EP_OUT;
		d.maker = "hasseb (emulated)";
		d.product = "DALI Master (emulated)";
	}
	u = vusb_new(f->e->tb, &d, f->model == PSEMU_HASSEB ? hasseb_firmware : firmware, f, err, errlen);
	if (!u)
		return -1;
	g_mutex_lock(&f->e->lock);
	f->usb = u;
	f->st.plugged = 1;
	f->st.devnum = d.devnum;
	f->last_final = -1;
	g_mutex_unlock(&f->e->lock);
	return 0;
}

int psemu_add(struct psemu *e, int port, const char *serial, int nballasts, char *err, size_t errlen)
{
	return psemu_add_model(e, PSEMU_TRIDONIC, port, serial, nballasts, err, errlen);
}

int psemu_add_model(struct psemu *e, int model, int port, const char *serial, int nballasts, char *err,
                    size_t errlen)
{
	struct iface *f;
	if (model != PSEMU_TRIDONIC && model != PSEMU_HASSEB) {
		snprintf(err, errlen, "psemu: no such interface model %d", model);
		return -1;
	}
	if (e->n >= PSEMU_MAX_IFACES || nballasts < 0 || nballasts > PSEMU_MAX_BALLASTS || port < 1) {
		snprintf(err, errlen, "psemu: too many interfaces or ballasts");
		return -1;
	}
	f = &e->ifc[e->n];
	memset(f, 0, sizeof *f);
	f->e = e;
	f->model = model;
	f->fw_major = 2;
	f->fw_minor = 5;
	f->index = e->n;
	f->port = port;
	f->next_devnum = 2 + 10 * e->n;
	f->st.min_gap = 1e9;
	snprintf(f->serial, sizeof f->serial, "%s", serial ? serial : "");
	f->nballasts = nballasts;
	for (int i = 0; i < PSEMU_MAX_BALLASTS; i++)
		ballast_init(&f->b[i], i < nballasts, f->index, i);
	if (plug(f, err, errlen) != 0)
		return -1;
	return e->n++;
}

int psemu_unplug(struct psemu *e, int iface)
{
	struct iface *f;
	struct vusb *u;
	if (iface < 0 || iface >= e->n)
		return -1;
	f = &e->ifc[iface];
	g_mutex_lock(&e->lock);
	u = f->usb;
	if (!u || f->nold >= MAX_OLD) {
		g_mutex_unlock(&e->lock);
		return -1;
	}
	f->old[f->nold++] = u;
	f->usb = NULL;
	f->st.plugged = 0;
	bus_down(f);
	g_mutex_unlock(&e->lock);
	vusb_unplug(u);
	return 0;
}

int psemu_replug(struct psemu *e, int iface, char *err, size_t errlen)
{
	if (iface < 0 || iface >= e->n || e->ifc[iface].usb) {
		snprintf(err, errlen, "psemu: interface %d is not unplugged", iface);
		return -1;
	}
	return plug(&e->ifc[iface], err, errlen);
}

void psemu_fault(struct psemu *e, int iface, int fault, int count)
{
	if (iface < 0 || iface >= e->n)
		return;
	g_mutex_lock(&e->lock);
	e->ifc[iface].fault = fault;
	e->ifc[iface].fault_count = count;
	g_mutex_unlock(&e->lock);
}

int psemu_hasseb_version(struct psemu *e, int iface, int major, int minor)
{
	if (iface < 0 || iface >= e->n || major < 0 || major > 255 || minor < 0 || minor > 255)
		return -1;
	g_mutex_lock(&e->lock);
	if (e->ifc[iface].model != PSEMU_HASSEB) {
		g_mutex_unlock(&e->lock);
		return -1;
	}
	e->ifc[iface].fw_major = (uint8_t)major;
	e->ifc[iface].fw_minor = (uint8_t)minor;
	g_mutex_unlock(&e->lock);
	return 0;
}

void psemu_set_clock(struct psemu *e, double (*now)(void *user), void *user)
{
	g_mutex_lock(&e->lock);
	e->clock = now ? now : mono;
	e->clock_user = user;
	g_mutex_unlock(&e->lock);
}

void psemu_set_bus_timing(struct psemu *e, int on)
{
	g_mutex_lock(&e->lock);
	e->timing = on != 0;
	if (e->timing && !e->later_thread)
		e->later_thread = g_thread_new("psemu-bus", deliver, e);
	g_mutex_unlock(&e->lock);
}

static struct ballast *slot_of(struct psemu *e, int iface, int slot)
{
	if (iface < 0 || iface >= e->n || slot < 0 || slot >= PSEMU_MAX_BALLASTS)
		return NULL;
	return &e->ifc[iface].b[slot];
}

int psemu_ballast(struct psemu *e, int iface, int slot, struct psemu_ballast *out)
{
	struct ballast *b = slot_of(e, iface, slot);
	double t;
	if (!b)
		return -1;
	g_mutex_lock(&e->lock);
	t = e->clock(e->clock_user);
	ballast_advance(b, t);
	init_advance(b, t);
	*out = b->s;
	g_mutex_unlock(&e->lock);
	return 0;
}

int psemu_ballast_setup(struct psemu *e, int iface, int slot, unsigned groups, int phys_min)
{
	struct ballast *b = slot_of(e, iface, slot);
	if (!b || phys_min < 1 || phys_min > 254)
		return -1;
	g_mutex_lock(&e->lock);
	b->s.groups = groups;
	b->s.phys_min = phys_min;
	if (b->s.min_level < phys_min)
		b->s.min_level = phys_min;
	g_mutex_unlock(&e->lock);
	return 0;
}

int psemu_ballast_identity(struct psemu *e, int iface, int slot, int short_addr, unsigned random_addr,
                           double reply_ms)
{
	struct ballast *b = slot_of(e, iface, slot);
	if (!b || short_addr < -1 || short_addr > 63 || random_addr > 0xFFFFFF || !(reply_ms >= 5.5 && reply_ms <= 10.5))
		return -1;
	g_mutex_lock(&e->lock);
	b->s.short_addr = short_addr;
	b->s.random = b->random_prev = random_addr;
	b->s.reply_ms = reply_ms;
	g_mutex_unlock(&e->lock);
	return 0;
}

int psemu_ballast_randoms(struct psemu *e, int iface, int slot, const unsigned *values, int n)
{
	struct ballast *b = slot_of(e, iface, slot);
	if (!b || n < 0 || n > MAX_SCRIPTED)
		return -1;
	g_mutex_lock(&e->lock);
	for (int i = 0; i < n; i++)
		b->scripted[i] = values[i] & 0xFFFFFF;
	b->nscripted = n;
	g_mutex_unlock(&e->lock);
	return 0;
}

int psemu_ballast_dead_after(struct psemu *e, int iface, int slot, int n)
{
	struct ballast *b = slot_of(e, iface, slot);
	if (!b)
		return -1;
	g_mutex_lock(&e->lock);
	b->dead_after = n < 0 ? -1 : n;
	b->s.dead = n == 0;
	g_mutex_unlock(&e->lock);
	return 0;
}

int psemu_stats(struct psemu *e, int iface, struct psemu_stats *out)
{
	if (iface < 0 || iface >= e->n)
		return -1;
	g_mutex_lock(&e->lock);
	*out = e->ifc[iface].st;
	g_mutex_unlock(&e->lock);
	return 0;
}

int psemu_dump(struct psemu *e, char *buf, size_t len)
{
	size_t k = 0;
	double t;
	g_mutex_lock(&e->lock);
	t = e->clock(e->clock_user);
	if (len)
		buf[0] = 0;
	for (int i = 0; i < e->n; i++)
		for (int a = 0; a < e->ifc[i].nballasts; a++) {
			struct ballast *b = &e->ifc[i].b[a];
			int w;
			ballast_advance(b, t);
			init_advance(b, t);
			w = snprintf(buf + k, len > k ? len - k : 0,
			             "iface %d slot %d level %d target %d fade %d sfl %d min %d short %d groups 0x%04x "
			             "random 0x%06x%s plugged %d\n",
			             i, a, b->s.level, b->s.target, b->s.fade_time, b->s.sfl, b->s.min_level,
			             b->s.short_addr, b->s.groups, b->s.random, b->s.dead ? " dead" : "",
			             e->ifc[i].st.plugged);
			if (w > 0)
				k += (size_t)w;
		}
	g_mutex_unlock(&e->lock);
	return k < len ? 0 : -1;
}

void psemu_free(struct psemu *e)
{
	if (!e)
		return;
	if (e->later_thread) {
		g_mutex_lock(&e->lock);
		e->stop = 1;
		g_cond_signal(&e->later_cond);
		g_mutex_unlock(&e->lock);
		g_thread_join(e->later_thread);
	}
	g_queue_clear_full(&e->later, g_free);
	for (int i = 0; i < e->n; i++) {
		struct iface *f = &e->ifc[i];
		vusb_free(f->usb);
		for (int k = 0; k < f->nold; k++)
			vusb_free(f->old[k]);
		for (int a = 0; a < PSEMU_MAX_BALLASTS; a++)
			if (f->b[a].rng)
				g_rand_free(f->b[a].rng);
	}
	g_object_unref(e->tb);
	g_cond_clear(&e->later_cond);
	g_mutex_clear(&e->lock);
	g_free(e);
}
