/* SPDX-License-Identifier: ISC */
/* Modbus points: where a value lives on a module and how its registers become
 * volts or lux (and a light output becomes registers).  Pure functions, no
 * I/O, so every decoding and scaling rule is unit-tested without a network.
 *
 * A reading is decoded to a raw number (the register value as the module
 * means it: u16, s16, u32, s32 or f32, with the word order of 32-bit types),
 * checked against the raw range [raw_min, raw_max] (outside: ERANGE, e.g. an
 * open-circuit code), then mapped linearly onto [min, max].  An output takes
 * the inverse map and is rounded to the nearest raw step. */
#ifndef PS_MODBUS_POINT_H
#define PS_MODBUS_POINT_H

#include <stddef.h>
#include <stdint.h>

#include "driver.h"

enum ps_modbus_point_table {
	PS_MB_INPUT_REGISTER = 0,  /* FC 04, read only */
	PS_MB_HOLDING_REGISTER,    /* FC 03 / 06 / 16 */
	PS_MB_COIL,                /* FC 01 / 05 */
	PS_MB_DISCRETE_INPUT,      /* FC 02, read only */
	PS_MB_TABLE_COUNT
};

enum ps_modbus_point_type { PS_MB_U16 = 0, PS_MB_S16, PS_MB_U32, PS_MB_S32, PS_MB_F32, PS_MB_TYPE_COUNT };

/* Word order of 32-bit types: ABCD = high word in the first register (the
 * usual lux meter), CDAB = low word first (ADAM-6000 counters).  Bytes within
 * a register are always big-endian, as the protocol sends them. */
enum ps_modbus_point_order { PS_MB_ABCD = 0, PS_MB_CDAB };

extern const char *const ps_modbus_point_table_names[];   /* config names, NULL-terminated */
extern const char *const ps_modbus_point_type_names[];
extern const char *const ps_modbus_point_order_names[];

struct ps_modbus_point {
	int role;              /* enum ps_role */
	int table;             /* enum ps_modbus_point_table */
	int type;              /* enum ps_modbus_point_type (registers only) */
	int order;             /* enum ps_modbus_point_order (32-bit types only) */
	int unit;              /* unit id, -1: the device's */
	int address;           /* 0-based protocol address (Modicon 40001 is 0) */
	uint16_t mask;         /* AND-ed into a 16-bit register before decoding */
	uint16_t status_mask;  /* any of these bits set in the register: ERANGE */
	double raw_min, raw_max;   /* the valid raw range, mapped onto min..max */
	double min, max;
	double period;         /* poll period in seconds, 0: read on demand */
};

/* The driver's options, device and point keys (opts.h). */
extern const struct ps_opts_spec ps_modbus_point_options[];

/* Parse a point's options for a role; 0, or -1 with errno EINVAL and a
 * "file:line: key: why" message in err. */
int ps_modbus_point_parse(struct ps_modbus_point *p, int role, const struct ps_opts *o, char *err,
                          size_t errlen);
/* The rules across a device's keys (exactly one of host and device, ...);
 * the same errors. */
int ps_modbus_point_check_device(const struct ps_opts *o, char *err, size_t errlen);
/* The driver's check method (driver.h): a device (role < 0) or a point. */
int ps_modbus_point_check(const struct ps_opts *o, int role, int *line, char *why, size_t n);

/* Registers (or bits) the point spans: 1 or 2. */
int ps_modbus_point_count(const struct ps_modbus_point *p);

/* "IR 0", "HR 10", "coil 16", "DI 1": for messages. */
const char *ps_modbus_point_table_short(int table);

/* Both: registers -> value. */
int ps_modbus_point_value(const struct ps_modbus_point *p, const uint16_t *regs, double *value, char *why,
                          size_t whylen);
/* The largest value a reading can give: the scaled end of the raw range
 * (an integer register's top code by default).  0 with *limit; -1 for a bit
 * (coil, discrete input) and for an f32 taken as it is (no raw range). */
int ps_modbus_point_full_scale(const struct ps_modbus_point *p, double *limit);
/* An output: value (clamped to min..max) -> registers, rounded to the
 * nearest raw step and kept inside the raw range.  Returns the raw number. */
double ps_modbus_point_encode(const struct ps_modbus_point *p, double value, uint16_t *regs);

#endif
