/* SPDX-License-Identifier: ISC */
#include "errbuf.h"

#include <stdarg.h>
#include <stdio.h>

int psd_errbuf_va(char *err, size_t n, const char *fmt, va_list ap)
{
	if (err && n > 0)
		vsnprintf(err, n, fmt, ap);
	return -1;
}

int psd_errbuf(char *err, size_t n, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	psd_errbuf_va(err, n, fmt, ap);
	va_end(ap);
	return -1;
}
