/* SPDX-License-Identifier: ISC */
/* Modbus point decoding and scaling against numbers worked out by hand and
 * against the register examples of real devices' manuals
 * (doc/hardware.md section 3). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <errno.h>
#include <math.h>
#include <string.h>
#include <cmocka.h>

#ifdef PS_WITH_MODBUS
#include "driver.h"
#include "modbus_point.h"

#include "helpers/test_opts.h"

/* Options from "key=value" strings, from line 10 of site.conf. */
struct optset {
	struct ps_test_opts t;
};

static const struct ps_opts *opts(struct optset *s, const char *const *kv)
{
	return ps_test_opts(&s->t, "site.conf", 10, kv);
}

static struct ps_modbus_point parsed(int role, const char *const *kv)
{
	struct optset s;
	struct ps_modbus_point p;
	char err[256] = "";
	int rc = ps_modbus_point_parse(&p, role, opts(&s, kv), err, sizeof err);
	if (rc != 0)
		fail_msg("%s", err);
	return p;
}

static void adam_input_is_0_to_10_volts(void **state)
{
	/* ADAM-6017/6024 AI: 0..65535 spans 0..10 V, so V = raw * 10 / 65535 */
	static const char *const kv[] = { "table=input_register", "address=0", NULL };
	struct ps_modbus_point p = parsed(PS_ROLE_SENSOR, kv);
	uint16_t r[1];
	double v;
	char why[128];
	(void)state;
	r[0] = 0;
	assert_int_equal(ps_modbus_point_value(&p, r, &v, why, sizeof why), 0);
	assert_true(v == 0);
	r[0] = 65535;
	assert_int_equal(ps_modbus_point_value(&p, r, &v, why, sizeof why), 0);
	assert_true(fabs(v - 10) < 1e-12);
	r[0] = 13107;   /* 13107 * 10 / 65535 = 2 exactly */
	assert_int_equal(ps_modbus_point_value(&p, r, &v, why, sizeof why), 0);
	assert_true(fabs(v - 2) < 1e-12);
}

static void twelve_bit_range_and_open_circuit_code(void **state)
{
	/* a 12-bit module: 0..4095 is 0..10 V; 0xFFFF (an open-circuit code) is outside */
	static const char *const kv[] = { "table=holding_register", "address=3", "raw_max=4095", NULL };
	struct ps_modbus_point p = parsed(PS_ROLE_SENSOR, kv);
	uint16_t r[1] = { 4095 };
	double v;
	char why[128];
	(void)state;
	assert_int_equal(ps_modbus_point_value(&p, r, &v, why, sizeof why), 0);
	assert_true(fabs(v - 10) < 1e-12);
	r[0] = 0xffff;
	assert_int_equal(ps_modbus_point_value(&p, r, &v, why, sizeof why), -1);
	assert_int_equal(errno, ERANGE);
	assert_non_null(strstr(why, "raw 65535 outside 0 to 4095"));
}

static void wago_left_justified_with_status_bits(void **state)
{
	/* WAGO 750-467: 10 V reads 0x7FF8, the low three bits are status;
	 * mask them off and treat any of them set as a fault */
	static const char *const kv[] = { "table=input_register", "address=0", "mask=0xfff8",
	                                  "status_mask=0x0007", "raw_max=32760", NULL };
	struct ps_modbus_point p = parsed(PS_ROLE_SENSOR, kv);
	uint16_t r[1] = { 0x7ff8 };
	double v;
	char why[128];
	(void)state;
	assert_int_equal(ps_modbus_point_value(&p, r, &v, why, sizeof why), 0);
	assert_true(fabs(v - 10) < 1e-12);
	r[0] = 0x3ffc;   /* 0x3FF8 with status bit 2 (over-range) set */
	assert_int_equal(ps_modbus_point_value(&p, r, &v, why, sizeof why), -1);
	assert_int_equal(errno, ERANGE);
	r[0] = 0x3ff8;   /* 16376 / 32760 * 10 */
	assert_int_equal(ps_modbus_point_value(&p, r, &v, why, sizeof why), 0);
	assert_true(fabs(v - 16376.0 / 32760 * 10) < 1e-12);
}

