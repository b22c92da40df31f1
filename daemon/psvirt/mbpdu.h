/* SPDX-License-Identifier: ISC */
/* The server side of the Modbus application protocol: one request PDU in,
 * one reply PDU out, from a register map given as callbacks.  No framing and
 * no I/O (mbframe.h frames it for TCP and RTU), so a server can answer many
 * connections without ever blocking, and the whole of it is fuzzed from
 * memory (tests/fuzz/fuzz_mbserve.c).
 *
 * Served, with the checks of the Modbus Application Protocol v1.1b3 (6.1 to
 * 6.17) in its order (function, then quantity, then address):
 *   01 read coils             02 read discrete inputs   (1-2000 bits)
 *   03 read holding registers 04 read input registers   (1-125)
 *   05 write single coil (0x0000 or 0xFF00)            06 write single register
 *   0F write multiple coils (1-1968)    10 write multiple registers (1-123)
 *   16 mask write register    17 read/write multiple registers (write first)
 * Any other function: exception 1 (illegal function); a quantity out of its
 * range or a byte count that does not match it: exception 3 (illegal data
 * value); an address run outside the table: exception 2 (illegal data
 * address). */
#ifndef PSD_MBPDU_H
#define PSD_MBPDU_H

#include <stddef.h>
#include <stdint.h>

enum {
	PSD_MBPDU_MAX = 253,           /* the longest PDU, request or reply */
	PSD_MBPDU_MAX_BITS = 2000,     /* the most bits one request reads */
};

/* Exception codes (the spec's names). */
enum {
	PSD_MBX_ILLEGAL_FUNCTION = 1,
	PSD_MBX_ILLEGAL_ADDRESS = 2,
	PSD_MBX_ILLEGAL_VALUE = 3,
	PSD_MBX_DEVICE_FAILURE = 4,
	PSD_MBX_GATEWAY_TARGET = 0x0b, /* gateway target device failed to respond */
};

enum psd_mbtable { PSD_MB_COILS, PSD_MB_DISCRETE, PSD_MB_HOLDING, PSD_MB_INPUT, PSD_MB_TABLES };

/* One run of bits or registers a request reads or writes. */
struct psd_mbspan {
	int table;                     /* enum psd_mbtable */
	unsigned addr, count;
	int write;
};

/* The register map: the size of each table (addresses 0 to size - 1) and
 * the callbacks that read and write it.  Bits travel as one 0 or 1 per
 * element of v.  The callbacks see only runs inside the table; they return
 * 0, or an exception code for the reply (e.g. 4, device failure). */
struct psd_mbmap {
	unsigned size[PSD_MB_TABLES];
	void *user;
	int (*read)(void *user, int table, unsigned addr, unsigned count, uint16_t *v);
	int (*write)(void *user, int table, unsigned addr, unsigned count, const uint16_t *v);
};

/* The length of the request PDU that starts with the have bytes at pdu, as
 * its function defines it: > 0 that length, 0 when more bytes are needed to
 * tell, -1 for a function this server does not know (its length is then
 * whatever the framing says). */
int psd_mbpdu_length(const uint8_t *pdu, size_t have);

/* The runs a well-formed request touches (1, or 2 for function 17) into
 * sp[2]; 0 for an unknown function or a malformed request. */
int psd_mbpdu_spans(const uint8_t *pdu, size_t n, struct psd_mbspan sp[2]);

/* Answer the request pdu[0..n) into out[PSD_MBPDU_MAX]: a normal reply or an
 * exception reply.  Returns the reply's length (>= 2). */
size_t psd_mbpdu_reply(const struct psd_mbmap *m, const uint8_t *pdu, size_t n, uint8_t *out);

/* An exception reply to function fc into out: returns its length (2). */
size_t psd_mbpdu_exception(uint8_t fc, uint8_t code, uint8_t *out);

#endif
