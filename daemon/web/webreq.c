/* SPDX-License-Identifier: ISC */
#include "webreq.h"

#include <string.h>

#include "ctlsock.h"
#include "errbuf.h"

static int hexval(char c)
{
	if (c >= '0' && c <= '9')
		return c - '0';
	if (c >= 'a' && c <= 'f')
		return c - 'a' + 10;
	if (c >= 'A' && c <= 'F')
		return c - 'A' + 10;
	return -1;
}

int psd_webreq_form(const char *body, const char *key, char *out, size_t n)
{
	size_t klen = strlen(key);
	const char *p = body;
	while (p && *p) {
		const char *amp = strchr(p, '&'), *end = amp ? amp : p + strlen(p);
		if ((size_t)(end - p) > klen && strncmp(p, key, klen) == 0 && p[klen] == '=') {
			size_t k = 0;
			for (const char *q = p + klen + 1; q < end; q++) {
				int c = (unsigned char)*q;
				if (c == '+') {
					c = ' ';
				} else if (c == '%') {
					int hi = end - q >= 3 ? hexval(q[1]) : -1, lo = hi >= 0 ? hexval(q[2]) : -1;
					if (lo < 0)
						return -1;
					c = hi * 16 + lo;
					q += 2;
				}
				if (c == 0 || k + 1 >= n)
					return -1;
				out[k++] = (char)c;
			}
			out[k] = 0;
			return 0;
		}
		if (!amp && (size_t)(end - p) == klen && strncmp(p, key, klen) == 0) {   /* "key" alone: empty */
			if (n == 0)
				return -1;
			out[0] = 0;
			return 0;
		}
		p = amp ? amp + 1 : NULL;
	}
	return -1;
}

int psd_webreq_cookie(const char *header, const char *name, char *out, size_t n)
{
	size_t nlen = strlen(name);
	const char *p = header;
	while (p && *p) {
		size_t len;
		p += strspn(p, " \t");
		len = strcspn(p, ";");
		if (len > nlen && strncmp(p, name, nlen) == 0 && p[nlen] == '=') {
			size_t v = len - nlen - 1;
			if (v + 1 > n)
				return -1;
			memcpy(out, p + nlen + 1, v);
			out[v] = 0;
			return 0;
		}
		p = p[len] ? p + len + 1 : NULL;
	}
	return -1;
}

/* What the console sends; tests/unit/test_cmdtab.c checks that it is
 * exactly what the command table grants PSD_CMDTAB_CONSOLE. */
static const char *const allowed[] = { "ping", "help", "status", "ratios", "target", "override", "release",
	                               "calibrate", "accept-test", NULL };

int psd_webreq_line_ok(const char *line, char *err, size_t errlen)
{
	size_t n = strlen(line), w = strcspn(line, " ");
	if (n == 0) {
		psd_errbuf(err, errlen, "empty request");
		return -1;
	}
	if (n >= PSD_CTL_MAX_LINE) {
		psd_errbuf(err, errlen, "the request is %zu bytes: at most %d", n, PSD_CTL_MAX_LINE - 1);
		return -1;
	}
	for (size_t i = 0; i < n; i++)
		if ((unsigned char)line[i] < 0x20 || (unsigned char)line[i] > 0x7e) {
			psd_errbuf(err, errlen, "byte %zu of the request is not printable ASCII", i + 1);
			return -1;
		}
	for (size_t i = 0; allowed[i]; i++)
		if (strlen(allowed[i]) == w && strncmp(line, allowed[i], w) == 0)
			return 0;
	psd_errbuf(err, errlen, "'%.*s' is not a request the web console sends (psensctl has the others)", (int)(w > 40 ? 40 : w),
	           line);
	return -1;
}