static void u32_lux_both_word_orders(void **state)
{
	/* the generic RS-485 lux meter's manual: registers 0x0002 0x06F6 are 132854 lx */
	static const char *const hi[] = { "table=holding_register", "address=7", "type=u32", NULL };
	static const char *const lo[] = { "table=holding_register", "address=7", "type=u32",
	                                  "word_order=cdab", NULL };
	struct ps_modbus_point a = parsed(PS_ROLE_TASK_LUX, hi), c = parsed(PS_ROLE_TASK_LUX, lo);
	uint16_t r[2] = { 0x0002, 0x06f6 }, s[2] = { 0x06f6, 0x0002 };
	double v;
	char why[128];
	(void)state;
	assert_int_equal(ps_modbus_point_count(&a), 2);
	assert_int_equal(ps_modbus_point_value(&a, r, &v, why, sizeof why), 0);
	assert_true(v == 132854);
	assert_int_equal(ps_modbus_point_value(&c, s, &v, why, sizeof why), 0);
	assert_true(v == 132854);
	/* NHZD210 example: 0x0000 0x0128 = 296 lx */
	r[0] = 0;
	r[1] = 0x0128;
	assert_int_equal(ps_modbus_point_value(&a, r, &v, why, sizeof why), 0);
	assert_true(v == 296);
}

static void signed_types(void **state)
{
	static const char *const s16[] = { "table=input_register", "address=0", "type=s16", NULL };
	static const char *const s32[] = { "table=input_register", "address=0", "type=s32", NULL };
	struct ps_modbus_point a = parsed(PS_ROLE_TASK_LUX, s16), b = parsed(PS_ROLE_TASK_LUX, s32);
	uint16_t r[2] = { 0xffff, 0xfffe };
	double v;
	char why[128];
	(void)state;
	assert_int_equal(ps_modbus_point_value(&a, r, &v, why, sizeof why), 0);
	assert_true(v == -1);
	assert_int_equal(ps_modbus_point_value(&b, r, &v, why, sizeof why), 0);
	assert_true(v == -2);
	r[0] = 0x8000;
	r[1] = 0;
	assert_int_equal(ps_modbus_point_value(&b, r, &v, why, sizeof why), 0);
	assert_true(v == -2147483648.0);
}

static void f32_bits(void **state)
{
	/* IEEE 754: 100.0 is 0x42C80000; in CDAB the low word comes first */
	static const char *const ab[] = { "table=input_register", "address=0", "type=f32", NULL };
	static const char *const cd[] = { "table=input_register", "address=0", "type=f32",
	                                  "word_order=cdab", NULL };
	struct ps_modbus_point a = parsed(PS_ROLE_TASK_LUX, ab), c = parsed(PS_ROLE_TASK_LUX, cd);
	uint16_t r[2] = { 0x42c8, 0x0000 }, s[2] = { 0x0000, 0x42c8 }, w[2];
	double v;
	char why[128];
	(void)state;
	assert_int_equal(ps_modbus_point_value(&a, r, &v, why, sizeof why), 0);
	assert_true(v == 100.0);
	assert_int_equal(ps_modbus_point_value(&c, s, &v, why, sizeof why), 0);
	assert_true(v == 100.0);
	r[0] = 0x7fc0;   /* a NaN */
	assert_int_equal(ps_modbus_point_value(&a, r, &v, why, sizeof why), -1);
	assert_int_equal(errno, ERANGE);
	/* -2.5 is 0xC0200000 */
	ps_modbus_point_encode(&c, -2.5, w);
	assert_int_equal(w[0], 0x0000);
	assert_int_equal(w[1], 0xc020);
}

static void dim_output_adam_6024(void **state)
{
	/* ADAM-6024 AO: 0..4095 is 0..10 V; light output 0..1 maps onto it */
	static const char *const kv[] = { "table=holding_register", "address=10", "raw_max=4095", NULL };
	struct ps_modbus_point p = parsed(PS_ROLE_DIM, kv);
	uint16_t r[1];
	(void)state;
	assert_true(ps_modbus_point_encode(&p, 0.5, r) == 2048);   /* 2047.5 rounds away from zero */
	assert_int_equal(r[0], 2048);
	ps_modbus_point_encode(&p, 1.0, r);
	assert_int_equal(r[0], 4095);
	ps_modbus_point_encode(&p, 1.7, r);   /* clamped */
	assert_int_equal(r[0], 4095);
	ps_modbus_point_encode(&p, -0.2, r);
	assert_int_equal(r[0], 0);
	ps_modbus_point_encode(&p, 0.1, r);   /* 409.5 -> 410 */
	assert_int_equal(r[0], 410);
}

