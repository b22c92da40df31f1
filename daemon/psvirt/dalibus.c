/* SPDX-License-Identifier: ISC */
/* psvirt's virtual DALI bus (dalibus.h; the command set is in psvirt(1),
 * DALI BUS). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dalibus.h"

#define STEPS_PER_DECADE (253.0 / 3.0)
#define TWICE_WINDOW 0.1      /* s: a send-twice command's second frame (101) */
#define YES 0xFF
#define MASK 0xFF

/* answers: -1 none */
#define NONE (-1)

double psd_dalibus_arc(int n)
{
	if (n <= 0)
		return 0;
	if (n > 254)
		n = 254;
	return pow(10.0, (n - 1) / STEPS_PER_DECADE - 3.0);
}

static uint32_t rnd(struct psd_dalibus *b)
{
	uint32_t x = b->rng ? b->rng : 0x9e3779b9u;
	x ^= x << 13;
	x ^= x >> 17;
	x ^= x << 5;
	return b->rng = x;
}

static void gear_reset(struct psd_dalibus_gear *g)
{
	g->from = g->target = 254;
	g->fade_len = 0;
	g->min = g->phys_min;
	g->max = 254;
	g->sfl = 254;
	g->pol = 254;
	g->fade_time = 0;
	g->fade_rate = 7;
	g->groups = 0;
	memset(g->scene, MASK, sizeof g->scene);
	g->reset_state = 1;
}

static void dev_reset(struct psd_dalibus_dev *d)
{
	d->groups = 0;
	for (int i = 0; i < PSD_DALIBUS_NINST; i++) {
		struct psd_dalibus_inst *in = &d->inst[i];
		in->enabled = 0;
		in->scheme = 0;
		in->filter = 1;
		in->priority = 4;
		in->group = MASK;
		in->t_report = in->type == 4 ? 30 : 20;
		in->t_deadtime = in->type == 4 ? 30 : 2;
		in->hysteresis = 10;
		in->hysteresis_min = 5;
		in->t_hold = 90;   /* x 10 s: 15 minutes */
		in->last_event = -1e9;
	}
}

void psd_dalibus_init(struct psd_dalibus *b, int ngear, int nzone, int addressed, uint32_t seed)
{
	memset(b, 0, sizeof *b);
	b->rng = seed ? seed : 1;
	if (ngear > PSD_DALIBUS_MAX_GEAR)
		ngear = PSD_DALIBUS_MAX_GEAR;
	if (nzone > PSD_DALIBUS_MAX_DEV)
		nzone = PSD_DALIBUS_MAX_DEV;
	if (nzone < 1)
		nzone = 1;
	b->ngear = ngear;
	b->ndev = nzone;
	for (int i = 0; i < ngear; i++) {
		struct psd_dalibus_gear *g = &b->gear[i];
		g->zone = i * nzone / (ngear > 0 ? ngear : 1);
		g->addr = addressed ? i : -1;
		g->phys_min = 1;
		g->random = 0xFFFFFF;
		gear_reset(g);
		g->reset_state = 1;
	}
	for (int k = 0; k < nzone; k++) {
		struct psd_dalibus_dev *d = &b->dev[k];
		d->zone = k;
		d->addr = addressed ? k : -1;
		d->random = 0xFFFFFF;
		d->inst[0].type = 3;
		d->inst[0].resolution = 2;
		d->inst[1].type = 4;
		d->inst[1].resolution = 10;
		dev_reset(d);
	}
	b->prev_t = -1e9;
}

int psd_dalibus_level(const struct psd_dalibus_gear *g, double now)
{
	double u;
	int lo;
	if (g->fade_len <= 0 || now >= g->fade_t0 + g->fade_len || g->from == g->target)
		return g->target;
	u = (now - g->fade_t0) / g->fade_len;
	if (u < 0)
		u = 0;
	/* a fade to off runs to the minimum, then the lamp goes off */
	lo = g->target ? g->target : g->min;
	return (int)lround(g->from + (lo - g->from) * u);
}

double psd_dalibus_output(const struct psd_dalibus *b, int z, double now)
{
	double sum = 0;
	int n = 0;
	for (int i = 0; i < b->ngear; i++)
		if (b->gear[i].zone == z) {
			sum += psd_dalibus_arc(psd_dalibus_level(&b->gear[i], now));
			n++;
		}
	return n ? sum / n : 0;
}

