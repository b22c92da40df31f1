/* SPDX-License-Identifier: ISC */
/* The Foxtron converters' protocol (doc/hardware.md section 6).  A message
 * is SOH (0x01), its bytes as uppercase hex, one checksum byte as hex (the
 * one's complement of the bytes' sum modulo 256), ETB (0x17).  The first
 * byte is the message type:
 *
 *   host to converter  0x0B send: prio, length in bits, the frame, param
 *                      (bit 0: send twice); its replies are told apart from
 *                      other masters' traffic
 *   converter to host  0x0D our frame got an answer: length, answer length,
 *                      the frame, the answer (answer length 0: a collision)
 *                      0x0E our frame got no answer: length, the frame
 *                      0x03 / 0x04 another master's frame with / without an
 *                      answer (0x04 with length 0: a framing error on the bus)
 *                      0x05 an event: 0 bus power back, 1 power lost or a
 *                      short, 2 mains on the bus, 3 supply defective,
 *                      4 buffer full, 5 our message's checksum was wrong,
 *                      6 our message was invalid
 *                      0x07 / 0x09 configuration answers */
#include <string.h>

#include "dali_foxtron.h"

#define SOH 0x01
#define ETB 0x17
#define MAX_MSG 64
#define T_SEND 0x0B
#define T_ANSWER 0x0D
#define T_NO_ANSWER 0x0E
#define T_SPONT_ANSWER 0x03
#define T_SPONT 0x04
#define T_EVENT 0x05
#define T_CONF 0x07
#define T_CONF_ACK 0x09

static int fox_encode(uint8_t *out, size_t cap, const struct ps_dali_frame *f)
{
	uint8_t p[8];
	int n = 0, nb, len = 0;
	unsigned sum = 0;
	if (ps_dali_frame_valid(f) != 0)
		return -1;
	nb = f->bits / 8;
	p[n++] = T_SEND;
	p[n++] = 0;   /* priority: as in the vendor's example */
	p[n++] = (uint8_t)f->bits;
	for (int i = nb - 1; i >= 0; i--)
		p[n++] = (uint8_t)(f->data >> (8 * i));
	p[n++] = f->twice ? 1 : 0;
	if (cap < (size_t)(2 * n + 4))
		return -1;
	out[len++] = SOH;
	for (int i = 0; i < n; i++) {
		sum += p[i];
		len += (int)ps_dali_frame_hex((char *)out + len, p[i], 1);
	}
	len += (int)ps_dali_frame_hex((char *)out + len, ~sum & 0xFF, 1);
	out[len++] = ETB;
	return len;
}

static size_t bad(struct ps_dali_frame_rx *rx, size_t used, const char *why)
{
	rx->event = PS_DALI_EV_MALFORMED;
	strncpy(rx->why, why, sizeof rx->why - 1);
	rx->why[sizeof rx->why - 1] = 0;
	return used;
}

/* The frame of bytes p[0..n), bits long: -1 if the length does not match. */
static long frame_of(const uint8_t *p, size_t n, unsigned bits)
{
	long v = 0;
	if (bits % 8 || bits / 8 != n || n > 3)
		return -1;
	for (size_t i = 0; i < n; i++)
		v = v << 8 | p[i];
	return v;
}

