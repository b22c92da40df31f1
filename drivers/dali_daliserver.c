/* SPDX-License-Identifier: ISC */
/* The daliserver network protocol (doc/hardware.md section 9): daliserver
 * shares a Tridonic DALI USB interface over TCP.  Every message is 4 bytes,
 * the first the protocol version, 2.
 *
 * Host to server:  version, type 0 ("send"), address byte, data byte:
 *                  one 16-bit forward frame, sent once
 * Server to host:  version, status, value, 0
 *                  status 0: sent, no backward frame (value 0)
 *                  status 1: sent, backward frame in value
 *                  status 255: the server could not send it (a USB error)
 *                  status 2: another frame seen on the bus; the last two
 *                  bytes are that 16-bit frame (not a reply)
 *
 * The request has no room for an 8- or 24-bit frame (no control devices)
 * nor for "send twice" (the server never sets the interface's send-twice
 * flag, and two requests are not promised to go out within 100 ms), so
 * those frames are refused.  Nor does the protocol report collisions, a
 * garbled answer or the bus power: those come back as status 255 or not at
 * all. */
#include <stdio.h>
#include <string.h>

#include "dali_daliserver.h"

#define MSG_LEN 4
#define VERSION 2
#define TYPE_SEND 0
#define ST_DONE 0
#define ST_ANSWER 1
#define ST_SEEN 2
#define ST_ERROR 255

static int ds_encode(uint8_t *out, size_t cap, const struct ps_dali_frame *f)
{
	if (ps_dali_frame_valid(f) != 0 || f->bits != 16 || f->twice || cap < MSG_LEN)
		return -1;
	out[0] = VERSION;
	out[1] = TYPE_SEND;
	out[2] = (uint8_t)(f->data >> 8);
	out[3] = (uint8_t)f->data;
	return MSG_LEN;
}

static size_t ds_decode(const uint8_t *buf, size_t len, struct ps_dali_frame_rx *rx)
{
	memset(rx, 0, sizeof *rx);
	if (len < MSG_LEN)
		return 0;
	rx->event = PS_DALI_EV_MALFORMED;
	if (buf[0] != VERSION) {
		snprintf(rx->why, sizeof rx->why, "protocol version %u, not 2 (%02X %02X %02X %02X)", buf[0], buf[0],
		         buf[1], buf[2], buf[3]);
		return MSG_LEN;
	}
	switch (buf[1]) {
	case ST_DONE:
	case ST_ANSWER:
		if (buf[3] != 0) {
			snprintf(rx->why, sizeof rx->why, "a reply whose last byte is %02X, not 0", buf[3]);
			return MSG_LEN;
		}
		rx->event = buf[1] == ST_ANSWER ? PS_DALI_EV_ANSWER : PS_DALI_EV_NO_ANSWER;
		rx->value = buf[1] == ST_ANSWER ? buf[2] : 0;
		return MSG_LEN;
	case ST_SEEN:
		rx->event = PS_DALI_EV_OBSERVED;
		rx->value = (unsigned)buf[2] << 8 | buf[3];
		rx->bits = 16;
		return MSG_LEN;
	case ST_ERROR:
		rx->event = PS_DALI_EV_BUS_ERROR;
		rx->value = PS_DALI_BUS_REJECTED;
		snprintf(rx->why, sizeof rx->why, "daliserver could not send the frame (status 255)");
		return MSG_LEN;
	}
	snprintf(rx->why, sizeof rx->why, "status %u is none of 0, 1, 2, 255", buf[1]);
	return MSG_LEN;
}

const struct ps_dali_codec ps_dali_daliserver = {
	.name = "daliserver",
	.replies_per_twice = 1,
	.max_msg = MSG_LEN,
	.encode = ds_encode,
	.decode = ds_decode,
};
