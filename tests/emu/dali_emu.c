/* psemu: the emulated DALI USB interface and its ballasts (see dali_emu.h).
 * The byte layouts are written here from the hardware notes' tables, not
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
#define TWICE_WINDOW 0.1        /* send-twice: the second frame within 100 ms */
#define SETTLE_P5 0.0212        /* longest settling time before a forward frame */

struct ballast {
	struct psemu_ballast s;
	double fade_t0, fade_dur;   /* running fade: start and duration */
	int fade_from;
};

struct iface {
	struct psemu *e;
	int index, port, next_devnum;
	char serial[64];
	struct vusb *usb;                /* NULL while unplugged */
	struct vusb *old[MAX_OLD];       /* earlier plugs: their fds may still be open */
	int nold;
	struct ballast b[PSEMU_MAX_BALLASTS];
	int nballasts;
	int fault, fault_count;
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

static void ballast_reset(struct ballast *b, int present)
{
	memset(b, 0, sizeof *b);
	b->s.present = present;
	b->s.level = b->s.target = 254;   /* power on level after mains on */
	b->s.min_level = b->s.phys_min = 1;
	b->s.max_level = 254;
	b->s.sfl = 254;
	b->s.power_on_level = 254;
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
	b->fade_from = b->s.level;
	b->s.target = level;
	b->fade_t0 = t;
	b->fade_dur = fade && b->s.fade_time > 0 ? 0.5 * pow(2.0, b->s.fade_time / 2.0) : 0;
	if (b->fade_dur == 0 || b->fade_from == 0)
		b->s.level = level;   /* from off, the lamp ignites at the target */
}

static int addressed(const struct ballast *b, int addr, unsigned frame)
{
	unsigned ab = frame >> 8;
	if (!b->s.present)
		return 0;
	if (ab >= 0xFE)
		return 1;
	if ((ab & 0x80) == 0)
		return (int)(ab >> 1) == addr;
	if ((ab & 0xE0) == 0x80)
		return (b->s.groups >> ((ab >> 1) & 0x0F)) & 1;
	return 0;
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
			unsigned writes = b->s.config_writes, cmds = b->s.commands;
			ballast_reset(b, 1);
			b->s.phys_min = b->s.min_level = pm;
			b->s.config_writes = writes;
			b->s.commands = cmds;
			break;
		}
		case 0x2A: b->s.max_level = b->s.dtr0 < b->s.min_level ? b->s.min_level : b->s.dtr0 > 254 ? 254 : b->s.dtr0; break;
		case 0x2B: b->s.min_level = b->s.dtr0 < b->s.phys_min ? b->s.phys_min : b->s.dtr0 > b->s.max_level ? b->s.max_level : b->s.dtr0; break;
		case 0x2C: b->s.sfl = b->s.dtr0; break;
		case 0x2D: b->s.power_on_level = b->s.dtr0; break;
		case 0x2E: b->s.fade_time = b->s.dtr0 > 15 ? 15 : b->s.dtr0; break;
		default: b->s.config_writes--; break;
		}
		return -1;
	}
	switch (op) {
	case 0x00: go_to(b, t, 0, 0); return -1;                              /* OFF */
	case 0x05: go_to(b, t, b->s.max_level, 0); return -1;                 /* RECALL MAX */
	case 0x06: go_to(b, t, b->s.min_level, 0); return -1;                 /* RECALL MIN */
	case 0x90: return (b->s.level > 0 ? 0x04 : 0) | (b->s.level != b->s.target ? 0x10 : 0);
	case 0x91: return 0xFF;
	case 0x92: return -1;                                                 /* lamp ok: "no" */
	case 0x9A: return b->s.phys_min;
	case 0xA0: return b->s.level;
	case 0xA1: return b->s.max_level;
	case 0xA2: return b->s.min_level;
	case 0xA3: return b->s.power_on_level;
	case 0xA4: return b->s.sfl;
	case 0xA5: return b->s.fade_time << 4 | 7;
	case 0xC0: return (int)(b->s.groups & 0xFF);
	case 0xC1: return (int)(b->s.groups >> 8);
	}
	return -1;
}

