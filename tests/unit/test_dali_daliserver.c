/* SPDX-License-Identifier: ISC */
/* The daliserver codec (drivers/dali_daliserver.c) against 4-byte messages
 * written by hand from the protocol's published description (daliserver's
 * README, "Communication protocol"; doc/hardware.md section 9): version 2,
 * request type 0 with the frame's address and data bytes; replies with
 * status 0 (no answer), 1 (the answer in the third byte), 2 (another frame
 * seen on the bus), 255 (a transfer error).  Also what the protocol cannot
 * carry (8- and 24-bit frames, send-twice) and the broken replies: a wrong
 * version, an unknown status, a non-zero padding byte, a message cut short. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

#include "dali_daliserver.h"

static const struct ps_dali_codec *const C = &ps_dali_daliserver;

static void expect_request(int bits, uint32_t data, int twice, int want_len, const uint8_t *want)
{
	struct ps_dali_frame f = { .bits = bits, .data = data, .twice = twice };
	uint8_t out[16];
	memset(out, 0xAA, sizeof out);
	assert_int_equal(C->encode(out, sizeof out, &f), want_len);
	if (want_len > 0)
		assert_memory_equal(out, want, (size_t)want_len);
}

static void encode(void **state)
{
	(void)state;
	/* DAPC 200 to short address 1: address byte 0AAAAAA0 = 0x02 */
	expect_request(16, 0x02C8, 0, 4, (const uint8_t[]){ 2, 0, 0x02, 0xC8 });
	/* QUERY ACTUAL LEVEL (0xA0) to short address 3: 0x07 */
	expect_request(16, 0x07A0, 0, 4, (const uint8_t[]){ 2, 0, 0x07, 0xA0 });
	/* broadcast OFF, as the README's alloff example sends it */
	expect_request(16, 0xFF00, 0, 4, (const uint8_t[]){ 2, 0, 0xFF, 0x00 });
	/* no 24-bit (control device), 8-bit or send-twice form */
	expect_request(24, 0xC1E100, 0, -1, NULL);
	expect_request(8, 0x5A, 0, -1, NULL);
	expect_request(16, 0xFF20, 1, -1, NULL);
	/* not a frame at all, and too little room */
	expect_request(16, 0x10000, 0, -1, NULL);
	struct ps_dali_frame f = { .bits = 16, .data = 0x02C8 };
	uint8_t out[3];
	assert_int_equal(C->encode(out, sizeof out, &f), -1);
	assert_int_equal(C->max_msg, 4);
	assert_true(C->answer_window == 0);   /* the server says "no answer" itself */
}

static struct ps_dali_frame_rx dec(const uint8_t *b, size_t n, size_t want_used)
{
	struct ps_dali_frame_rx rx;
	memset(&rx, 0x55, sizeof rx);
	assert_int_equal(C->decode(b, n, &rx), want_used);
	return rx;
}

static void decode(void **state)
{
	struct ps_dali_frame_rx rx;
	(void)state;
	rx = dec((const uint8_t[]){ 2, 1, 0xFE, 0 }, 4, 4);
	assert_int_equal(rx.event, PS_DALI_EV_ANSWER);
	assert_int_equal(rx.value, 254);
	rx = dec((const uint8_t[]){ 2, 1, 0x00, 0 }, 4, 4);   /* an answer of 0 is still an answer */
	assert_int_equal(rx.event, PS_DALI_EV_ANSWER);
	assert_int_equal(rx.value, 0);
	rx = dec((const uint8_t[]){ 2, 0, 0, 0 }, 4, 4);
	assert_int_equal(rx.event, PS_DALI_EV_NO_ANSWER);
	rx = dec((const uint8_t[]){ 2, 255, 0, 0 }, 4, 4);
	assert_int_equal(rx.event, PS_DALI_EV_BUS_ERROR);
	assert_int_equal(rx.value, PS_DALI_BUS_REJECTED);
	assert_non_null(strstr(rx.why, "daliserver"));
	/* another frame on the bus: broadcast RECALL MAX LEVEL (0xFF05) */
	rx = dec((const uint8_t[]){ 2, 2, 0xFF, 0x05 }, 4, 4);
	assert_int_equal(rx.event, PS_DALI_EV_OBSERVED);
	assert_int_equal(rx.value, 0xFF05);
	assert_int_equal(rx.bits, 16);
	/* a message is taken off a longer stream, 4 bytes at a time */
	rx = dec((const uint8_t[]){ 2, 0, 0, 0, 2, 1, 7, 0 }, 8, 4);
	assert_int_equal(rx.event, PS_DALI_EV_NO_ANSWER);
}

static void broken(void **state)
{
	struct ps_dali_frame_rx rx;
	(void)state;
	/* fewer than 4 bytes: wait for the rest */
	dec((const uint8_t[]){ 2, 1, 0xFE }, 3, 0);
	dec((const uint8_t[]){ 2 }, 1, 0);
	dec(NULL, 0, 0);
	rx = dec((const uint8_t[]){ 1, 1, 0xFE, 0 }, 4, 4);
	assert_int_equal(rx.event, PS_DALI_EV_MALFORMED);
	assert_non_null(strstr(rx.why, "version 1"));
	rx = dec((const uint8_t[]){ 2, 7, 0x10, 0 }, 4, 4);
	assert_int_equal(rx.event, PS_DALI_EV_MALFORMED);
	assert_non_null(strstr(rx.why, "status 7"));
	rx = dec((const uint8_t[]){ 2, 1, 0x10, 0x05 }, 4, 4);
	assert_int_equal(rx.event, PS_DALI_EV_MALFORMED);
	assert_non_null(strstr(rx.why, "05"));
	assert_non_null(memchr(rx.why, 0, sizeof rx.why));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(encode),
		cmocka_unit_test(decode),
		cmocka_unit_test(broken),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
