/* SPDX-License-Identifier: ISC */
/* Modbus request PDUs answered from a register map (see mbpdu.h). */
#include "mbpdu.h"

#include <string.h>

enum {
	FC_READ_COILS = 0x01,
	FC_READ_DISCRETE = 0x02,
	FC_READ_HOLDING = 0x03,
	FC_READ_INPUT = 0x04,
	FC_WRITE_COIL = 0x05,
	FC_WRITE_REGISTER = 0x06,
	FC_WRITE_COILS = 0x0f,
	FC_WRITE_REGISTERS = 0x10,
	FC_MASK_WRITE = 0x16,
	FC_READ_WRITE = 0x17,
};

static unsigned u16(const uint8_t *p)
{
	return (unsigned)p[0] << 8 | p[1];
}

static void put16(uint8_t *p, unsigned v)
{
	p[0] = (uint8_t)(v >> 8);
	p[1] = (uint8_t)v;
}

int psd_mbpdu_length(const uint8_t *pdu, size_t have)
{
	if (have < 1)
		return 0;
	switch (pdu[0]) {
	case FC_READ_COILS:
	case FC_READ_DISCRETE:
	case FC_READ_HOLDING:
	case FC_READ_INPUT:
	case FC_WRITE_COIL:
	case FC_WRITE_REGISTER:
		return 5;
	case FC_MASK_WRITE:
		return 7;
	case FC_WRITE_COILS:
	case FC_WRITE_REGISTERS:
		return have < 6 ? 0 : 6 + pdu[5];
	case FC_READ_WRITE:
		return have < 10 ? 0 : 10 + pdu[9];
	default:
		return -1;
	}
}

size_t psd_mbpdu_exception(uint8_t fc, uint8_t code, uint8_t *out)
{
	out[0] = (uint8_t)(fc | 0x80);
	out[1] = code;
	return 2;
}

int psd_mbpdu_spans(const uint8_t *pdu, size_t n, struct psd_mbspan sp[2])
{
	int len = psd_mbpdu_length(pdu, n);
	if (len <= 0 || (size_t)len != n)
		return 0;
	switch (pdu[0]) {
	case FC_READ_COILS: sp[0] = (struct psd_mbspan){ PSD_MB_COILS, u16(pdu + 1), u16(pdu + 3), 0 }; return 1;
	case FC_READ_DISCRETE: sp[0] = (struct psd_mbspan){ PSD_MB_DISCRETE, u16(pdu + 1), u16(pdu + 3), 0 }; return 1;
	case FC_READ_HOLDING: sp[0] = (struct psd_mbspan){ PSD_MB_HOLDING, u16(pdu + 1), u16(pdu + 3), 0 }; return 1;
	case FC_READ_INPUT: sp[0] = (struct psd_mbspan){ PSD_MB_INPUT, u16(pdu + 1), u16(pdu + 3), 0 }; return 1;
	case FC_WRITE_COIL: sp[0] = (struct psd_mbspan){ PSD_MB_COILS, u16(pdu + 1), 1, 1 }; return 1;
	case FC_WRITE_REGISTER:
	case FC_MASK_WRITE: sp[0] = (struct psd_mbspan){ PSD_MB_HOLDING, u16(pdu + 1), 1, 1 }; return 1;
	case FC_WRITE_COILS: sp[0] = (struct psd_mbspan){ PSD_MB_COILS, u16(pdu + 1), u16(pdu + 3), 1 }; return 1;
	case FC_WRITE_REGISTERS: sp[0] = (struct psd_mbspan){ PSD_MB_HOLDING, u16(pdu + 1), u16(pdu + 3), 1 }; return 1;
	default:   /* FC_READ_WRITE: the write is done first */
		sp[0] = (struct psd_mbspan){ PSD_MB_HOLDING, u16(pdu + 5), u16(pdu + 7), 1 };
		sp[1] = (struct psd_mbspan){ PSD_MB_HOLDING, u16(pdu + 1), u16(pdu + 3), 0 };
		return 2;
	}
}

/* The run lies inside the table (computed in unsigned long: addr + count
 * can pass 65535). */