/* The bits of value (r bits) left-aligned in nbytes bytes, the rest filled
 * by repeating the value from its most significant bit (103's rule for an
 * input value whose resolution is not a multiple of 8). */
static uint32_t filled(unsigned v, int r, int nbytes)
{
	uint32_t out = 0;
	int total = 8 * nbytes;
	for (int i = 0; i < total; i++) {
		int bit = r - 1 - (i % r);
		out = out << 1 | ((v >> bit) & 1u);
	}
	return out;
}

static int clamp(int v, int lo, int hi)
{
	return v < lo ? lo : v > hi ? hi : v;
}

/* Arc level to, with fade seconds (0: at once); 255 stops a fade. */
static void go_to(struct psd_dalibus_gear *g, double now, int to, double fade)
{
	int cur = psd_dalibus_level(g, now);
	g->reset_state = 0;
	if (to == MASK) {
		g->from = g->target = cur;
		g->fade_len = 0;
		return;
	}
	if (to > 0)
		to = clamp(to, g->min, g->max);
	g->from = cur > 0 ? cur : g->min;
	g->target = to;
	g->fade_t0 = now;
	g->fade_len = cur == 0 && to == 0 ? 0 : fade;
}

/* The bus lost its power: each gear goes to its SYSTEM FAILURE LEVEL at
 * once, MASK keeping the level it has (IEC 62386-102); a site's safe level
 * after a short is this, not the last command. */
void psd_dalibus_power_lost(struct psd_dalibus *b, double now)
{
	for (int i = 0; i < b->ngear; i++)
		go_to(&b->gear[i], now, b->gear[i].sfl, 0);
}

static double fade_seconds(int code)
{
	return code <= 0 ? 0 : 0.5 * pow(2.0, code / 2.0);
}

/* ---------------------------------------------------------------- 102 */

static int gear_addressed(const struct psd_dalibus_gear *g, unsigned ab)
{
	if ((ab & 0x80) == 0)
		return g->addr == (int)(ab >> 1);
	if ((ab & 0xE0) == 0x80)
		return (g->groups >> ((ab >> 1) & 0x0F)) & 1;
	if (ab >= 0xFE)
		return 1;
	if (ab == 0xFC || ab == 0xFD)
		return g->addr < 0;
	return 0;
}

static int config_opcode(unsigned op)
{
	return op >= 0x20 && op <= 0x81;
}

