/* SPDX-License-Identifier: ISC */
/* The Tridonic / Lunatone DALI USB interface (USB 17b5:0020) as a byte codec.
 * The protocol is reverse-engineered (daliserver, python-dali, dali_mon agree;
 * doc/hardware.md section 1).  64-byte reports both ways.
 *
 * Host -> device SEND:  12 seq flags 03 00 00 addr data dtr0 0...
 *   flags 0x20: the interface sends the frame twice (config commands)
 *   flags 0x10: the interface first sends DTR0 = byte 8
 * Device -> host:       mode type f2 f3 f4 f5 i6 i7 seq 0...
 *   mode 0x12 = response to one of our SENDs (seq in byte 8), 0x11 = another
 *   master's traffic, 0x01 = info; type 0x73 = our 16-bit frame went out
 *   (echo), 0x71 = no backward frame, 0x72 = backward frame in byte 5,
 *   0x77 = bus status in byte 5 (1 checksum, 2 bus shorted, 3 framing error:
 *   a garbled answer, e.g. two ballasts answering at once). */
#include <string.h>

#include "usb_tridonic.h"

#define LEN 64
#define CMD_SEND 0x12
#define FLAG_TWICE 0x20
#define FLAG_DTR0 0x10
#define FRAME_16BIT 0x03

#define MODE_INFO 0x01
#define MODE_OBSERVE 0x11
#define MODE_RESPONSE 0x12
#define TYPE_NONE 0x71
#define TYPE_8BIT 0x72
#define TYPE_16BIT 0x73
#define TYPE_STATUS 0x77

static int tri_encode_send(uint8_t *out, size_t cap, int seq, unsigned frame, int send_twice, int dtr0)
{
	if (cap < LEN || seq < 0 || seq > 255 || frame > 0xFFFF || dtr0 > 255)
		return -1;
	memset(out, 0, LEN);
	out[0] = CMD_SEND;
	out[1] = (uint8_t)seq;
	out[2] = (uint8_t)((send_twice ? FLAG_TWICE : 0) | (dtr0 >= 0 ? FLAG_DTR0 : 0));
	out[3] = FRAME_16BIT;
	out[6] = (uint8_t)(frame >> 8);
	out[7] = (uint8_t)frame;
	out[8] = dtr0 >= 0 ? (uint8_t)dtr0 : 0;
	return LEN;
}

static void tri_decode(const uint8_t *in, size_t len, struct ps_dali_reply *r)
{
	r->event = PS_DALI_EV_MALFORMED;
	r->seq = -1;
	r->value = 0;
	/* the fields we read end at byte 8; real reports are always 64 bytes */
	if (len < 9)
		return;
	switch (in[0]) {
	case MODE_INFO:
		r->event = PS_DALI_EV_INFO;
		r->value = (unsigned)in[3] << 8 | in[4];
		return;
	case MODE_OBSERVE:
		if (in[1] >= TYPE_NONE && in[1] <= 0x78) {
			r->event = in[1] == TYPE_16BIT ? PS_DALI_EV_OBSERVED : PS_DALI_EV_IGNORE;
			r->value = (unsigned)in[4] << 8 | in[5];
		}
		return;
	case MODE_RESPONSE:
		r->seq = in[8];
		switch (in[1]) {
		case TYPE_NONE:
			r->event = PS_DALI_EV_NO_ANSWER;
			return;
		case TYPE_8BIT:
			r->event = PS_DALI_EV_ANSWER;
			r->value = in[5];
			return;
		case TYPE_16BIT:
			r->event = PS_DALI_EV_ECHO;
			r->value = (unsigned)in[4] << 8 | in[5];
			return;
		case TYPE_STATUS:
			/* 1 checksum, 2 bus shorted, 3 framing: the transaction failed;
			 * 4 ok, 5 DSI, 6 DALI mode: news, not an answer */
			r->value = in[5];
			r->event = in[5] >= 1 && in[5] <= 3 ? PS_DALI_EV_BUS_ERROR : PS_DALI_EV_IGNORE;
			return;
		case 0x74: case 0x75: case 0x76: case 0x78:
			r->event = PS_DALI_EV_IGNORE;   /* other frame kinds: not ours */
			return;
		}
		r->seq = -1;
		return;
	}
}

/* 1..255, 0 avoided: a zeroed report can never look like an answer */
static int tri_next_seq(int seq)
{
	return seq >= 255 || seq < 1 ? 1 : seq + 1;
}

const struct ps_dali_transport ps_usb_tridonic = {
	.name = "tridonic",
	.vid = 0x17B5,
	.pid = 0x0020,
	.interface = 0,
	.ep_in = 0x81,
	.ep_out = 0x02,
	.report_len = LEN,
	.has_echo = 1,
	.encode_send = tri_encode_send,
	.decode = tri_decode,
	.next_seq = tri_next_seq,
};
