/* SPDX-License-Identifier: ISC */
/* Modbus point options, register decoding and scaling (modbus_point.h). */
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "modbus_point.h"

const char *const ps_modbus_point_table_names[] = { "input_register", "holding_register", "coil",
                                          "discrete_input", NULL };
const char *const ps_modbus_point_type_names[] = { "u16", "s16", "u32", "s32", "f32", NULL };
const char *const ps_modbus_point_order_names[] = { "abcd", "cdab", NULL };

const char *ps_modbus_point_table_short(int table)
{
	static const char *const s[] = { "IR", "HR", "coil", "DI" };
	return table >= 0 && table < PS_MB_TABLE_COUNT ? s[table] : "?";
}

int ps_modbus_point_count(const struct ps_modbus_point *p)
{
	if (p->table == PS_MB_COIL || p->table == PS_MB_DISCRETE_INPUT)
		return 1;
	return p->type == PS_MB_U32 || p->type == PS_MB_S32 || p->type == PS_MB_F32 ? 2 : 1;
}

static void type_range(int type, double *lo, double *hi)
{
	switch (type) {
	case PS_MB_U16: *lo = 0; *hi = 65535; break;
	case PS_MB_S16: *lo = -32768; *hi = 32767; break;
	case PS_MB_U32: *lo = 0; *hi = 4294967295.0; break;
	case PS_MB_S32: *lo = -2147483648.0; *hi = 2147483647.0; break;
	default: *lo = -FLT_MAX; *hi = FLT_MAX; break;
	}
}

static const char *const parity_names[] = { "none", "even", "odd", NULL };
static const char *const baud_names[] = { "1200", "2400", "4800", "9600", "19200", "38400", "57600", "115200",
                                          "230400", NULL };