/* A command to one gear: its answer, or NONE. */
static int gear_command(struct psd_dalibus *b, struct psd_dalibus_gear *g, unsigned op, int confirmed,
                        double now)
{
	int lv = psd_dalibus_level(g, now), d0 = b->dtr[0];
	double rate_step = 506.0 / pow(2.0, g->fade_rate / 2.0) * 0.2;   /* steps in 200 ms */
	if (config_opcode(op) && !confirmed)
		return NONE;
	switch (op) {
	case 0x00: go_to(g, now, 0, 0); return NONE;
	case 0x01: if (lv > 0) go_to(g, now, clamp(lv + (int)rate_step, g->min, g->max), 0.2); return NONE;
	case 0x02: if (lv > 0) go_to(g, now, clamp(lv - (int)rate_step, g->min, g->max), 0.2); return NONE;
	case 0x03: if (lv > 0 && lv < g->max) go_to(g, now, lv + 1, 0); return NONE;
	case 0x04: if (lv > g->min) go_to(g, now, lv - 1, 0); return NONE;
	case 0x05: go_to(g, now, g->max, 0); return NONE;
	case 0x06: go_to(g, now, g->min, 0); return NONE;
	case 0x07: go_to(g, now, lv <= g->min ? 0 : lv - 1, 0); return NONE;
	case 0x08: go_to(g, now, lv == 0 ? g->min : clamp(lv + 1, g->min, g->max), 0); return NONE;
	case 0x20: gear_reset(g); return NONE;
	case 0x21: b->dtr[0] = (uint8_t)lv; return NONE;
	case 0x25: return NONE;   /* IDENTIFY DEVICE: nothing to see here */
	case 0x2A: g->max = clamp(d0, g->min, 254); break;
	case 0x2B: g->min = clamp(d0, g->phys_min, g->max); break;
	case 0x2C: g->sfl = d0; break;
	case 0x2D: g->pol = d0; break;
	case 0x2E: g->fade_time = d0 > 15 ? 15 : d0; break;
	case 0x2F: g->fade_rate = d0 < 1 ? 1 : d0 > 15 ? 15 : d0; break;
	case 0x80:
		if (d0 == MASK)
			g->addr = -1;
		else if ((d0 & 0x81) == 0x01)
			g->addr = d0 >> 1;
		return NONE;
	case 0x90:
		return (lv > 0) << 2 | (psd_dalibus_level(g, now) != g->target) << 4 | g->reset_state << 5 |
		       (g->addr < 0) << 6;
	case 0x91: return YES;
	case 0x93: return lv > 0 ? YES : NONE;
	case 0x95: return g->reset_state ? YES : NONE;
	case 0x96: return g->addr < 0 ? YES : NONE;
	case 0x97: return 0x08;   /* version 2.0 */
	case 0x98: return b->dtr[0];
	case 0x99: return 6;      /* LED gear (207) */
	case 0x9A: return g->phys_min;
	case 0x9C: return b->dtr[1];
	case 0x9D: return b->dtr[2];
	case 0xA0: return lv;
	case 0xA1: return g->max;
	case 0xA2: return g->min;
	case 0xA3: return g->pol;
	case 0xA4: return g->sfl;
	case 0xA5: return g->fade_time << 4 | g->fade_rate;
	case 0xC0: return g->groups & 0xFF;
	case 0xC1: return g->groups >> 8;
	case 0xC2: return (int)(g->random >> 16 & 0xFF);
	case 0xC3: return (int)(g->random >> 8 & 0xFF);
	case 0xC4: return (int)(g->random & 0xFF);
	default:
		if (op >= 0x10 && op <= 0x1F) {
			if (g->scene[op & 15] != MASK)
				go_to(g, now, g->scene[op & 15], fade_seconds(g->fade_time));
			return NONE;
		}
		if (op >= 0x40 && op <= 0x4F) {
			g->scene[op & 15] = (uint8_t)d0;
			break;
		}
		if (op >= 0x50 && op <= 0x5F) {
			g->scene[op & 15] = MASK;
			break;
		}
		if (op >= 0x60 && op <= 0x6F) {
			g->groups |= (uint16_t)(1u << (op & 15));
			break;
		}
		if (op >= 0x70 && op <= 0x7F) {
			g->groups &= (uint16_t)~(1u << (op & 15));
			break;
		}
		if (op >= 0xB0 && op <= 0xBF)
			return g->scene[op & 15];
		return NONE;
	}
	/* a setting changed: the arc level stays within min and max */
	g->reset_state = 0;
	if (g->target > 0)
		go_to(g, now, clamp(g->target, g->min, g->max), 0);
	return NONE;
}

/* The special commands 0xA1-0xCB to one gear. */
static int gear_special(struct psd_dalibus *b, struct psd_dalibus_gear *g, unsigned ab, unsigned data,
                        int confirmed)
{
	switch (ab) {
	case 0xA1: g->selected = g->withdrawn = 0; return NONE;
	case 0xA5:
		if (confirmed && (data == 0 || (data == 0xFF && g->addr < 0) ||
		                  ((data & 0x81) == 0x01 && g->addr == (int)(data >> 1)))) {
			g->selected = 1;
			g->withdrawn = 0;
		}
		return NONE;
	case 0xA7:
		if (confirmed && g->selected)
			g->random = rnd(b) & 0xFFFFFF;
		return NONE;
	case 0xA9: return g->selected && !g->withdrawn && g->random <= b->search ? YES : NONE;
	case 0xAB:
		if (g->selected && g->random == b->search)
			g->withdrawn = 1;
		return NONE;
	case 0xB7:
		if (g->selected && g->random == b->search) {
			if (data == MASK)
				g->addr = -1;
			else if ((data & 0x81) == 0x01)
				g->addr = (int)(data >> 1);
		}
		return NONE;
	case 0xB9: return g->selected && (data & 0x81) == 0x01 && g->addr == (int)(data >> 1) ? YES : NONE;
	case 0xBB:
		if (g->selected && g->random == b->search)
			return g->addr < 0 ? MASK : g->addr << 1 | 1;
		return NONE;
	}
	return NONE;
}

