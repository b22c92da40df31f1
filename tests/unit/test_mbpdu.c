/* SPDX-License-Identifier: ISC */
/* The Modbus server's PDUs (daemon/psvirt/mbpdu.c) against the request and reply
 * examples of the Modbus Application Protocol Specification v1.1b3 (the
 * example tables of sections 6.1 to 6.17) and its exception rules (7). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

#include "mbpdu.h"

/* A plain memory map: 100 of each, reads and writes counted. */
struct mem {
	uint16_t t[PSD_MB_TABLES][100];
	int reads, writes;
};

static int mem_read(void *user, int table, unsigned addr, unsigned count, uint16_t *v)
{
	struct mem *m = user;
	assert_true(addr + count <= 100);
	memcpy(v, m->t[table] + addr, count * sizeof *v);
	m->reads++;
	return 0;
}

static int mem_write(void *user, int table, unsigned addr, unsigned count, const uint16_t *v)
{
	struct mem *m = user;
	assert_true(addr + count <= 100);
	assert_true(table == PSD_MB_COILS || table == PSD_MB_HOLDING);
	memcpy(m->t[table] + addr, v, count * sizeof *v);
	m->writes++;
	return 0;
}

static struct psd_mbmap map_of(struct mem *m)
{
	memset(m, 0, sizeof *m);
	return (struct psd_mbmap){ { 100, 100, 100, 100 }, m, mem_read, mem_write };
}

/* reply to req must be want, byte for byte */
#define ANSWER(map, req, want)                                                             \
	do {                                                                               \
		static const uint8_t q_[] = req, w_[] = want;                              \
		uint8_t out_[PSD_MBPDU_MAX];                                               \
		size_t n_ = psd_mbpdu_reply(map, q_, sizeof q_, out_);                     \
		assert_int_equal(n_, sizeof w_);                                           \
		assert_memory_equal(out_, w_, sizeof w_);                                  \
	} while (0)
#define B(...) { __VA_ARGS__ }

static void read_coils_spec_example(void **state)
{
	/* 6.1: coils 20-38 (addresses 19-37): 27..20 = CD, 35..28 = 6B, 38..36 = 05 */
	static const uint8_t bytes[] = { 0xcd, 0x6b, 0x05 };
	struct mem m;
	struct psd_mbmap map = map_of(&m);
	(void)state;
	for (int i = 0; i < 19; i++)
		m.t[PSD_MB_COILS][19 + i] = (bytes[i / 8] >> (i % 8)) & 1;
	ANSWER(&map, B(0x01, 0x00, 0x13, 0x00, 0x13), B(0x01, 0x03, 0xcd, 0x6b, 0x05));
}

static void read_discrete_spec_example(void **state)
{
	/* 6.2: inputs 197-218 (addresses 196-217; here 60-81, inside this
	 * map): AC DB 35 */
	static const uint8_t bytes[] = { 0xac, 0xdb, 0x35 };
	struct mem m;
	struct psd_mbmap map = map_of(&m);
	(void)state;
	for (int i = 0; i < 22; i++)
		m.t[PSD_MB_DISCRETE][60 + i] = (bytes[i / 8] >> (i % 8)) & 1;
	ANSWER(&map, B(0x02, 0x00, 0x3c, 0x00, 0x16), B(0x02, 0x03, 0xac, 0xdb, 0x35));
}

static void read_registers_spec_examples(void **state)
{
	struct mem m;
	struct psd_mbmap map = map_of(&m);
	(void)state;
	/* 6.3: registers 108-110 (addresses 107-109, here 7-9) = 555, 0, 100 */
	m.t[PSD_MB_HOLDING][7] = 0x022b;
	m.t[PSD_MB_HOLDING][9] = 0x0064;
	ANSWER(&map, B(0x03, 0x00, 0x07, 0x00, 0x03), B(0x03, 0x06, 0x02, 0x2b, 0x00, 0x00, 0x00, 0x64));
	/* 6.4: input register 9 (address 8) = 10 */
	m.t[PSD_MB_INPUT][8] = 10;
	ANSWER(&map, B(0x04, 0x00, 0x08, 0x00, 0x01), B(0x04, 0x02, 0x00, 0x0a));
}

