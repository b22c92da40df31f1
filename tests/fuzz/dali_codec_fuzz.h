/* SPDX-License-Identifier: ISC */
/* The one fuzz body every serial DALI codec (drivers/dali_atx.c,
 * dali_foxtron.c, dali_luba.c) shares: its decoder on any byte stream, taken
 * message by message as the serial link does, and its encoder on any frame.
 * Checks the codec's promises: every call uses at most what it was given, a
 * full buffer always yields a message, answers fit in a byte, observed
 * frames are 0, 8, 16 or 24 bits, reasons are terminated.  A target defines
 * its codec and includes this once. */
#ifndef DALI_CODEC_FUZZ_H
#define DALI_CODEC_FUZZ_H

#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "dali_frame.h"

static void fuzz_dali_decode_all(const struct ps_dali_codec *c, const uint8_t *data, size_t size)
{
	size_t off = 0;
	while (off < size) {
		struct ps_dali_frame_rx rx;
		size_t used = c->decode(data + off, size - off, &rx);
		if (used > size - off)
			abort();
		if (!used) {
			if (size - off >= c->max_msg)
				abort();   /* a full message's worth of bytes must decide */
			return;
		}
		if (rx.event == PS_DALI_EV_ANSWER && rx.value > 255)
			abort();
		if (rx.event == PS_DALI_EV_OBSERVED && rx.bits != 0 && rx.bits != 8 && rx.bits != 16 && rx.bits != 24)
			abort();
		if (!memchr(rx.why, 0, sizeof rx.why))
			abort();
		off += used;
	}
}

static void fuzz_dali_encode_one(const struct ps_dali_codec *c, const uint8_t *data, size_t size)
{
	if (size < 5)
		return;
	uint8_t out[64];
	struct ps_dali_frame f = { .bits = data[0] % 3 == 0 ? 8 : data[0] % 3 == 1 ? 16 : 24,
		                   .data = (uint32_t)data[1] << 16 | (uint32_t)data[2] << 8 | data[3],
		                   .twice = data[4] & 1 };
	int n = c->encode(out, sizeof out, &f);
	if (n > (int)sizeof out || (n >= 0 && ps_dali_frame_valid(&f) != 0))
		abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	fuzz_dali_decode_all(&FUZZ_DALI_CODEC, data, size);
	fuzz_dali_encode_one(&FUZZ_DALI_CODEC, data, size);
	return 0;
}

#endif
