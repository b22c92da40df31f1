/* SPDX-License-Identifier: ISC */
/* The web console's password (psensd.conf(5) [web] password_file): stored
 * as a salted PBKDF2-HMAC-SHA256 hash on one line,
 *   pbkdf2-sha256$ITERATIONS$SALT_HEX$HASH_HEX
 * made by `psensctl web-passwd FILE` and checked in constant time. */
#ifndef PSD_WEBPASS_H
#define PSD_WEBPASS_H

#include <stddef.h>

enum { PSD_WEBPASS_LINE = 200, PSD_WEBPASS_ITER = 60000 };

/* A new hash line of password with a random salt (getrandom) and iter
 * iterations into out (PSD_WEBPASS_LINE bytes).  -1 and errno on failure. */
int psd_webpass_make(const char *password, unsigned iter, char *out, size_t n);
/* 1 when the stored line is well formed (err says what is not otherwise). */
int psd_webpass_valid(const char *line, char *err, size_t errlen);
/* 1 when password matches the stored line, 0 when not (or it is malformed). */
int psd_webpass_check(const char *line, const char *password);

#endif
