/* SPDX-License-Identifier: ISC */
/* The hasseb DALI Master's codec (drivers/usb_hasseb.c) against reports
 * written from the firmware's published protocol (doc/hardware.md section
 * 1.2): 10 bytes starting 0xAA; a send report with the answer flag set for
 * queries (also to unaddressed gear) and COMPARE, the send-twice delay, no DTR0 prefix; transmission
 * reports for each status, the sequence number rule, and broken reports. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

#ifdef PS_WITH_USB
#include "usb_hasseb.h"

static void encode(void **state)
{
	uint8_t out[64];
	/* QUERY ACTUAL LEVEL of short 5 (0B A0), sequence 0x2A: an answer may come */
	static const uint8_t q[10] = { 0xAA, 0x07, 0x2A, 16, 1, 0, 0, 0x0B, 0xA0, 0 };
	/* DAPC short 5 level 200 (0A C8): no answer */
	static const uint8_t dapc[10] = { 0xAA, 0x07, 0x01, 16, 0, 0, 0, 0x0A, 0xC8, 0 };
	/* RESET to short 5 (0B 20) sent twice, 10 ms apart */
	static const uint8_t twice[10] = { 0xAA, 0x07, 0x02, 16, 0, 0, 10, 0x0B, 0x20, 0 };
	/* COMPARE (A9 00): a special command that answers */
	static const uint8_t cmp[10] = { 0xAA, 0x07, 0x03, 16, 1, 0, 0, 0xA9, 0x00, 0 };
	(void)state;
	assert_int_equal(ps_usb_hasseb.encode_send(out, sizeof out, 0x2A, 0x0BA0, 0, -1), 10);
	assert_memory_equal(out, q, 10);
	assert_int_equal(ps_usb_hasseb.encode_send(out, sizeof out, 1, 0x0AC8, 0, -1), 10);
	assert_memory_equal(out, dapc, 10);
	assert_int_equal(ps_usb_hasseb.encode_send(out, sizeof out, 2, 0x0B20, 1, -1), 10);
	assert_memory_equal(out, twice, 10);
	assert_int_equal(ps_usb_hasseb.encode_send(out, sizeof out, 3, 0xA900, 0, -1), 10);
	assert_memory_equal(out, cmp, 10);
	/* QUERY CONTROL GEAR PRESENT to unaddressed gear (FD 91): an answer may come */
	assert_int_equal(ps_usb_hasseb.encode_send(out, sizeof out, 4, 0xFD91, 0, -1), 10);
	assert_int_equal(out[4], 1);
	/* OFF to unaddressed gear (FD 00): none */
	assert_int_equal(ps_usb_hasseb.encode_send(out, sizeof out, 4, 0xFD00, 0, -1), 10);
	assert_int_equal(out[4], 0);
	/* no DTR0 prefix, no sequence number 0, no room */
	assert_int_equal(ps_usb_hasseb.encode_send(out, sizeof out, 4, 0x0B2C, 1, 170), -1);
	assert_int_equal(ps_usb_hasseb.encode_send(out, sizeof out, 0, 0x0BA0, 0, -1), -1);
	assert_int_equal(ps_usb_hasseb.encode_send(out, 9, 4, 0x0BA0, 0, -1), -1);
	/* read firmware version (02), sequence 5: AA 02 05 then zeros */
	static const uint8_t ver[10] = { 0xAA, 0x02, 0x05, 0, 0, 0, 0, 0, 0, 0 };
	memset(out, 0x77, sizeof out);
	assert_int_equal(ps_usb_hasseb.encode_version(out, sizeof out, 5), 10);
	assert_memory_equal(out, ver, 10);
	assert_int_equal(ps_usb_hasseb.encode_version(out, sizeof out, 0), -1);
	assert_int_equal(ps_usb_hasseb.encode_version(out, 9, 5), -1);
	assert_int_equal(ps_usb_hasseb.vid, 0x04CC);
	assert_int_equal(ps_usb_hasseb.pid, 0x0802);
}

