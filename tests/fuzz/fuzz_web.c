/* SPDX-License-Identifier: ISC */
/* Fuzz what a web console request carries (daemon/web/webreq.c, websess.c,
 * webpass.c).  The first byte picks the parser, the rest is its input.
 * Invariants: every answer is 0 or -1 (or 0/1), an output is terminated
 * within its buffer, an accepted form value or cookie is no longer than
 * the input, an accepted request line is printable ASCII whose first word
 * is one the console may send, and no token the fuzzer makes is taken as
 * a session. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "webpass.h"
#include "webreq.h"
#include "websess.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static const char *const words[] = { "ping", "help", "status", "ratios", "target", "override", "release",
	                             "calibrate", "accept-test", NULL };

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	static struct psd_websess sess;
	static int ready;
	char *in, out[64], err[200];
	const char *why;
	int rc;
	if (size < 1 || size > 4096)
		return 0;
	if (!ready) {
		psd_websess_init(&sess, "pbkdf2-sha256$1000$000102030405060708090a0b0c0d0e0f$"
		                        "c914cc4f06cc6e8f46d157e3a1b5aa7abceebb17bb0444cd4c4ac16ca2ae9864", 60);
		ready = 1;
	}
	if (!(in = malloc(size)))
		return 0;
	memcpy(in, data + 1, size - 1);
	in[size - 1] = 0;
	memset(out, 'x', sizeof out);
	memset(err, 'x', sizeof err);
	switch (data[0] % 5) {
	case 0:
		rc = psd_webreq_form(in, data[0] & 8 ? "line" : "password", out, sizeof out);
		if (rc != 0 && rc != -1)
			abort();
		if (rc == 0 && (!memchr(out, 0, sizeof out) || strlen(out) > strlen(in)))
			abort();
		break;
	case 1:
		rc = psd_webreq_cookie(in, "psd_session", out, sizeof out);
		if (rc != 0 && rc != -1)
			abort();
		if (rc == 0 && (!memchr(out, 0, sizeof out) || strlen(out) > strlen(in)))
			abort();
		break;
	case 2:
		rc = psd_webreq_line_ok(in, err, sizeof err);
		if (rc == -1) {
			if (!memchr(err, 0, sizeof err) || !err[0])
				abort();
		} else if (rc == 0) {
			size_t w = strcspn(in, " "), k;
			for (size_t i = 0; in[i]; i++)
				if ((unsigned char)in[i] < 0x20 || (unsigned char)in[i] > 0x7e)
					abort();
			for (k = 0; words[k]; k++)
				if (strlen(words[k]) == w && strncmp(in, words[k], w) == 0)
					break;
			if (!words[k])
				abort();
		} else {
			abort();
		}
		break;
	case 3:
		if (psd_websess_valid(&sess, in, 0, &why) != 0)   /* no forged signature passes */
			abort();
		psd_websess_revoke(&sess, in, 0);
		break;
	default:
		rc = psd_webpass_valid(in, err, sizeof err);
		if (rc != 0 && rc != 1)
			abort();
		if (!rc && (!memchr(err, 0, sizeof err) || !err[0]))
			abort();
		break;
	}
	free(in);
	return 0;
}