static int inside(const struct psd_mbmap *m, int table, unsigned addr, unsigned count)
{
	return (unsigned long)addr + count <= m->size[table];
}

static size_t read_bits(const struct psd_mbmap *m, const uint8_t *q, uint8_t *out)
{
	int table = q[0] == FC_READ_COILS ? PSD_MB_COILS : PSD_MB_DISCRETE, x;
	unsigned addr = u16(q + 1), count = u16(q + 3), nbytes = (count + 7) / 8;
	uint16_t v[PSD_MBPDU_MAX_BITS];
	if (count < 1 || count > PSD_MBPDU_MAX_BITS)
		return psd_mbpdu_exception(q[0], PSD_MBX_ILLEGAL_VALUE, out);
	if (!inside(m, table, addr, count))
		return psd_mbpdu_exception(q[0], PSD_MBX_ILLEGAL_ADDRESS, out);
	if ((x = m->read(m->user, table, addr, count, v)) != 0)
		return psd_mbpdu_exception(q[0], (uint8_t)x, out);
	out[0] = q[0];
	out[1] = (uint8_t)nbytes;
	memset(out + 2, 0, nbytes);
	for (unsigned i = 0; i < count; i++)
		if (v[i])
			out[2 + i / 8] |= (uint8_t)(1u << (i % 8));
	return 2 + nbytes;
}

static size_t read_registers(const struct psd_mbmap *m, const uint8_t *q, uint8_t *out)
{
	int table = q[0] == FC_READ_HOLDING ? PSD_MB_HOLDING : PSD_MB_INPUT, x;
	unsigned addr = u16(q + 1), count = u16(q + 3);
	uint16_t v[125];
	if (count < 1 || count > 125)
		return psd_mbpdu_exception(q[0], PSD_MBX_ILLEGAL_VALUE, out);
	if (!inside(m, table, addr, count))
		return psd_mbpdu_exception(q[0], PSD_MBX_ILLEGAL_ADDRESS, out);
	if ((x = m->read(m->user, table, addr, count, v)) != 0)
		return psd_mbpdu_exception(q[0], (uint8_t)x, out);
	out[0] = q[0];
	out[1] = (uint8_t)(2 * count);
	for (unsigned i = 0; i < count; i++)
		put16(out + 2 + 2 * i, v[i]);
	return 2 + 2 * count;
}

/* 05 and 06: the reply echoes the request. */
static size_t write_single(const struct psd_mbmap *m, const uint8_t *q, uint8_t *out)
{
	int coil = q[0] == FC_WRITE_COIL, table = coil ? PSD_MB_COILS : PSD_MB_HOLDING, x;
	unsigned addr = u16(q + 1), value = u16(q + 3);
	uint16_t v = (uint16_t)value;
	if (coil && value != 0x0000 && value != 0xff00)
		return psd_mbpdu_exception(q[0], PSD_MBX_ILLEGAL_VALUE, out);
	if (!inside(m, table, addr, 1))
		return psd_mbpdu_exception(q[0], PSD_MBX_ILLEGAL_ADDRESS, out);
	if (coil)
		v = value != 0;
	if ((x = m->write(m->user, table, addr, 1, &v)) != 0)
		return psd_mbpdu_exception(q[0], (uint8_t)x, out);
	memcpy(out, q, 5);
	return 5;
}

/* 0F and 10: the reply is the function, the address and the quantity. */
static size_t write_multiple(const struct psd_mbmap *m, const uint8_t *q, uint8_t *out)
{
	int coils = q[0] == FC_WRITE_COILS, table = coils ? PSD_MB_COILS : PSD_MB_HOLDING, x;
	unsigned addr = u16(q + 1), count = u16(q + 3), nbytes = q[5];
	unsigned max = coils ? 1968 : 123, want = coils ? (count + 7) / 8 : 2 * count;
	uint16_t v[1968];
	if (count < 1 || count > max || nbytes != want)
		return psd_mbpdu_exception(q[0], PSD_MBX_ILLEGAL_VALUE, out);
	if (!inside(m, table, addr, count))
		return psd_mbpdu_exception(q[0], PSD_MBX_ILLEGAL_ADDRESS, out);
	for (unsigned i = 0; i < count; i++)
		v[i] = coils ? (q[6 + i / 8] >> (i % 8)) & 1 : (uint16_t)u16(q + 6 + 2 * i);
	if ((x = m->write(m->user, table, addr, count, v)) != 0)
		return psd_mbpdu_exception(q[0], (uint8_t)x, out);
	memcpy(out, q, 5);
	return 5;
}