/* ---- the bus ----------------------------------------------------------------- */

#define NO_ANSWER (-1)
#define COLLISION (-2)

/* Put one forward frame on the bus: every ballast that it addresses acts. */
static int bus_frame(struct iface *f, unsigned frame)
{
	double t = f->e->clock(f->e->clock_user), rt = real_now();
	int answer = NO_ANSWER;
	/* send-twice is bus timing: the real clock, not the fade clock */
	int twice = f->have_prev && f->prev_frame == frame && rt - f->prev_frame_t <= TWICE_WINDOW;
	f->st.bus_frames++;
	f->st.last_frame = frame;
	if ((frame >> 8) == 0xA3) {                /* DTR0: every ballast */
		for (int i = 0; i < f->nballasts; i++)
			f->b[i].s.dtr0 = (int)(frame & 0xFF);
	} else {
		for (int i = 0; i < f->nballasts; i++) {
			int a;
			if (!addressed(&f->b[i], i, frame))
				continue;
			a = ballast_frame(&f->b[i], t, frame, twice);
			if (a < 0)
				continue;
			if (answer == NO_ANSWER)
				answer = a;
			else if (answer != a)
				answer = COLLISION;   /* different bits on the wire at once */
		}
	}
	/* a frame just repeated has been used up as a pair */
	f->have_prev = !twice;
	f->prev_frame = frame;
	f->prev_frame_t = rt;
	if (answer == COLLISION)
		f->st.collisions++;
	return answer;
}

static void bus_down(struct iface *f)
{
	double t = f->e->clock(f->e->clock_user);
	for (int i = 0; i < f->nballasts; i++) {
		struct ballast *b = &f->b[i];
		if (!b->s.present)
			continue;
		ballast_advance(b, t);
		if (b->s.sfl != 255)
			go_to(b, t, clamp_level(b, b->s.sfl), 0);
	}
	f->have_prev = 0;
}

/* ---- the interface firmware ---------------------------------------------------- */

static void report(struct iface *f, uint8_t mode, uint8_t type, unsigned frame, uint8_t seq)
{
	uint8_t r[REPORT] = { 0 };
	r[0] = mode;
	r[1] = type;
	r[4] = (uint8_t)(frame >> 8);
	r[5] = (uint8_t)frame;
	r[6] = 0x00;
	r[7] = type == 0x73 ? 0xF5 : 0x8A;   /* the undocumented "interval" field */
	r[8] = seq;
	if (f->usb)
		vusb_queue_in(f->usb, r, sizeof r);
}

