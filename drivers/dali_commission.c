/* SPDX-License-Identifier: ISC */
/* DALI commissioning jobs as step machines (see dali_commission.h).
 *
 * Each job is a program counter (pc) over its own steps and a few
 * registers, and a run/result pair: X_run does what the pc says until it
 * needs the bus (a transaction in c->tx), a wait (c->wait_until) or has
 * ended; X_result files the transaction's outcome under the pc that asked
 * for it and moves the pc on.  The facts (frames,
 * the send-twice rule, INITIALISE's window, RANDOMISE's 100 ms) are those
 * of IEC 62386-102 as doc/hardware.md section 2 restates them. */
#include <json-c/json.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "dali_commission.h"
#include "dali_device.h"

#define RANDOMISE_WAIT 0.1      /* the new random address within 100 ms */
#define INIT_REFRESH 720.0      /* INITIALISE again after 12 of its 15 minutes */
#define MAX_RESTARTS 16         /* searches that found nobody where they ended */
#define MAX_CLASHES 16          /* random addresses drawn again */
#define FLASH_HALF 0.5          /* identify: seconds at MAX, then at MIN */
#define FADE_MARGIN 0.3         /* verify: after the longest fade */
#define ALL_GROUPS 0xFFFF

enum {
	PC_END = 0,
	SC_PRESENT, SC_DETAIL, SC_UNADDR, SC_DEV, SC_DEV_TYPE, SC_DEV_UNADDR,
	AD_PRESENT, AD_UNADDR, AD_TERMINATE, AD_INIT, AD_INIT_DUP, AD_RANDOMISE, AD_FIRST,
	AD_BIN, AD_BIN_CMP, AD_CONFIRM, AD_QUERY, AD_PROGRAM, AD_VERIFY, AD_UNPROGRAM, AD_CLASH, AD_WITHDRAW, AD_FINAL,
	PC_SEARCH,
	GR_CMD, GR_Q0, GR_Q1, GR_DTR1, GR_DTR2, GR_DCMD, GR_DQ,
	ID_QUERY, ID_G0, ID_G1, ID_FLASH, ID_RESTORE, ID_DEVICE, ID_DEVICE_CHECK,
	VE_PRESENT, VE_INFO, VE_CMD, VE_QUERY,
	AB_TERMINATE, AB_RESTORE,
};

const char *const ps_dali_commission_kinds[] = { "scan", "address", "group", "identify", "verify", NULL };
static const char *const ps_dali_commission_states[] = { "running", "done", "failed", "aborted", NULL };

/* what a scan asks each short address that answers */
static const int scan_queries[] = {
	PS_DALI_QUERY_DEVICE_TYPE, PS_DALI_QUERY_PHYSICAL_MINIMUM, PS_DALI_QUERY_MIN_LEVEL, PS_DALI_QUERY_MAX_LEVEL,
	PS_DALI_QUERY_FADE, PS_DALI_QUERY_GROUPS_0_7, PS_DALI_QUERY_GROUPS_8_15, PS_DALI_QUERY_SYSTEM_FAILURE_LEVEL,
	PS_DALI_QUERY_POWER_ON_LEVEL, PS_DALI_QUERY_STATUS, PS_DALI_QUERY_ACTUAL_LEVEL,
};
#define NSCAN ((int)(sizeof scan_queries / sizeof scan_queries[0]))

/* what verify needs of each ballast: groups, MIN, MAX, fade */
static const int verify_queries[] = {
	PS_DALI_QUERY_GROUPS_0_7, PS_DALI_QUERY_GROUPS_8_15, PS_DALI_QUERY_MIN_LEVEL, PS_DALI_QUERY_MAX_LEVEL,
	PS_DALI_QUERY_FADE,
};
#define NVERIFY ((int)(sizeof verify_queries / sizeof verify_queries[0]))

static uint64_t bit(int a)
{
	return (uint64_t)1 << a;
}

static unsigned short_frame(int a, int opcode)
{
	struct ps_dali_addr sa = { PS_DALI_SHORT, a };
	return (unsigned)ps_dali_cmd(&sa, opcode);
}

static unsigned special(int ab, int data)
{
	return (unsigned)ps_dali_special(ab, data);
}

/* a short address as special commands carry it (0AAAAAA1), -1 otherwise */
static int short_of(unsigned data)
{
	return (data & 0x81) == 0x01 ? (int)(data >> 1) : -1;
}

/* The address job in the control-device space (IEC 62386-103): the same
 * search with 103's special commands (address byte 0xC1, the command in the
 * instance byte; short addresses as 0..63, not 0AAAAAA1), QUERY DEVICE
 * STATUS for "is anyone there". */
static unsigned device_frame(unsigned frame)
{
	static const struct { int gear, dev; } map[] = {
		{ PS_DALI_TERMINATE, PS_DALI_DEVICE_TERMINATE }, { PS_DALI_INITIALISE, PS_DALI_DEVICE_INITIALISE },
		{ PS_DALI_RANDOMISE, PS_DALI_DEVICE_RANDOMISE }, { PS_DALI_COMPARE, PS_DALI_DEVICE_COMPARE },
		{ PS_DALI_WITHDRAW, PS_DALI_DEVICE_WITHDRAW }, { PS_DALI_SEARCHADDRH, PS_DALI_DEVICE_SEARCHADDRH },
		{ PS_DALI_SEARCHADDRM, PS_DALI_DEVICE_SEARCHADDRM }, { PS_DALI_SEARCHADDRL, PS_DALI_DEVICE_SEARCHADDRL },
		{ PS_DALI_PROGRAM_SHORT_ADDRESS, PS_DALI_DEVICE_PROGRAM_SHORT_ADDRESS },
		{ PS_DALI_VERIFY_SHORT_ADDRESS, PS_DALI_DEVICE_VERIFY_SHORT_ADDRESS },
		{ PS_DALI_QUERY_SHORT_ADDRESS, PS_DALI_DEVICE_QUERY_SHORT_ADDRESS },
	};
	int ab = (int)(frame >> 8), data = (int)(frame & 0xFF);
	if (frame == (PS_DALI_UNADDRESSED << 8 | PS_DALI_QUERY_GEAR_PRESENT))
		return (unsigned)ps_dali_device_frame(PS_DALI_DEVICE_UNADDRESSED, PS_DALI_DEVICE_SELF,
		                                      PS_DALI_DEVICE_QUERY_STATUS);
	if (!(ab & 0x80) && data == PS_DALI_QUERY_GEAR_PRESENT)
		return (unsigned)ps_dali_device_cmd(ab >> 1, PS_DALI_DEVICE_QUERY_STATUS);
	for (size_t i = 0; i < sizeof map / sizeof map[0]; i++) {
		if (map[i].gear != ab)
			continue;
		if (ab == PS_DALI_INITIALISE)
			data = data == 0x00 ? PS_DALI_DEVICE_INIT_ALL : data == 0xFF ? PS_DALI_DEVICE_INIT_UNADDRESSED : data >> 1;
		else if (ab == PS_DALI_PROGRAM_SHORT_ADDRESS || ab == PS_DALI_VERIFY_SHORT_ADDRESS)
			data = data == 0xFF ? 0xFF : data >> 1;
		return (unsigned)ps_dali_device_special(map[i].dev, data);
	}
	return frame;
}

static void emit(struct ps_dali_commission *c, unsigned frame, int twice, int answer)
{
	if (c->devices_space)
		frame = device_frame(frame);
	c->tx = (struct ps_dali_tx){ frame, twice, answer };
	c->have_tx = 1;
}