#define DEV PS_OPT_DEVICE
#define PT PS_OPT_POINT
const struct ps_opts_spec ps_modbus_point_options[] = {
	{ .key = "host", .type = PS_OPT_STRING, .scope = DEV,
	  .doc = "TCP: the module's IP address (exactly one of host and device)" },
	{ .key = "port", .type = PS_OPT_LONG, .scope = DEV, .def = "502", .min = 1, .max = 65535,
	  .doc = "TCP: the module's port" },
	{ .key = "device", .type = PS_OPT_STRING, .scope = DEV,
	  .doc = "RTU: the serial device, e.g. /dev/ttyUSB0" },
	{ .key = "baud", .type = PS_OPT_LONG, .scope = DEV, .def = "9600", .names = baud_names,
	  .doc = "RTU: the line's rate" },
	{ .key = "parity", .type = PS_OPT_ENUM, .scope = DEV, .def = "none", .names = parity_names,
	  .doc = "RTU: the parity bit" },
	{ .key = "data_bits", .type = PS_OPT_LONG, .scope = DEV, .def = "8", .min = 7, .max = 8,
	  .doc = "RTU: bits per character" },
	{ .key = "stop_bits", .type = PS_OPT_LONG, .scope = DEV, .def = "1", .min = 1, .max = 2,
	  .doc = "RTU: stop bits" },
	{ .key = "unit", .type = PS_OPT_LONG, .scope = DEV, .def = "1", .min = 0, .max = 255,
	  .doc = "the unit (slave) id; RTU 1 to 247" },
	{ .key = "timeout", .type = PS_OPT_DOUBLE, .scope = DEV, .def = "0.2",
	  .min = 0.001, .max = 10, .doc = "seconds to wait for a reply (also bounds a TCP connect)" },
	{ .key = "byte_timeout", .type = PS_OPT_DOUBLE, .scope = DEV, .def = "0.05",
	  .min = 0, .max = 10,
	  .doc = "seconds allowed between the bytes of a reply (0: the response timeout only)" },
	{ .key = "retries", .type = PS_OPT_LONG, .scope = DEV, .def = "1", .min = 0, .max = 5,
	  .doc = "further tries after a timeout or a garbled reply" },
	{ .key = "backoff_min", .type = PS_OPT_DOUBLE, .scope = DEV, .def = "1",
	  .min = 0.001, .max = 3600, .doc = "seconds before reconnecting after the connection is lost" },
	{ .key = "backoff_max", .type = PS_OPT_DOUBLE, .scope = DEV, .def = "60",
	  .min = 0.001, .max = 86400, .doc = "the longest wait the doubling backoff reaches, seconds" },
	{ .key = "lost_after", .type = PS_OPT_LONG, .scope = DEV, .def = "3",
	  .min = 1, .max = 1000, .doc = "RTU: timeouts in a row before the serial device is reopened" },
	{ .key = "table", .type = PS_OPT_ENUM, .scope = PT, .names = ps_modbus_point_table_names,
	  .doc = "where the value lives (required)" },
	{ .key = "address", .type = PS_OPT_LONG, .scope = PT, .min = 0, .max = 65535,
	  .doc = "the 0-based protocol address: 40001 is 0 (required)" },
	{ .key = "type", .type = PS_OPT_ENUM, .scope = PT, .def = "u16",
	  .names = ps_modbus_point_type_names, .doc = "a register's type; 32-bit types take two" },
	{ .key = "word_order", .type = PS_OPT_ENUM, .scope = PT, .def = "abcd",
	  .names = ps_modbus_point_order_names,
	  .doc = "32-bit types: abcd high word first, cdab low word first" },
	{ .key = "unit", .type = PS_OPT_LONG, .scope = PT, .min = 0, .max = 255,
	  .doc = "the point's own unit id (default: the device's)" },
	{ .key = "mask", .type = PS_OPT_LONG, .scope = PT, .def = "0xffff",
	  .min = 1, .max = 0xffff, .doc = "AND-ed into a 16-bit register before decoding" },
	{ .key = "status_mask", .type = PS_OPT_LONG, .scope = PT, .def = "0",
	  .min = 0, .max = 0xffff, .doc = "any of these bits set in a 16-bit register: a fault (ERANGE)" },
	{ .key = "raw_min", .type = PS_OPT_DOUBLE, .scope = PT, .min = -FLT_MAX, .max = FLT_MAX,
	  .doc = "the valid raw range's start, mapped onto min (default: the type's range)" },
	{ .key = "raw_max", .type = PS_OPT_DOUBLE, .scope = PT, .min = -FLT_MAX, .max = FLT_MAX,
	  .doc = "the valid raw range's end, mapped onto max" },
	{ .key = "min", .type = PS_OPT_DOUBLE, .scope = PT, .min = -1e15, .max = 1e15,
	  .doc = "the value at raw_min (default: sensor 0 V, dim 0, else as read)" },
	{ .key = "max", .type = PS_OPT_DOUBLE, .scope = PT, .min = -1e15, .max = 1e15,
	  .doc = "the value at raw_max (default: sensor 10 V, dim 1, else as read)" },
	{ .key = "period", .type = PS_OPT_DOUBLE, .scope = PT, .def = "0", .min = 0, .max = 86400,
	  .doc = "poll period in seconds (0: read when asked)" },
	{ .key = NULL },
};
#undef DEV
#undef PT

/* Which tables a role may use: values come from registers, outputs go to
 * holding registers (or coils for relays), inputs are bits. */
static int table_fits(int role, int table)
{
	switch (role) {
	case PS_ROLE_SENSOR:
	case PS_ROLE_TASK_LUX:
	case PS_ROLE_ROOFTOP: return table == PS_MB_INPUT_REGISTER || table == PS_MB_HOLDING_REGISTER;
	case PS_ROLE_DIM: return table == PS_MB_HOLDING_REGISTER;
	case PS_ROLE_RELAY: return table == PS_MB_HOLDING_REGISTER || table == PS_MB_COIL;
	case PS_ROLE_INPUT: return table == PS_MB_COIL || table == PS_MB_DISCRETE_INPUT;
	default: return 0;
	}
}

/* A point's keys through the table, then the rules across them; errors go
 * through the reader (its err, or its line for a check). */
