/* Modbus point options, register decoding and scaling (modbus_point.h). */
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "modbus_point.h"

const char *const ps_mb_table_names[] = { "input_register", "holding_register", "coil",
                                          "discrete_input", NULL };
const char *const ps_mb_type_names[] = { "u16", "s16", "u32", "s32", "f32", NULL };
const char *const ps_mb_order_names[] = { "abcd", "cdab", NULL };

const char *ps_mb_table_short(int table)
{
	static const char *const s[] = { "IR", "HR", "coil", "DI" };
	return table >= 0 && table < PS_MB_TABLE_COUNT ? s[table] : "?";
}

int ps_mb_point_count(const struct ps_mb_point *p)
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

static int fail(const struct ps_opts *o, const char *key, char *err, size_t errlen, const char *why)
{
	const char *v = ps_opt_get(o, key);
	snprintf(err, errlen, "%s:%d: %s%s%s%s %s", o && o->file ? o->file : "(config)",
	         ps_opt_line(o, key), key, v ? ": '" : "", v ? v : "", v ? "'" : "", why);
	errno = EINVAL;
	return -1;
}

/* Which tables a role may use: values come from registers, outputs go to
 * holding registers (or coils for relays), inputs are bits. */
static int table_fits(int role, int table)
{
	switch (role) {
	case PS_ROLE_SENSOR:
	case PS_ROLE_TASK_LUX: return table == PS_MB_INPUT_REGISTER || table == PS_MB_HOLDING_REGISTER;
	case PS_ROLE_DIM: return table == PS_MB_HOLDING_REGISTER;
	case PS_ROLE_RELAY: return table == PS_MB_HOLDING_REGISTER || table == PS_MB_COIL;
	case PS_ROLE_INPUT: return table == PS_MB_COIL || table == PS_MB_DISCRETE_INPUT;
	default: return 0;
	}
}

int ps_mb_point_parse(struct ps_mb_point *p, int role, const struct ps_opts *o, char *err,
                      size_t errlen)
{
	long addr, unit, mask, status;
	double tlo, thi, lo, hi;
	int given_raw, given_scale;
	memset(p, 0, sizeof *p);
	p->role = role;
	if (!ps_opt_get(o, "table"))
		return fail(o, "table", err, errlen, "is required (input_register, holding_register, coil "
		            "or discrete_input)");
	if (!ps_opt_get(o, "address"))
		return fail(o, "address", err, errlen, "is required (0-based: 40001 is 0)");
	if (ps_opt_enum(o, "table", ps_mb_table_names, 0, &p->table, err, errlen) ||
	    ps_opt_enum(o, "type", ps_mb_type_names, PS_MB_U16, &p->type, err, errlen) ||
	    ps_opt_enum(o, "word_order", ps_mb_order_names, PS_MB_ABCD, &p->order, err, errlen) ||
	    ps_opt_long(o, "address", 0, 0, 65535, &addr, err, errlen) ||
	    ps_opt_long(o, "unit", -1, 0, 255, &unit, err, errlen) ||
	    ps_opt_long(o, "mask", 0xffff, 1, 0xffff, &mask, err, errlen) ||
	    ps_opt_long(o, "status_mask", 0, 0, 0xffff, &status, err, errlen) ||
	    ps_opt_double(o, "period", 0, 0, 86400, &p->period, err, errlen))
		return -1;
	p->address = (int)addr;
	p->unit = (int)unit;
	p->mask = (uint16_t)mask;
	p->status_mask = (uint16_t)status;
	if (!table_fits(role, p->table))
		return fail(o, "table", err, errlen, role == PS_ROLE_INPUT
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
	if (addr + ps_mb_point_count(p) - 1 > 65535)
		return fail(o, "address", err, errlen, "leaves no room for the second register");
	if (ps_mb_point_count(p) == 2 && (ps_opt_get(o, "mask") || ps_opt_get(o, "status_mask")))
		return fail(o, ps_opt_get(o, "mask") ? "mask" : "status_mask", err, errlen,
		            "applies to 16-bit types only");
	type_range(p->type, &tlo, &thi);
	given_raw = ps_opt_get(o, "raw_min") || ps_opt_get(o, "raw_max");
	given_scale = ps_opt_get(o, "min") || ps_opt_get(o, "max");
	if (ps_opt_double(o, "raw_min", tlo, tlo, thi, &p->raw_min, err, errlen) ||
	    ps_opt_double(o, "raw_max", thi, tlo, thi, &p->raw_max, err, errlen))
		return -1;
	if (p->raw_min == p->raw_max)
		return fail(o, "raw_max", err, errlen, "must differ from raw_min");
	/* default scaling: an integer sensor register spans 0..10 V and a dim
	 * register spans light output 0..1; everything else (and every f32,
	 * which already carries engineering units) is taken as it is */
	lo = p->raw_min;
	hi = p->raw_max;
	if (p->type != PS_MB_F32 && role == PS_ROLE_SENSOR)
		lo = 0, hi = 10;
	else if (p->type != PS_MB_F32 && role == PS_ROLE_DIM)
		lo = 0, hi = 1;
	if (p->type == PS_MB_F32 && given_scale && !given_raw)
		return fail(o, ps_opt_get(o, "min") ? "min" : "max", err, errlen,
		            "on an f32 point needs raw_min and raw_max too");
	if (ps_opt_double(o, "min", lo, -1e15, 1e15, &p->min, err, errlen) ||
	    ps_opt_double(o, "max", hi, -1e15, 1e15, &p->max, err, errlen))
		return -1;
	if (p->min == p->max)
		return fail(o, "max", err, errlen, "must differ from min");
	if (role == PS_ROLE_DIM && (fmin(p->min, p->max) > 0 || fmax(p->min, p->max) < 1))
		return fail(o, "max", err, errlen, "leaves light output 0..1 outside min..max");
	return 0;
}

static uint32_t join32(const struct ps_mb_point *p, const uint16_t *regs)
{
	return p->order == PS_MB_ABCD ? (uint32_t)regs[0] << 16 | regs[1]
	                              : (uint32_t)regs[1] << 16 | regs[0];
}

int ps_mb_decode(const struct ps_mb_point *p, const uint16_t *regs, double *raw, char *why,
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

static int identity(const struct ps_mb_point *p)
{
	return p->min == p->raw_min && p->max == p->raw_max;
}

int ps_mb_scale(const struct ps_mb_point *p, double raw, double *value, char *why, size_t whylen)
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

int ps_mb_value(const struct ps_mb_point *p, const uint16_t *regs, double *value, char *why,
                size_t whylen)
{
	double raw;
	if (ps_mb_decode(p, regs, &raw, why, whylen) != 0)
		return -1;
	return ps_mb_scale(p, raw, value, why, whylen);
}

double ps_mb_encode(const struct ps_mb_point *p, double value, uint16_t *regs)
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
