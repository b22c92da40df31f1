/* SPDX-License-Identifier: ISC */
/* The DALI-2 control-device codec (drivers/dali_device.c) against frames
 * written out by hand from IEC 62386-103's layout (address byte, instance
 * byte, opcode; special commands under 0xC1; events with bit 16 clear and
 * the source form in bits 23, 22 and 15), the 304/303 opcodes and timer
 * steps, and the input value's left-aligned bytes with the top bits
 * repeated below it (103, 9.7.2). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "dali_device.h"

static void special_commands(void **state)
{
	(void)state;
	assert_int_equal(ps_dali_device_special(PS_DALI_DEVICE_INITIALISE, PS_DALI_DEVICE_INIT_UNADDRESSED), 0xC1017F);
	assert_int_equal(ps_dali_device_special(PS_DALI_DEVICE_RANDOMISE, 0), 0xC10200);
	assert_int_equal(ps_dali_device_special(PS_DALI_DEVICE_COMPARE, 0), 0xC10300);
	assert_int_equal(ps_dali_device_special(PS_DALI_DEVICE_WITHDRAW, 0), 0xC10400);
	assert_int_equal(ps_dali_device_special(PS_DALI_DEVICE_SEARCHADDRH, 0x12), 0xC10512);
	assert_int_equal(ps_dali_device_special(PS_DALI_DEVICE_SEARCHADDRM, 0x34), 0xC10634);
	assert_int_equal(ps_dali_device_special(PS_DALI_DEVICE_SEARCHADDRL, 0x56), 0xC10756);
	assert_int_equal(ps_dali_device_special(PS_DALI_DEVICE_PROGRAM_SHORT_ADDRESS, 5), 0xC10805);
	assert_int_equal(ps_dali_device_special(PS_DALI_DEVICE_VERIFY_SHORT_ADDRESS, 5), 0xC10905);
	assert_int_equal(ps_dali_device_special(PS_DALI_DEVICE_QUERY_SHORT_ADDRESS, 0), 0xC10A00);
	assert_int_equal(ps_dali_device_special(PS_DALI_DEVICE_DTR0, 30), 0xC1301E);
	assert_int_equal(ps_dali_device_special(PS_DALI_DEVICE_TERMINATE, 256), -1);
	assert_int_equal(ps_dali_device_frame(0x0B, 0x01, 0x8C), 0x0B018C);
	assert_int_equal(ps_dali_device_frame(0x100, 0, 0), -1);
	/* INITIALISE and RANDOMISE twice; COMPARE, VERIFY, QUERY SHORT ADDRESS answer */
	assert_true(ps_dali_device_needs_twice(0xC1017F));
	assert_true(ps_dali_device_needs_twice(0xC10200));
	assert_false(ps_dali_device_needs_twice(0xC10300));
	assert_false(ps_dali_device_needs_twice(0xC10805));
	assert_true(ps_dali_device_expects_answer(0xC10300));
	assert_true(ps_dali_device_expects_answer(0xC10905));
	assert_true(ps_dali_device_expects_answer(0xC10A00));
	assert_false(ps_dali_device_expects_answer(0xC10512));
	assert_false(ps_dali_device_expects_answer(0xC1301E));
}