static int parse_point(struct ps_modbus_point *p, int role, const struct ps_opts_reader *r)
{
	const struct ps_opts *o = r->opts;
	long addr = -1, unit = -1, mask, status;
	double tlo, thi, lo, hi;
	int given_raw, given_scale;
	memset(p, 0, sizeof *p);
	p->role = role;
	p->table = -1;
	if (ps_opts_choice(r, "table", &p->table) || ps_opts_choice(r, "type", &p->type) ||
	    ps_opts_choice(r, "word_order", &p->order) || ps_opts_long(r, "address", &addr) ||
	    ps_opts_long(r, "unit", &unit) || ps_opts_long(r, "mask", &mask) || ps_opts_long(r, "status_mask", &status) ||
	    ps_opts_double(r, "period", &p->period))
		return -1;
	if (p->table < 0)
		return ps_opts_fail(r, "table", "table is required (input_register, holding_register, coil or "
		                    "discrete_input)");
	if (addr < 0)
		return ps_opts_fail(r, "address", "address is required (0-based: 40001 is 0)");
	p->address = (int)addr;
	p->unit = (int)unit;
	p->mask = (uint16_t)mask;
	p->status_mask = (uint16_t)status;
	if (!table_fits(role, p->table))
		return ps_opts_fail(r, "table", "table: '%s' %s", ps_modbus_point_table_names[p->table], role == PS_ROLE_INPUT
		                    ? "does not suit an input point (coil or discrete_input)"
		                    : role == PS_ROLE_DIM ? "does not suit a dim output (holding_register)"
		                    : role == PS_ROLE_RELAY ? "does not suit a relay (coil or holding_register)"
		                    : "does not suit a reading (input_register or holding_register)");
	if (p->table == PS_MB_COIL || p->table == PS_MB_DISCRETE_INPUT) {
		/* a bit is 0 or 1: no type, no scaling */
		p->raw_min = p->min = 0;
		p->raw_max = p->max = 1;
		return 0;
	}
	if (addr + ps_modbus_point_count(p) - 1 > 65535)
		return ps_opts_fail(r, "address", "address: '%ld' leaves no room for the second register", addr);
	if (ps_modbus_point_count(p) == 2 && (ps_opts_get(o, "mask") || ps_opts_get(o, "status_mask"))) {
		const char *k = ps_opts_get(o, "mask") ? "mask" : "status_mask";
		return ps_opts_fail(r, k, "%s: '%s' applies to 16-bit types only", k, ps_opts_get(o, k));
	}
	type_range(p->type, &tlo, &thi);
	given_raw = ps_opts_get(o, "raw_min") || ps_opts_get(o, "raw_max");
	given_scale = ps_opts_get(o, "min") || ps_opts_get(o, "max");
	p->raw_min = tlo;
	p->raw_max = thi;
	if (ps_opts_double(r, "raw_min", &p->raw_min) || ps_opts_double(r, "raw_max", &p->raw_max))
		return -1;
	for (int i = 0; i < 2; i++) {
		const char *k = i ? "raw_max" : "raw_min";
		double v = i ? p->raw_max : p->raw_min;
		if (v < tlo || v > thi)
			return ps_opts_fail(r, k, "%s: '%s' is outside %g to %g", k, ps_opts_get(o, k), tlo, thi);
	}
	if (p->raw_min == p->raw_max)
		return ps_opts_fail(r, "raw_max", "raw_max: '%g' must differ from raw_min", p->raw_max);
	/* default scaling: an integer sensor register spans 0..10 V and a dim
	 * register spans light output 0..1; everything else (and every f32,
	 * which already carries engineering units) is taken as it is */
	lo = p->raw_min;
	hi = p->raw_max;
	if (p->type != PS_MB_F32 && role == PS_ROLE_SENSOR)
		lo = 0, hi = 10;
	else if (p->type != PS_MB_F32 && role == PS_ROLE_DIM)
		lo = 0, hi = 1;
	if (p->type == PS_MB_F32 && given_scale && !given_raw) {
		const char *k = ps_opts_get(o, "min") ? "min" : "max";
		return ps_opts_fail(r, k, "%s: '%s' on an f32 point needs raw_min and raw_max too", k, ps_opts_get(o, k));
	}
	p->min = lo;
	p->max = hi;
	if (ps_opts_double(r, "min", &p->min) || ps_opts_double(r, "max", &p->max))
		return -1;
	if (p->min == p->max)
		return ps_opts_fail(r, "max", "max: '%g' must differ from min", p->max);
	if (role == PS_ROLE_DIM && (fmin(p->min, p->max) > 0 || fmax(p->min, p->max) < 1))
		return ps_opts_fail(r, "max", "max: '%g' leaves light output 0..1 outside min..max", p->max);
	return 0;
}

