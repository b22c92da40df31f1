/* SPDX-License-Identifier: ISC */
/* Modbus framing for a server: requests found in a connection's bytes and
 * replies built around a PDU (mbpdu.h), for Modbus TCP (the MBAP header)
 * and Modbus RTU (address, PDU, CRC-16, frames ended by a silence).  No I/O
 * and no clock: the caller owns the buffers and says when the line has been
 * silent, so a server can keep any number of connections in one poll loop.
 *
 * TCP (Modbus Messaging on TCP/IP v1.0b, 3.1.3): transaction id, protocol
 * id (must be 0), length (the unit id and the PDU: 2 to 254, and equal to
 * the PDU's own length where the function defines one), unit id.  A frame
 * that breaks these is not Modbus: the server drops the connection, as
 * devices do, since nothing after it can be trusted to start a frame.
 *
 * RTU (Modbus over serial line v1.02, 2.5.1): a request of a function this
 * server serves ends at its own length (so a frame that a pseudo-terminal or
 * a loaded host delivers in pieces is still whole); any other ends at a
 * silence of 3.5 characters.  Bytes that do not start a frame with a good
 * CRC are dropped one at a time until a frame starts (resynchronisation),
 * without a reply; the caller bounds how long an unfinished frame may wait. */
#ifndef PSD_MBFRAME_H
#define PSD_MBFRAME_H

#include <stddef.h>
#include <stdint.h>

enum {
	PSD_MBFRAME_TCP_MAX = 260,     /* MBAP 7 + PDU 253 */
	PSD_MBFRAME_RTU_MAX = 256,     /* address 1 + PDU 253 + CRC 2 */
};

/* One request found in a buffer. */
struct psd_mbadu {
	unsigned tid;                  /* TCP transaction id (0 on RTU) */
	unsigned unit;                 /* unit id or RTU address */
	const uint8_t *pdu;            /* into the buffer */
	size_t npdu;
};

/* The first TCP frame of buf[0..len): its length in bytes (> 0) with *adu
 * set; 0 when more bytes are needed; -1 when the bytes are not a Modbus TCP
 * frame, with *why set to the reason. */
int psd_mbframe_tcp(const uint8_t *buf, size_t len, struct psd_mbadu *adu, const char **why);
/* A TCP reply to req around pdu[0..n) into out[PSD_MBFRAME_TCP_MAX]:
 * returns its length. */
size_t psd_mbframe_tcp_put(const struct psd_mbadu *req, const uint8_t *pdu, size_t n, uint8_t *out);

/* CRC-16/MODBUS (polynomial 0xA001 reflected, initial 0xFFFF), as sent:
 * low byte first. */
uint16_t psd_mbframe_crc(const uint8_t *p, size_t n);
/* The first RTU frame of buf[0..len) given whether the line has been
 * silent for 3.5 characters since the last byte: its length (> 0) with
 * *adu set; 0 when more bytes may come; -1 when no frame starts at buf[0]
 * (the caller drops that byte and looks again), with *why set. */
int psd_mbframe_rtu(const uint8_t *buf, size_t len, int silent, struct psd_mbadu *adu, const char **why);
/* An RTU reply from unit around pdu[0..n) into out[PSD_MBFRAME_RTU_MAX]:
 * returns its length. */
size_t psd_mbframe_rtu_put(unsigned unit, const uint8_t *pdu, size_t n, uint8_t *out);
/* The silence that ends a frame at this line speed, in seconds: 3.5
 * characters of 11 bits, and 1.75 ms above 19200 baud (2.5.1.1). */
double psd_mbframe_rtu_silence(long baud);

#endif
