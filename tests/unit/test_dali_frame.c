/* SPDX-License-Identifier: ISC */
/* The serial DALI codecs (drivers/dali_atx.c, drivers/dali_foxtron.c) and the
 * frame layer's helpers, against byte strings written from the interfaces'
 * published protocol descriptions (doc/hardware.md sections 5 and 6): the
 * vendor's own worked example where there is one, else messages built by hand
 * with the stated checksum rule (the sums are worked in the comments).  Each
 * reply kind, and the broken ones: incomplete, overlong, bad hex, a wrong
 * checksum, bytes outside a message, a message cut short by the next. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

#include "dali_atx.h"
#include "dali_foxtron.h"

static struct ps_dali_frame fr(int bits, uint32_t data, int twice)
{
	return (struct ps_dali_frame){ .bits = bits, .data = data, .twice = twice };
}

static void expect_encoding(const struct ps_dali_codec *c, struct ps_dali_frame f, const char *want)
{
	uint8_t out[64];
	int n = c->encode(out, sizeof out, &f);
	assert_int_equal(n, (int)strlen(want));
	assert_memory_equal(out, want, strlen(want));
}

/* decode the whole string as one message */
static struct ps_dali_frame_rx dec(const struct ps_dali_codec *c, const char *s, size_t want_used)
{
	struct ps_dali_frame_rx rx;
	size_t used = c->decode((const uint8_t *)s, strlen(s), &rx);
	assert_int_equal(used, want_used);
	return rx;
}

static void frame_helpers(void **state)
{
	char hex[8];
	struct ps_dali_frame f = fr(16, 0x0BA0, 0);
	(void)state;
	assert_int_equal(ps_dali_frame_valid(&f), 0);
	f = fr(16, 0x10000, 0);
	assert_int_equal(ps_dali_frame_valid(&f), -1);
	f = fr(12, 0x100, 0);
	assert_int_equal(ps_dali_frame_valid(&f), -1);
	f = fr(24, 0xFFFFFF, 0);
	assert_int_equal(ps_dali_frame_valid(&f), 0);
	assert_int_equal(ps_dali_frame_hex(hex, 0xA1E002, 3), 6);
	assert_memory_equal(hex, "A1E002", 6);
	assert_int_equal(ps_dali_frame_unhex((const uint8_t *)"c8", 2), 0xC8);
	assert_int_equal(ps_dali_frame_unhex((const uint8_t *)"0G", 2), -1);
	assert_string_equal(ps_dali_frame_event_name(PS_DALI_EV_NO_ANSWER), "no answer");
	assert_string_equal(ps_dali_frame_event_name(99), "unknown");
}

static void atx_encode(void **state)
{
	uint8_t small[4];
	struct ps_dali_frame f = fr(16, 0x0BA0, 0);
	(void)state;
	/* QUERY ACTUAL LEVEL of short 5 is 0B A0; DAPC short 5 level 200 is 0A C8 */
	expect_encoding(&ps_dali_atx, fr(16, 0x0BA0, 0), "h0BA0\n");
	expect_encoding(&ps_dali_atx, fr(16, 0x0AC8, 0), "h0AC8\n");
	/* RESET (0x20) to short 5, sent twice by the HAT */
	expect_encoding(&ps_dali_atx, fr(16, 0x0B20, 1), "t0B20\n");
	expect_encoding(&ps_dali_atx, fr(8, 0xFF, 0), "jFF\n");
	expect_encoding(&ps_dali_atx, fr(24, 0x01FE00, 0), "l01FE00\n");
	/* no send-twice form for 24 bits; no 12-bit frames; no room */
	f = fr(24, 0x01FE00, 1);
	assert_int_equal(ps_dali_atx.encode(small, 64, &f), -1);
	f = fr(12, 1, 0);
	assert_int_equal(ps_dali_atx.encode(small, 64, &f), -1);
	f = fr(16, 0x0BA0, 0);
	assert_int_equal(ps_dali_atx.encode(small, sizeof small, &f), -1);
}