int ps_modbus_point_parse(struct ps_modbus_point *p, int role, const struct ps_opts *o, char *err, size_t errlen)
{
	struct ps_opts_reader r = { o, ps_modbus_point_options, PS_OPT_POINT, err, errlen, NULL };
	return parse_point(p, role, &r);
}

/* The device's rules across keys (the table judges each key). */
static int check_device(const struct ps_opts_reader *r)
{
	const struct ps_opts *o = r->opts;
	static const char *const rtu_only[] = { "baud", "parity", "data_bits", "stop_bits", "lost_after", NULL };
	const char *host = ps_opts_get(o, "host"), *device = ps_opts_get(o, "device");
	double bmin = 1, bmax = 60;
	long unit = 1;
	if (!host == !device)
		return ps_opts_fail(r, host ? "device" : "host", "a modbus device needs either host (TCP) or device (RTU)");
	for (int i = 0; host && rtu_only[i]; i++)
		if (ps_opts_get(o, rtu_only[i]))
			return ps_opts_fail(r, rtu_only[i], "%s: applies to RTU (device =), not TCP", rtu_only[i]);
	if (device && ps_opts_get(o, "port"))
		return ps_opts_fail(r, "port", "port: applies to TCP (host =), not RTU");
	if (ps_opts_double(r, "backoff_min", &bmin) || ps_opts_double(r, "backoff_max", &bmax) ||
	    ps_opts_long(r, "unit", &unit))
		return -1;
	if (bmax < bmin)
		return ps_opts_fail(r, "backoff_max", "backoff_max: must not be below backoff_min");
	if (device && (unit == 0 || unit > 247))
		return ps_opts_fail(r, "unit", "unit: RTU units are 1 to 247");
	return 0;
}

int ps_modbus_point_check(const struct ps_opts *o, int role, int *line, char *why, size_t n)
{
	struct ps_modbus_point p;
	struct ps_opts_reader r = { o, ps_modbus_point_options, role < 0 ? PS_OPT_DEVICE : PS_OPT_POINT, why, n, line };
	return role < 0 ? check_device(&r) : parse_point(&p, role, &r);
}

int ps_modbus_point_check_device(const struct ps_opts *o, char *err, size_t errlen)
{
	struct ps_opts_reader r = { o, ps_modbus_point_options, PS_OPT_DEVICE, err, errlen, NULL };
	return check_device(&r);
}

static uint32_t join32(const struct ps_modbus_point *p, const uint16_t *regs)
{
	return p->order == PS_MB_ABCD ? (uint32_t)regs[0] << 16 | regs[1]
	                              : (uint32_t)regs[1] << 16 | regs[0];
}

/* Registers as read -> raw number.  -1 with errno ERANGE when a status bit
 * is set or an f32 is not finite; the reason goes to why. */
