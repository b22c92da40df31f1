/* SPDX-License-Identifier: ISC */
/* Modbus TCP and RTU framing (daemon/psvirt/mbframe.c): the MBAP header of Modbus
 * Messaging on TCP/IP v1.0b (3.1.3) and the RTU frame of Modbus over Serial
 * Line v1.02 (2.5.1), against their examples: the CRC of 02 07 is 0x1241
 * (appendix B), the read of 10 registers from unit 1 ends C5 CD. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

#include "mbframe.h"

static int tcp(const uint8_t *b, size_t n, struct psd_mbadu *adu)
{
	const char *why = NULL;
	int rc = psd_mbframe_tcp(b, n, adu, &why);
	if (rc < 0)
		assert_non_null(why);
	return rc;
}

static void mbap_takes_a_whole_frame_only(void **state)
{
	/* transaction 1, protocol 0, length 6, unit 0x11, read 3 from 0x6B */
	static const uint8_t f[] = { 0x00, 0x01, 0x00, 0x00, 0x00, 0x06, 0x11, 0x03, 0x00, 0x6b, 0x00, 0x03 };
	struct psd_mbadu adu;
	(void)state;
	for (size_t n = 0; n < sizeof f; n++)
		assert_int_equal(tcp(f, n, &adu), 0);
	assert_int_equal(tcp(f, sizeof f, &adu), 12);
	assert_int_equal(adu.tid, 1);
	assert_int_equal(adu.unit, 0x11);
	assert_int_equal(adu.npdu, 5);
	assert_ptr_equal(adu.pdu, f + 7);
}

static void mbap_two_frames_in_one_buffer(void **state)
{
	static const uint8_t f[] = { 0x12, 0x34, 0, 0, 0, 2, 1, 0x07, 0x12, 0x35, 0, 0, 0, 6, 1, 3, 0, 0, 0, 1 };
	struct psd_mbadu adu;
	(void)state;
	assert_int_equal(tcp(f, sizeof f, &adu), 8);
	assert_int_equal(adu.tid, 0x1234);
	assert_int_equal(adu.npdu, 1);   /* function 07: the MBAP length says */
	assert_int_equal(tcp(f + 8, sizeof f - 8, &adu), 12);
	assert_int_equal(adu.tid, 0x1235);
}

static void mbap_refuses_what_is_not_modbus(void **state)
{
	static const uint8_t proto[] = { 0, 1, 0, 1, 0, 6, 1, 3, 0, 0, 0, 1 };
	static const uint8_t len1[] = { 0, 1, 0, 0, 0, 1, 1 };
	static const uint8_t len255[] = { 0, 1, 0, 0, 0, 255, 1, 3 };
	static const uint8_t longer[] = { 0, 1, 0, 0, 0, 8, 1, 3, 0, 0, 0, 1, 0, 0 };
	static const uint8_t shorter[] = { 0, 1, 0, 0, 0, 4, 1, 3, 0, 0, 0, 1 };
	static const uint8_t bytecount[] = { 0, 1, 0, 0, 0, 9, 1, 0x10, 0, 0, 0, 1, 4, 0, 1 };
	struct psd_mbadu adu;
	(void)state;
	assert_int_equal(tcp(proto, 7, &adu), -1);   /* known from the header alone */
	assert_int_equal(tcp(len1, sizeof len1, &adu), -1);
	assert_int_equal(tcp(len255, 7, &adu), -1);
	/* the function's own length disagrees as soon as its first byte is in */
	assert_int_equal(tcp(longer, 7, &adu), 0);
	assert_int_equal(tcp(longer, 8, &adu), -1);
	/* length 4: a 3-byte PDU, too short for function 03 */
	assert_int_equal(tcp(shorter, 7, &adu), 0);
	assert_int_equal(tcp(shorter, 8, &adu), -1);
	/* 0x10 with a byte count of 4 is 10 bytes of PDU, not 8 */
	assert_int_equal(tcp(bytecount, 12, &adu), 0);
	assert_int_equal(tcp(bytecount, 13, &adu), -1);
}

static void mbap_reply(void **state)
{
	static const uint8_t pdu[] = { 0x03, 0x02, 0x01, 0x02 };
	static const uint8_t want[] = { 0xab, 0xcd, 0, 0, 0, 5, 9, 0x03, 0x02, 0x01, 0x02 };
	struct psd_mbadu req = { 0xabcd, 9, NULL, 0 };
	uint8_t out[PSD_MBFRAME_TCP_MAX];
	(void)state;
	assert_int_equal(psd_mbframe_tcp_put(&req, pdu, sizeof pdu, out), sizeof want);
	assert_memory_equal(out, want, sizeof want);
}

static void crc_spec_examples(void **state)
{
	static const uint8_t a[] = { 0x02, 0x07 };
	static const uint8_t b[] = { 0x01, 0x03, 0x00, 0x00, 0x00, 0x0a };
	(void)state;
	assert_int_equal(psd_mbframe_crc(a, sizeof a), 0x1241);
	assert_int_equal(psd_mbframe_crc(b, sizeof b), 0xcdc5);   /* sent C5 CD */
}