/* ---------------------------------------------------------------- 103 */

static int dev_addressed(const struct psd_dalibus_dev *d, unsigned ab)
{
	if ((ab & 0x80) == 0)
		return d->addr == (int)(ab >> 1);
	if ((ab & 0xC0) == 0x80)
		return (d->groups >> ((ab >> 1) & 0x1F)) & 1;
	if (ab == 0xFF)
		return 1;
	if (ab == 0xFD)
		return d->addr < 0;
	return 0;
}

static int inst_selected(const struct psd_dalibus_inst *in, int i, unsigned ib)
{
	if (ib == 0xFF)
		return 1;
	if (ib < 0x20)
		return (int)ib == i;
	if ((ib & 0xE0) == 0x80)
		return in->group == (int)(ib & 0x1F);
	if ((ib & 0xE0) == 0xC0)
		return in->type == (int)(ib & 0x1F);
	return 0;
}

static int dev_command(struct psd_dalibus *b, struct psd_dalibus_dev *d, unsigned op, int confirmed)
{
	unsigned groups16 = (unsigned)b->ddtr[2] << 8 | b->ddtr[1];
	if (op <= 0x2F && !confirmed)
		return NONE;
	switch (op) {
	case 0x10: dev_reset(d); return NONE;
	case 0x14:
		if (b->ddtr[0] == MASK)
			d->addr = -1;
		else if (b->ddtr[0] < 64)
			d->addr = b->ddtr[0];
		return NONE;
	case 0x16: d->app_enabled = 1; return NONE;
	case 0x17: d->app_enabled = 0; return NONE;
	case 0x19: d->groups |= groups16; return NONE;
	case 0x1A: d->groups |= groups16 << 16; return NONE;
	case 0x1B: d->groups &= ~groups16; return NONE;
	case 0x1C: d->groups &= ~(groups16 << 16); return NONE;
	case 0x30: return (d->addr < 0) << 2;
	case 0x33: return d->addr < 0 ? YES : NONE;
	case 0x34: return 0x08;   /* version 2.0 */
	case 0x35: return PSD_DALIBUS_NINST;
	case 0x36: return b->ddtr[0];
	case 0x37: return b->ddtr[1];
	case 0x38: return b->ddtr[2];
	case 0x39: return (int)(d->random >> 16 & 0xFF);
	case 0x3A: return (int)(d->random >> 8 & 0xFF);
	case 0x3B: return (int)(d->random & 0xFF);
	case 0x3D: return NONE;   /* an input device: no application controller */
	case 0x41: return (int)(d->groups & 0xFF);
	case 0x42: return (int)(d->groups >> 8 & 0xFF);
	case 0x43: return (int)(d->groups >> 16 & 0xFF);
	case 0x44: return (int)(d->groups >> 24 & 0xFF);
	case 0x46: return 0x02;   /* instances present, no application controller */
	}
	return NONE;
}

/* An instance type's own settings: the send-twice commands setting them
 * from DTR0 (query 0) and the queries (query 1); 304: SET REPORT TIMER
 * 0x30, HYSTERESIS 0x31, DEADTIME 0x32, HYSTERESIS MIN 0x33, queried by
 * 0x3E, 0x3F, 0x3D, 0x3C; 303: SET HOLD TIMER 0x21, REPORT TIMER 0x22,
 * DEADTIME 0x23, queried by 0x2D, 0x2E, 0x2C. */
static int *inst_timer(struct psd_dalibus_inst *in, unsigned op, int query)
{
	if (in->type == 4) {
		switch (op) {
		case 0x30: case 0x3E: return query == (op == 0x3E) ? &in->t_report : NULL;
		case 0x31: case 0x3F: return query == (op == 0x3F) ? &in->hysteresis : NULL;
		case 0x32: case 0x3D: return query == (op == 0x3D) ? &in->t_deadtime : NULL;
		case 0x33: case 0x3C: return query == (op == 0x3C) ? &in->hysteresis_min : NULL;
		}
	} else if (in->type == 3) {
		switch (op) {
		case 0x21: case 0x2D: return query == (op == 0x2D) ? &in->t_hold : NULL;
		case 0x22: case 0x2E: return query == (op == 0x2E) ? &in->t_report : NULL;
		case 0x23: case 0x2C: return query == (op == 0x2C) ? &in->t_deadtime : NULL;
		}
	}
	return NULL;
}