static void step(struct ps_dali_commission *c, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void step(struct ps_dali_commission *c, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(c->step, sizeof c->step, fmt, ap);
	va_end(ap);
}

static void end(struct ps_dali_commission *c, double now, int state, const char *fmt, ...)
	__attribute__((format(printf, 4, 5)));
static void end(struct ps_dali_commission *c, double now, int state, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(c->msg, sizeof c->msg, fmt, ap);
	va_end(ap);
	c->state = state;
	c->ended = now;
	c->pc = PC_END;
	c->have_tx = 0;
	c->wait_until = -INFINITY;
	c->hold = 0;
	snprintf(c->step, sizeof c->step, "%s", ps_dali_commission_states[state]);
}

static void start(struct ps_dali_commission *c, int kind, int pc, double now)
{
	memset(c, 0, sizeof *c);
	c->kind = kind;
	c->state = PS_DALI_COMMISSION_RUNNING;
	c->started = now;
	c->ended = NAN;
	c->pc = pc;
	c->unaddressed = -1;
	c->groups_after = -1;
	c->saved_level = PS_DALI_NO_ANSWER;
	c->wait_until = -INFINITY;
	for (int a = 0; a < 64; a++) {
		struct ps_dali_gear *g = &c->gear[a];
		g->device_type = g->phys_min = g->min_level = g->max_level = g->fade = g->sfl = g->power_on =
			g->status = g->actual = g->groups = PS_DALI_NO_ANSWER;
		c->got[a][0] = c->got[a][1] = PS_DALI_NO_ANSWER;
	}
}

/* the lowest short address no ballast has, -1 when all 64 are taken */
static int free_address(const struct ps_dali_commission *c)
{
	for (int a = 0; a < 64; a++)
		if (!((c->used | c->claimed | c->bad) & bit(a)))
			return a;
	return -1;
}

/* set the search address to c->want, sending only the bytes that differ,
 * then go on at ret */
static void search_to(struct ps_dali_commission *c, unsigned want, int ret)
{
	c->want = want;
	c->want_ret = ret;
	c->pc = PC_SEARCH;
}

static double fade_seconds(int fade)
{
	return fade >= 0 ? ps_dali_fade_time_seconds(fade >> 4) : ps_dali_fade_time_seconds(15);
}

/* a level as a ballast with these limits ends at */
static int expected(const struct ps_dali_gear *g, int level)
{
	if (level == 0 || level == PS_DALI_MASK)
		return level;
	if (g->min_level >= 0 && level < g->min_level)
		return g->min_level;
	if (g->max_level >= 0 && level > g->max_level)
		return g->max_level;
	return level;
}

static int reaches(const struct ps_dali_addr *a, int short_addr, int groups)
{
	switch (a->kind) {
	case PS_DALI_SHORT:
		return a->n == short_addr;
	case PS_DALI_GROUP:
		return groups >= 0 && ((groups >> a->n) & 1);
	case PS_DALI_BROADCAST:
		return 1;
	}
	return 0;
}

static void verify_judge(struct ps_dali_commission *c, double now)
{
	int members = 0, followed = 0, strays = 0;
	uint64_t all = 0;
	char bad[160] = "";
	size_t k = 0;
	c->ok = 1;
	for (int t = 0; t < c->nvt; t++) {
		struct ps_dali_verify_target *v = &c->vt[t];
		v->ok = v->members != 0;
		all |= v->members;
		for (int a = 0; a < 64; a++) {
			if (!(v->members & bit(a)))
				continue;
			if (c->got[a][0] != expected(&c->gear[a], c->levels[0]) ||
			    c->got[a][1] != expected(&c->gear[a], c->levels[1])) {
				v->ok = 0;
				if (k < sizeof bad - 8)
					k += (size_t)snprintf(bad + k, sizeof bad - k, " %d", a);
			}
		}
		c->ok &= v->ok;
	}
	for (int a = 0; a < 64; a++) {
		if (all & bit(a)) {
			members++;
			followed += c->got[a][0] == expected(&c->gear[a], c->levels[0]) &&
			            c->got[a][1] == expected(&c->gear[a], c->levels[1]);
		} else if ((c->used & bit(a)) && c->got[a][0] == expected(&c->gear[a], c->levels[0]) &&
		           c->got[a][1] == expected(&c->gear[a], c->levels[1])) {
			strays++;   /* follows a command it should not hear */
		}
	}
	c->ok &= strays == 0;
	if (!members)
		end(c, now, PS_DALI_COMMISSION_DONE, "no ballast answers to these addresses");
	else if (c->ok)
		end(c, now, PS_DALI_COMMISSION_DONE, "all %d ballasts follow (levels %d and %d)", members, c->levels[0],
		    c->levels[1]);
	else
		end(c, now, PS_DALI_COMMISSION_DONE, "%d of %d ballasts follow%s%s%s", followed, members,
		    k ? "; not following:" : "", bad, strays ? "; ballasts outside the zone follow it too" : "");
}

static void address_done(struct ps_dali_commission *c, double now)
{
	end(c, now, PS_DALI_COMMISSION_DONE,
	    "%d %s found: %d new short addresses, %d kept theirs%s; %d random-address clashes separated, "
	    "%d searches restarted, %d lost%s",
	    c->nfound, c->devices_space ? "control devices" : "ballasts", c->programmed, c->kept, c->no_free ? ", some left without (no free address)" : "",
	    c->clashes, c->restarts, c->lost, c->inits > 1 ? ", INITIALISE renewed" : "");
}

/* a step the job does not have */
static int internal(struct ps_dali_commission *c, double now)
{
	end(c, now, PS_DALI_COMMISSION_FAILED, "internal: step %d", c->pc);
	return 0;
}

/* the value of a query's answer, or PS_DALI_NO_ANSWER / PS_DALI_COLLIDED */
static int value_of(int rx, unsigned value)
{
	return rx == PS_DALI_RX_ANSWER ? (int)value : rx == PS_DALI_RX_COLLISION ? PS_DALI_COLLIDED : PS_DALI_NO_ANSWER;
}

static void scan_store(struct ps_dali_gear *g, int k, int v)
{
	switch (scan_queries[k]) {
	case PS_DALI_QUERY_DEVICE_TYPE: g->device_type = v; break;
	case PS_DALI_QUERY_PHYSICAL_MINIMUM: g->phys_min = v; break;
	case PS_DALI_QUERY_MIN_LEVEL: g->min_level = v; break;
	case PS_DALI_QUERY_MAX_LEVEL: g->max_level = v; break;
	case PS_DALI_QUERY_FADE: g->fade = v; break;
	case PS_DALI_QUERY_GROUPS_0_7: g->groups = v; break;
	case PS_DALI_QUERY_GROUPS_8_15:
		g->groups = g->groups < 0 ? g->groups : v < 0 ? v : v << 8 | g->groups;
		break;
	case PS_DALI_QUERY_SYSTEM_FAILURE_LEVEL: g->sfl = v; break;
	case PS_DALI_QUERY_POWER_ON_LEVEL: g->power_on = v; break;
	case PS_DALI_QUERY_STATUS: g->status = v; break;
	case PS_DALI_QUERY_ACTUAL_LEVEL: g->actual = v; break;
	}
}

static void verify_store(struct ps_dali_gear *g, int k, int v)
{
	switch (verify_queries[k]) {
	case PS_DALI_QUERY_GROUPS_0_7: g->groups = v; break;
	case PS_DALI_QUERY_GROUPS_8_15:
		g->groups = g->groups < 0 ? g->groups : v < 0 ? v : v << 8 | g->groups;
		break;
	case PS_DALI_QUERY_MIN_LEVEL: g->min_level = v; break;
	case PS_DALI_QUERY_MAX_LEVEL: g->max_level = v; break;
	case PS_DALI_QUERY_FADE: g->fade = v; break;
	}
}

static void record(struct ps_dali_commission *c, int address)
{
	if (c->nfound < 64)
		c->found[c->nfound] = (struct ps_dali_found){ c->found_at, address, c->was };
	c->nfound++;
}

/* a search that ended where nobody answers: a ballast went quiet */
static void restart(struct ps_dali_commission *c, double now)
{
	if (++c->restarts > MAX_RESTARTS) {
		end(c, now, PS_DALI_COMMISSION_FAILED,
		    "the search ended %d times where no ballast answers (a ballast answering now and then?)", c->restarts);
		return;
	}
	c->pc = AD_FIRST;
}

static void do_abort(struct ps_dali_commission *c, double now)
{
	c->abort_req = 0;
	c->wait_until = -INFINITY;
	if (c->kind == PS_DALI_COMMISSION_ADDRESS && c->inits > 0 && c->pc != AD_FINAL)
		c->pc = AB_TERMINATE;   /* leave no gear in its initialisation state */
	else if (c->kind == PS_DALI_COMMISSION_IDENTIFY && c->pc == ID_FLASH)
		c->pc = AB_RESTORE;
	else
		end(c, now, PS_DALI_COMMISSION_ABORTED, "aborted");
}

/* ---- scan: every short address and its settings ---- */

static int scan_run(struct ps_dali_commission *c, double now)
{
	switch (c->pc) {
	case SC_PRESENT:
		step(c, "scan: short address %d of 63", c->i);
		emit(c, short_frame(c->i, PS_DALI_QUERY_GEAR_PRESENT), 0, 1);
		return 0;
	case SC_DETAIL:
		step(c, "scan: short address %d of 63, its settings", c->i);
		emit(c, short_frame(c->i, scan_queries[c->k]), 0, 1);
		return 0;
	case SC_UNADDR:
		step(c, "scan: gear without a short address?");
		emit(c, (PS_DALI_UNADDRESSED << 8) | PS_DALI_QUERY_GEAR_PRESENT, 0, 1);
		return 0;
	case SC_DEV:
		step(c, "scan: control device %d of 63", c->i);
		emit(c, (unsigned)ps_dali_device_cmd(c->i, PS_DALI_DEVICE_QUERY_NUMBER_OF_INSTANCES), 0, 1);
		return 0;
	case SC_DEV_TYPE:
		step(c, "scan: control device %d, instance %d", c->i, c->k);
		emit(c, (unsigned)ps_dali_device_inst_cmd(c->i, c->k, PS_DALI_DEVICE_QUERY_INSTANCE_TYPE), 0, 1);
		return 0;
	case SC_DEV_UNADDR:
		step(c, "scan: control devices without a short address?");
		emit(c, (unsigned)ps_dali_device_frame(PS_DALI_DEVICE_UNADDRESSED, PS_DALI_DEVICE_SELF,
		                                       PS_DALI_DEVICE_QUERY_NUMBER_OF_INSTANCES), 0, 1);
		return 0;
	default:
		return internal(c, now);
	}
}

static void scan_done(struct ps_dali_commission *c, double now)
{
	int n = 0, several = 0, nd = 0;
	for (int a = 0; a < 64; a++) {
		n += c->gear[a].present != 0;
		several += c->gear[a].present == 2;
		nd += c->devices[a].present != 0;
	}
	if (!c->with_devices) {
		end(c, now, PS_DALI_COMMISSION_DONE, "%d short addresses answer%s; gear without a short address: %s", n,
		    several ? ", some by several ballasts at once" : "",
		    c->unaddressed == 0 ? "none" : c->unaddressed == 1 ? "yes" : "several");
		return;
	}
	end(c, now, PS_DALI_COMMISSION_DONE,
	    "%d short addresses answer%s; gear without a short address: %s; %d control devices, without a short "
	    "address: %s",
	    n, several ? ", some by several ballasts at once" : "",
	    c->unaddressed == 0 ? "none" : c->unaddressed == 1 ? "yes" : "several", nd,
	    c->dev_unaddressed == 0 ? "none" : c->dev_unaddressed == 1 ? "yes" : "several");
}

static int scan_result(struct ps_dali_commission *c, double now, int rx, unsigned value)
{
	int v = value_of(rx, value);
	switch (c->pc) {
	case SC_PRESENT:
		c->gear[c->i].present = rx == PS_DALI_RX_ANSWER ? 1 : rx == PS_DALI_RX_COLLISION ? 2 : 0;
		if (c->gear[c->i].present) {
			c->k = 0;
			c->pc = SC_DETAIL;
			return 1;
		}
		c->scanned = ++c->i;
		c->pc = c->i < 64 ? SC_PRESENT : SC_UNADDR;
		return 1;
	case SC_DETAIL:
		scan_store(&c->gear[c->i], c->k, v);
		if (++c->k < NSCAN)
			return 1;
		c->scanned = ++c->i;
		c->pc = c->i < 64 ? SC_PRESENT : SC_UNADDR;
		return 1;
	case SC_UNADDR:
		c->unaddressed = rx == PS_DALI_RX_ANSWER ? 1 : rx == PS_DALI_RX_COLLISION ? 2 : 0;
		if (c->with_devices) {
			c->i = 0;
			c->pc = SC_DEV;
			return 1;
		}
		scan_done(c, now);
		return 0;
	case SC_DEV: {
		struct ps_dali_ctl_device *d = &c->devices[c->i];
		d->present = rx == PS_DALI_RX_ANSWER ? 1 : rx == PS_DALI_RX_COLLISION ? 2 : 0;
		d->instances = rx == PS_DALI_RX_ANSWER ? (int)(value > 32 ? 32 : value) : 0;
		if (d->instances > 0) {
			c->k = 0;
			c->pc = SC_DEV_TYPE;
			return 1;
		}
		c->pc = ++c->i < 64 ? SC_DEV : SC_DEV_UNADDR;
		return 1;
	}
	case SC_DEV_TYPE:
		c->devices[c->i].type[c->k] = (signed char)(rx == PS_DALI_RX_ANSWER && value < 32 ? (int)value : -1);
		if (++c->k < c->devices[c->i].instances)
			return 1;
		c->pc = ++c->i < 64 ? SC_DEV : SC_DEV_UNADDR;
		return 1;
	case SC_DEV_UNADDR:
		c->dev_unaddressed = rx == PS_DALI_RX_ANSWER ? 1 : rx == PS_DALI_RX_COLLISION ? 2 : 0;
		scan_done(c, now);
		return 0;
	}
	return 1;
}

/* ---- address, its search: the next ballast's random address by a binary
 * search with SEARCHADDRH/M/L and COMPARE, from the smallest half where
 * COMPARE came back garbled (dali_commission.h); address_run and
 * address_result hand it the steps they do not have ---- */

static int search_run(struct ps_dali_commission *c, double now)
{
	switch (c->pc) {
	case AD_FIRST:
		step(c, "address: searching for ballast %d", c->nfound + 1);
		/* the smallest garbled half that still holds a ballast, else all */
		while (c->nnode > 0 && c->node[c->nnode - 1].found >= 2)
			c->nnode--;
		c->from_node = c->nnode > 0;
		c->lo = c->from_node ? c->node[c->nnode - 1].base : 0;
		c->hi = c->from_node ? c->node[c->nnode - 1].top : 0xFFFFFF;
		c->hi_rx = PS_DALI_RX_NONE;   /* nobody said yes to hi yet */
		c->pc = AD_BIN;
		return 1;
	case AD_BIN_CMP:
	case AD_CONFIRM:
		emit(c, special(PS_DALI_COMPARE, 0), 0, 1);
		return 0;
	case AD_BIN:
		if (c->lo >= c->hi) {
			c->found_at = c->hi;
			if (c->hi_rx == PS_DALI_RX_COLLISION) {
				c->pc = AD_CLASH;
				return 1;
			}
			search_to(c, c->found_at, c->hi_rx == PS_DALI_RX_NONE ? AD_CONFIRM : AD_QUERY);
			return 1;
		}
		c->mid = c->lo + (c->hi - c->lo) / 2;
		search_to(c, c->mid, AD_BIN_CMP);
		return 1;
	case PC_SEARCH: {
		static const int byte_cmd[3] = { PS_DALI_SEARCHADDRH, PS_DALI_SEARCHADDRM, PS_DALI_SEARCHADDRL };
		int b;
		for (b = 0; b < 3; b++) {
			int shift = 16 - 8 * b;
			if (!(c->search_known & (1 << b)) || ((c->search >> shift) & 0xFF) != ((c->want >> shift) & 0xFF))
				break;
		}
		if (b == 3) {
			c->pc = c->want_ret;
			return 1;
		}
		c->k = b;
		emit(c, special(byte_cmd[b], (int)(c->want >> (16 - 8 * b)) & 0xFF), 0, 0);
		return 0;
	}
	default:
		return internal(c, now);
	}
}

static int search_result(struct ps_dali_commission *c, int rx)
{
	int yes = rx == PS_DALI_RX_ANSWER || rx == PS_DALI_RX_COLLISION;
	switch (c->pc) {
	case AD_BIN_CMP:
		if (yes) {
			if (rx == PS_DALI_RX_COLLISION && c->nnode < 24)
				c->node[c->nnode++] = (struct ps_dali_search_node){ c->lo, c->mid, 0 };
			c->hi = c->mid;
			c->hi_rx = rx;
		} else {
			c->lo = c->mid + 1;
		}
		c->pc = AD_BIN;
		return 1;
	case AD_CONFIRM:
		if (yes) {
			c->hi_rx = rx;
			c->pc = rx == PS_DALI_RX_COLLISION ? AD_CLASH : AD_QUERY;
		} else if (c->from_node) {
			c->nnode = 0;   /* the garble was not two ballasts after all: search all */
			c->pc = AD_FIRST;
		} else {
			c->pc = AD_FINAL;   /* nobody answers anywhere: all found */
		}
		return 1;
	case PC_SEARCH: {
		int shift = 16 - 8 * c->k;
		c->search = (c->search & ~(0xFFu << shift)) | (c->want & (0xFFu << shift));
		c->search_known |= 1 << c->k;
		return 1;
	}
	}
	return 1;
}

/* ---- address: short addresses for the ballasts the search finds ---- */

static int address_run(struct ps_dali_commission *c, double now)
{
	switch (c->pc) {
	case AD_UNADDR:
		step(c, "address: gear without a short address?");
		emit(c, (PS_DALI_UNADDRESSED << 8) | PS_DALI_QUERY_GEAR_PRESENT, 0, 1);
		return 0;
	case AD_PRESENT:
		step(c, "address: which short addresses answer (%d of 63)", c->i);
		emit(c, short_frame(c->i, PS_DALI_QUERY_GEAR_PRESENT), 0, 1);
		return 0;
	case AD_TERMINATE:
	case AD_FINAL:
	case AB_TERMINATE:
		emit(c, special(PS_DALI_TERMINATE, 0), 0, 0);
		return 0;
	case AD_INIT:
		step(c, "address: INITIALISE %s", c->mode == PS_DALI_ADDRESS_ALL ? "all" : "unaddressed");
		emit(c, special(PS_DALI_INITIALISE, c->mode == PS_DALI_ADDRESS_ALL ? 0x00 : 0xFF), 1, 0);
		return 0;
	case AD_INIT_DUP:
		while (c->i < 64 && !(c->dup & bit(c->i)))
			c->i++;
		if (c->i >= 64) {
			c->pc = c->reinit ? AD_FIRST : AD_RANDOMISE;
			return 1;
		}
		step(c, "address: INITIALISE short %d (several ballasts share it)", c->i);
		emit(c, special(PS_DALI_INITIALISE, c->i << 1 | 1), 1, 0);
		return 0;
	case AD_RANDOMISE:
		step(c, "address: RANDOMISE");
		emit(c, special(PS_DALI_RANDOMISE, 0), 1, 0);
		return 0;
	case AD_QUERY:
		step(c, "address: ballast %d at random address 0x%06X", c->nfound + 1, c->found_at);
		emit(c, special(PS_DALI_QUERY_SHORT_ADDRESS, 0), 0, 1);
		return 0;
	case AD_PROGRAM:
		step(c, "address: random address 0x%06X gets short address %d", c->found_at, c->addr);
		emit(c, special(PS_DALI_PROGRAM_SHORT_ADDRESS, c->addr << 1 | 1), 0, 0);
		return 0;
	case AD_VERIFY:
		emit(c, special(PS_DALI_VERIFY_SHORT_ADDRESS, c->addr << 1 | 1), 0, 1);
		return 0;
	case AD_UNPROGRAM:
		emit(c, special(PS_DALI_PROGRAM_SHORT_ADDRESS, 0xFF), 0, 0);
		return 0;
	case AD_CLASH:
		c->nnode = 0;
		if (++c->clashes > MAX_CLASHES) {
			end(c, now, PS_DALI_COMMISSION_FAILED,
			    "random addresses collided %d times: ballasts that cannot draw distinct ones", c->clashes);
			return 0;
		}
		step(c, "address: two ballasts drew random address 0x%06X: RANDOMISE again", c->found_at);
		c->pc = AD_RANDOMISE;
		return 1;
	case AD_WITHDRAW:
		emit(c, special(PS_DALI_WITHDRAW, 0), 0, 0);
		return 0;
	default:
		return search_run(c, now);
	}
}

static int address_result(struct ps_dali_commission *c, double now, int rx, unsigned value)
{
	int yes = rx == PS_DALI_RX_ANSWER || rx == PS_DALI_RX_COLLISION;
	switch (c->pc) {
	case AD_PRESENT:
		if (yes)
			c->used |= bit(c->i);
		if (rx == PS_DALI_RX_COLLISION)
			c->dup |= bit(c->i);
		if (++c->i < 64)
			return 1;
		c->scanned = 64;
		c->pc = c->mode == PS_DALI_ADDRESS_NEW ? AD_UNADDR : AD_TERMINATE;
		return 1;
	case AD_UNADDR:
		c->unaddressed = rx == PS_DALI_RX_ANSWER ? 1 : rx == PS_DALI_RX_COLLISION ? 2 : 0;
		if (!yes && !c->dup) {
			end(c, now, PS_DALI_COMMISSION_DONE, "every ballast has a short address of its own: nothing to do");
			return 0;
		}
		c->pc = AD_TERMINATE;
		return 1;
	case AD_TERMINATE:
		c->pc = AD_INIT;
		return 1;
	case AD_INIT:
		c->inits++;
		c->init_at = now;
		c->search_known = 0;   /* gear new to the search holds an unknown search address */
		c->i = 0;
		if (c->mode == PS_DALI_ADDRESS_NEW)
			c->pc = AD_INIT_DUP;
		else
			c->pc = c->reinit ? AD_FIRST : AD_RANDOMISE;
		return 1;
	case AD_INIT_DUP:
		c->i++;
		return 1;
	case AD_RANDOMISE:
		c->nnode = 0;   /* every address is new */
		c->wait_until = now + RANDOMISE_WAIT;
		c->pc = AD_FIRST;
		return 1;
	case AD_QUERY:
		if (rx == PS_DALI_RX_NONE) {
			c->nnode = 0;
			restart(c, now);
			return 1;
		}
		if (rx == PS_DALI_RX_COLLISION) {
			c->pc = AD_CLASH;
			return 1;
		}
		c->was = value == 0xFF ? -1 : short_of(value);
		c->refound = 0;
		for (int j = 0; j < c->nfound && j < 64; j++)
			if (c->was >= 0 && c->found[j].random == c->found_at && c->found[j].address == c->was)
				c->refound = 1;   /* re-enabled by a renewed INITIALISE: already done */
		if (c->refound) {
			c->pc = AD_WITHDRAW;
		} else if (c->was >= 0 && !(c->claimed & bit(c->was))) {
			c->claimed |= bit(c->was);
			c->kept++;
			record(c, c->was);
			c->pc = AD_WITHDRAW;
		} else if ((c->addr = free_address(c)) < 0) {
			c->no_free++;
			record(c, -1);
			c->pc = AD_WITHDRAW;
		} else {
			c->pc = AD_PROGRAM;
		}
		return 1;
	case AD_PROGRAM:
		c->pc = AD_VERIFY;
		return 1;
	case AD_VERIFY:
		if (rx == PS_DALI_RX_ANSWER) {
			c->claimed |= bit(c->addr);
			c->programmed++;
			record(c, c->addr);
			c->pc = AD_WITHDRAW;
		} else if (rx == PS_DALI_RX_COLLISION) {
			c->pc = AD_UNPROGRAM;   /* two took it: take it back from both */
		} else {
			/* gone before it could confirm: its address may be taken, keep off it */
			c->bad |= bit(c->addr);
			c->lost++;
			c->pc = AD_WITHDRAW;
		}
		return 1;
	case AD_UNPROGRAM:
		c->pc = AD_CLASH;
		return 1;
	case AD_WITHDRAW:
		for (int j = 0; j < c->nnode; j++)
			if (c->node[j].base <= c->found_at && c->found_at <= c->node[j].top)
				c->node[j].found++;
		if (now - c->init_at > INIT_REFRESH) {
			/* before the 15 minutes run out; gear it re-enables is found
			 * again (and recognised), so nothing learnt so far holds */
			c->reinit = 1;
			c->nnode = 0;
			c->pc = AD_INIT;
		} else {
			c->pc = AD_FIRST;
		}
		return 1;
	case AD_FINAL:
		address_done(c, now);
		return 0;
	case AB_TERMINATE:
		end(c, now, PS_DALI_COMMISSION_ABORTED, "aborted: %d ballasts had been found (%d new addresses)", c->nfound,
		    c->programmed);
		return 0;
	default:
		return search_result(c, rx);
	}
	return 1;
}

/* ---- group: add to or remove from a group, then check ---- */

static int group_run(struct ps_dali_commission *c, double now)
{
	unsigned mask = 1u << (c->group % 16);
	switch (c->pc) {
	case GR_DTR1:
		step(c, "group: control device %d, %s device group %d", c->target.n, c->add ? "ADD TO" : "REMOVE FROM",
		     c->group);
		emit(c, (unsigned)ps_dali_device_special(PS_DALI_DEVICE_DTR1, (int)(mask & 0xFF)), 0, 0);
		return 0;
	case GR_DTR2:
		emit(c, (unsigned)ps_dali_device_special(PS_DALI_DEVICE_DTR2, (int)(mask >> 8)), 0, 0);
		return 0;
	case GR_DCMD:
		emit(c, (unsigned)ps_dali_device_cmd(c->target.n, (c->add ? PS_DALI_DEVICE_ADD_TO_GROUPS_0_15 :
		                                                   PS_DALI_DEVICE_REMOVE_FROM_GROUPS_0_15) + (c->group >= 16)),
		     1, 0);
		return 0;
	case GR_DQ:
		emit(c, (unsigned)ps_dali_device_cmd(c->target.n, PS_DALI_DEVICE_QUERY_GROUPS_0_7 + c->k), 0, 1);
		return 0;
	case GR_CMD:
		step(c, "group: %s group %d", c->add ? "ADD TO" : "REMOVE FROM", c->group);
		emit(c, (unsigned)ps_dali_cmd(&c->target, (c->add ? PS_DALI_ADD_TO_GROUP : PS_DALI_REMOVE_FROM_GROUP) +
		                                              c->group), 1, 0);
		return 0;
	case GR_Q0:
		emit(c, short_frame(c->target.n, PS_DALI_QUERY_GROUPS_0_7), 0, 1);
		return 0;
	case GR_Q1:
		emit(c, short_frame(c->target.n, PS_DALI_QUERY_GROUPS_8_15), 0, 1);
		return 0;
	default:
		return internal(c, now);
	}
}

static int group_result(struct ps_dali_commission *c, double now, int rx, unsigned value)
{
	switch (c->pc) {
	case GR_DTR1:
		c->pc = GR_DTR2;
		return 1;
	case GR_DTR2:
		c->pc = GR_DCMD;
		return 1;
	case GR_DCMD:
		c->pc = GR_DQ;
		c->k = 0;
		return 1;
	case GR_DQ:
		if (rx != PS_DALI_RX_ANSWER) {
			end(c, now, PS_DALI_COMMISSION_FAILED, "control device %d: %s to QUERY DEVICE GROUPS", c->target.n,
			    rx == PS_DALI_RX_NONE ? "no answer" : "no clean answer");
			return 0;
		}
		c->device_groups |= (value & 0xFFu) << (8 * c->k);
		if (++c->k < 4)
			return 1;
		c->device_groups_known = 1;
		if (((c->device_groups >> c->group) & 1) == (unsigned)c->add)
			end(c, now, PS_DALI_COMMISSION_DONE, "control device %d is %s device group %d", c->target.n,
			    c->add ? "in" : "out of", c->group);
		else
			end(c, now, PS_DALI_COMMISSION_FAILED, "control device %d did not take it: still %s device group %d",
			    c->target.n, c->add ? "out of" : "in", c->group);
		return 0;
	case GR_CMD:
		if (c->target.kind != PS_DALI_SHORT) {
			end(c, now, PS_DALI_COMMISSION_DONE, "%s group %d sent to %s", c->add ? "ADD TO" : "REMOVE FROM",
			    c->group, c->target.kind == PS_DALI_GROUP ? "a group" : "all gear");
			return 0;
		}
		c->pc = GR_Q0;
		return 1;
	case GR_Q0:
		if (rx != PS_DALI_RX_ANSWER) {
			end(c, now, PS_DALI_COMMISSION_FAILED, "short address %d: %s", c->target.n,
			    rx == PS_DALI_RX_NONE ? "no ballast answers" : "several ballasts answer, with different groups");
			return 0;
		}
		c->tmp = (int)value;
		c->pc = GR_Q1;
		return 1;
	case GR_Q1:
		if (rx != PS_DALI_RX_ANSWER) {
			end(c, now, PS_DALI_COMMISSION_FAILED, "short address %d: no clean answer to QUERY GROUPS 8-15",
			    c->target.n);
			return 0;
		}
		c->groups_after = (int)value << 8 | c->tmp;
		if (((c->groups_after >> c->group) & 1) == c->add)
			end(c, now, PS_DALI_COMMISSION_DONE, "short address %d is %s group %d", c->target.n,
			    c->add ? "in" : "out of", c->group);
		else
			end(c, now, PS_DALI_COMMISSION_FAILED, "short address %d did not take it: still %s group %d",
			    c->target.n, c->add ? "out of" : "in", c->group);
		return 0;
	}
	return 1;
}

/* ---- identify: flash one ballast, then restore its level ---- */

static int identify_run(struct ps_dali_commission *c, double now)
{
	switch (c->pc) {
	case ID_DEVICE_CHECK:
		step(c, "identify: control device %d there?", c->target.n);
		emit(c, (unsigned)ps_dali_device_cmd(c->target.n, PS_DALI_DEVICE_QUERY_STATUS), 0, 1);
		return 0;
	case ID_DEVICE:
		step(c, "identify: control device %d", c->target.n);
		emit(c, (unsigned)ps_dali_device_cmd(c->target.n, PS_DALI_DEVICE_IDENTIFY), 1, 0);
		return 0;
	case ID_QUERY:
		step(c, "identify: short address %d, its level", c->target.n);
		emit(c, short_frame(c->target.n, PS_DALI_QUERY_ACTUAL_LEVEL), 0, 1);
		return 0;
	case ID_G0:
		emit(c, short_frame(c->target.n, PS_DALI_QUERY_GROUPS_0_7), 0, 1);
		return 0;
	case ID_G1:
		emit(c, short_frame(c->target.n, PS_DALI_QUERY_GROUPS_8_15), 0, 1);
		return 0;
	case ID_FLASH:
		step(c, "identify: short address %d flashing (%.0f of %.0f s)", c->target.n,
		     fmax(0, now - c->t0), c->seconds);
		emit(c, short_frame(c->target.n, c->k % 2 ? PS_DALI_RECALL_MIN : PS_DALI_RECALL_MAX), 0, 0);
		return 0;
	case ID_RESTORE:
	case AB_RESTORE:
		if (c->saved_level < 0 || c->saved_level == PS_DALI_MASK) {
			/* level unknown: the held zone points set it afterwards */
			if (c->pc == AB_RESTORE)
				end(c, now, PS_DALI_COMMISSION_ABORTED, "aborted");
			else
				end(c, now, PS_DALI_COMMISSION_DONE, "flashed %d times", c->flashes);
			return 0;
		}
		step(c, "identify: short address %d back to level %d", c->target.n, c->saved_level);
		if (c->saved_level == 0)
			emit(c, short_frame(c->target.n, PS_DALI_OFF), 0, 0);
		else
			emit(c, (unsigned)ps_dali_dapc(&c->target, c->saved_level), 0, 0);
		return 0;
	default:
		return internal(c, now);
	}
}

static int identify_result(struct ps_dali_commission *c, double now, int rx, unsigned value)
{
	int v = value_of(rx, value);
	switch (c->pc) {
	case ID_DEVICE_CHECK:
		if (rx == PS_DALI_RX_NONE) {
			end(c, now, PS_DALI_COMMISSION_FAILED, "no control device answers at short address %d",
			    c->target.n);
			return 0;
		}
		c->pc = ID_DEVICE;
		return 1;
	case ID_DEVICE:
		end(c, now, PS_DALI_COMMISSION_DONE,
		    "control device %d told to identify itself (IDENTIFY DEVICE: its own signal, about 10 s)",
		    c->target.n);
		return 0;
	case ID_QUERY:
		if (rx == PS_DALI_RX_NONE) {
			end(c, now, PS_DALI_COMMISSION_FAILED, "no ballast answers at short address %d", c->target.n);
			return 0;
		}
		c->saved_level = v;
		c->pc = ID_G0;
		return 1;
	case ID_G0:
		c->tmp = v;
		c->pc = ID_G1;
		return 1;
	case ID_G1:
		c->hold_groups[c->target.n] = c->tmp < 0 || v < 0 ? ALL_GROUPS : v << 8 | c->tmp;
		c->hold = bit(c->target.n);
		c->k = 0;
		c->t0 = now;
		c->pc = ID_FLASH;
		return 1;
	case ID_FLASH:
		c->k++;
		c->flashes = (c->k + 1) / 2;
		c->wait_until = c->t0 + c->k * FLASH_HALF;
		if (c->k * FLASH_HALF >= c->seconds)
			c->pc = ID_RESTORE;
		return 1;
	case ID_RESTORE:
		end(c, now, PS_DALI_COMMISSION_DONE, "flashed %d times, back at level %d", c->flashes, c->saved_level);
		return 0;
	case AB_RESTORE:
		end(c, now, PS_DALI_COMMISSION_ABORTED, "aborted; back at level %d", c->saved_level);
		return 0;
	}
	return 1;
}

/* ---- verify: command each target two levels, read every ballast back ---- */

static int verify_run(struct ps_dali_commission *c, double now)
{
	switch (c->pc) {
	case VE_PRESENT:
		step(c, "verify: which short addresses answer (%d of 63)", c->i);
		emit(c, short_frame(c->i, PS_DALI_QUERY_GEAR_PRESENT), 0, 1);
		return 0;
	case VE_INFO:
		while (c->i < 64 && !(c->used & bit(c->i)))
			c->i++;
		if (c->i >= 64) {
			/* who answers to each target; from now on their light is ours */
			for (int t = 0; t < c->nvt; t++) {
				struct ps_dali_verify_target *v = &c->vt[t];
				if (v->addr.kind == PS_DALI_SHORT)
					v->members = bit(v->addr.n);
				for (int a = 0; a < 64; a++)
					if ((c->used & bit(a)) && reaches(&v->addr, a, c->gear[a].groups))
						v->members |= bit(a);
				c->hold |= v->members;
			}
			for (int a = 0; a < 64; a++)
				c->hold_groups[a] = c->gear[a].groups >= 0 ? c->gear[a].groups : ALL_GROUPS;
			c->i = c->k = 0;
			c->pc = VE_CMD;
			return 1;
		}
		step(c, "verify: short address %d, its groups and levels", c->i);
		emit(c, short_frame(c->i, verify_queries[c->tmp]), 0, 1);
		return 0;
	case VE_CMD:
		if (c->i >= c->nvt) {
			double fade = 0;
			/* the longest fade of the gear that answered: one that did not
			 * (gone dead) is read back as no answer whatever its fade, so
			 * its unknown fade (taken as the longest, 90.5 s) is not waited */
			for (int a = 0; a < 64; a++)
				if (c->hold & c->used & bit(a))
					fade = fmax(fade, fade_seconds(c->gear[a].fade));
			c->i = 0;
			c->pc = VE_QUERY;
			c->wait_until = now + fade + FADE_MARGIN;
			step(c, "verify: level %d sent, waiting %.1f s for the fade", c->levels[c->k], fade + FADE_MARGIN);
			return 1;
		}
		step(c, "verify: %s to level %d", c->vt[c->i].name, c->levels[c->k]);
		emit(c, (unsigned)ps_dali_dapc(&c->vt[c->i].addr, c->levels[c->k]), 0, 0);
		return 0;
	case VE_QUERY:
		while (c->i < 64 && !(c->used & bit(c->i)) && !(c->hold & bit(c->i)))
			c->i++;
		if (c->i >= 64) {
			if (++c->k < 2) {
				c->i = 0;
				c->pc = VE_CMD;
				return 1;
			}
			verify_judge(c, now);
			return 0;
		}
		step(c, "verify: level %d: short address %d", c->levels[c->k], c->i);
		emit(c, short_frame(c->i, PS_DALI_QUERY_ACTUAL_LEVEL), 0, 1);
		return 0;
	default:
		return internal(c, now);
	}
}

static int verify_result(struct ps_dali_commission *c, double now, int rx, unsigned value)
{
	int v = value_of(rx, value), yes = rx == PS_DALI_RX_ANSWER || rx == PS_DALI_RX_COLLISION;
	(void)now;   /* verify decides at the end of a run, not on a result */
	switch (c->pc) {
	case VE_PRESENT:
		if (yes) {
			c->used |= bit(c->i);
			c->gear[c->i].present = rx == PS_DALI_RX_ANSWER ? 1 : 2;
		}
		if (++c->i >= 64) {
			c->i = 0;
			c->tmp = 0;
			c->pc = VE_INFO;
		}
		return 1;
	case VE_INFO:
		verify_store(&c->gear[c->i], c->tmp, v);
		if (++c->tmp >= NVERIFY) {
			c->tmp = 0;
			c->i++;
		}
		return 1;
	case VE_CMD:
		c->i++;
		return 1;
	case VE_QUERY:
		c->got[c->i][c->k] = v;
		c->i++;
		return 1;
	}
	return 1;
}

/* Each job is a run/result pair over its own steps (pc).  run does what the
 * pc says: 1 when the pc moved on and run should go again, 0 when it asked
 * for a transaction (c->tx) or a wait (c->wait_until), or the job ended.
 * result files a transaction's outcome under the pc that asked for it and
 * moves the pc on: 1 to go on running, 0 when the job ended. */
static int (*const job_run[])(struct ps_dali_commission *c, double now) = {
	[PS_DALI_COMMISSION_SCAN] = scan_run,
	[PS_DALI_COMMISSION_ADDRESS] = address_run,
	[PS_DALI_COMMISSION_GROUP] = group_run,
	[PS_DALI_COMMISSION_IDENTIFY] = identify_run,
	[PS_DALI_COMMISSION_VERIFY] = verify_run,
};
static int (*const job_result[])(struct ps_dali_commission *c, double now, int rx, unsigned value) = {
	[PS_DALI_COMMISSION_SCAN] = scan_result,
	[PS_DALI_COMMISSION_ADDRESS] = address_result,
	[PS_DALI_COMMISSION_GROUP] = group_result,
	[PS_DALI_COMMISSION_IDENTIFY] = identify_result,
	[PS_DALI_COMMISSION_VERIFY] = verify_result,
};

/* Do what the pc says until a transaction, a wait or the end. */
static void run(struct ps_dali_commission *c, double now)
{
	c->have_tx = 0;
	while (c->state == PS_DALI_COMMISSION_RUNNING && !(now < c->wait_until) && c->pc != PC_END &&
	       job_run[c->kind](c, now))
		;
}

void ps_dali_commission_result(struct ps_dali_commission *c, double now, int rx, unsigned value, const char *why)
{
	if (c->state != PS_DALI_COMMISSION_RUNNING || !c->have_tx)
		return;
	c->have_tx = 0;
	c->frames++;
	/* a control device answers QUERY SHORT ADDRESS with 0..63 */
	if (c->devices_space && rx == PS_DALI_RX_ANSWER && value <= 63 &&
	    c->tx.frame == (unsigned)ps_dali_device_special(PS_DALI_DEVICE_QUERY_SHORT_ADDRESS, 0))
		value = value << 1 | 1;
	if (rx == PS_DALI_RX_FAILED) {
		end(c, now, PS_DALI_COMMISSION_FAILED, "%s", why && *why ? why : "the interface did not answer");
		return;
	}
	if (!job_result[c->kind](c, now, rx, value))
		return;
	if (c->abort_req)
		do_abort(c, now);
	run(c, now);
}

int ps_dali_commission_next(const struct ps_dali_commission *c, struct ps_dali_tx *tx, double *until)
{
	if (c->state != PS_DALI_COMMISSION_RUNNING)
		return PS_DALI_NEXT_NONE;
	if (c->have_tx) {
		*tx = c->tx;
		return PS_DALI_NEXT_TX;
	}
	*until = c->wait_until;
	return PS_DALI_NEXT_WAIT;
}

void ps_dali_commission_poll(struct ps_dali_commission *c, double now)
{
	if (c->state == PS_DALI_COMMISSION_RUNNING && !c->have_tx && now >= c->wait_until)
		run(c, now);
}

void ps_dali_commission_abort(struct ps_dali_commission *c, double now)
{
	if (c->state != PS_DALI_COMMISSION_RUNNING)
		return;
	if (c->have_tx) {
		c->abort_req = 1;   /* its transaction may be on the bus: after its result */
		return;
	}
	do_abort(c, now);
	run(c, now);
}

void ps_dali_commission_fail(struct ps_dali_commission *c, double now, const char *why)
{
	if (c->state == PS_DALI_COMMISSION_RUNNING)
		end(c, now, PS_DALI_COMMISSION_FAILED, "%s", why);
}

int ps_dali_commission_holds(const struct ps_dali_commission *c, const struct ps_dali_addr *a)
{
	if (c->state != PS_DALI_COMMISSION_RUNNING || !c->hold)
		return 0;
	for (int s = 0; s < 64; s++)
		if ((c->hold & bit(s)) && reaches(a, s, c->hold_groups[s]))
			return 1;
	return 0;
}

/* ---- starting ------------------------------------------------------------------------ */

int ps_dali_commission_scan(struct ps_dali_commission *c, double now)
{
	start(c, PS_DALI_COMMISSION_SCAN, SC_PRESENT, now);
	run(c, now);
	return 0;
}

int ps_dali_commission_scan_devices(struct ps_dali_commission *c, double now)
{
	start(c, PS_DALI_COMMISSION_SCAN, SC_PRESENT, now);
	c->with_devices = 1;
	run(c, now);
	return 0;
}

static int address_start(struct ps_dali_commission *c, int mode, int devices, double now)
{
	if (mode != PS_DALI_ADDRESS_NEW && mode != PS_DALI_ADDRESS_ALL) {
		snprintf(c->msg, sizeof c->msg, "address: the mode is new or all");
		return -1;
	}
	start(c, PS_DALI_COMMISSION_ADDRESS, AD_PRESENT, now);
	c->devices_space = devices;
	c->mode = mode;
	run(c, now);
	return 0;
}

int ps_dali_commission_address(struct ps_dali_commission *c, int mode, double now)
{
	return address_start(c, mode, 0, now);
}

int ps_dali_commission_address_devices(struct ps_dali_commission *c, int mode, double now)
{
	return address_start(c, mode, 1, now);
}

int ps_dali_commission_group(struct ps_dali_commission *c, const struct ps_dali_addr *a, int group, int add,
                             double now)
{
	if (group < 0 || group > 15 || ps_dali_addr_byte(a, 1) < 0) {
		snprintf(c->msg, sizeof c->msg, "group: a group is 0 to 15, at a short address 0 to 63, a group or broadcast");
		return -1;
	}
	start(c, PS_DALI_COMMISSION_GROUP, GR_CMD, now);
	c->target = *a;
	c->group = group;
	c->add = add != 0;
	run(c, now);
	return 0;
}

int ps_dali_commission_group_device(struct ps_dali_commission *c, int short_addr, int group, int add, double now)
{
	if (short_addr < 0 || short_addr > 63 || group < 0 || group > 31) {
		snprintf(c->msg, sizeof c->msg, "group device: a short address 0 to 63 and a device group 0 to 31");
		return -1;
	}
	start(c, PS_DALI_COMMISSION_GROUP, GR_DTR1, now);
	c->target = (struct ps_dali_addr){ PS_DALI_SHORT, short_addr };
	c->group = group;
	c->add = add != 0;
	c->on_device = 1;
	run(c, now);
	return 0;
}

int ps_dali_commission_identify(struct ps_dali_commission *c, int short_addr, double seconds, double now)
{
	if (short_addr < 0 || short_addr > 63 || !(seconds >= 1 && seconds <= 600)) {
		snprintf(c->msg, sizeof c->msg, "identify: a short address 0 to 63, for 1 to 600 s");
		return -1;
	}
	start(c, PS_DALI_COMMISSION_IDENTIFY, ID_QUERY, now);
	c->target = (struct ps_dali_addr){ PS_DALI_SHORT, short_addr };
	c->seconds = seconds;
	run(c, now);
	return 0;
}

int ps_dali_commission_identify_device(struct ps_dali_commission *c, int short_addr, double now)
{
	if (short_addr < 0 || short_addr > 63) {
		snprintf(c->msg, sizeof c->msg, "identify device: a short address 0 to 63");
		return -1;
	}
	start(c, PS_DALI_COMMISSION_IDENTIFY, ID_DEVICE_CHECK, now);
	c->target = (struct ps_dali_addr){ PS_DALI_SHORT, short_addr };
	run(c, now);
	return 0;
}

int ps_dali_commission_verify(struct ps_dali_commission *c, const struct ps_dali_addr *targets,
                              const char *const *names, int n, int level1, int level2, double now)
{
	if (n < 1 || n > PS_DALI_VERIFY_MAX || level1 < 0 || level1 > PS_DALI_MAX_LEVEL || level2 < 0 ||
	    level2 > PS_DALI_MAX_LEVEL || level1 == level2) {
		snprintf(c->msg, sizeof c->msg, "verify: 1 to %d addresses and two different levels 0 to 254",
		         PS_DALI_VERIFY_MAX);
		return -1;
	}
	for (int t = 0; t < n; t++)
		if (ps_dali_addr_byte(&targets[t], 0) < 0) {
			snprintf(c->msg, sizeof c->msg, "verify: %s: not a DALI address", names[t]);
			return -1;
		}
	start(c, PS_DALI_COMMISSION_VERIFY, VE_PRESENT, now);
	for (int t = 0; t < n; t++) {
		c->vt[t].addr = targets[t];
		snprintf(c->vt[t].name, sizeof c->vt[t].name, "%s", names[t] ? names[t] : "");
	}
	c->nvt = n;
	c->levels[0] = level1;
	c->levels[1] = level2;
	run(c, now);
	return 0;
}

/* ---- the report ----------------------------------------------------------------------- */

static void put_int(json_object *o, const char *key, int v)
{
	/* unknown values: no answer is null, a collision is "collision" */
	json_object_object_add(o, key, v >= 0 ? json_object_new_int(v) :
	                               v == PS_DALI_COLLIDED ? json_object_new_string("collision") : NULL);
}

static json_object *groups_json(int groups)
{
	json_object *a;
	if (groups < 0)
		return groups == PS_DALI_COLLIDED ? json_object_new_string("collision") : NULL;
	a = json_object_new_array();
	for (int g = 0; g < 16; g++)
		if ((groups >> g) & 1)
			json_object_array_add(a, json_object_new_int(g));
	return a;
}

static const char *addr_text(const struct ps_dali_addr *a, char *buf, size_t len)
{
	if (a->kind == PS_DALI_SHORT)
		snprintf(buf, len, "%d", a->n);
	else if (a->kind == PS_DALI_GROUP)
		snprintf(buf, len, "group %d", a->n);
	else
		snprintf(buf, len, "broadcast");
	return buf;
}

static void scan_json(const struct ps_dali_commission *c, json_object *o)
{
	json_object *list = json_object_new_array();
	for (int a = 0; a < 64; a++) {
		const struct ps_dali_gear *g = &c->gear[a];
		json_object *b;
		if (!g->present)
			continue;
		b = json_object_new_object();
		json_object_object_add(b, "address", json_object_new_int(a));
		json_object_object_add(b, "ballasts", json_object_new_string(g->present == 2 ? "several" : "one"));
		put_int(b, "device_type", g->device_type);
		put_int(b, "physical_min", g->phys_min);
		put_int(b, "min_level", g->min_level);
		put_int(b, "max_level", g->max_level);
		put_int(b, "fade_time", g->fade >= 0 ? g->fade >> 4 : g->fade);
		json_object_object_add(b, "fade_time_s",
		                       g->fade >= 0 ? json_object_new_double(ps_dali_fade_time_seconds(g->fade >> 4)) : NULL);
		put_int(b, "fade_rate", g->fade >= 0 ? g->fade & 0x0F : g->fade);
		json_object_object_add(b, "groups", groups_json(g->groups));
		put_int(b, "failure_level", g->sfl);
		put_int(b, "power_on_level", g->power_on);
		put_int(b, "status", g->status);
		put_int(b, "actual_level", g->actual);
		json_object_array_add(list, b);
	}
	json_object_object_add(o, "scanned", json_object_new_int(c->scanned));
	json_object_object_add(o, "ballasts", list);
	json_object_object_add(o, "unaddressed", c->unaddressed < 0 ? NULL :
	                       json_object_new_string(c->unaddressed == 0 ? "none" : c->unaddressed == 1 ? "one" : "several"));
	if (!c->with_devices)
		return;
	list = json_object_new_array();
	for (int a = 0; a < 64; a++) {
		const struct ps_dali_ctl_device *d = &c->devices[a];
		json_object *b, *insts;
		if (!d->present)
			continue;
		b = json_object_new_object();
		insts = json_object_new_array();
		json_object_object_add(b, "address", json_object_new_int(a));
		json_object_object_add(b, "devices", json_object_new_string(d->present == 2 ? "several" : "one"));
		for (int k = 0; k < d->instances; k++) {
			json_object *x = json_object_new_object();
			const char *kind = d->type[k] == PS_DALI_TYPE_LIGHT ? "light sensor (304)"
			                 : d->type[k] == PS_DALI_TYPE_OCCUPANCY ? "occupancy sensor (303)"
			                 : d->type[k] == PS_DALI_TYPE_PUSH_BUTTON ? "push button (301)" : NULL;
			json_object_object_add(x, "number", json_object_new_int(k));
			put_int(x, "type", d->type[k]);
			json_object_object_add(x, "kind", kind ? json_object_new_string(kind) : NULL);
			json_object_array_add(insts, x);
		}
		json_object_object_add(b, "instances", insts);
		json_object_array_add(list, b);
	}
	json_object_object_add(o, "devices", list);
	json_object_object_add(o, "devices_unaddressed",
	                       json_object_new_string(c->dev_unaddressed == 0 ? "none" : c->dev_unaddressed == 1 ? "one"
	                                                                                                        : "several"));
}

static void address_json(const struct ps_dali_commission *c, json_object *o)
{
	json_object *list = json_object_new_array();
	char hex[16];
	json_object_object_add(o, "mode", json_object_new_string(c->mode == PS_DALI_ADDRESS_ALL ? "all" : "new"));
	for (int i = 0; i < c->nfound && i < 64; i++) {
		json_object *f = json_object_new_object();
		snprintf(hex, sizeof hex, "0x%06X", c->found[i].random);
		json_object_object_add(f, "random", json_object_new_string(hex));
		put_int(f, "address", c->found[i].address);
		put_int(f, "was", c->found[i].was);
		json_object_array_add(list, f);
	}
	json_object_object_add(o, "found", list);
	json_object_object_add(o, "programmed", json_object_new_int(c->programmed));
	json_object_object_add(o, "kept", json_object_new_int(c->kept));
	json_object_object_add(o, "clashes", json_object_new_int(c->clashes));
	json_object_object_add(o, "restarts", json_object_new_int(c->restarts));
	json_object_object_add(o, "lost", json_object_new_int(c->lost));
	json_object_object_add(o, "without_address", json_object_new_int(c->no_free));
}

static void verify_json(const struct ps_dali_commission *c, json_object *o)
{
	json_object *targets = json_object_new_array(), *levels = json_object_new_array(), *others;
	char buf[24];
	uint64_t all = 0;
	json_object_array_add(levels, json_object_new_int(c->levels[0]));
	json_object_array_add(levels, json_object_new_int(c->levels[1]));
	json_object_object_add(o, "levels", levels);
	for (int t = 0; t < c->nvt; t++) {
		const struct ps_dali_verify_target *v = &c->vt[t];
		json_object *vt = json_object_new_object(), *members = json_object_new_array();
		json_object_object_add(vt, "point", json_object_new_string(v->name));
		json_object_object_add(vt, "address", json_object_new_string(addr_text(&v->addr, buf, sizeof buf)));
		for (int a = 0; a < 64; a++) {
			json_object *m, *exp, *got;
			if (!(v->members & bit(a)))
				continue;
			m = json_object_new_object();
			exp = json_object_new_array();
			got = json_object_new_array();
			json_object_object_add(m, "address", json_object_new_int(a));
			for (int k = 0; k < 2; k++) {
				json_object_array_add(exp, json_object_new_int(expected(&c->gear[a], c->levels[k])));
				json_object_array_add(got, c->got[a][k] >= 0 ? json_object_new_int(c->got[a][k]) :
				                           c->got[a][k] == PS_DALI_COLLIDED ? json_object_new_string("collision") : NULL);
			}
			json_object_object_add(m, "expected", exp);
			json_object_object_add(m, "got", got);
			json_object_object_add(m, "ok", json_object_new_boolean(c->got[a][0] == expected(&c->gear[a], c->levels[0]) &&
			                                                        c->got[a][1] == expected(&c->gear[a], c->levels[1])));
			json_object_array_add(members, m);
		}
		all |= v->members;
		json_object_object_add(vt, "ballasts", members);
		json_object_object_add(vt, "ok", c->state == PS_DALI_COMMISSION_DONE ? json_object_new_boolean(v->ok) : NULL);
		json_object_array_add(targets, vt);
	}
	json_object_object_add(o, "targets", targets);
	others = json_object_new_array();
	if (c->state == PS_DALI_COMMISSION_DONE)
		for (int a = 0; a < 64; a++)
			if (!(all & bit(a)) && (c->used & bit(a)) && c->got[a][0] == expected(&c->gear[a], c->levels[0]) &&
			    c->got[a][1] == expected(&c->gear[a], c->levels[1]))
				json_object_array_add(others, json_object_new_int(a));
	json_object_object_add(o, "others_following", others);
	json_object_object_add(o, "ok", c->state == PS_DALI_COMMISSION_DONE ? json_object_new_boolean(c->ok) : NULL);
}

void ps_dali_commission_json(const struct ps_dali_commission *c, double now, struct json_object *o)
{
	char buf[24];
	double until = isnan(c->ended) ? now : c->ended;
	json_object_object_add(o, "job", json_object_new_string(ps_dali_commission_kinds[c->kind]));
	json_object_object_add(o, "state", json_object_new_string(ps_dali_commission_states[c->state]));
	json_object_object_add(o, "step", json_object_new_string(c->step));
	json_object_object_add(o, "frames", json_object_new_int64((int64_t)c->frames));
	json_object_object_add(o, "elapsed_s", json_object_new_double(floor((until - c->started) * 1000 + 0.5) / 1000));
	json_object_object_add(o, "message", c->msg[0] ? json_object_new_string(c->msg) : NULL);
	switch (c->kind) {
	case PS_DALI_COMMISSION_SCAN:
		scan_json(c, o);
		break;
	case PS_DALI_COMMISSION_ADDRESS:
		address_json(c, o);
		break;
	case PS_DALI_COMMISSION_GROUP:
		if (c->on_device) {
			json_object *a = json_object_new_array();
			json_object_object_add(o, "control_device", json_object_new_int(c->target.n));
			json_object_object_add(o, "group", json_object_new_int(c->group));
			json_object_object_add(o, "action", json_object_new_string(c->add ? "add" : "remove"));
			for (int g = 0; g < 32; g++)
				if ((c->device_groups >> g) & 1)
					json_object_array_add(a, json_object_new_int(g));
			json_object_object_add(o, "device_groups", c->device_groups_known ? a : NULL);
			if (!c->device_groups_known)
				json_object_put(a);
			break;
		}
		json_object_object_add(o, "address", json_object_new_string(addr_text(&c->target, buf, sizeof buf)));
		json_object_object_add(o, "group", json_object_new_int(c->group));
		json_object_object_add(o, "action", json_object_new_string(c->add ? "add" : "remove"));
		json_object_object_add(o, "groups", groups_json(c->groups_after));
		break;
	case PS_DALI_COMMISSION_IDENTIFY:
		json_object_object_add(o, "address", json_object_new_int(c->target.n));
		json_object_object_add(o, "seconds", json_object_new_double(c->seconds));
		json_object_object_add(o, "flashes", json_object_new_int(c->flashes));
		put_int(o, "level", c->saved_level);
		break;
	case PS_DALI_COMMISSION_VERIFY:
		verify_json(c, o);
		break;
	}
}