static void atx_decode(void **state)
{
	struct ps_dali_frame_rx rx;
	const char two[] = "N\nJ10\n";
	char longline[41];
	(void)state;
	rx = dec(&ps_dali_atx, "J7F\n", 4);
	assert_int_equal(rx.event, PS_DALI_EV_ANSWER);
	assert_int_equal(rx.value, 0x7F);
	rx = dec(&ps_dali_atx, "Jfe\r\n", 5);
	assert_int_equal(rx.event, PS_DALI_EV_ANSWER);
	assert_int_equal(rx.value, 0xFE);
	rx = dec(&ps_dali_atx, "N\n", 2);
	assert_int_equal(rx.event, PS_DALI_EV_NO_ANSWER);
	rx = dec(&ps_dali_atx, "X\n", 2);
	assert_int_equal(rx.event, PS_DALI_EV_BUS_ERROR);
	assert_int_equal(rx.value, PS_DALI_BUS_FRAMING);
	rx = dec(&ps_dali_atx, "Z\n", 2);
	assert_int_equal(rx.event, PS_DALI_EV_BUS_ERROR);
	assert_int_equal(rx.value, PS_DALI_BUS_SEND_COLLISION);
	/* another master's broadcast OFF (FF 00), seen on the bus */
	rx = dec(&ps_dali_atx, "hFF00\n", 6);
	assert_int_equal(rx.event, PS_DALI_EV_OBSERVED);
	assert_int_equal(rx.value, 0xFF00);
	assert_int_equal(rx.bits, 16);
	rx = dec(&ps_dali_atx, "\n", 1);
	assert_int_equal(rx.event, PS_DALI_EV_IGNORE);
	/* two messages in one read: the first only */
	assert_int_equal(ps_dali_atx.decode((const uint8_t *)two, strlen(two), &rx), 2);
	assert_int_equal(rx.event, PS_DALI_EV_NO_ANSWER);
	/* incomplete: wait */
	assert_int_equal(ps_dali_atx.decode((const uint8_t *)"J7", 2, &rx), 0);
	/* broken */
	rx = dec(&ps_dali_atx, "JZZ\n", 4);
	assert_int_equal(rx.event, PS_DALI_EV_MALFORMED);
	rx = dec(&ps_dali_atx, "J123\n", 5);
	assert_int_equal(rx.event, PS_DALI_EV_MALFORMED);
	rx = dec(&ps_dali_atx, "Q\n", 2);
	assert_int_equal(rx.event, PS_DALI_EV_MALFORMED);
	assert_true(strstr(rx.why, "none of") != NULL);
	memset(longline, 'J', 40);
	longline[40] = 0;
	rx = dec(&ps_dali_atx, longline, 32);
	assert_int_equal(rx.event, PS_DALI_EV_MALFORMED);
}

static void foxtron_encode(void **state)
{
	uint8_t small[8];
	struct ps_dali_frame f = fr(16, 0x0390, 0);
	(void)state;
	/* the vendor's example: QUERY STATUS (0x90) to short address 1 (03 90):
	 * 0B 00 10 03 90 00, sum 0xAE, checksum ~0xAE = 0x51 */
	expect_encoding(&ps_dali_foxtron, fr(16, 0x0390, 0), "\x01" "0B001003900051" "\x17");
	/* RESET to short 1 sent twice: param bit 0; 0B 00 10 03 20 01, sum 0x3F, checksum 0xC0 */
	expect_encoding(&ps_dali_foxtron, fr(16, 0x0320, 1), "\x01" "0B0010032001C0" "\x17");
	/* a 24-bit frame: 0B 00 18 A1 E0 02 00, sum 0x1A6, checksum ~0xA6 = 0x59 */
	expect_encoding(&ps_dali_foxtron, fr(24, 0xA1E002, 0), "\x01" "0B0018A1E0020059" "\x17");
	/* 8-bit: 0B 00 08 FF 00, sum 0x112, checksum ~0x12 = 0xED */
	expect_encoding(&ps_dali_foxtron, fr(8, 0xFF, 0), "\x01" "0B0008FF00ED" "\x17");
	assert_int_equal(ps_dali_foxtron.encode(small, sizeof small, &f), -1);
}