static int inst_command(struct psd_dalibus *b, struct psd_dalibus_dev *d, struct psd_dalibus_inst *in,
                        unsigned op, int confirmed)
{
	int *t, d0 = b->ddtr[0];
	int nbytes = (in->resolution + 7) / 8;
	uint32_t word;
	if (((op >= 0x61 && op <= 0x68) || inst_timer(in, op, 0)) && !confirmed)
		return NONE;
	if ((t = inst_timer(in, op, 0))) {
		*t = in->type == 4 && op == 0x31 && d0 > 25 ? 25 : d0;
		return NONE;
	}
	if ((t = inst_timer(in, op, 1)))
		return *t;
	switch (op) {
	case 0x61: in->priority = d0 < 2 ? 2 : d0 > 5 ? 5 : d0; return NONE;
	case 0x62: in->enabled = 1; return NONE;
	case 0x63: in->enabled = 0; return NONE;
	case 0x64: in->group = d0 < 32 || d0 == MASK ? d0 : in->group; return NONE;
	case 0x67: in->scheme = d0 <= 4 ? d0 : 0; return NONE;
	case 0x68: in->filter = d0; return NONE;
	case 0x80: return in->type;
	case 0x81: return in->resolution;
	case 0x82: return 0;
	case 0x83: return in->enabled << 1;
	case 0x84: return in->priority;
	case 0x86: return in->enabled ? YES : NONE;
	case 0x88: return in->group;
	case 0x8B: return in->scheme;
	case 0x8C:
		word = filled(in->value, in->resolution, nbytes);
		d->latch = nbytes > 1 ? (uint8_t)(word >> (8 * (nbytes - 2))) : 0;
		return (int)(word >> (8 * (nbytes - 1)) & 0xFF);
	case 0x8D: return d->latch;
	case 0x90: return in->filter & 0xFF;
	}
	return NONE;
}

static int dev_special(struct psd_dalibus *b, struct psd_dalibus_dev *d, unsigned cmd, unsigned data,
                       int confirmed)
{
	switch (cmd) {
	case 0x00: d->selected = d->withdrawn = 0; return NONE;
	case 0x01:
		if (confirmed && (data == 0xFF || (data == 0x7F && d->addr < 0) || (int)data == d->addr)) {
			d->selected = 1;
			d->withdrawn = 0;
		}
		return NONE;
	case 0x02:
		if (confirmed && d->selected)
			d->random = rnd(b) & 0xFFFFFF;
		return NONE;
	case 0x03: return d->selected && !d->withdrawn && d->random <= b->dsearch ? YES : NONE;
	case 0x04:
		if (d->selected && d->random == b->dsearch)
			d->withdrawn = 1;
		return NONE;
	case 0x08:
		if (d->selected && d->random == b->dsearch && (data < 64 || data == MASK))
			d->addr = data == MASK ? -1 : (int)data;
		return NONE;
	case 0x09: return d->selected && d->addr == (int)data ? YES : NONE;
	case 0x0A:
		if (d->selected && d->random == b->dsearch)
			return d->addr < 0 ? MASK : d->addr;
		return NONE;
	}
	return NONE;
}

/* ---------------------------------------------------------------- the bus */

static int silenced(const struct psd_dalibus *b, int target)
{
	return b->fault == PSD_DALIBUS_SILENT && (b->target == PSD_DALIBUS_EVERY || b->target == target);
}

/* Collect one device's answer into the bus's: one answer, identical
 * answers superimposed, different ones garbled. */
static void collect(int a, int *n, int *val, int *garbled)
{
	if (a == NONE)
		return;
	if (*n && *val != a)
		*garbled = 1;
	*val = a;
	(*n)++;
}

/* Whether this frame completes a send-twice pair (or was sent twice by the
 * interface). */