/* 16: register = (register AND and) OR (or AND NOT and); the reply echoes. */
static size_t mask_write(const struct psd_mbmap *m, const uint8_t *q, uint8_t *out)
{
	unsigned addr = u16(q + 1), and_mask = u16(q + 3), or_mask = u16(q + 5);
	uint16_t v;
	int x;
	if (!inside(m, PSD_MB_HOLDING, addr, 1))
		return psd_mbpdu_exception(q[0], PSD_MBX_ILLEGAL_ADDRESS, out);
	if ((x = m->read(m->user, PSD_MB_HOLDING, addr, 1, &v)) != 0)
		return psd_mbpdu_exception(q[0], (uint8_t)x, out);
	v = (uint16_t)((v & and_mask) | (or_mask & ~and_mask));
	if ((x = m->write(m->user, PSD_MB_HOLDING, addr, 1, &v)) != 0)
		return psd_mbpdu_exception(q[0], (uint8_t)x, out);
	memcpy(out, q, 7);
	return 7;
}

/* 17: write first, then read, both checked before either is done. */
static size_t read_write(const struct psd_mbmap *m, const uint8_t *q, uint8_t *out)
{
	unsigned raddr = u16(q + 1), rcount = u16(q + 3), waddr = u16(q + 5), wcount = u16(q + 7);
	uint16_t v[125];
	int x;
	if (rcount < 1 || rcount > 125 || wcount < 1 || wcount > 121 || q[9] != 2 * wcount)
		return psd_mbpdu_exception(q[0], PSD_MBX_ILLEGAL_VALUE, out);
	if (!inside(m, PSD_MB_HOLDING, raddr, rcount) || !inside(m, PSD_MB_HOLDING, waddr, wcount))
		return psd_mbpdu_exception(q[0], PSD_MBX_ILLEGAL_ADDRESS, out);
	for (unsigned i = 0; i < wcount; i++)
		v[i] = (uint16_t)u16(q + 10 + 2 * i);
	if ((x = m->write(m->user, PSD_MB_HOLDING, waddr, wcount, v)) != 0 ||
	    (x = m->read(m->user, PSD_MB_HOLDING, raddr, rcount, v)) != 0)
		return psd_mbpdu_exception(q[0], (uint8_t)x, out);
	out[0] = q[0];
	out[1] = (uint8_t)(2 * rcount);
	for (unsigned i = 0; i < rcount; i++)
		put16(out + 2 + 2 * i, v[i]);
	return 2 + 2 * rcount;
}

size_t psd_mbpdu_reply(const struct psd_mbmap *m, const uint8_t *pdu, size_t n, uint8_t *out)
{
	int len = psd_mbpdu_length(pdu, n);
	if (n < 1)
		return psd_mbpdu_exception(0, PSD_MBX_ILLEGAL_FUNCTION, out);
	if (len < 0)
		return psd_mbpdu_exception(pdu[0], PSD_MBX_ILLEGAL_FUNCTION, out);
	/* the framing checks the length; a caller without framing gets the
	 * spec's answer to a malformed request */
	if (len == 0 || (size_t)len != n)
		return psd_mbpdu_exception(pdu[0], PSD_MBX_ILLEGAL_VALUE, out);
	switch (pdu[0]) {
	case FC_READ_COILS:
	case FC_READ_DISCRETE: return read_bits(m, pdu, out);
	case FC_READ_HOLDING:
	case FC_READ_INPUT: return read_registers(m, pdu, out);
	case FC_WRITE_COIL:
	case FC_WRITE_REGISTER: return write_single(m, pdu, out);
	case FC_WRITE_COILS:
	case FC_WRITE_REGISTERS: return write_multiple(m, pdu, out);
	case FC_MASK_WRITE: return mask_write(m, pdu, out);
	default: return read_write(m, pdu, out);
	}
}
