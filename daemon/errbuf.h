/* SPDX-License-Identifier: ISC */
/* The daemon's one way to report a failure to its caller: a message in the
 * caller's buffer and -1.  (sim/ returns struct ps_err; drivers/ set errno
 * and dev->err through ps_dev_fail.) */
#ifndef PSD_ERRBUF_H
#define PSD_ERRBUF_H

#include <stdarg.h>
#include <stddef.h>

/* printf into err (at most n bytes, always terminated); returns -1. */
int psd_errbuf(char *err, size_t n, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
int psd_errbuf_va(char *err, size_t n, const char *fmt, va_list ap) __attribute__((format(printf, 3, 0)));

#endif
