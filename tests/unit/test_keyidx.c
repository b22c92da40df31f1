/* SPDX-License-Identifier: ISC */
/* The key index: every key added is found at its position, keys never
 * added are not, through many growths and colliding probes; and the config
 * reader built on it still finds a key set twice in a section of 20,000. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "conf.h"
#include "keyidx.h"

enum { NKEYS = 20000 };

static void every_key_found_at_its_position(void **state)
{
	static char keys[NKEYS][16];
	struct ps_keyidx x = { 0 };
	size_t pos;
	(void)state;
	assert_int_equal(ps_keyidx_find(&x, "h0", &pos), 0);   /* empty: no table yet */
	for (size_t i = 0; i < NKEYS; i++) {
		snprintf(keys[i], sizeof keys[i], "h%zu", i);
		assert_int_equal(ps_keyidx_add(&x, keys[i], i), 0);
	}
	assert_int_equal(x.n, NKEYS);
	assert_true(x.cap >= 2 * x.n);   /* at most half full */
	for (size_t i = 0; i < NKEYS; i++) {
		char probe[16];
		snprintf(probe, sizeof probe, "h%zu", i);   /* a copy: found by content */
		assert_int_equal(ps_keyidx_find(&x, probe, &pos), 1);
		assert_int_equal(pos, i);
	}
	assert_int_equal(ps_keyidx_find(&x, "h20000", &pos), 0);
	assert_int_equal(ps_keyidx_find(&x, "", &pos), 0);
	assert_int_equal(ps_keyidx_find(&x, "h", &pos), 0);
	ps_keyidx_free(&x);
	assert_null(x.slot);
	assert_int_equal(x.cap, 0);
}

static void a_duplicate_among_many_is_reported_once(void **state)
{
	size_t len = 0, cap = 32 * NKEYS;
	char *text = malloc(cap);
	struct ps_conf c;
	struct ps_err e;
	(void)state;
	assert_non_null(text);
	len += (size_t)snprintf(text + len, cap - len, "[year_hours]\n");
	for (int i = 0; i < NKEYS; i++)
		len += (size_t)snprintf(text + len, cap - len, "h%d = %d\n", i, i);
	len += (size_t)snprintf(text + len, cap - len, "h7 = again\n");
	assert_int_equal(ps_conf_load_string(&c, text, "many.conf", &e), 0);
	assert_int_equal(c.nerrors, 1);
	assert_string_equal(c.errors[0], "many.conf:20002: key 'h7' set twice in [year_hours] (first at line 9)");
	struct ps_conf_section *s;
	s = ps_conf_section(&c, "year_hours");
	assert_non_null(s);
	assert_int_equal(s->nkv, NKEYS);
	assert_string_equal(ps_conf_str(&c, s, "h19999", "absent"), "19999");
	assert_string_equal(ps_conf_str(&c, s, "h7", "absent"), "7");   /* the first one kept */
	assert_string_equal(ps_conf_str(&c, s, "h20000", "absent"), "absent");
	ps_conf_free(&c);
	free(text);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(every_key_found_at_its_position),
		cmocka_unit_test(a_duplicate_among_many_is_reported_once),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
