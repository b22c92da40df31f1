/* SPDX-License-Identifier: ISC */
/* Driver options for unit tests, as the configuration reader would hand them
 * to a driver (drivers/opts.h): from "key=value" strings or from key, value
 * pairs, each on its own line of a named file, so that errors naming
 * file:line can be checked. */
#ifndef PS_TEST_OPTS_H
#define PS_TEST_OPTS_H

#include <stdarg.h>

#include "opts.h"

enum { PS_TEST_OPTS_MAX = 24 };

struct ps_test_opts {
	struct ps_opt v[PS_TEST_OPTS_MAX];
	char buf[PS_TEST_OPTS_MAX][64];
	struct ps_opts o;
};

/* kv: "key=value" strings ending with NULL; option i is on line first_line + i
 * of file.  Fails the test (cmocka) on more than PS_TEST_OPTS_MAX options or
 * a string without '='. */
const struct ps_opts *ps_test_opts(struct ps_test_opts *s, const char *file, int first_line,
                                   const char *const *kv);
/* ap: key, value, ..., NULL (the strings are not copied). */
const struct ps_opts *ps_test_vopts(struct ps_test_opts *s, const char *file, int first_line, va_list ap);

#endif
