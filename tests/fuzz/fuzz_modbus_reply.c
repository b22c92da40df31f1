/* SPDX-License-Identifier: ISC */
/* Fuzz the decoding of register replies as the Modbus driver sees them: the
 * first bytes choose a point's options (as text, through the real option
 * parser), the rest are the registers a module sent.  Every decoded value
 * must be finite and inside min..max, and an output's encoding must stay
 * inside the raw range and decode back within half a raw step. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#ifdef PS_WITH_MODBUS
#include "driver.h"
#include "modbus_point.h"

static const char *const raws[] = { "0", "4095", "65535", "-32768", "32760", "1e6", "-1", "100" };
static const char *const scales[] = { "0", "1", "10", "-0.5", "2000", "1e9", "-1e3", "0.25" };

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct ps_opt v[10];
	struct ps_opts o = { v, 0, "fuzz.conf" };
	struct ps_modbus_point p;
	char addr[16], mask[16], stat[16], err[256], why[128];
	uint16_t regs[2], out[2];
	double value;
	int role;
	if (size < 8)
		return 0;
	role = data[0] % PS_ROLE_COUNT;
	v[o.n++] = (struct ps_opt){ "table", ps_modbus_point_table_names[data[1] % PS_MB_TABLE_COUNT], 1, 0 };
	v[o.n++] = (struct ps_opt){ "type", ps_modbus_point_type_names[(data[1] >> 2) % PS_MB_TYPE_COUNT], 2, 0 };
	v[o.n++] = (struct ps_opt){ "word_order", ps_modbus_point_order_names[(data[1] >> 5) & 1], 3, 0 };
	snprintf(addr, sizeof addr, "%u", (unsigned)(data[2] << 8 | data[3]));
	v[o.n++] = (struct ps_opt){ "address", addr, 4, 0 };
	if (data[4] & 1) {
		snprintf(mask, sizeof mask, "%u", (unsigned)(data[5] << 8 | 0xff));
		v[o.n++] = (struct ps_opt){ "mask", mask, 5, 0 };
	}
	if (data[4] & 2) {
		snprintf(stat, sizeof stat, "%u", (unsigned)(data[5] & 7));
		v[o.n++] = (struct ps_opt){ "status_mask", stat, 6, 0 };
	}
	if (data[4] & 4) {
		v[o.n++] = (struct ps_opt){ "raw_min", raws[data[6] & 7], 7, 0 };
		v[o.n++] = (struct ps_opt){ "raw_max", raws[(data[6] >> 3) & 7], 8, 0 };
	}
	if (data[4] & 8) {
		v[o.n++] = (struct ps_opt){ "min", scales[data[7] & 7], 9, 0 };
		v[o.n++] = (struct ps_opt){ "max", scales[(data[7] >> 3) & 7], 10, 0 };
	}
	if (ps_modbus_point_parse(&p, role, &o, err, sizeof err) != 0)
		return 0;
	data += 8;
	size -= 8;
	while (size >= 4) {
		regs[0] = (uint16_t)(data[0] << 8 | data[1]);
		regs[1] = (uint16_t)(data[2] << 8 | data[3]);
		if (ps_modbus_point_value(&p, regs, &value, why, sizeof why) == 0) {
			double lo = fmin(p.min, p.max), hi = fmax(p.min, p.max);
			if (!isfinite(value) || value < lo - 1e-9 * fabs(lo) - 1e-9 || value > hi + 1e-9 * fabs(hi) + 1e-9)
				abort();
			/* an output written from this value decodes back within half a
			 * raw step (f32: within float precision) */
			if (role == PS_ROLE_DIM) {
				double raw = ps_modbus_point_encode(&p, value, out), back;
				if (ps_modbus_point_value(&p, out, &back, why, sizeof why) != 0)
					abort();
				if (raw < fmin(p.raw_min, p.raw_max) || raw > fmax(p.raw_min, p.raw_max))
					abort();
				if (p.type != PS_MB_F32 &&
				    fabs(back - value) > 0.5 * fabs(p.max - p.min) / fabs(p.raw_max - p.raw_min) * (1 + 1e-9) + 1e-12)
					abort();
			}
		}
		data += 4;
		size -= 4;
	}
	return 0;
}
#else
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	(void)data;
	(void)size;
	return 0;
}
#endif
