/* SPDX-License-Identifier: ISC */
/* The command line every program shares: see cli.h. */
#include "cli.h"

#include <math.h>
#include <stdlib.h>

#include "version.h"

int ps_cli_version(const char *prog)
{
	printf("%s (psensd) %s\n", prog, PS_VERSION);
	return fflush(stdout) == 0 ? 0 : 1;
}

void ps_cli_deprecated(const char *prog, const char *old, const char *now)
{
	fprintf(stderr, "%s: warning: %s is deprecated and goes in the next release; use %s\n", prog, old,
	        now);
}

int ps_cli_is_number(const char *s)
{
	char *end;
	double v = strtod(s, &end);
	return end != s && !*end && isfinite(v);
}