static int confirmed_by(struct psd_dalibus *b, double now, int bits, uint32_t frame, int twice)
{
	int c = twice || (b->prev_bits == bits && b->prev_frame == frame && now - b->prev_t <= TWICE_WINDOW);
	if (c && !twice) {
		b->prev_bits = 0;   /* a third copy starts a new pair */
	} else {
		b->prev_bits = bits;
		b->prev_frame = frame;
		b->prev_t = now;
	}
	return c;
}

static void frame16(struct psd_dalibus *b, double now, uint32_t f, int conf, int *n, int *val, int *garbled,
                    int *touched)
{
	unsigned ab = f >> 8 & 0xFF, data = f & 0xFF;
	if (ab >= 0xA0 && ab <= 0xCB && (ab & 1)) {
		switch (ab) {
		case 0xA3: b->dtr[0] = (uint8_t)data; return;
		case 0xC3: b->dtr[1] = (uint8_t)data; return;
		case 0xC5: b->dtr[2] = (uint8_t)data; return;
		case 0xB1: b->search = (b->search & 0x00FFFF) | data << 16; return;
		case 0xB3: b->search = (b->search & 0xFF00FF) | data << 8; return;
		case 0xB5: b->search = (b->search & 0xFFFF00) | data; return;
		}
		for (int i = 0; i < b->ngear; i++)
			if (!silenced(b, b->gear[i].addr < 0 ? -2 : b->gear[i].addr)) {
				if (b->fault == PSD_DALIBUS_COLLIDE && (b->target == PSD_DALIBUS_EVERY || b->target == b->gear[i].addr))
					*touched = 1;
				collect(gear_special(b, &b->gear[i], ab, data, conf), n, val, garbled);
			}
		return;
	}
	for (int i = 0; i < b->ngear; i++) {
		struct psd_dalibus_gear *g = &b->gear[i];
		if (!gear_addressed(g, ab) || silenced(b, g->addr < 0 ? -2 : g->addr))
			continue;
		if (b->fault == PSD_DALIBUS_COLLIDE && (b->target == PSD_DALIBUS_EVERY || b->target == g->addr))
			*touched = 1;
		if (!(ab & 1))
			go_to(g, now, (int)data, fade_seconds(g->fade_time));
		else
			collect(gear_command(b, g, data, conf, now), n, val, garbled);
	}
}

static void frame24(struct psd_dalibus *b, uint32_t f, int conf, int *n, int *val, int *garbled, int *touched)
{
	unsigned ab = f >> 16 & 0xFF, ib = f >> 8 & 0xFF, op = f & 0xFF;
	if (!(ab & 1))
		return;   /* another input device's event */
	if (ab == 0xC1) {
		switch (ib) {
		case 0x05: b->dsearch = (b->dsearch & 0x00FFFF) | op << 16; return;
		case 0x06: b->dsearch = (b->dsearch & 0xFF00FF) | op << 8; return;
		case 0x07: b->dsearch = (b->dsearch & 0xFFFF00) | op; return;
		case 0x30: case 0x31: case 0x32: b->ddtr[ib - 0x30] = (uint8_t)op; return;
		}
		for (int k = 0; k < b->ndev; k++) {
			struct psd_dalibus_dev *d = &b->dev[k];
			if (silenced(b, PSD_DALIBUS_DEVICE + (d->addr < 0 ? 99 : d->addr)))
				continue;
			if (b->fault == PSD_DALIBUS_COLLIDE &&
			    (b->target == PSD_DALIBUS_EVERY || b->target == PSD_DALIBUS_DEVICE + d->addr))
				*touched = 1;
			collect(dev_special(b, d, ib, op, conf), n, val, garbled);
		}
		return;
	}
	if (ab > 0xBF && ab != 0xFD && ab != 0xFF)
		return;   /* other special commands: not modelled */
	for (int k = 0; k < b->ndev; k++) {
		struct psd_dalibus_dev *d = &b->dev[k];
		if (!dev_addressed(d, ab) || silenced(b, PSD_DALIBUS_DEVICE + (d->addr < 0 ? 99 : d->addr)))
			continue;
		if (b->fault == PSD_DALIBUS_COLLIDE &&
		    (b->target == PSD_DALIBUS_EVERY || b->target == PSD_DALIBUS_DEVICE + d->addr))
			*touched = 1;
		if (ib == 0xFE) {
			collect(dev_command(b, d, op, conf), n, val, garbled);
			continue;
		}
		for (int i = 0; i < PSD_DALIBUS_NINST; i++)
			if (inst_selected(&d->inst[i], i, ib))
				collect(inst_command(b, d, &d->inst[i], op, conf), n, val, garbled);
	}
}

