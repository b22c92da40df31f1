/* SPDX-License-Identifier: ISC */
/* Fuzz the foxtron DALI codec's decoder (drivers/dali_foxtron.c) on any byte stream,
 * taken message by message as the serial link does, and its encoder on any
 * frame.  Checks its promises: every call uses at most what it was given, a
 * full buffer always yields a message, answers fit in a byte, observed
 * frames are 0, 8, 16 or 24 bits, reasons are terminated. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "dali_foxtron.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	const struct ps_dali_codec *c = &ps_dali_foxtron;
	size_t off = 0;
	while (off < size) {
		struct ps_dali_frame_rx rx;
		size_t used = c->decode(data + off, size - off, &rx);
		if (used > size - off)
			abort();
		if (!used) {
			if (size - off >= c->max_msg)
				abort();   /* a full message's worth of bytes must decide */
			break;
		}
		if (rx.event == PS_DALI_EV_ANSWER && rx.value > 255)
			abort();
		if (rx.event == PS_DALI_EV_OBSERVED && rx.bits != 0 && rx.bits != 8 && rx.bits != 16 && rx.bits != 24)
			abort();
		if (!memchr(rx.why, 0, sizeof rx.why))
			abort();
		off += used;
	}
	if (size >= 5) {
		uint8_t out[64];
		struct ps_dali_frame f = { .bits = data[0] % 3 == 0 ? 8 : data[0] % 3 == 1 ? 16 : 24,
			                   .data = (uint32_t)data[1] << 16 | (uint32_t)data[2] << 8 | data[3],
			                   .twice = data[4] & 1 };
		int n = c->encode(out, sizeof out, &f);
		if (n > (int)sizeof out || (n >= 0 && ps_dali_frame_valid(&f) != 0))
			abort();
	}
	return 0;
}
