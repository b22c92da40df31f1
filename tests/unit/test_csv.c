/* SPDX-License-Identifier: ISC */
/* The daemon's CSV writer against RFC 4180 and strtod: a field holding a
 * comma, a double quote, CR or LF is quoted with its quotes doubled (the
 * RFC's rules 6 and 7), any other is written as it is; every double reads
 * back bit for bit (strtod of the text is the same double, -0 and the
 * subnormals included) with the fewest digits that do it; NaN and Inf are
 * empty fields, never a word a CSV reader takes for text. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "csv.h"

/* what psd_csv_text writes for t */
static void field(const char *t, char *out, size_t n)
{
	FILE *fp;
	memset(out, 0, n);   /* fmemopen writes no NUL for an empty field */
	fp = fmemopen(out, n, "w");
	assert_non_null(fp);
	psd_csv_text(fp, t);
	fclose(fp);
}

static void text_quoting(void **state)
{
	static const struct {
		const char *in, *out;
	} cases[] = {
		{ "office", "office" },
		{ "daylight mean", "daylight mean" },
		{ "a,b", "\"a,b\"" },
		{ "say \"hi\"", "\"say \"\"hi\"\"\"" },
		{ "\"", "\"\"\"\"" },
		{ "two\nlines", "\"two\nlines\"" },
		{ "cr\rhere", "\"cr\rhere\"" },
		{ "crlf\r\n", "\"crlf\r\n\"" },
		{ "", "" },
		{ "caf\xc3\xa9;tab\there", "caf\xc3\xa9;tab\there" },   /* not special in RFC 4180 */
	};
	char out[64];
	(void)state;
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		field(cases[i].in, out, sizeof out);
		assert_string_equal(out, cases[i].out);
	}
	field(NULL, out, sizeof out);
	assert_string_equal(out, "");
}

static void numbers_known(void **state)
{
	static const struct {
		double v;
		const char *out;
	} cases[] = {
		{ 0.3, "0.3" },
		{ 0.1 + 0.2, "0.30000000000000004" },   /* 17 digits: 15 read back as 0.3 */
		{ 1.0 / 3.0, "0.3333333333333333" },    /* 16 */
		{ 21600, "21600" },
		{ -122.3959, "-122.3959" },
		{ 9007199254740993.0, "9007199254740992" },   /* 2^53 + 1 is 2^53 as a double */
		{ 1e21, "1e+21" },
		{ 5e-324, "4.94065645841247e-324" },   /* the least subnormal: 15 digits do */
		{ DBL_MAX, "1.7976931348623157e+308" },
	};
	char out[32];
	(void)state;
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		psd_csv_num_text(cases[i].v, out);
		assert_string_equal(out, cases[i].out);
	}
	psd_csv_num_text(NAN, out);
	assert_string_equal(out, "");
	psd_csv_num_text(INFINITY, out);
	assert_string_equal(out, "");
	psd_csv_num_text(-INFINITY, out);
	assert_string_equal(out, "");
}

/* 100000 doubles from random bit patterns (every exponent, both signs),
 * and -0: strtod of the text is the same 64 bits. */
static void numbers_round_trip(void **state)
{
	uint64_t x = 0x9e3779b97f4a7c15u;
	char out[32];
	double back, v = -0.0;
	(void)state;
	psd_csv_num_text(v, out);
	back = strtod(out, NULL);
	assert_true(back == 0 && signbit(back));
	for (int i = 0; i < 100000; i++) {
		uint64_t b;
		x ^= x << 13;
		x ^= x >> 7;
		x ^= x << 17;
		memcpy(&v, &x, sizeof v);
		if (!isfinite(v))
			continue;
		psd_csv_num_text(v, out);
		back = strtod(out, NULL);
		memcpy(&b, &back, sizeof b);
		if (b != x)
			fail_msg("%s reads back as %.17g, not %.17g", out, back, v);
	}
}

static void num_to_stream(void **state)
{
	char out[64] = "";
	FILE *fp = fmemopen(out, sizeof out, "w");
	(void)state;
	assert_non_null(fp);
	psd_csv_num(fp, 0.5);
	fputc(',', fp);
	psd_csv_num(fp, NAN);
	fputc(',', fp);
	psd_csv_num(fp, -1e-7);
	fclose(fp);
	assert_string_equal(out, "0.5,,-1e-07");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(text_quoting),
		cmocka_unit_test(numbers_known),
		cmocka_unit_test(numbers_round_trip),
		cmocka_unit_test(num_to_stream),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
