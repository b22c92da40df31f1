/* SPDX-License-Identifier: ISC */
/* The AtxLED DALI HAT's line protocol (doc/hardware.md section 5): ASCII
 * lines ending in a newline, frames as uppercase hex.
 *
 * Host to HAT:  'j' + 2 hex digits   an 8-bit frame
 *               'h' + 4              a 16-bit frame
 *               't' + 4              a 16-bit frame the HAT sends twice
 *               'l' + 6              a 24-bit frame
 * HAT to host:  'J' + 2 hex digits   a backward frame
 *               'N'                  no backward frame
 *               'X'                  a garbled answer (several devices answered)
 *               'Z'                  our frame collided with another master's: send again
 * A frame sent twice is answered once per sending.  Lines of the frame forms
 * ('j', 'h', 'l' and their digits) coming from the HAT are other masters'
 * frames it saw on the bus; carriage returns are ignored. */
#include <string.h>

#include "dali_atx.h"

#define MAX_LINE 32

static int atx_encode(uint8_t *out, size_t cap, const struct ps_dali_frame *f)
{
	char c;
	int n;
	if (ps_dali_frame_valid(f) != 0)
		return -1;
	switch (f->bits) {
	case 8: c = 'j'; n = 1; break;
	case 16: c = f->twice ? 't' : 'h'; n = 2; break;
	default: c = 'l'; n = 3; break;
	}
	/* only 16-bit frames have a send-twice form */
	if (f->twice && f->bits != 16)
		return -1;
	if (cap < (size_t)(2 * n + 2))
		return -1;
	out[0] = (uint8_t)c;
	ps_dali_frame_hex((char *)out + 1, f->data, n);
	out[2 * n + 1] = '\n';
	return 2 * n + 2;
}

static void bad(struct ps_dali_frame_rx *rx, const char *why)
{
	rx->event = PS_DALI_EV_MALFORMED;
	strncpy(rx->why, why, sizeof rx->why - 1);
	rx->why[sizeof rx->why - 1] = 0;
}

static size_t atx_decode(const uint8_t *buf, size_t len, struct ps_dali_frame_rx *rx)
{
	const uint8_t *nl = memchr(buf, '\n', len < MAX_LINE ? len : MAX_LINE);
	size_t n, used;
	long v;
	memset(rx, 0, sizeof *rx);
	if (!nl) {
		if (len < MAX_LINE)
			return 0;
		bad(rx, "a line longer than 32 bytes");
		return MAX_LINE;
	}
	used = (size_t)(nl - buf) + 1;
	n = used - 1;
	while (n > 0 && buf[n - 1] == '\r')
		n--;
	if (n == 0) {
		rx->event = PS_DALI_EV_IGNORE;
		return used;
	}
	switch (buf[0]) {
	case 'N':
		if (n != 1)
			break;
		rx->event = PS_DALI_EV_NO_ANSWER;
		return used;
	case 'J':
		if (n != 3 || (v = ps_dali_frame_unhex(buf + 1, 2)) < 0)
			break;
		rx->event = PS_DALI_EV_ANSWER;
		rx->value = (unsigned)v;
		return used;
	case 'X':
	case 'Z':
		if (n != 1)
			break;
		rx->event = PS_DALI_EV_BUS_ERROR;
		rx->value = buf[0] == 'X' ? PS_DALI_BUS_FRAMING : PS_DALI_BUS_SEND_COLLISION;
		strcpy(rx->why, buf[0] == 'X' ? "garbled answer (several devices answered)"
		                              : "our frame collided with another master's");
		return used;
	case 'j':
	case 'h':
	case 'l': {
		int bits = buf[0] == 'j' ? 8 : buf[0] == 'h' ? 16 : 24;
		if (n != (size_t)(1 + bits / 4) || (v = ps_dali_frame_unhex(buf + 1, (size_t)bits / 4)) < 0)
			break;
		rx->event = PS_DALI_EV_OBSERVED;
		rx->value = (unsigned)v;
		rx->bits = bits;
		return used;
	}
	}
	bad(rx, "a line that is none of J.., N, X, Z or a frame");
	return used;
}

const struct ps_dali_codec ps_dali_atx = {
	.name = "atx",
	.baud = 19200,
	.replies_per_twice = 2,
	.max_msg = MAX_LINE,
	.encode = atx_encode,
	.decode = atx_decode,
};
