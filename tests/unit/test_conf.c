/* SPDX-License-Identifier: ISC */
/* The INI configuration reader: located errors, all of them in one pass. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "conf.h"

static int has_error(const struct ps_conf *c, const char *needle)
{
	for (size_t i = 0; i < c->nerrors; i++)
		if (strstr(c->errors[i], needle))
			return 1;
	return 0;
}

static void typed_values_and_lines(void **state)
{
	struct ps_conf c;
	struct ps_err e;
	double d;
	long n;
	int b, k;
	static const char *const kinds[] = { "daylight", "electric", NULL };
	(void)state;
	assert_int_equal(ps_conf_load_string(&c,
		"top = 1\n[psensd]\nperiod = 2.5\ncount = 0x10\n; comment\n"
		"flag = yes\nkind = electric\n[zone a]\nname = x\n", "t.conf", &e), 0);
	assert_int_equal(c.nerrors, 0);
	struct ps_conf_section *s = ps_conf_section(&c, "psensd");
	assert_non_null(s);
	assert_int_equal(s->line, 2);
	assert_int_equal(ps_conf_double(&c, s, "period", 1, 0, 10, &d), 0);
	assert_true(d == 2.5);
	assert_int_equal(ps_conf_int(&c, s, "count", 0, 0, 100, &n), 0);
	assert_int_equal(n, 16);
	assert_int_equal(ps_conf_bool(&c, s, "flag", 0, &b), 0);
	assert_int_equal(b, 1);
	assert_int_equal(ps_conf_enum(&c, s, "kind", kinds, 0, &k), 0);
	assert_int_equal(k, 1);
	assert_int_equal(ps_conf_kv(s, "kind")->line, 7);
	assert_int_equal(ps_conf_double(&c, s, "absent", 7, 0, 10, &d), 0);
	assert_true(d == 7);
	assert_string_equal(ps_conf_section_is(&c.sec[2], "zone"), "a");
	assert_null(ps_conf_section_is(&c.sec[2], "zo"));
	ps_conf_str(&c, &c.sec[0], "top", NULL);
	ps_conf_str(&c, &c.sec[2], "name", NULL);
	ps_conf_check_unused(&c);
	assert_int_equal(c.nerrors, 0);
	ps_conf_free(&c);
}

static void all_errors_in_one_pass(void **state)
{
	struct ps_conf c;
	struct ps_err e;
	double d;
	long n;
	(void)state;
	assert_int_equal(ps_conf_load_string(&c,
		"[a]\n"              /* 1 */
		"x = abc\n"          /* 2: not a number */
		"this line is bad\n" /* 3: syntax */
		"y = 20\n"           /* 4: out of range */
		"[b\n"               /* 5: syntax */
		"x = 1\n"            /* 6 */
		"x = 2\n"            /* 7: duplicate */
		"typo = 3\n",        /* 8: unused */
		"bad.conf", &e), 0);
	struct ps_conf_section *a = ps_conf_section(&c, "a");
	assert_non_null(a);
	assert_int_equal(ps_conf_double(&c, a, "x", 0, 0, 10, &d), -1);
	assert_int_equal(ps_conf_int(&c, a, "y", 0, 0, 10, &n), -1);
	ps_conf_check_unused(&c);
	assert_true(has_error(&c, "bad.conf:2: x: 'abc' is not a number"));
	assert_true(has_error(&c, "bad.conf:3: expected"));
	assert_true(has_error(&c, "bad.conf:4: y: 20 is outside 0 to 10"));
	assert_true(has_error(&c, "bad.conf:5: section header without ']'"));
	assert_true(has_error(&c, "bad.conf:7: key 'x' set twice"));
	assert_true(has_error(&c, "bad.conf:8: unknown key 'typo'"));
	ps_conf_free(&c);
}

static void long_lines_and_missing_files(void **state)
{
	struct ps_conf c;
	struct ps_err e;
	char *text = malloc(10000);
	(void)state;
	memcpy(text, "[a]\nk = ", 8);
	memset(text + 8, 'v', 9000);
	strcpy(text + 9008, "\nz = 1\n");
	assert_int_equal(ps_conf_load_string(&c, text, "long.conf", &e), 0);
	assert_true(has_error(&c, "long.conf:2: line longer than"));
	/* the line after the long one is read normally */
	assert_non_null(ps_conf_kv(ps_conf_section(&c, "a"), "z"));
	assert_int_equal(ps_conf_kv(ps_conf_section(&c, "a"), "z")->line, 3);
	ps_conf_free(&c);
	free(text);
	assert_int_equal(ps_conf_load(&c, "/nonexistent/x.conf", &e), -1);
	assert_int_equal(e.code, PS_EIO);
	assert_non_null(strstr(e.msg, "/nonexistent/x.conf"));
}

static void paths_resolve_against_the_file(void **state)
{
	struct ps_conf c;
	struct ps_err e;
	(void)state;
	assert_int_equal(ps_conf_load_string(&c, "[s]\np = img/a.hdr\nq = /abs/b\n",
	                                     "/etc/psensd/scene.conf", &e), 0);
	char *p = ps_conf_path(&c, ps_conf_section(&c, "s"), "p");
	char *q = ps_conf_path(&c, ps_conf_section(&c, "s"), "q");
	assert_string_equal(p, "/etc/psensd/img/a.hdr");
	assert_string_equal(q, "/abs/b");
	free(p);
	free(q);
	ps_conf_free(&c);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(typed_values_and_lines),
		cmocka_unit_test(all_errors_in_one_pass),
		cmocka_unit_test(long_lines_and_missing_files),
		cmocka_unit_test(paths_resolve_against_the_file),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