static void writes_spec_examples(void **state)
{
	struct mem m;
	struct psd_mbmap map = map_of(&m);
	(void)state;
	/* 6.5: coil 173 (address 172, here 72) ON: the reply echoes */
	ANSWER(&map, B(0x05, 0x00, 0x48, 0xff, 0x00), B(0x05, 0x00, 0x48, 0xff, 0x00));
	assert_int_equal(m.t[PSD_MB_COILS][72], 1);
	/* 6.6: register 2 (address 1) = 3 */
	ANSWER(&map, B(0x06, 0x00, 0x01, 0x00, 0x03), B(0x06, 0x00, 0x01, 0x00, 0x03));
	assert_int_equal(m.t[PSD_MB_HOLDING][1], 3);
	/* 6.11: 10 coils from 20 (address 19): CD 01 = 1011 0011 then 01 */
	ANSWER(&map, B(0x0f, 0x00, 0x13, 0x00, 0x0a, 0x02, 0xcd, 0x01), B(0x0f, 0x00, 0x13, 0x00, 0x0a));
	{
		static const int want[10] = { 1, 0, 1, 1, 0, 0, 1, 1, 1, 0 };
		for (int i = 0; i < 10; i++)
			assert_int_equal(m.t[PSD_MB_COILS][19 + i], want[i]);
	}
	/* 6.12: registers 2 and 3 = 000A 0102 */
	ANSWER(&map, B(0x10, 0x00, 0x01, 0x00, 0x02, 0x04, 0x00, 0x0a, 0x01, 0x02), B(0x10, 0x00, 0x01, 0x00, 0x02));
	assert_int_equal(m.t[PSD_MB_HOLDING][1], 0x000a);
	assert_int_equal(m.t[PSD_MB_HOLDING][2], 0x0102);
}

static void mask_write_spec_example(void **state)
{
	/* 6.16: register 5 (address 4) = 0x12, AND 0xF2, OR 0x25 -> 0x17 */
	struct mem m;
	struct psd_mbmap map = map_of(&m);
	(void)state;
	m.t[PSD_MB_HOLDING][4] = 0x12;
	ANSWER(&map, B(0x16, 0x00, 0x04, 0x00, 0xf2, 0x00, 0x25), B(0x16, 0x00, 0x04, 0x00, 0xf2, 0x00, 0x25));
	assert_int_equal(m.t[PSD_MB_HOLDING][4], 0x17);
}

static void read_write_spec_example(void **state)
{
	/* 6.17: write 00FF x 3 at 15-17 (addresses 14-16), read 6 from 4
	 * (address 3): the read sees the map after the write */
	struct mem m;
	struct psd_mbmap map = map_of(&m);
	static const uint16_t regs[6] = { 0x00fe, 0x0acd, 0x0001, 0x0003, 0x000d, 0x00ff };
	(void)state;
	memcpy(m.t[PSD_MB_HOLDING] + 3, regs, sizeof regs);
	ANSWER(&map, B(0x17, 0x00, 0x03, 0x00, 0x06, 0x00, 0x0e, 0x00, 0x03, 0x06, 0x00, 0xff, 0x00, 0xff, 0x00, 0xff),
	       B(0x17, 0x0c, 0x00, 0xfe, 0x0a, 0xcd, 0x00, 0x01, 0x00, 0x03, 0x00, 0x0d, 0x00, 0xff));
	assert_int_equal(m.t[PSD_MB_HOLDING][14], 0xff);
	assert_int_equal(m.t[PSD_MB_HOLDING][16], 0xff);
	/* overlapping: write 7 at 5, read 5: the new value */
	ANSWER(&map, B(0x17, 0x00, 0x05, 0x00, 0x01, 0x00, 0x05, 0x00, 0x01, 0x02, 0x00, 0x07), B(0x17, 0x02, 0x00, 0x07));
}

static void unknown_functions_are_exception_1(void **state)
{
	struct mem m;
	struct psd_mbmap map = map_of(&m);
	(void)state;
	ANSWER(&map, B(0x07), B(0x87, 0x01));                      /* read exception status */
	ANSWER(&map, B(0x08, 0x00, 0x00, 0x12, 0x34), B(0x88, 0x01));  /* diagnostics */
	ANSWER(&map, B(0x11), B(0x91, 0x01));                      /* report server id */
	ANSWER(&map, B(0x2b, 0x0e, 0x01, 0x00), B(0xab, 0x01));    /* device identification */
	ANSWER(&map, B(0x41, 0xaa), B(0xc1, 0x01));
	ANSWER(&map, B(0x00), B(0x80, 0x01));
	assert_int_equal(m.reads + m.writes, 0);
}

