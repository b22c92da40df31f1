/* SPDX-License-Identifier: ISC */
/* A DALI-2 input instance as a point (see dali_input.h). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "dali_input.h"

/* rx as dali_commission.h has them */
enum { RX_NONE = 0, RX_ANSWER, RX_COLLISION, RX_FAILED };

static void add(struct ps_dali_input *in, long frame, int twice, int answer)
{
	if (frame >= 0 && in->ncfg < PS_DALI_INPUT_MAX_TX)
		in->cfg[in->ncfg++] = (struct ps_dali_input_tx){ (uint32_t)frame, twice, answer };
}

/* DTR0 = v, then the instance's command sent twice */
static void set(struct ps_dali_input *in, int opcode, int v)
{
	add(in, ps_dali_device_special(PS_DALI_DEVICE_DTR0, v), 0, 0);
	add(in, ps_dali_device_inst_cmd(in->c.address, in->c.instance, opcode), 1, 0);
}

int ps_dali_input_init(struct ps_dali_input *in, const struct ps_dali_input_conf *c, char *why, size_t n)
{
	int light = c->type == PS_DALI_TYPE_LIGHT, report, code;
	memset(in, 0, sizeof *in);
	in->c = *c;
	if (c->address < 0 || c->address > 63 || c->instance < 0 || c->instance > 31) {
		snprintf(why, n, "device address %d instance %d: the address is 0 to 63, the instance 0 to 31", c->address,
		         c->instance);
		return -1;
	}
	if (!light && c->type != PS_DALI_TYPE_OCCUPANCY) {
		snprintf(why, n, "instance type %d: only light sensors (4) and occupancy sensors (3)", c->type);
		return -1;
	}
	report = ps_dali_device_timer_code(c->report, 1, 1);
	if (report < 0) {
		snprintf(why, n, "report time %g s is outside 1 s to 4 min 15 s", c->report);
		return -1;
	}
	in->bits = light ? 10 : 2;
	in->last = -INFINITY;
	in->wanted = -INFINITY;
	set(in, light ? PS_DALI_LIGHT_SET_REPORT_TIMER : PS_DALI_OCC_SET_REPORT_TIMER, report);
	if (c->deadtime >= 0) {
		if ((code = ps_dali_device_timer_code(c->deadtime, 0.05, 0)) < 0) {
			snprintf(why, n, "dead time %g s is outside 0 to 12.75 s", c->deadtime);
			return -1;
		}
		set(in, light ? PS_DALI_LIGHT_SET_DEADTIME_TIMER : PS_DALI_OCC_SET_DEADTIME_TIMER, code);
	}
	if (light && c->hysteresis >= 0)
		set(in, PS_DALI_LIGHT_SET_HYSTERESIS, c->hysteresis > 255 ? 255 : c->hysteresis);
	if (light && c->hysteresis_min >= 0)
		set(in, PS_DALI_LIGHT_SET_HYSTERESIS_MIN, c->hysteresis_min > 255 ? 255 : c->hysteresis_min);
	if (!light && c->hold >= 0) {
		if ((code = ps_dali_device_timer_code(c->hold, 10, 1)) < 0) {
			snprintf(why, n, "hold time %g s is outside 10 s to 2550 s", c->hold);
			return -1;
		}
		set(in, PS_DALI_OCC_SET_HOLD_TIMER, code);
	}
	set(in, PS_DALI_DEVICE_SET_EVENT_SCHEME, PS_DALI_SCHEME_DEVICE_INSTANCE);
	/* the filter: DTR0 bits 0..7, DTR1 8..15, DTR2 16..23 */
	add(in, ps_dali_device_special(PS_DALI_DEVICE_DTR1, 0), 0, 0);
	add(in, ps_dali_device_special(PS_DALI_DEVICE_DTR2, 0), 0, 0);
	set(in, PS_DALI_DEVICE_SET_EVENT_FILTER,
	    light ? PS_DALI_LIGHT_FILTER_ILLUMINANCE
	          : PS_DALI_OCC_FILTER_OCCUPIED | PS_DALI_OCC_FILTER_VACANT | PS_DALI_OCC_FILTER_REPEAT);
	add(in, ps_dali_device_inst_cmd(c->address, c->instance, PS_DALI_DEVICE_ENABLE_INSTANCE), 1, 0);
	add(in, ps_dali_device_inst_cmd(c->address, c->instance, PS_DALI_DEVICE_QUERY_RESOLUTION), 0, 1);
	return 0;
}

void ps_dali_input_connected(struct ps_dali_input *in, double now)
{
	in->icfg = 0;
	in->busy = 0;
	in->stage = 0;
	in->next_poll = now;
}

/* seconds without a value before a poll: the sensor's own repeat, with
 * room for it when events come */
static double poll_after(const struct ps_dali_input *in)
{
	return in->c.events ? 1.25 * in->c.report : in->c.report;
}

static double retry_after(const struct ps_dali_input *in)
{
	return fmax(1.0, in->c.report / 4);
}

