/* SPDX-License-Identifier: ISC */
/* The daemon's JSON writer against RFC 8259: a string's quote, backslash
 * and control characters escaped (section 7: \", \\, \n, \t, \u0001), "/"
 * and UTF-8 left as they are; the RFC's own example object (section 13)
 * written and read back; NaN and Inf as null (JSON has neither); numbers
 * with the digits asked for (a whole double is written 800.0, json-c's
 * form, a valid JSON number that readers take as a double). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <string.h>
#include <cmocka.h>

#include "json.h"

static void strings_escaped(void **state)
{
	json_object *o = json_object_new_object();
	(void)state;
	psd_json_str(o, "a", "say \"hi\" \\ \x01\n\t/\xc3\xa9");
	psd_json_str(o, "none", NULL);
	assert_string_equal(psd_json_text(o, 10), "{\"a\":\"say \\\"hi\\\" \\\\ \\u0001\\n\\t/\xc3\xa9\",\"none\":null}");
	json_object_put(o);
}

static void numbers_never_nan(void **state)
{
	json_object *o = json_object_new_object();
	json_object *back;
	(void)state;
	psd_json_num(o, "nan", NAN);
	psd_json_num(o, "inf", INFINITY);
	psd_json_num(o, "minf", -INFINITY);
	psd_json_num(o, "third", 1.0 / 3.0);
	assert_string_equal(psd_json_text(o, 10), "{\"nan\":null,\"inf\":null,\"minf\":null,\"third\":0.3333333333}");
	/* 17 digits: the double itself */
	back = json_tokener_parse(psd_json_text(o, 17));
	assert_non_null(back);
	assert_true(json_object_get_double(json_object_object_get(back, "third")) == 1.0 / 3.0);
	json_object_put(back);
	json_object_put(o);
}

/* RFC 8259 section 13, the first example, written by the writer: the URL
 * keeps its slashes, and the text reads back to the same values. */
static void rfc_example(void **state)
{
	json_object *img = json_object_new_object(), *thumb = json_object_new_object(), *o = json_object_new_object();
	json_object *ids = json_object_new_array(), *back, *x;
	(void)state;
	psd_json_num(img, "Width", 800);
	psd_json_num(img, "Height", 600);
	psd_json_str(img, "Title", "View from 15th Floor");
	psd_json_str(thumb, "Url", "http://www.example.com/image/481989943");
	psd_json_num(thumb, "Height", 125);
	psd_json_num(thumb, "Width", 100);
	json_object_object_add(img, "Thumbnail", thumb);
	json_object_object_add(img, "Animated", json_object_new_boolean(0));
	json_object_array_add(ids, json_object_new_int(116));
	json_object_array_add(ids, json_object_new_int(943));
	json_object_array_add(ids, json_object_new_int(234));
	json_object_array_add(ids, json_object_new_int(38793));
	json_object_object_add(img, "IDs", ids);
	json_object_object_add(o, "Image", img);
	assert_string_equal(psd_json_text(o, 10),
	                    "{\"Image\":{\"Width\":800.0,\"Height\":600.0,\"Title\":\"View from 15th Floor\","
	                    "\"Thumbnail\":{\"Url\":\"http://www.example.com/image/481989943\",\"Height\":125.0,"
	                    "\"Width\":100.0},\"Animated\":false,\"IDs\":[116,943,234,38793]}}");
	back = json_tokener_parse(psd_json_text(o, 10));
	assert_non_null(back);
	assert_true(json_object_object_get_ex(back, "Image", &x));
	assert_true(json_object_object_get_ex(x, "Thumbnail", &x));
	assert_string_equal(json_object_get_string(json_object_object_get(x, "Url")),
	                    "http://www.example.com/image/481989943");
	json_object_put(back);
	json_object_put(o);
}

/* The RFC's second example's coordinates at 10 digits, as a reply
 * carries them. */
static void digits(void **state)
{
	json_object *o = json_object_new_object();
	(void)state;
	psd_json_num(o, "Latitude", 37.7668);
	psd_json_num(o, "Longitude", -122.3959);
	psd_json_num(o, "sum", 0.1 + 0.2);
	assert_string_equal(psd_json_text(o, 10), "{\"Latitude\":37.7668,\"Longitude\":-122.3959,\"sum\":0.3}");
	json_object_put(o);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(strings_escaped),
		cmocka_unit_test(numbers_never_nan),
		cmocka_unit_test(rfc_example),
		cmocka_unit_test(digits),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
