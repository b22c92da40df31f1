/* SPDX-License-Identifier: ISC */
/* Errors of the simulation library: a project code and a message that names
 * the file and the line or byte offset.  The library never prints; the tools
 * print ps_err.msg. */
#ifndef PS_ERR_H
#define PS_ERR_H

#include <stddef.h>

enum ps_errcode {
	PS_OK = 0,
	PS_EIO = 1,      /* could not open, read or write a file (errno kept in sys_errno) */
	PS_EFORMAT,      /* malformed input: bad header, truncated data, bad number */
	PS_ERANGE,       /* a value outside what is allowed */
	PS_ENOMEM,       /* out of memory, or an allocation larger than the input allows */
	PS_EINVAL,       /* a bad argument or option from the caller */
	PS_EUNSUPPORTED, /* valid input this code does not handle (says which) */
	PS_EMISSING,     /* something required is absent (a file, a key, a program) */
	PS_ECOUNT
};

struct ps_err {
	int code;          /* enum ps_errcode */
	int sys_errno;     /* errno at the failure for PS_EIO, else 0 */
	char msg[512];     /* "file:line: what is wrong", ready to print */
};

/* Fill *e (may be NULL) and return -1, so callers can write
 * `return ps_err_set(e, PS_EFORMAT, "%s:%d: ...", path, line);` */
int ps_err_set(struct ps_err *e, int code, const char *fmt, ...)
	__attribute__((format(printf, 3, 4)));

/* Like ps_err_set with code PS_EIO and the current errno appended (": No such file"). */
int ps_err_sys(struct ps_err *e, const char *fmt, ...)
	__attribute__((format(printf, 2, 3)));

#endif
