/* SPDX-License-Identifier: ISC */
#include "err.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

int ps_err_set(struct ps_err *e, int code, const char *fmt, ...)
{
	if (e) {
		va_list ap;
		e->code = code;
		e->sys_errno = 0;
		va_start(ap, fmt);
		vsnprintf(e->msg, sizeof e->msg, fmt, ap);
		va_end(ap);
	}
	return -1;
}

int ps_err_sys(struct ps_err *e, const char *fmt, ...)
{
	int saved = errno;   /* before anything else can change it */
	if (e) {
		va_list ap;
		size_t n;
		e->code = PS_EIO;
		e->sys_errno = saved;
		va_start(ap, fmt);
		vsnprintf(e->msg, sizeof e->msg, fmt, ap);
		va_end(ap);
		n = strlen(e->msg);
		if (n < sizeof e->msg)
			snprintf(e->msg + n, sizeof e->msg - n, ": %s", strerror(saved));
	}
	errno = saved;
	return -1;
}
