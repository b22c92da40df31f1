/* SPDX-License-Identifier: ISC */
#include "binout.h"

#include <unistd.h>

int ps_binout_check(const char *path, const char *example, struct ps_err *e)
{
	if (path || !isatty(STDOUT_FILENO))
		return 0;
	return ps_err_set(e, PS_EINVAL, "standard output is a terminal: not writing a binary picture "
	                  "there; redirect it (%s) or name a file with --output FILE", example);
}
