/* SPDX-License-Identifier: ISC */
/* The Lunatone LUBA protocol (doc/hardware.md section 7): binary messages
 *
 *   0x59 ('Y')  command  length  payload[length]  checksum
 *
 * the checksum the XOR of the command, the length and the payload.
 *
 * Host to interface: 0x32 queue a DALI frame: line (0), bits (16 or 24),
 * mode (the priority 1-5 in the low bits, 0x80 send twice), the frame
 * left-aligned in 3 bytes, one padding byte.  The interface answers 0x33:
 * length 2 accepted (a frame id), length 1 an error code.
 * Interface to host: 0x31 an event: time tick (2 bytes), line, status (bits
 * 7-6 the type, 5-0 its information), then by type: 0 our frame was sent
 * (a frame id, the frame); 2 a frame was seen on the bus (information: its
 * length in bits, 62 only a start and stop bit, 63 a framing error; the
 * frame: one byte is a backward frame, two or three another master's
 * forward frame).  There is no "no answer" message: a query's answer is the
 * backward frame that follows its sent event, or none within the window. */
#include <string.h>

#include "dali_luba.h"

#define START 0x59
#define CMD_QUEUE 0x32
#define RSP_QUEUE 0x33
#define EVENT 0x31
#define MAX_LEN 23
#define EV_SENT 0
#define EV_SEEN 2

static int luba_encode(uint8_t *out, size_t cap, const struct ps_dali_frame *f)
{
	uint8_t ck = 0;
	int n = 0;
	if (ps_dali_frame_valid(f) != 0 || f->bits == 8 || cap < 11)
		return -1;
	out[n++] = START;
	out[n++] = CMD_QUEUE;
	out[n++] = 7;
	out[n++] = 0;   /* the line: one bus */
	out[n++] = (uint8_t)f->bits;
	/* priority 2 for plain commands, 5 for queries and configuration */
	out[n++] = (uint8_t)((f->twice ? 0x80 : 0) | (f->twice || f->expect_answer ? 5 : 2));
	if (f->bits == 16) {
		out[n++] = (uint8_t)(f->data >> 8);
		out[n++] = (uint8_t)f->data;
		out[n++] = 0;
	} else {
		out[n++] = (uint8_t)(f->data >> 16);
		out[n++] = (uint8_t)(f->data >> 8);
		out[n++] = (uint8_t)f->data;
	}
	out[n++] = 0;
	for (int i = 1; i < n; i++)
		ck ^= out[i];
	out[n++] = ck;
	return n;
}

static size_t bad(struct ps_dali_frame_rx *rx, size_t used, const char *why)
{
	rx->event = PS_DALI_EV_MALFORMED;
	strncpy(rx->why, why, sizeof rx->why - 1);
	rx->why[sizeof rx->why - 1] = 0;
	return used;
}

static unsigned frame_of(const uint8_t *p, size_t n)
{
	unsigned v = 0;
	for (size_t i = 0; i < n; i++)
		v = v << 8 | p[i];
	return v;
}

static size_t luba_decode(const uint8_t *buf, size_t len, struct ps_dali_frame_rx *rx)
{
	const uint8_t *p;
	size_t n, total;
	uint8_t ck = 0;
	memset(rx, 0, sizeof *rx);
	if (len == 0)
		return 0;
	if (buf[0] != START) {
		const uint8_t *s = memchr(buf, START, len);
		return bad(rx, s ? (size_t)(s - buf) : len, "bytes outside a message");
	}
	if (len < 3)
		return 0;
	n = buf[2];
	if (n < 1 || n > MAX_LEN)
		return bad(rx, 1, "a message length outside 1 to 23");
	total = 3 + n + 1;
	if (len < total)
		return 0;
	for (size_t i = 1; i < total - 1; i++)
		ck ^= buf[i];
	if (ck != buf[total - 1])
		return bad(rx, total, "a message with a wrong checksum");
	p = buf + 3;
	switch (buf[1]) {
	case RSP_QUEUE:
		if (n == 2) {
			rx->event = PS_DALI_EV_IGNORE;   /* accepted: the sent event follows */
			return total;
		}
		if (n == 1) {
			rx->event = PS_DALI_EV_BUS_ERROR;
			rx->value = PS_DALI_BUS_REJECTED;
			strcpy(rx->why, "the interface refused the frame");
			return total;
		}
		break;
	case EVENT: {
		int type, info;
		if (n < 4)
			break;
		type = p[3] >> 6;
		info = p[3] & 0x3F;
		if (type == EV_SENT) {
			if (n < 5)
				break;
			rx->event = PS_DALI_EV_ECHO;
			rx->value = n > 5 && n - 5 <= 3 ? frame_of(p + 5, n - 5) : 0;
			rx->bits = (int)(n - 5) * 8;
			return total;
		}
		if (type != EV_SEEN) {
			rx->event = PS_DALI_EV_IGNORE;
			return total;
		}
		if (info == 62 || info == 63) {
			rx->event = PS_DALI_EV_BUS_ERROR;
			rx->value = PS_DALI_BUS_FRAMING;
			strcpy(rx->why, info == 63 ? "a framing error on the bus (several devices answered)"
			                           : "only a start and a stop bit on the bus");
			return total;
		}
		if (info < 1 || info > 32 || n - 4 < 1 || n - 4 > 3)
			break;
		if (n - 4 == 1) {
			rx->event = PS_DALI_EV_ANSWER;
			rx->value = p[4];
			return total;
		}
		rx->event = PS_DALI_EV_OBSERVED;
		rx->value = frame_of(p + 4, n - 4);
		rx->bits = (int)(n - 4) * 8;
		return total;
	}
	}
	return bad(rx, total, "a message of an unknown command or the wrong length");
}

const struct ps_dali_codec ps_dali_luba = {
	.name = "luba",
	.baud = 38400,
	.replies_per_twice = 1,
	.max_msg = 3 + MAX_LEN + 1,
	.answer_window = 0.025,
	.encode = luba_encode,
	.decode = luba_decode,
};