static void rtu_frames(void **state)
{
	static const uint8_t good[] = { 0x01, 0x03, 0x00, 0x00, 0x00, 0x0a, 0xc5, 0xcd };
	static const uint8_t bad[] = { 0x01, 0x03, 0x00, 0x00, 0x00, 0x0a, 0xc5, 0xce };
	static const uint8_t fc07[] = { 0x02, 0x07, 0x41, 0x12 };
	uint8_t two[16];
	struct psd_mbadu adu;
	const char *why = NULL;
	(void)state;
	/* a known function, whole, with a good CRC: at once */
	for (size_t n = 0; n < sizeof good; n++)
		assert_int_equal(psd_mbframe_rtu(good, n, 0, &adu, &why), 0);
	assert_int_equal(psd_mbframe_rtu(good, sizeof good, 0, &adu, &why), 8);
	assert_int_equal(adu.unit, 1);
	assert_int_equal(adu.npdu, 5);
	/* a served function cut short waits for the rest, silence or not (the
	 * caller's frame timeout bounds it); a bad CRC drops the first byte */
	assert_int_equal(psd_mbframe_rtu(good, 5, 1, &adu, &why), 0);
	assert_int_equal(psd_mbframe_rtu(bad, sizeof bad, 0, &adu, &why), -1);
	assert_string_equal(why, "bad CRC");
	/* function 07 is not served, so its length is the silence's */
	assert_int_equal(psd_mbframe_rtu(fc07, sizeof fc07, 0, &adu, &why), 0);
	assert_int_equal(psd_mbframe_rtu(fc07, sizeof fc07, 1, &adu, &why), 4);
	assert_int_equal(adu.npdu, 1);
	/* a frame, then the start of the next */
	memcpy(two, good, sizeof good);
	memcpy(two + sizeof good, good, 3);
	assert_int_equal(psd_mbframe_rtu(two, sizeof good + 3, 0, &adu, &why), 8);
}

/* Noise, then a frame: dropping a byte at a time finds the frame. */
static void rtu_resynchronises(void **state)
{
	static const uint8_t good[] = { 0x01, 0x03, 0x00, 0x00, 0x00, 0x0a, 0xc5, 0xcd };
	uint8_t b[16] = { 0x01, 0x03, 0x00 };   /* a frame cut short */
	struct psd_mbadu adu;
	const char *why = NULL;
	size_t at = 0, n = 3 + sizeof good;
	int rc;
	(void)state;
	memcpy(b + 3, good, sizeof good);
	while ((rc = psd_mbframe_rtu(b + at, n - at, 1, &adu, &why)) < 0)
		at++;
	assert_int_equal(at, 3);
	assert_int_equal(rc, 8);
	assert_int_equal(adu.unit, 1);
}

static void rtu_unknown_function_ends_at_the_silence(void **state)
{
	uint8_t f[8] = { 0x05, 0x41, 0xaa, 0xbb };
	struct psd_mbadu adu;
	const char *why = NULL;
	uint16_t crc = psd_mbframe_crc(f, 4);
	(void)state;
	f[4] = (uint8_t)(crc & 0xff);
	f[5] = (uint8_t)(crc >> 8);
	assert_int_equal(psd_mbframe_rtu(f, 6, 0, &adu, &why), 0);
	assert_int_equal(psd_mbframe_rtu(f, 6, 1, &adu, &why), 6);
	assert_int_equal(adu.npdu, 3);
	assert_int_equal(adu.pdu[0], 0x41);
}

static void rtu_reply_and_silence(void **state)
{
	static const uint8_t pdu[] = { 0x07 };
	uint8_t out[PSD_MBFRAME_RTU_MAX];
	(void)state;
	assert_int_equal(psd_mbframe_rtu_put(2, pdu, 1, out), 4);
	assert_int_equal(out[2], 0x41);
	assert_int_equal(out[3], 0x12);
	/* 3.5 characters of 11 bits; 1.75 ms above 19200 baud */
	assert_float_equal(psd_mbframe_rtu_silence(9600), 38.5 / 9600, 1e-12);
	assert_float_equal(psd_mbframe_rtu_silence(19200), 38.5 / 19200, 1e-12);
	assert_float_equal(psd_mbframe_rtu_silence(38400), 1.75e-3, 1e-12);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(mbap_takes_a_whole_frame_only),
		cmocka_unit_test(mbap_two_frames_in_one_buffer),
		cmocka_unit_test(mbap_refuses_what_is_not_modbus),
		cmocka_unit_test(mbap_reply),
		cmocka_unit_test(crc_spec_examples),
		cmocka_unit_test(rtu_frames),
		cmocka_unit_test(rtu_resynchronises),
		cmocka_unit_test(rtu_unknown_function_ends_at_the_silence),
		cmocka_unit_test(rtu_reply_and_silence),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