static void device_and_instance_commands(void **state)
{
	(void)state;
	/* device 5 = address byte 0000101 1 = 0x0B; the device itself = 0xFE */
	assert_int_equal(ps_dali_device_cmd(5, PS_DALI_DEVICE_QUERY_NUMBER_OF_INSTANCES), 0x0BFE35);
	assert_int_equal(ps_dali_device_cmd(63, PS_DALI_DEVICE_IDENTIFY), 0x7FFE00);
	assert_int_equal(ps_dali_device_cmd(-1, PS_DALI_DEVICE_QUERY_STATUS), 0xFFFE30);
	assert_int_equal(ps_dali_device_cmd(64, PS_DALI_DEVICE_QUERY_STATUS), -1);
	assert_int_equal(ps_dali_device_inst_cmd(5, 1, PS_DALI_DEVICE_QUERY_INPUT_VALUE), 0x0B018C);
	assert_int_equal(ps_dali_device_inst_cmd(5, 1, PS_DALI_DEVICE_QUERY_INPUT_VALUE_LATCH), 0x0B018D);
	assert_int_equal(ps_dali_device_inst_cmd(5, 0, PS_DALI_DEVICE_QUERY_INSTANCE_TYPE), 0x0B0080);
	assert_int_equal(ps_dali_device_inst_cmd(5, 1, PS_DALI_LIGHT_SET_REPORT_TIMER), 0x0B0130);
	assert_int_equal(ps_dali_device_inst_cmd(2, 0, PS_DALI_OCC_SET_HOLD_TIMER), 0x050021);
	assert_int_equal(ps_dali_device_inst_cmd(5, 32, PS_DALI_DEVICE_ENABLE_INSTANCE), -1);
	/* configuration twice, queries answer */
	assert_true(ps_dali_device_needs_twice(0x0BFE00));   /* IDENTIFY DEVICE */
	assert_true(ps_dali_device_needs_twice(0x0BFE14));   /* SET SHORT ADDRESS */
	assert_false(ps_dali_device_needs_twice(0x0BFE35));
	assert_true(ps_dali_device_needs_twice(0x0B0162));   /* ENABLE INSTANCE */
	assert_true(ps_dali_device_needs_twice(0x0B0167));   /* SET EVENT SCHEME */
	assert_true(ps_dali_device_needs_twice(0x0B0168));   /* SET EVENT FILTER */
	assert_true(ps_dali_device_needs_twice(0x0B0130));   /* 304 SET REPORT TIMER */
	assert_true(ps_dali_device_needs_twice(0x0B0133));   /* 304 SET HYSTERESIS MIN */
	assert_true(ps_dali_device_needs_twice(0x0B0022));   /* 303 SET REPORT TIMER */
	assert_false(ps_dali_device_needs_twice(0x0B018C));
	assert_true(ps_dali_device_expects_answer(0x0BFE35));
	assert_true(ps_dali_device_expects_answer(0x0B018C));
	assert_true(ps_dali_device_expects_answer(0x0B018D));
	assert_true(ps_dali_device_expects_answer(0x0B013E));  /* 304 QUERY REPORT TIMER */
	assert_true(ps_dali_device_expects_answer(0x0B002D));  /* 303 QUERY HOLD TIMER */
	assert_false(ps_dali_device_expects_answer(0x0B0162));
	/* an event frame (bit 16 clear) is neither */
	assert_false(ps_dali_device_expects_answer(0x0A1200));
	assert_false(ps_dali_device_needs_twice(0x0A1230));
}

static void events_in_every_scheme(void **state)
{
	struct ps_dali_device_event ev;
	(void)state;
	/* device scheme: 0 AAAAAA 0 | 0 TTTTT IIIIIIIIII: device 5, type 4, info 512 */
	assert_int_equal(ps_dali_device_event_decode(0x0A1200, &ev), 0);
	assert_int_equal(ev.scheme, PS_DALI_SCHEME_DEVICE);
	assert_int_equal(ev.address, 5);
	assert_int_equal(ev.instance_type, 4);
	assert_int_equal(ev.instance, -1);
	assert_int_equal(ev.info, 512);
	/* device/instance: bit 15 set, instance number 1, occupied + movement */
	assert_int_equal(ps_dali_device_event_decode(0x0A8403, &ev), 0);
	assert_int_equal(ev.scheme, PS_DALI_SCHEME_DEVICE_INSTANCE);
	assert_int_equal(ev.address, 5);
	assert_int_equal(ev.instance, 1);
	assert_int_equal(ev.instance_type, -1);
	assert_int_equal(ev.info, PS_DALI_OCC_EV_OCCUPIED | PS_DALI_OCC_EV_MOVEMENT);
	/* instance: 1 0 TTTTT 0 | 1 NNNNN info: type 3, number 0, info 2 */
	assert_int_equal(ps_dali_device_event_decode(0x868002, &ev), 0);
	assert_int_equal(ev.scheme, PS_DALI_SCHEME_INSTANCE);
	assert_int_equal(ev.instance_type, 3);
	assert_int_equal(ev.instance, 0);
	assert_int_equal(ev.address, -1);
	/* device group: 1 0 GGGGG 0 | 0 TTTTT: group 7, type 4, info 1023 */
	assert_int_equal(ps_dali_device_event_decode(0x8E13FF, &ev), 0);
	assert_int_equal(ev.scheme, PS_DALI_SCHEME_DEVICE_GROUP);
	assert_int_equal(ev.device_group, 7);
	assert_int_equal(ev.instance_type, 4);
	assert_int_equal(ev.info, 1023);
	/* instance group: 1 1 GGGGG 0 | 0 TTTTT: group 2, type 4 */
	assert_int_equal(ps_dali_device_event_decode(0xC41000, &ev), 0);
	assert_int_equal(ev.scheme, PS_DALI_SCHEME_INSTANCE_GROUP);
	assert_int_equal(ev.instance_group, 2);
	assert_int_equal(ev.instance_type, 4);
	/* 11xxxxx0 with bit 15 set: no source form; commands are not events */
	assert_int_equal(ps_dali_device_event_decode(0xC48000, &ev), -1);
	assert_int_equal(ps_dali_device_event_decode(0x0B018C, &ev), -1);
	assert_int_equal(ps_dali_device_event_decode(0x1000000, &ev), -1);
}

