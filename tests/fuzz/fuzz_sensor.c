/* SPDX-License-Identifier: ISC */
/* Fuzz the sensitivity-file reader and both readings of what it accepts. */
#include <stddef.h>
#include <stdint.h>

#include "sensor.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct ps_sensor s;
	struct ps_err e;
	if (ps_sensor_parse(&s, (const char *)data, size, "fuzz.sen", &e) == 0) {
		(void)ps_sensor_integral(&s);
		(void)ps_sensor_value(&s, 0.7, 2.0);
		if (ps_sensor_set_reading(&s, PS_READ_CELL, &e) == 0)
			(void)ps_sensor_m(&s, 1.0, -1.0);
		ps_sensor_free(&s);
	}
	return 0;
}