static int ps_modbus_point_decode(const struct ps_modbus_point *p, const uint16_t *regs, double *raw, char *why,
                                  size_t whylen)
{
	uint32_t u;
	float f;
	if (p->table == PS_MB_COIL || p->table == PS_MB_DISCRETE_INPUT) {
		*raw = regs[0] ? 1 : 0;
		return 0;
	}
	switch (p->type) {
	case PS_MB_U16:
	case PS_MB_S16:
		if (regs[0] & p->status_mask) {
			snprintf(why, whylen, "status bits 0x%04x set in 0x%04x", regs[0] & p->status_mask,
			         regs[0]);
			errno = ERANGE;
			return -1;
		}
		*raw = p->type == PS_MB_U16 ? (double)(regs[0] & p->mask)
		                            : (double)(int16_t)(regs[0] & p->mask);
		return 0;
	case PS_MB_U32: *raw = (double)join32(p, regs); return 0;
	case PS_MB_S32: *raw = (double)(int32_t)join32(p, regs); return 0;
	default:
		u = join32(p, regs);
		memcpy(&f, &u, sizeof f);
		if (!isfinite(f)) {
			snprintf(why, whylen, "f32 0x%08x is not a finite number", (unsigned)u);
			errno = ERANGE;
			return -1;
		}
		*raw = f;
		return 0;
	}
}

static int identity(const struct ps_modbus_point *p)
{
	return p->min == p->raw_min && p->max == p->raw_max;
}

/* raw -> value, -1 with errno ERANGE when raw is outside the raw range. */
static int ps_modbus_point_scale(const struct ps_modbus_point *p, double raw, double *value, char *why, size_t whylen)
{
	double lo = fmin(p->raw_min, p->raw_max), hi = fmax(p->raw_min, p->raw_max);
	if (!(raw >= lo && raw <= hi)) {
		snprintf(why, whylen, "raw %.9g outside %.9g to %.9g", raw, lo, hi);
		errno = ERANGE;
		return -1;
	}
	if (identity(p))
		*value = raw;
	else
		*value = p->min + (raw - p->raw_min) / (p->raw_max - p->raw_min) * (p->max - p->min);
	return 0;
}

int ps_modbus_point_value(const struct ps_modbus_point *p, const uint16_t *regs, double *value, char *why,
                          size_t whylen)
{
	double raw;
	if (ps_modbus_point_decode(p, regs, &raw, why, whylen) != 0)
		return -1;
	return ps_modbus_point_scale(p, raw, value, why, whylen);
}

int ps_modbus_point_full_scale(const struct ps_modbus_point *p, double *limit)
{
	if (p->table == PS_MB_COIL || p->table == PS_MB_DISCRETE_INPUT ||
	    (p->type == PS_MB_F32 && fmax(fabs(p->raw_min), fabs(p->raw_max)) >= FLT_MAX))
		return -1;
	/* the map is linear: its largest value is at one end of the raw range */
	*limit = fmax(p->min, p->max);
	return 0;
}

double ps_modbus_point_encode(const struct ps_modbus_point *p, double value, uint16_t *regs)
{
	double vlo = fmin(p->min, p->max), vhi = fmax(p->min, p->max);
	double lo = fmin(p->raw_min, p->raw_max), hi = fmax(p->raw_min, p->raw_max);
	double raw;
	uint32_t u;
	float f;
	if (p->table == PS_MB_COIL || p->table == PS_MB_DISCRETE_INPUT) {
		regs[0] = value >= 0.5;
		return regs[0];
	}
	if (isnan(value))
		value = vlo;
	value = fmin(fmax(value, vlo), vhi);
	raw = identity(p) ? value
	                  : p->raw_min + (value - p->min) / (p->max - p->min) * (p->raw_max - p->raw_min);
	if (p->type != PS_MB_F32) {
		raw = round(raw);
		raw = fmin(fmax(raw, ceil(lo)), floor(hi));
	}
	switch (p->type) {
	case PS_MB_U16: regs[0] = (uint16_t)raw; return raw;
	case PS_MB_S16: regs[0] = (uint16_t)(int16_t)raw; return raw;
	case PS_MB_U32: u = (uint32_t)raw; break;
	case PS_MB_S32: u = (uint32_t)(int32_t)raw; break;
	default:
		f = (float)raw;
		memcpy(&u, &f, sizeof u);
		raw = f;
		break;
	}
	if (p->order == PS_MB_ABCD) {
		regs[0] = (uint16_t)(u >> 16);
		regs[1] = (uint16_t)u;
	} else {
		regs[0] = (uint16_t)u;
		regs[1] = (uint16_t)(u >> 16);
	}
	return raw;
}
