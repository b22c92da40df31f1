/* SPDX-License-Identifier: ISC */
/* The hasseb DALI Master (USB 04cc:0802) as a byte codec, after the
 * firmware's published "hasseb USB DALI Master protocol" (doc/hardware.md
 * section 1.2).  10-byte reports both ways, starting with 0xAA.
 *
 * Host -> device, send a frame:  AA 07 seq bits answer 00 twice_ms addr data 00
 *   bits 16; answer 1 when a backward frame may come; twice_ms the delay
 *   before the second sending (0: send once)
 * Device -> host:                AA type seq status length d0 d1 d2 ..
 *   type 0x07 a transmission report for seq: status 1 no answer, 2 an
 *   answer in d0, 3 invalid data (a garbled answer), 4 an answer too early,
 *   5 and 6 a byte sniffed on the bus (in sniffing mode only); type 0x02 the
 *   firmware version in d-bytes 3 and 4; type 0x00 nothing.
 * Host -> device, read the firmware version:  AA 02 seq 00 ..
 * The interface has no DTR0 prefix: a command with dtr0 cannot be encoded
 * (the driver then sends DTR0 as a frame of its own). */
#include <string.h>

#include "dali.h"
#include "usb_hasseb.h"

#define LEN 10
#define PREAMBLE 0xAA
#define CMD_SEND 0x07
#define REP_VERSION 0x02
#define REP_TX 0x07
#define TWICE_MS 10

/* Queries of control gear (also broadcast to unaddressed gear, address
 * byte 0xFD), and the special commands that answer */
static int answers(unsigned frame)
{
	unsigned a = frame >> 8, op = frame & 0xFF;
	if (a == 0xFD && op >= 0x90 && op <= 0xC5)
		return 1;
	return ps_dali_expects_answer(frame) || a == PS_DALI_COMPARE || a == PS_DALI_VERIFY_SHORT_ADDRESS ||
	       a == PS_DALI_QUERY_SHORT_ADDRESS;
}

static int hb_encode_send(uint8_t *out, size_t cap, int seq, unsigned frame, int send_twice, int dtr0)
{
	if (cap < LEN || seq < 1 || seq > 255 || frame > 0xFFFF || dtr0 >= 0)
		return -1;
	memset(out, 0, LEN);
	out[0] = PREAMBLE;
	out[1] = CMD_SEND;
	out[2] = (uint8_t)seq;
	out[3] = 16;
	out[4] = (uint8_t)answers(frame);
	out[6] = send_twice ? TWICE_MS : 0;
	out[7] = (uint8_t)(frame >> 8);
	out[8] = (uint8_t)frame;
	return LEN;
}

static void hb_decode(const uint8_t *in, size_t len, struct ps_dali_reply *r)
{
	r->event = PS_DALI_EV_MALFORMED;
	r->seq = -1;
	r->value = 0;
	if (len < LEN || in[0] != PREAMBLE)
		return;
	switch (in[1]) {
	case 0x00:
		r->event = PS_DALI_EV_IGNORE;
		return;
	case REP_VERSION:
		r->event = PS_DALI_EV_INFO;
		r->value = (unsigned)in[3] << 8 | in[4];
		return;
	case REP_TX:
		break;
	default:
		return;
	}
	switch (in[3]) {
	case 1:
		r->event = PS_DALI_EV_NO_ANSWER;
		break;
	case 2:
		r->event = PS_DALI_EV_ANSWER;
		r->value = in[5];
		break;
	case 3:
		r->event = PS_DALI_EV_BUS_ERROR;
		r->value = PS_DALI_BUS_FRAMING;
		break;
	case 4:
		/* a backward frame before the settling time (5.5 ms after our
		 * frame): not a valid answer, and no sign that several answered */
		r->event = PS_DALI_EV_BUS_ERROR;
		r->value = PS_DALI_BUS_EARLY;
		break;
	case 5:
		r->event = PS_DALI_EV_OBSERVED;
		r->value = in[5];
		return;
	case 6:
		r->event = PS_DALI_EV_IGNORE;
		return;
	default:
		return;
	}
	/* a transmission report answers a sequence number; 0 is never ours */
	if (in[2] == 0) {
		r->event = PS_DALI_EV_MALFORMED;
		return;
	}
	r->seq = in[2];
}

/* "read firmware version": AA 02 seq, zeros to 10 bytes */
static int hb_encode_version(uint8_t *out, size_t cap, int seq)
{
	if (cap < LEN || seq < 1 || seq > 255)
		return -1;
	memset(out, 0, LEN);
	out[0] = PREAMBLE;
	out[1] = REP_VERSION;
	out[2] = (uint8_t)seq;
	return LEN;
}

/* 1..255: the protocol does not allow 0 */
static int hb_next_seq(int seq)
{
	return seq >= 255 || seq < 1 ? 1 : seq + 1;
}

const struct ps_dali_transport ps_usb_hasseb = {
	.name = "hasseb",
	.vid = 0x04CC,
	.pid = 0x0802,
	.interface = 0,
	.ep_in = 0x81,
	.ep_out = 0x01,
	.report_len = 64,   /* IN transfers take up to a full packet; reports are 10 bytes */
	.has_echo = 0,
	.encode_send = hb_encode_send,
	.decode = hb_decode,
	.next_seq = hb_next_seq,
	.encode_version = hb_encode_version,
};