static size_t fox_decode(const uint8_t *buf, size_t len, struct ps_dali_frame_rx *rx)
{
	uint8_t p[MAX_MSG / 2];
	size_t end, n, i;
	unsigned sum = 0;
	long v;
	memset(rx, 0, sizeof *rx);
	if (len == 0)
		return 0;
	if (buf[0] != SOH) {
		const uint8_t *s = memchr(buf, SOH, len);
		return bad(rx, s ? (size_t)(s - buf) : len, "bytes outside a message");
	}
	for (end = 1; end < len && end < MAX_MSG && buf[end] != ETB && buf[end] != SOH; end++)
		;
	if (end == len && len < MAX_MSG)
		return 0;
	if (end >= MAX_MSG)
		return bad(rx, end, "a message longer than 64 bytes");
	if (buf[end] == SOH)
		return bad(rx, end, "a message cut short (a new one began before its end)");
	/* buf[end] is ETB */
	if ((end - 1) % 2 || end - 1 < 4)
		return bad(rx, end + 1, "a message of an odd or too small number of hex digits");
	n = (end - 1) / 2;
	for (i = 0; i < n; i++) {
		if ((v = ps_dali_frame_unhex(buf + 1 + 2 * i, 2)) < 0)
			return bad(rx, end + 1, "a message with a character that is not a hex digit");
		p[i] = (uint8_t)v;
	}
	for (i = 0; i + 1 < n; i++)
		sum += p[i];
	if ((~sum & 0xFF) != p[n - 1])
		return bad(rx, end + 1, "a message with a wrong checksum");
	n--;   /* the payload without its checksum */
	switch (p[0]) {
	case T_ANSWER:
	case T_SPONT_ANSWER:
		/* type, length, answer length, the frame, the answer (if any) */
		if (n < 3)
			break;
		if (p[2] == 0) {
			if ((v = frame_of(p + 3, n - 3, p[1])) < 0)
				break;
			rx->event = p[0] == T_ANSWER ? PS_DALI_EV_BUS_ERROR : PS_DALI_EV_OBSERVED;
			rx->value = p[0] == T_ANSWER ? PS_DALI_BUS_FRAMING : (unsigned)v;
			rx->bits = p[1];
			if (p[0] == T_ANSWER)
				strcpy(rx->why, "garbled answer (several devices answered)");
			return end + 1;
		}
		if (n < 4 || (v = frame_of(p + 3, n - 4, p[1])) < 0)
			break;
		if (p[0] == T_ANSWER) {
			rx->event = PS_DALI_EV_ANSWER;
			rx->value = p[n - 1];
		} else {
			rx->event = PS_DALI_EV_OBSERVED;
			rx->value = (unsigned)v;
			rx->bits = p[1];
		}
		return end + 1;
	case T_NO_ANSWER:
	case T_SPONT:
		if (n < 2 || (v = p[1] ? frame_of(p + 2, n - 2, p[1]) : (n == 2 ? 0 : -1)) < 0)
			break;
		rx->event = p[0] == T_NO_ANSWER ? PS_DALI_EV_NO_ANSWER : PS_DALI_EV_OBSERVED;
		rx->value = (unsigned)v;
		rx->bits = p[1];
		return end + 1;
	case T_EVENT:
		if (n != 2)
			break;
		switch (p[1]) {
		case 0:
		case 1:
		case 2:
		case 3:
			rx->event = PS_DALI_EV_POWER;
			rx->value = p[1] == 0;
			strcpy(rx->why, p[1] == 0 ? "bus power back" : p[1] == 1 ? "bus power lost or the bus shorted" :
			                p[1] == 2 ? "mains voltage on the bus" : "the bus power supply is defective");
			return end + 1;
		case 4:
		case 5:
		case 6:
			rx->event = PS_DALI_EV_BUS_ERROR;
			rx->value = p[1] == 5 ? PS_DALI_BUS_CHECKSUM : PS_DALI_BUS_REJECTED;
			strcpy(rx->why, p[1] == 4 ? "the converter's buffer is full" :
			                p[1] == 5 ? "the converter saw a wrong checksum" : "the converter refused the message");
			return end + 1;
		}
		break;
	case T_CONF:
	case T_CONF_ACK:
		if (n < 4)
			break;
		rx->event = PS_DALI_EV_INFO;
		rx->value = (unsigned)p[2] << 8 | p[3];
		return end + 1;
	}
	return bad(rx, end + 1, "a message of an unknown type or the wrong length");
}

/* The configuration query for the firmware version (06 02, checksum 0xF7):
 * what the vendor suggests to keep a DALInet connection from timing out. */
static int fox_keepalive(uint8_t *out, size_t cap)
{
	static const char msg[] = "\x01" "0602F7" "\x17";
	if (cap < sizeof msg - 1)
		return -1;
	memcpy(out, msg, sizeof msg - 1);
	return (int)(sizeof msg - 1);
}

const struct ps_dali_codec ps_dali_foxtron = {
	.name = "foxtron",
	.baud = 9600,
	.replies_per_twice = 1,
	.max_msg = MAX_MSG,
	.keepalive = 20,
	.encode_keepalive = fox_keepalive,
	.encode = fox_encode,
	.decode = fox_decode,
};
