/* SPDX-License-Identifier: ISC */
#include "webpass.h"

#include <errno.h>
#include <nettle/pbkdf2.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>

#include "errbuf.h"

enum { SALT = 16, HASH = 32, ITER_MIN = 1000, ITER_MAX = 10000000 };
static const char prefix[] = "pbkdf2-sha256$";

static void hex(const unsigned char *b, size_t n, char *out)
{
	static const char digits[] = "0123456789abcdef";
	for (size_t i = 0; i < n; i++) {
		out[2 * i] = digits[b[i] >> 4];
		out[2 * i + 1] = digits[b[i] & 15];
	}
	out[2 * n] = 0;
}

static int unhex(const char *s, size_t n, unsigned char *out)
{
	for (size_t i = 0; i < n; i++) {
		unsigned v = 0;
		for (int k = 0; k < 2; k++) {
			char c = s[2 * i + k];
			v <<= 4;
			if (c >= '0' && c <= '9')
				v |= (unsigned)(c - '0');
			else if (c >= 'a' && c <= 'f')
				v |= (unsigned)(c - 'a' + 10);
			else
				return -1;
		}
		out[i] = (unsigned char)v;
	}
	return 0;
}

/* Split a stored line: 0 with its parts, -1 with why. */
static int parse(const char *line, unsigned long *iter, unsigned char salt[SALT], unsigned char hash[HASH],
                 char *err, size_t errlen)
{
	const char *p = line;
	char *end;
	if (strncmp(p, prefix, sizeof prefix - 1) != 0) {
		psd_errbuf(err, errlen, "not a psensd password hash (it starts '%s'; make one with psensctl web-passwd FILE)",
		           prefix);
		return -1;
	}
	p += sizeof prefix - 1;
	errno = 0;
	*iter = strtoul(p, &end, 10);
	if (end == p || *end != '$' || errno || *iter < ITER_MIN || *iter > ITER_MAX) {
		psd_errbuf(err, errlen, "the iteration count is not %d to %d", ITER_MIN, ITER_MAX);
		return -1;
	}
	p = end + 1;
	if (strlen(p) != 2 * SALT + 1 + 2 * HASH || p[2 * SALT] != '$' || unhex(p, SALT, salt) != 0 ||
	    unhex(p + 2 * SALT + 1, HASH, hash) != 0) {
		psd_errbuf(err, errlen, "the salt and hash are not %d and %d lower-case hex digits", 2 * SALT, 2 * HASH);
		return -1;
	}
	return 0;
}

int psd_webpass_make(const char *password, unsigned iter, char *out, size_t n)
{
	unsigned char salt[SALT], hash[HASH];
	char s[2 * SALT + 1], h[2 * HASH + 1];
	if (iter < ITER_MIN || iter > ITER_MAX || n < PSD_WEBPASS_LINE) {
		errno = EINVAL;
		return -1;
	}
	if (getrandom(salt, sizeof salt, 0) != (ssize_t)sizeof salt)
		return -1;
	pbkdf2_hmac_sha256(strlen(password), (const uint8_t *)password, iter, sizeof salt, salt, sizeof hash, hash);
	hex(salt, sizeof salt, s);
	hex(hash, sizeof hash, h);
	snprintf(out, n, "%s%u$%s$%s", prefix, iter, s, h);
	return 0;
}

int psd_webpass_valid(const char *line, char *err, size_t errlen)
{
	unsigned long iter;
	unsigned char salt[SALT], hash[HASH];
	return parse(line, &iter, salt, hash, err, errlen) == 0;
}

int psd_webpass_check(const char *line, const char *password)
{
	unsigned long iter;
	unsigned char salt[SALT], want[HASH], got[HASH], diff = 0;
	char err[8];
	if (parse(line, &iter, salt, want, err, sizeof err) != 0)
		return 0;
	pbkdf2_hmac_sha256(strlen(password), (const uint8_t *)password, (unsigned)iter, sizeof salt, salt, sizeof got,
	                   got);
	for (size_t i = 0; i < HASH; i++)   /* every byte, whatever the first differing one */
		diff |= (unsigned char)(got[i] ^ want[i]);
	return diff == 0;
}