static void one_to_ten_volt_output(void **state)
{
	/* a 1-10 V ballast on a module that takes millivolts (0..10000): light
	 * output 0 at 1 V, full at 10 V, so min (the output at raw_min = 0 V) is
	 * -1/9; the level 0.5 is 5.5 V */
	static const char *const kv[] = { "table=holding_register", "address=10", "raw_min=0",
	                                  "raw_max=10000", "min=-0.111111111111111111", "max=1", NULL };
	struct ps_modbus_point p = parsed(PS_ROLE_DIM, kv);
	uint16_t r[1];
	double v;
	char why[64];
	(void)state;
	ps_modbus_point_encode(&p, 0, r);
	assert_int_equal(r[0], 1000);
	ps_modbus_point_encode(&p, 0.5, r);
	assert_int_equal(r[0], 5500);
	ps_modbus_point_encode(&p, 1, r);
	assert_int_equal(r[0], 10000);
	/* the inverse, read back */
	assert_int_equal(ps_modbus_point_value(&p, r, &v, why, sizeof why), 0);
	assert_true(fabs(v - 1) < 1e-12);
}

static void bits(void **state)
{
	static const char *const relay[] = { "table=coil", "address=16", NULL };
	static const char *const in[] = { "table=discrete_input", "address=1", NULL };
	struct ps_modbus_point a = parsed(PS_ROLE_RELAY, relay), b = parsed(PS_ROLE_INPUT, in);
	uint16_t r[1];
	double v;
	char why[64];
	(void)state;
	ps_modbus_point_encode(&a, 1, r);
	assert_int_equal(r[0], 1);
	ps_modbus_point_encode(&a, 0.2, r);
	assert_int_equal(r[0], 0);
	r[0] = 1;
	assert_int_equal(ps_modbus_point_value(&b, r, &v, why, sizeof why), 0);
	assert_true(v == 1);
}

/* The full scale: the value of the raw range's end that reads highest (the
 * top code of an integer register by default, the configured end of an f32
 * range); none for a bit or an f32 taken as it is. */
static void full_scale_is_the_top_of_the_range(void **state)
{
	static const char *const adam[] = { "table=input_register", "address=0", NULL };
	static const char *const twelve[] = { "table=holding_register", "address=3", "raw_max=4095", NULL };
	static const char *const inverted[] = { "table=input_register", "address=0", "min=10", "max=0", NULL };
	static const char *const f32[] = { "table=input_register", "address=0", "type=f32", NULL };
	static const char *const f32r[] = { "table=input_register", "address=0", "type=f32", "raw_min=0",
	                                    "raw_max=200000", NULL };
	static const char *const in[] = { "table=discrete_input", "address=1", NULL };
	struct ps_modbus_point p;
	uint16_t r[1] = { 65535 };
	double lim, v;
	char why[64];
	(void)state;
	p = parsed(PS_ROLE_SENSOR, adam);
	assert_int_equal(ps_modbus_point_full_scale(&p, &lim), 0);
	assert_int_equal(ps_modbus_point_value(&p, r, &v, why, sizeof why), 0);
	assert_true(lim == 10 && v == lim);   /* the top code reads the full scale */
	p = parsed(PS_ROLE_SENSOR, twelve);
	assert_int_equal(ps_modbus_point_full_scale(&p, &lim), 0);
	assert_true(lim == 10);
	p = parsed(PS_ROLE_SENSOR, inverted);   /* raw 0 reads 10 V */
	assert_int_equal(ps_modbus_point_full_scale(&p, &lim), 0);
	assert_true(lim == 10);
	p = parsed(PS_ROLE_TASK_LUX, f32r);
	assert_int_equal(ps_modbus_point_full_scale(&p, &lim), 0);
	assert_true(lim == 200000);
	p = parsed(PS_ROLE_TASK_LUX, f32);
	assert_int_equal(ps_modbus_point_full_scale(&p, &lim), -1);
	p = parsed(PS_ROLE_INPUT, in);
	assert_int_equal(ps_modbus_point_full_scale(&p, &lim), -1);
}