static struct ps_dali_reply dec(const uint8_t *b, size_t n)
{
	struct ps_dali_reply r;
	ps_usb_hasseb.decode(b, n, &r);
	return r;
}

static void decode(void **state)
{
	static const uint8_t none[10] = { 0xAA, 0x07, 0x2A, 1, 0, 0, 0, 0, 0, 0 };
	static const uint8_t ans[10] = { 0xAA, 0x07, 0x2A, 2, 1, 0xC8, 0, 0, 0, 0 };
	static const uint8_t garbled[10] = { 0xAA, 0x07, 0x2B, 3, 0, 0, 0, 0, 0, 0 };
	static const uint8_t early[10] = { 0xAA, 0x07, 0x2C, 4, 0, 0, 0, 0, 0, 0 };
	static const uint8_t idle[10] = { 0xAA, 0x00, 0, 0, 0, 0, 0, 0, 0, 0 };
	static const uint8_t ver[10] = { 0xAA, 0x02, 0x05, 2, 5, 0, 0, 0, 0, 0 };
	static const uint8_t seq0[10] = { 0xAA, 0x07, 0x00, 2, 1, 0xC8, 0, 0, 0, 0 };
	static const uint8_t nopre[10] = { 0x55, 0x07, 0x2A, 2, 1, 0xC8, 0, 0, 0, 0 };
	static const uint8_t badst[10] = { 0xAA, 0x07, 0x2A, 9, 0, 0, 0, 0, 0, 0 };
	uint8_t padded[64] = { 0 };
	struct ps_dali_reply r;
	(void)state;
	r = dec(none, 10);
	assert_int_equal(r.event, PS_DALI_EV_NO_ANSWER);
	assert_int_equal(r.seq, 0x2A);
	r = dec(ans, 10);
	assert_int_equal(r.event, PS_DALI_EV_ANSWER);
	assert_int_equal(r.value, 0xC8);
	/* the device's 10 bytes in a 64-byte transfer */
	memcpy(padded, ans, 10);
	r = dec(padded, sizeof padded);
	assert_int_equal(r.event, PS_DALI_EV_ANSWER);
	r = dec(garbled, 10);
	assert_int_equal(r.event, PS_DALI_EV_BUS_ERROR);
	assert_int_equal(r.value, PS_DALI_BUS_FRAMING);
	assert_int_equal(r.seq, 0x2B);
	/* an answer too early is not a garbled one: nothing says several answered */
	r = dec(early, 10);
	assert_int_equal(r.event, PS_DALI_EV_BUS_ERROR);
	assert_int_equal(r.value, PS_DALI_BUS_EARLY);
	assert_int_equal(r.seq, 0x2C);
	r = dec(idle, 10);
	assert_int_equal(r.event, PS_DALI_EV_IGNORE);
	r = dec(ver, 10);
	assert_int_equal(r.event, PS_DALI_EV_INFO);
	assert_int_equal(r.value, 0x0205);
	r = dec(seq0, 10);
	assert_int_equal(r.event, PS_DALI_EV_MALFORMED);
	r = dec(nopre, 10);
	assert_int_equal(r.event, PS_DALI_EV_MALFORMED);
	r = dec(badst, 10);
	assert_int_equal(r.event, PS_DALI_EV_MALFORMED);
	r = dec(ans, 9);
	assert_int_equal(r.event, PS_DALI_EV_MALFORMED);
	assert_int_equal(ps_usb_hasseb.next_seq(255), 1);
	assert_int_equal(ps_usb_hasseb.next_seq(7), 8);
	assert_int_equal(ps_usb_hasseb.next_seq(0), 1);
}
#else
static void encode(void **state)
{
	(void)state;
	skip();
}
static void decode(void **state)
{
	(void)state;
	skip();
}
#endif

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(encode),
		cmocka_unit_test(decode),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