static void quantities_are_exception_3(void **state)
{
	struct mem m;
	struct psd_mbmap map = map_of(&m);
	(void)state;
	ANSWER(&map, B(0x01, 0x00, 0x00, 0x00, 0x00), B(0x81, 0x03));
	ANSWER(&map, B(0x01, 0x00, 0x00, 0x07, 0xd1), B(0x81, 0x03));   /* 2001 coils */
	ANSWER(&map, B(0x03, 0x00, 0x00, 0x00, 0x00), B(0x83, 0x03));
	ANSWER(&map, B(0x03, 0x00, 0x00, 0x00, 0x7e), B(0x83, 0x03));   /* 126 registers */
	ANSWER(&map, B(0x04, 0x00, 0x00, 0x00, 0x00), B(0x84, 0x03));
	ANSWER(&map, B(0x05, 0x00, 0x00, 0x12, 0x34), B(0x85, 0x03));   /* a coil is 0000 or FF00 */
	ANSWER(&map, B(0x10, 0x00, 0x00, 0x00, 0x02, 0x02, 0x00, 0x01), B(0x90, 0x03));   /* 2 bytes for 2 registers */
	ANSWER(&map, B(0x0f, 0x00, 0x00, 0x00, 0x09, 0x01, 0xff), B(0x8f, 0x03));        /* 1 byte for 9 coils */
	/* a quantity beyond the table is 3 before it is 2 (the spec's order) */
	ANSWER(&map, B(0x03, 0x03, 0xe7, 0x00, 0x7e), B(0x83, 0x03));
	/* a request shorter than its function: malformed */
	ANSWER(&map, B(0x03, 0x00, 0x00), B(0x83, 0x03));
	assert_int_equal(m.writes, 0);
}

static void addresses_are_exception_2_at_both_edges(void **state)
{
	struct mem m;
	struct psd_mbmap map = map_of(&m);
	(void)state;
	ANSWER(&map, B(0x03, 0x00, 0x63, 0x00, 0x01), B(0x03, 0x02, 0x00, 0x00));   /* 99: the last */
	ANSWER(&map, B(0x03, 0x00, 0x63, 0x00, 0x02), B(0x83, 0x02));               /* 99-100 */
	ANSWER(&map, B(0x03, 0x00, 0x64, 0x00, 0x01), B(0x83, 0x02));               /* 100 */
	ANSWER(&map, B(0x03, 0xff, 0xff, 0x00, 0x7d), B(0x83, 0x02));               /* 65535 + 125 */
	ANSWER(&map, B(0x06, 0x00, 0x64, 0x00, 0x01), B(0x86, 0x02));
	ANSWER(&map, B(0x01, 0x00, 0x5d, 0x00, 0x08), B(0x81, 0x02));               /* coils 93-100 */
	ANSWER(&map, B(0x17, 0x00, 0x00, 0x00, 0x01, 0x00, 0x64, 0x00, 0x01, 0x02, 0x00, 0x01), B(0x97, 0x02));
	assert_int_equal(m.writes, 0);   /* a write that fails writes nothing */
}

static void lengths_and_spans(void **state)
{
	static const uint8_t wr[] = { 0x10, 0x00, 0x05, 0x00, 0x02, 0x04, 0, 1, 0, 2 };
	static const uint8_t rw[] = { 0x17, 0x00, 0x01, 0x00, 0x02, 0x00, 0x03, 0x00, 0x01, 0x02, 0, 9 };
	struct psd_mbspan sp[2];
	(void)state;
	assert_int_equal(psd_mbpdu_length(wr, 0), 0);
	assert_int_equal(psd_mbpdu_length(wr, 5), 0);     /* the byte count not yet there */
	assert_int_equal(psd_mbpdu_length(wr, 6), 10);
	assert_int_equal(psd_mbpdu_length(rw, 10), 12);
	assert_int_equal(psd_mbpdu_length((const uint8_t *)"\x2b", 1), -1);
	assert_int_equal(psd_mbpdu_spans(wr, sizeof wr, sp), 1);
	assert_int_equal(sp[0].table, PSD_MB_HOLDING);
	assert_int_equal(sp[0].addr, 5);
	assert_int_equal(sp[0].count, 2);
	assert_true(sp[0].write);
	assert_int_equal(psd_mbpdu_spans(rw, sizeof rw, sp), 2);
	assert_int_equal(sp[0].addr, 3);
	assert_true(sp[0].write);
	assert_int_equal(sp[1].addr, 1);
	assert_int_equal(sp[1].count, 2);
	assert_false(sp[1].write);
	assert_int_equal(psd_mbpdu_spans(wr, sizeof wr - 1, sp), 0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(read_coils_spec_example),
		cmocka_unit_test(read_discrete_spec_example),
		cmocka_unit_test(read_registers_spec_examples),
		cmocka_unit_test(writes_spec_examples),
		cmocka_unit_test(mask_write_spec_example),
		cmocka_unit_test(read_write_spec_example),
		cmocka_unit_test(unknown_functions_are_exception_1),
		cmocka_unit_test(quantities_are_exception_3),
		cmocka_unit_test(addresses_are_exception_2_at_both_edges),
		cmocka_unit_test(lengths_and_spans),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