int psd_dalibus_frame(struct psd_dalibus *b, double now, int bits, uint32_t frame, int twice, uint8_t *answer)
{
	int n = 0, val = 0, garbled = 0, touched = 0, conf;
	b->frames++;
	if (b->fault == PSD_DALIBUS_SHORT)
		return PSD_DALIBUS_NOPOWER;
	conf = confirmed_by(b, now, bits, frame, twice);
	if (bits == 16)
		frame16(b, now, frame & 0xFFFF, conf, &n, &val, &garbled, &touched);
	else if (bits == 24)
		frame24(b, frame & 0xFFFFFF, conf, &n, &val, &garbled, &touched);
	/* 8-bit frames are backward frames of other devices: nothing answers */
	if (touched && n > 0)
		return PSD_DALIBUS_GARBLED;
	if (garbled)
		return PSD_DALIBUS_GARBLED;
	if (n == 0)
		return PSD_DALIBUS_NONE;
	*answer = (uint8_t)val;
	return PSD_DALIBUS_ANSWER;
}

void psd_dalibus_sense(struct psd_dalibus *b, int z, unsigned light10, int occupied)
{
	if (z < 0 || z >= b->ndev)
		return;
	b->dev[z].inst[0].value = occupied ? 3 : 0;
	b->dev[z].inst[1].value = light10 > 1023 ? 1023 : light10;
}

/* An event frame (103): bit 16 clear; the source by the instance's scheme. */
static uint32_t event_frame(const struct psd_dalibus_dev *d, const struct psd_dalibus_inst *in, int i)
{
	uint32_t info = in->value & 0x3FF, a = d->addr < 0 ? 0 : (uint32_t)d->addr;
	uint32_t grp = in->group == MASK ? 0 : (uint32_t)in->group & 0x1F;
	switch (in->scheme) {
	case 1: return a << 17 | (uint32_t)in->type << 10 | info;
	case 2: return a << 17 | 1u << 15 | (uint32_t)i << 10 | info;
	case 3: return 1u << 23 | 0u << 17 | (uint32_t)in->type << 10 | info;
	case 4: return 3u << 22 | grp << 17 | 1u << 15 | (uint32_t)in->type << 10 | info;
	}
	return 3u << 22 | (uint32_t)in->type << 17 | (uint32_t)i << 10 | info;
}

int psd_dalibus_events(struct psd_dalibus *b, double now, uint32_t *ev)
{
	int n = 0;
	if (b->fault == PSD_DALIBUS_SHORT)
		return 0;
	for (int k = 0; k < b->ndev; k++) {
		struct psd_dalibus_dev *d = &b->dev[k];
		if (silenced(b, PSD_DALIBUS_DEVICE + (d->addr < 0 ? 99 : d->addr)))
			continue;
		for (int i = 0; i < PSD_DALIBUS_NINST && n < PSD_DALIBUS_MAX_EVENTS; i++) {
			struct psd_dalibus_inst *in = &d->inst[i];
			double since = now - in->last_event;
			int due, changed;
			if (!in->enabled || !(in->filter & 1) || (in->scheme != 0 && in->scheme != 4 && d->addr < 0))
				continue;
			if (in->type == 4) {
				int band = (int)(in->reported * (unsigned)in->hysteresis / 100);
				if (band < in->hysteresis_min)
					band = in->hysteresis_min;
				changed = abs((int)in->value - (int)in->reported) > band;
				due = (changed && since >= in->t_deadtime * 0.05) || (in->t_report > 0 && since >= in->t_report);
			} else {
				changed = in->value != in->reported;
				due = (changed && since >= in->t_deadtime) || (in->t_report > 0 && since >= in->t_report);
			}
			if (!due)
				continue;
			in->reported = in->value;
			in->last_event = now;
			ev[n++] = event_frame(d, in, i);
		}
	}
	return n;
}