static void foxtron_decode(void **state)
{
	struct ps_dali_frame_rx rx;
	(void)state;
	/* an answer 0x7F to 03 90: 0D 10 08 03 90 7F, sum 0x137, checksum ~0x37 = 0xC8 */
	rx = dec(&ps_dali_foxtron, "\x01" "0D100803907FC8" "\x17", 16);
	assert_int_equal(rx.event, PS_DALI_EV_ANSWER);
	assert_int_equal(rx.value, 0x7F);
	/* no answer: 0E 10 03 90, sum 0xB1, checksum 0x4E */
	rx = dec(&ps_dali_foxtron, "\x01" "0E1003904E" "\x17", 12);
	assert_int_equal(rx.event, PS_DALI_EV_NO_ANSWER);
	assert_int_equal(rx.value, 0x0390);
	/* answer length 0: a collision of answers; 0D 10 00 03 90, sum 0xB0, checksum 0x4F */
	rx = dec(&ps_dali_foxtron, "\x01" "0D100003904F" "\x17", 14);
	assert_int_equal(rx.event, PS_DALI_EV_BUS_ERROR);
	assert_int_equal(rx.value, PS_DALI_BUS_FRAMING);
	/* bus power lost (05 01, checksum 0xF9) and back (05 00, checksum 0xFA) */
	rx = dec(&ps_dali_foxtron, "\x01" "0501F9" "\x17", 8);
	assert_int_equal(rx.event, PS_DALI_EV_POWER);
	assert_int_equal(rx.value, 0);
	rx = dec(&ps_dali_foxtron, "\x01" "0500FA" "\x17", 8);
	assert_int_equal(rx.event, PS_DALI_EV_POWER);
	assert_int_equal(rx.value, 1);
	/* the converter saw a bad checksum in our message: 05 05, checksum 0xF5 */
	rx = dec(&ps_dali_foxtron, "\x01" "0505F5" "\x17", 8);
	assert_int_equal(rx.event, PS_DALI_EV_BUS_ERROR);
	assert_int_equal(rx.value, PS_DALI_BUS_CHECKSUM);
	/* another master's broadcast OFF: 04 10 FF 00, sum 0x113, checksum 0xEC */
	rx = dec(&ps_dali_foxtron, "\x01" "0410FF00EC" "\x17", 12);
	assert_int_equal(rx.event, PS_DALI_EV_OBSERVED);
	assert_int_equal(rx.value, 0xFF00);
	assert_int_equal(rx.bits, 16);
	/* a 24-bit input notification: 04 18 A1 E0 02, sum 0x19F, checksum 0x60 */
	rx = dec(&ps_dali_foxtron, "\x01" "0418A1E00260" "\x17", 14);
	assert_int_equal(rx.event, PS_DALI_EV_OBSERVED);
	assert_int_equal(rx.value, 0xA1E002);
	assert_int_equal(rx.bits, 24);
	/* a framing error of another master's frame: 04 00, checksum 0xFB */
	rx = dec(&ps_dali_foxtron, "\x01" "0400FB" "\x17", 8);
	assert_int_equal(rx.event, PS_DALI_EV_OBSERVED);
	assert_int_equal(rx.bits, 0);
	/* firmware version 4.6 (07 02 04 06, sum 0x13, checksum 0xEC) */
	rx = dec(&ps_dali_foxtron, "\x01" "07020406EC" "\x17", 12);
	assert_int_equal(rx.event, PS_DALI_EV_INFO);
	assert_int_equal(rx.value, 0x0406);
	/* broken: a wrong checksum, bad hex, odd digits, bytes outside, cut short, too long */
	rx = dec(&ps_dali_foxtron, "\x01" "0E1003904F" "\x17", 12);
	assert_int_equal(rx.event, PS_DALI_EV_MALFORMED);
	assert_true(strstr(rx.why, "checksum") != NULL);
	rx = dec(&ps_dali_foxtron, "\x01" "0E10G3904E" "\x17", 12);
	assert_int_equal(rx.event, PS_DALI_EV_MALFORMED);
	rx = dec(&ps_dali_foxtron, "\x01" "0E1003904" "\x17", 11);
	assert_int_equal(rx.event, PS_DALI_EV_MALFORMED);
	rx = dec(&ps_dali_foxtron, "zz\x01", 2);
	assert_int_equal(rx.event, PS_DALI_EV_MALFORMED);
	assert_true(strstr(rx.why, "outside") != NULL);
	rx = dec(&ps_dali_foxtron, "\x01" "0E10" "\x01" "0E1003904E" "\x17", 5);
	assert_int_equal(rx.event, PS_DALI_EV_MALFORMED);
	assert_true(strstr(rx.why, "cut short") != NULL);
	assert_int_equal(ps_dali_foxtron.decode((const uint8_t *)"\x01" "0E10", 5, &rx), 0);
	{
		char big[80];
		big[0] = 0x01;
		memset(big + 1, '0', 78);
		big[79] = 0;
		rx = dec(&ps_dali_foxtron, big, 64);
		assert_int_equal(rx.event, PS_DALI_EV_MALFORMED);
	}
	/* an unknown type with a right checksum: 42 00, checksum 0xBD */
	rx = dec(&ps_dali_foxtron, "\x01" "4200BD" "\x17", 8);
	assert_int_equal(rx.event, PS_DALI_EV_MALFORMED);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(frame_helpers),
		cmocka_unit_test(atx_encode),
		cmocka_unit_test(atx_decode),
		cmocka_unit_test(foxtron_encode),
		cmocka_unit_test(foxtron_decode),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
