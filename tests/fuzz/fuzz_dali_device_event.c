/* SPDX-License-Identifier: ISC */
/* Fuzz the DALI-2 control-device decoders: any 24-bit word as an event
 * message (a decoded event encodes back to the same frame, its fields in
 * range), the frame describer, and input values of every resolution from
 * the answer bytes.  Checks: nothing reads past the input, no value
 * outside its resolution. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include "dali_device.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	char buf[96];
	struct ps_dali_device_event ev;
	for (size_t i = 0; i + 3 <= size && i < 3 * 64; i += 3) {
		uint32_t f = (uint32_t)data[i] << 16 | (uint32_t)data[i + 1] << 8 | data[i + 2];
		ps_dali_device_describe(f, buf, sizeof buf);
		if (ps_dali_device_event_decode(f, &ev) == 0) {
			if (ev.info > 1023 || ev.address > 63 || ev.instance > 31 || ev.instance_type > 31 ||
			    ev.device_group > 31 || ev.instance_group > 31)
				abort();
			if (ps_dali_device_event_encode(&ev) != (long)f)
				abort();
		}
		(void)ps_dali_device_needs_twice(f);
		(void)ps_dali_device_expects_answer(f);
	}
	if (size >= 1) {
		int bits = data[0] % 34;
		int n = ps_dali_device_input_bytes(bits);
		if (n > 0 && (size_t)n + 1 <= size) {
			long v = ps_dali_device_input_value(data + 1, n, bits);
			if (v < 0 || (bits < 32 && v >= 1L << bits))
				abort();
		}
	}
	return 0;
}
