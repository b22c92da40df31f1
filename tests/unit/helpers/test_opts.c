/* SPDX-License-Identifier: ISC */
/* Driver options for unit tests (test_opts.h). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "test_opts.h"

const struct ps_opts *ps_test_opts(struct ps_test_opts *s, const char *file, int first_line,
                                   const char *const *kv)
{
	size_t n = 0;
	for (; kv[n]; n++) {
		char *eq;
		if (n >= PS_TEST_OPTS_MAX)
			fail_msg("more than %d options", PS_TEST_OPTS_MAX);
		snprintf(s->buf[n], sizeof s->buf[n], "%s", kv[n]);
		eq = strchr(s->buf[n], '=');
		if (!eq)
			fail_msg("option '%s' has no '='", kv[n]);
		*eq = 0;
		s->v[n] = (struct ps_opt){ s->buf[n], eq + 1, first_line + (int)n, 0 };
	}
	s->o = (struct ps_opts){ s->v, n, file };
	return &s->o;
}

const struct ps_opts *ps_test_vopts(struct ps_test_opts *s, const char *file, int first_line, va_list ap)
{
	size_t n = 0;
	const char *k;
	while ((k = va_arg(ap, const char *))) {
		if (n >= PS_TEST_OPTS_MAX)
			fail_msg("more than %d options", PS_TEST_OPTS_MAX);
		s->v[n] = (struct ps_opt){ k, va_arg(ap, const char *), first_line + (int)n, 0 };
		n++;
	}
	s->o = (struct ps_opts){ s->v, n, file };
	return &s->o;
}