static void expect_error(int role, const char *const *kv, const char *text)
{
	struct optset s;
	struct ps_modbus_point p;
	char err[256] = "";
	assert_int_equal(ps_modbus_point_parse(&p, role, opts(&s, kv), err, sizeof err), -1);
	assert_int_equal(errno, EINVAL);
	if (!strstr(err, text))
		fail_msg("'%s' lacks '%s'", err, text);
}

static void bad_options_name_file_and_line(void **state)
{
	static const char *const notable[] = { "address=0", NULL };
	static const char *const badtable[] = { "table=registers", "address=0", NULL };
	static const char *const input_dim[] = { "table=input_register", "address=0", NULL };
	static const char *const addr[] = { "table=holding_register", "address=65535", "type=u32", NULL };
	static const char *const same[] = { "table=input_register", "address=0", "raw_min=5", "raw_max=5", NULL };
	static const char *const raw32[] = { "table=input_register", "address=0", "raw_max=70000", NULL };
	static const char *const mask32[] = { "table=input_register", "address=0", "type=u32", "mask=0xff", NULL };
	static const char *const fscale[] = { "table=input_register", "address=0", "type=f32", "max=5", NULL };
	static const char *const word[] = { "table=input_register", "address=0", "word_order=badc", NULL };
	(void)state;
	expect_error(PS_ROLE_SENSOR, notable, "site.conf:0: table is required");
	expect_error(PS_ROLE_SENSOR, badtable, "site.conf:10: table: 'registers' is not one of input_register, holding_register, coil, discrete_input");
	expect_error(PS_ROLE_DIM, input_dim, "site.conf:10: table: 'input_register' does not suit a dim output");
	expect_error(PS_ROLE_TASK_LUX, addr, "site.conf:11: address: '65535' leaves no room");
	expect_error(PS_ROLE_SENSOR, same, "site.conf:13: raw_max: '5' must differ from raw_min");
	expect_error(PS_ROLE_SENSOR, raw32, "site.conf:12: raw_max: '70000' is outside 0 to 65535");
	expect_error(PS_ROLE_TASK_LUX, mask32, "site.conf:13: mask: '0xff' applies to 16-bit types only");
	expect_error(PS_ROLE_SENSOR, fscale, "site.conf:13: max: '5' on an f32 point needs raw_min");
	expect_error(PS_ROLE_SENSOR, word, "site.conf:12: word_order: 'badc' is not one of abcd, cdab");
}

/* Every u16 value through the dim map and back stays within half a step. */
static void round_trip_error_is_half_a_step(void **state)
{
	static const char *const kv[] = { "table=holding_register", "address=10", "raw_max=4095", NULL };
	struct ps_modbus_point p = parsed(PS_ROLE_DIM, kv);
	double worst = 0;
	(void)state;
	for (int i = 0; i <= 10000; i++) {
		double level = i / 10000.0, back;
		uint16_t r[1];
		char why[64];
		ps_modbus_point_encode(&p, level, r);
		assert_int_equal(ps_modbus_point_value(&p, r, &back, why, sizeof why), 0);
		worst = fmax(worst, fabs(back - level));
	}
	assert_true(worst <= 0.5 / 4095 + 1e-15);
	assert_true(worst > 0.4 / 4095);   /* and the test does see rounding */
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(adam_input_is_0_to_10_volts),
		cmocka_unit_test(twelve_bit_range_and_open_circuit_code),
		cmocka_unit_test(wago_left_justified_with_status_bits),
		cmocka_unit_test(u32_lux_both_word_orders),
		cmocka_unit_test(signed_types),
		cmocka_unit_test(f32_bits),
		cmocka_unit_test(dim_output_adam_6024),
		cmocka_unit_test(one_to_ten_volt_output),
		cmocka_unit_test(bits),
		cmocka_unit_test(full_scale_is_the_top_of_the_range),
		cmocka_unit_test(bad_options_name_file_and_line),
		cmocka_unit_test(round_trip_error_is_half_a_step),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
#else
int main(void)
{
	printf("the modbus driver is not compiled in (WITH_MODBUS)\n");
	return 77;
}
#endif