static void firmware(struct vusb *dev, uint8_t ep, const uint8_t *p, size_t len, void *user)
{
	struct iface *f = user;
	struct psemu *e = f->e;
	double now = real_now();
	int answer, fault = PSEMU_FAULT_NONE, twice, dtr0;
	unsigned frame;
	uint8_t seq;
	(void)ep;
	g_mutex_lock(&e->lock);
	if (dev != f->usb || !p || len != REPORT || p[0] != 0x12) {
		/* INIT and other commands are not used by the driver; ignore */
		g_mutex_unlock(&e->lock);
		return;
	}
	f->st.sends++;
	if (f->last_final >= 0) {
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
	seq = p[1];
	twice = (p[2] & 0x20) != 0;
	dtr0 = (p[2] & 0x10) ? p[8] : -1;
	frame = (unsigned)p[6] << 8 | p[7];
	if (p[3] != 0x03) {                      /* only 16-bit frames here */
		report(f, 0x12, 0x77, 3, seq);
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
	if (dtr0 >= 0) {
		bus_frame(f, 0xA300u | (unsigned)dtr0);
		report(f, 0x12, 0x73, 0xA300u | (unsigned)dtr0, seq);
	}
	answer = bus_frame(f, frame);
	report(f, 0x12, 0x73, frame, seq);
	if (twice) {
		answer = bus_frame(f, frame);
		report(f, 0x12, 0x73, frame, seq);
	}
	switch (fault) {
	case PSEMU_FAULT_NO_ANSWER:
		break;
	case PSEMU_FAULT_GARBLED:
		report(f, 0x12, 0x77, 3, seq);
		f->last_final = now;
		break;
	case PSEMU_FAULT_UNPLUG: {
		struct vusb *u = f->usb;
		f->old[f->nold++] = u;
		f->usb = NULL;
		f->st.plugged = 0;
		bus_down(f);
		g_mutex_unlock(&e->lock);
		vusb_unplug(u);
		return;
	}
	default:
		if (answer == NO_ANSWER)
			report(f, 0x12, 0x71, 0, seq);
		else if (answer == COLLISION)
			report(f, 0x12, 0x77, 3, seq);
		else
			report(f, 0x12, 0x72, (unsigned)answer, seq);
		f->last_final = now;
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
	 * environment instead (emulation.md pitfall 2) */
	if (!pre || !strstr(pre, "libumockdev-preload")) {
		snprintf(err, errlen, "libumockdev-preload.so.0 is not preloaded");
		return NULL;
	}
	e = g_new0(struct psemu, 1);
	g_mutex_init(&e->lock);
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
	struct vusb_desc d = { 0x17B5, 0x0020, f->port, f->next_devnum++, f->serial, REPORT };
	struct vusb *u = vusb_new(f->e->tb, &d, firmware, f, err, errlen);
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
	struct iface *f;
	if (e->n >= PSEMU_MAX_IFACES || nballasts < 0 || nballasts > PSEMU_MAX_BALLASTS || port < 1) {
		snprintf(err, errlen, "psemu: too many interfaces or ballasts");
		return -1;
	}
	f = &e->ifc[e->n];
	memset(f, 0, sizeof *f);
	f->e = e;
	f->index = e->n;
	f->port = port;
	f->next_devnum = 2 + 10 * e->n;
	f->st.min_gap = 1e9;
	snprintf(f->serial, sizeof f->serial, "%s", serial ? serial : "");
	f->nballasts = nballasts;
	for (int i = 0; i < PSEMU_MAX_BALLASTS; i++)
		ballast_reset(&f->b[i], i < nballasts);
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

void psemu_set_clock(struct psemu *e, double (*now)(void *user), void *user)
{
	g_mutex_lock(&e->lock);
	e->clock = now ? now : mono;
	e->clock_user = user;
	g_mutex_unlock(&e->lock);
}

int psemu_ballast(struct psemu *e, int iface, int addr, struct psemu_ballast *out)
{
	struct ballast *b;
	if (iface < 0 || iface >= e->n || addr < 0 || addr >= PSEMU_MAX_BALLASTS)
		return -1;
	g_mutex_lock(&e->lock);
	b = &e->ifc[iface].b[addr];
	ballast_advance(b, e->clock(e->clock_user));
	*out = b->s;
	g_mutex_unlock(&e->lock);
	return 0;
}

int psemu_ballast_setup(struct psemu *e, int iface, int addr, unsigned groups, int phys_min)
{
	struct ballast *b;
	if (iface < 0 || iface >= e->n || addr < 0 || addr >= PSEMU_MAX_BALLASTS || phys_min < 1 || phys_min > 254)
		return -1;
	g_mutex_lock(&e->lock);
	b = &e->ifc[iface].b[addr];
	b->s.groups = groups;
	b->s.phys_min = phys_min;
	if (b->s.min_level < phys_min)
		b->s.min_level = phys_min;
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
			w = snprintf(buf + k, len > k ? len - k : 0,
			             "iface %d addr %d level %d target %d fade %d sfl %d min %d plugged %d\n", i, a,
			             b->s.level, b->s.target, b->s.fade_time, b->s.sfl, b->s.min_level,
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
	for (int i = 0; i < e->n; i++) {
		struct iface *f = &e->ifc[i];
		vusb_free(f->usb);
		for (int k = 0; k < f->nold; k++)
			vusb_free(f->old[k]);
	}
	g_object_unref(e->tb);
	g_mutex_clear(&e->lock);
	g_free(e);
}