int ps_dali_input_next(struct ps_dali_input *in, double now, struct ps_dali_input_tx *tx, double *due)
{
	int op;
	*due = INFINITY;
	if (in->busy)
		return 0;
	if (in->icfg < in->ncfg) {
		if (now < in->next_poll) {
			*due = in->next_poll;
			return 0;
		}
		*tx = in->cfg[in->icfg];
		in->busy = 1;
		in->frames++;
		return 1;
	}
	if (in->stage == 0) {
		double t = ps_dali_input_refreshing(in) ? in->next_poll : fmax(in->next_poll, in->last + poll_after(in));
		if (now < t) {
			*due = t;
			return 0;
		}
		in->polls++;
	}
	op = in->stage == 0 ? PS_DALI_DEVICE_QUERY_INPUT_VALUE : PS_DALI_DEVICE_QUERY_INPUT_VALUE_LATCH;
	*tx = (struct ps_dali_input_tx){ (uint32_t)ps_dali_device_inst_cmd(in->c.address, in->c.instance, op), 0, 1 };
	in->busy = 1;
	in->frames++;
	return 1;
}

static void take(struct ps_dali_input *in, double now, long raw)
{
	in->value = in->c.type == PS_DALI_TYPE_LIGHT ? raw : (raw >> (in->bits - 1)) & 1;
	in->last = now;
	in->next_poll = now;
}

void ps_dali_input_result(struct ps_dali_input *in, double now, int rx, unsigned value)
{
	int nb = ps_dali_device_input_bytes(in->bits);
	in->busy = 0;
	if (in->icfg < in->ncfg) {
		const struct ps_dali_input_tx *t = &in->cfg[in->icfg];
		if (rx == RX_FAILED || rx == RX_COLLISION) {
			in->failures++;
			snprintf(in->why, sizeof in->why, "device %d instance %d: its configuration got no result",
			         in->c.address, in->c.instance);
			in->next_poll = now + retry_after(in);
			return;
		}
		if (t->answer && rx == RX_ANSWER && (t->frame & 0xFF) == PS_DALI_DEVICE_QUERY_RESOLUTION && value >= 1 &&
		    value <= 32)
			in->bits = (int)value;
		in->icfg++;
		return;
	}
	if (rx != RX_ANSWER) {
		in->failures++;
		snprintf(in->why, sizeof in->why, "device %d instance %d: %s to QUERY INPUT VALUE%s", in->c.address,
		         in->c.instance, rx == RX_NONE ? "no answer" : rx == RX_COLLISION ? "a garbled answer" : "no result",
		         in->stage ? " LATCH" : "");
		in->stage = 0;
		in->next_poll = now + retry_after(in);
		return;
	}
	in->bytes[in->stage++] = (uint8_t)value;
	if (in->stage < nb)
		return;
	in->stage = 0;
	take(in, now, ps_dali_device_input_value(in->bytes, nb, in->bits));
}

int ps_dali_input_event(struct ps_dali_input *in, double now, uint32_t frame)
{
	struct ps_dali_device_event ev;
	if (ps_dali_device_event_decode(frame, &ev) != 0 || ev.address != in->c.address)
		return 0;
	if (ev.scheme == PS_DALI_SCHEME_DEVICE_INSTANCE ? ev.instance != in->c.instance
	                                                : ev.scheme != PS_DALI_SCHEME_DEVICE || ev.instance_type != in->c.type)
		return 0;
	in->events++;
	if (in->c.type == PS_DALI_TYPE_LIGHT)
		take(in, now, (long)ev.info);
	else
		take(in, now, (long)(ev.info & PS_DALI_OCC_EV_OCCUPIED ? 1u << (in->bits - 1) : 0));
	return 1;
}

void ps_dali_input_refresh(struct ps_dali_input *in, double now)
{
	if (!(in->last >= now))
		in->wanted = now;
}

int ps_dali_input_refreshing(const struct ps_dali_input *in)
{
	return in->wanted > in->last;
}

double ps_dali_input_age(const struct ps_dali_input *in, double now)
{
	return in->last == -INFINITY ? INFINITY : fmax(0, now - in->last);
}

int ps_dali_input_value(const struct ps_dali_input *in, double now, double *v, int *err, char *why, size_t n)
{
	if (in->last == -INFINITY) {
		*err = ETIMEDOUT;
		snprintf(why, n, "device %d instance %d: no value yet%s%s", in->c.address, in->c.instance,
		         in->why[0] ? ": " : "", in->why);
		return -1;
	}
	if (now - in->last > 2 * in->c.report) {
		*err = ENODEV;
		snprintf(why, n, "device %d instance %d: no value for %.0f s (more than 2 x T_report %g s)%s%s",
		         in->c.address, in->c.instance, now - in->last, in->c.report, in->why[0] ? ": " : "", in->why);
		return -1;
	}
	*v = (double)in->value;
	return 0;
}
