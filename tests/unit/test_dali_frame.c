/* SPDX-License-Identifier: ISC */
/* The serial DALI codecs (drivers/dali_atx.c, dali_foxtron.c, dali_luba.c)
 * and the frame layer's helpers, against byte strings written from the
 * interfaces' published protocol descriptions (doc/hardware.md sections 5
 * to 7): the
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
#include "dali_luba.h"

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

/* binary: decode n bytes */
static struct ps_dali_frame_rx decb(const uint8_t *b, size_t n, size_t want_used)
{
	struct ps_dali_frame_rx rx;
	assert_int_equal(ps_dali_luba.decode(b, n, &rx), want_used);
	return rx;
}

static void luba_encode(void **state)
{
	uint8_t out[16];
	struct ps_dali_frame f;
	/* QUERY ACTUAL LEVEL of short 1 (03 A0), priority 5: checksum = 32^07^00^10^05^03^A0^00^00 = 0x83 */
	static const uint8_t q[] = { 0x59, 0x32, 0x07, 0x00, 0x10, 0x05, 0x03, 0xA0, 0x00, 0x00, 0x83 };
	/* DAPC short 1 level 200 (02 C8), priority 2: checksum 0xED */
	static const uint8_t dapc[] = { 0x59, 0x32, 0x07, 0x00, 0x10, 0x02, 0x02, 0xC8, 0x00, 0x00, 0xED };
	/* RESET to short 1 sent twice (mode 0x85): checksum 0x83 */
	static const uint8_t twice[] = { 0x59, 0x32, 0x07, 0x00, 0x10, 0x85, 0x03, 0x20, 0x00, 0x00, 0x83 };
	/* a 24-bit frame A1 E0 02: checksum 0x6C */
	static const uint8_t f24[] = { 0x59, 0x32, 0x07, 0x00, 0x18, 0x02, 0xA1, 0xE0, 0x02, 0x00, 0x6C };
	(void)state;
	f = (struct ps_dali_frame){ .bits = 16, .data = 0x03A0, .expect_answer = 1 };
	assert_int_equal(ps_dali_luba.encode(out, sizeof out, &f), 11);
	assert_memory_equal(out, q, 11);
	f = fr(16, 0x02C8, 0);
	assert_int_equal(ps_dali_luba.encode(out, sizeof out, &f), 11);
	assert_memory_equal(out, dapc, 11);
	f = fr(16, 0x0320, 1);
	assert_int_equal(ps_dali_luba.encode(out, sizeof out, &f), 11);
	assert_memory_equal(out, twice, 11);
	f = fr(24, 0xA1E002, 0);
	assert_int_equal(ps_dali_luba.encode(out, sizeof out, &f), 11);
	assert_memory_equal(out, f24, 11);
	f = fr(8, 0xFF, 0);
	assert_int_equal(ps_dali_luba.encode(out, sizeof out, &f), -1);
	assert_true(ps_dali_luba.answer_window > 0);
}

static void luba_decode(void **state)
{
	struct ps_dali_frame_rx rx;
	/* queued (id 7): 33^02^07^00 = 0x36 */
	static const uint8_t acc[] = { 0x59, 0x33, 0x02, 0x07, 0x00, 0x36 };
	/* refused (error 5): 33^01^05 = 0x37 */
	static const uint8_t ref[] = { 0x59, 0x33, 0x01, 0x05, 0x37 };
	/* sent: tick 00 10, line 0, status type 0, id 7, frame 03 A0: checksum 0x82 */
	static const uint8_t sent[] = { 0x59, 0x31, 0x07, 0x00, 0x10, 0x00, 0x00, 0x07, 0x03, 0xA0, 0x82 };
	/* seen: type 2, 8 bits (0x88), the backward frame C8: checksum 0x66 */
	static const uint8_t ans[] = { 0x59, 0x31, 0x05, 0x00, 0x12, 0x00, 0x88, 0xC8, 0x66 };
	/* seen: type 2, framing error (0xBF): checksum 0x99 */
	static const uint8_t fe[] = { 0x59, 0x31, 0x04, 0x00, 0x13, 0x00, 0xBF, 0x99 };
	/* seen: type 2, 16 bits (0x90), another master's FF 00: checksum 0x4C */
	static const uint8_t obs[] = { 0x59, 0x31, 0x06, 0x00, 0x14, 0x00, 0x90, 0xFF, 0x00, 0x4C };
	static const uint8_t badck[] = { 0x59, 0x31, 0x05, 0x00, 0x12, 0x00, 0x88, 0xC8, 0x67 };
	static const uint8_t zero[] = { 0x59, 0x31, 0x00, 0x31 };
	(void)state;
	rx = decb(acc, sizeof acc, 6);
	assert_int_equal(rx.event, PS_DALI_EV_IGNORE);
	rx = decb(ref, sizeof ref, 5);
	assert_int_equal(rx.event, PS_DALI_EV_BUS_ERROR);
	assert_int_equal(rx.value, PS_DALI_BUS_REJECTED);
	rx = decb(sent, sizeof sent, 11);
	assert_int_equal(rx.event, PS_DALI_EV_ECHO);
	assert_int_equal(rx.value, 0x03A0);
	rx = decb(ans, sizeof ans, 9);
	assert_int_equal(rx.event, PS_DALI_EV_ANSWER);
	assert_int_equal(rx.value, 0xC8);
	rx = decb(fe, sizeof fe, 8);
	assert_int_equal(rx.event, PS_DALI_EV_BUS_ERROR);
	assert_int_equal(rx.value, PS_DALI_BUS_FRAMING);
	rx = decb(obs, sizeof obs, 10);
	assert_int_equal(rx.event, PS_DALI_EV_OBSERVED);
	assert_int_equal(rx.value, 0xFF00);
	assert_int_equal(rx.bits, 16);
	rx = decb(badck, sizeof badck, 9);
	assert_int_equal(rx.event, PS_DALI_EV_MALFORMED);
	assert_true(strstr(rx.why, "checksum") != NULL);
	rx = decb(zero, sizeof zero, 1);
	assert_int_equal(rx.event, PS_DALI_EV_MALFORMED);
	rx = decb((const uint8_t *)"zzY", 3, 2);
	assert_int_equal(rx.event, PS_DALI_EV_MALFORMED);
	assert_int_equal(ps_dali_luba.decode(ans, 8, &rx), 0);
	assert_int_equal(ps_dali_luba.decode(ans, 2, &rx), 0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(frame_helpers),
		cmocka_unit_test(atx_encode),
		cmocka_unit_test(atx_decode),
		cmocka_unit_test(foxtron_encode),
		cmocka_unit_test(foxtron_decode),
		cmocka_unit_test(luba_encode),
		cmocka_unit_test(luba_decode),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