static void events_round_trip(void **state)
{
	struct ps_dali_device_event ev, back;
	(void)state;
	for (uint32_t f = 0; f <= 0xFFFFFF; f += 0x1F3) {
		if (ps_dali_device_event_decode(f, &ev) != 0)
			continue;
		assert_int_equal(ps_dali_device_event_encode(&ev), (long)f);
		assert_int_equal(ps_dali_device_event_decode(f, &back), 0);
		assert_memory_equal(&ev, &back, sizeof ev);
	}
	ev = (struct ps_dali_device_event){ PS_DALI_SCHEME_DEVICE, 64, -1, -1, 4, -1, 0 };
	assert_int_equal(ps_dali_device_event_encode(&ev), -1);
	ev = (struct ps_dali_device_event){ 5, 1, -1, -1, 4, -1, 0 };
	assert_int_equal(ps_dali_device_event_encode(&ev), -1);
}

static void input_values(void **state)
{
	static const uint8_t v512[] = { 0x80, 0x20 }, v1023[] = { 0xFF, 0xFF }, v0[] = { 0, 0 }, v300[] = { 0x4B, 0x12 },
	                     occ[] = { 0xAA };
	(void)state;
	/* 10 bits: two bytes, the value left-aligned, its top 6 bits repeated below */
	assert_int_equal(ps_dali_device_input_bytes(10), 2);
	assert_int_equal(ps_dali_device_input_value(v512, 2, 10), 512);
	assert_int_equal(ps_dali_device_input_value(v1023, 2, 10), 1023);
	assert_int_equal(ps_dali_device_input_value(v0, 2, 10), 0);
	assert_int_equal(ps_dali_device_input_value(v300, 2, 10), 300);
	/* 8 bits as is; 2 bits (occupancy: occupied, movement) = the top two */
	assert_int_equal(ps_dali_device_input_value(occ, 1, 8), 0xAA);
	assert_int_equal(ps_dali_device_input_value(occ, 1, 2), 2);
	assert_int_equal(ps_dali_device_input_value(v300, 1, 10), -1);
	assert_int_equal(ps_dali_device_input_value(v300, 2, 0), -1);
	assert_int_equal(ps_dali_device_input_bytes(33), 0);
}

static void timer_codes(void **state)
{
	(void)state;
	/* 304 T_report: 1 s steps, 1 s .. 4 min 15 s */
	assert_int_equal(ps_dali_device_timer_code(30, 1, 1), 30);
	assert_int_equal(ps_dali_device_timer_code(255, 1, 1), 255);
	assert_int_equal(ps_dali_device_timer_code(1, 1, 1), 1);
	assert_int_equal(ps_dali_device_timer_code(256, 1, 1), -1);
	assert_int_equal(ps_dali_device_timer_code(0.4, 1, 1), -1);
	/* T_deadtime: 50 ms steps, default 1.5 s = 30, up to 12.75 s */
	assert_int_equal(ps_dali_device_timer_code(1.5, 0.05, 0), 30);
	assert_int_equal(ps_dali_device_timer_code(12.75, 0.05, 0), 255);
	assert_int_equal(ps_dali_device_timer_code(0, 0.05, 0), 0);
	assert_int_equal(ps_dali_device_timer_code(13, 0.05, 0), -1);
	/* 303 hold timer: 10 s steps */
	assert_int_equal(ps_dali_device_timer_code(600, 10, 1), 60);
	assert_int_equal(ps_dali_device_timer_code(0.0 / 0.0, 1, 1), -1);
}

static void describe(void **state)
{
	char buf[96];
	(void)state;
	ps_dali_device_describe(0x0B018C, buf, sizeof buf);
	assert_string_equal(buf, "device 5 instance 1 QUERY INPUT VALUE");
	ps_dali_device_describe(0xC1017F, buf, sizeof buf);
	assert_string_equal(buf, "INITIALISE 0x7F");
	ps_dali_device_describe(0x0A1200, buf, sizeof buf);
	assert_string_equal(buf, "event device 5 type 4 info 512");
	ps_dali_device_describe(0xFFFE35, buf, sizeof buf);
	assert_string_equal(buf, "devices QUERY NUMBER OF INSTANCES");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(special_commands),
		cmocka_unit_test(device_and_instance_commands),
		cmocka_unit_test(events_in_every_scheme),
		cmocka_unit_test(events_round_trip),
		cmocka_unit_test(input_values),
		cmocka_unit_test(timer_codes),
		cmocka_unit_test(describe),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
