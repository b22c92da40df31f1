/* SPDX-License-Identifier: ISC */
/* The web console's checks (daemon/web/): the password hash against
 * Python's hashlib.pbkdf2_hmac, a login token's signature, expiry and
 * revocation, the growing wait after failed logins, and the parsing of what
 * a request carries (form fields, the cookie, the control line a page may
 * send). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "webpass.h"
#include "webreq.h"
#include "websess.h"

/* hashlib.pbkdf2_hmac('sha256', b'correct horse', bytes(range(16)), 1000).hex() */
static const char known[] = "pbkdf2-sha256$1000$000102030405060708090a0b0c0d0e0f$"
                            "c914cc4f06cc6e8f46d157e3a1b5aa7abceebb17bb0444cd4c4ac16ca2ae9864";

static void pass_known(void **state)
{
	char err[160];
	(void)state;
	assert_int_equal(psd_webpass_valid(known, err, sizeof err), 1);
	assert_int_equal(psd_webpass_check(known, "correct horse"), 1);
	assert_int_equal(psd_webpass_check(known, "correct horse "), 0);
	assert_int_equal(psd_webpass_check(known, "Correct horse"), 0);
	assert_int_equal(psd_webpass_check(known, ""), 0);
}

static void pass_made(void **state)
{
	char a[PSD_WEBPASS_LINE], b[PSD_WEBPASS_LINE];
	(void)state;
	assert_int_equal(psd_webpass_make("on site 42", 1000, a, sizeof a), 0);
	assert_int_equal(psd_webpass_make("on site 42", 1000, b, sizeof b), 0);
	assert_string_not_equal(a, b);   /* a fresh salt each time */
	assert_int_equal(strncmp(a, "pbkdf2-sha256$1000$", 19), 0);
	assert_int_equal(psd_webpass_check(a, "on site 42"), 1);
	assert_int_equal(psd_webpass_check(b, "on site 42"), 1);
	assert_int_equal(psd_webpass_check(a, "on site 43"), 0);
	assert_int_equal(psd_webpass_make("x", 10, a, sizeof a), -1);   /* too few iterations */
}

static void pass_malformed(void **state)
{
	static const char *const bad[] = {
		"",
		"secret",   /* a password in clear, not a hash */
		"pbkdf2-sha1$1000$000102030405060708090a0b0c0d0e0f$c914cc4f06cc6e8f46d157e3a1b5aa7abceebb17bb0444cd4c4ac16ca2ae9864",
		"pbkdf2-sha256$10$000102030405060708090a0b0c0d0e0f$c914cc4f06cc6e8f46d157e3a1b5aa7abceebb17bb0444cd4c4ac16ca2ae9864",
		"pbkdf2-sha256$1000$0001020304050607$c914cc4f06cc6e8f46d157e3a1b5aa7abceebb17bb0444cd4c4ac16ca2ae9864",
		"pbkdf2-sha256$1000$000102030405060708090a0b0c0d0e0f$C914cc4f06cc6e8f46d157e3a1b5aa7abceebb17bb0444cd4c4ac16ca2ae9864",
		"pbkdf2-sha256$1000$000102030405060708090a0b0c0d0e0f$c914cc4f06cc6e8f46d157e3a1b5aa7abceebb17bb0444cd4c4ac16ca2ae98",
		"pbkdf2-sha256$1000$000102030405060708090a0b0c0d0e0f$c914cc4f06cc6e8f46d157e3a1b5aa7abceebb17bb0444cd4c4ac16ca2ae9864 ",
		NULL,
	};
	char err[160];
	(void)state;
	for (int i = 0; bad[i]; i++) {
		err[0] = 0;
		if (psd_webpass_valid(bad[i], err, sizeof err))
			fail_msg("'%s' taken as a hash", bad[i]);
		assert_true(err[0] != 0);
		assert_int_equal(psd_webpass_check(bad[i], "correct horse"), 0);
	}
}

static void session_expiry(void **state)
{
	static struct psd_websess s, other;
	char tok[PSD_WEBSESS_TOKEN], bad[PSD_WEBSESS_TOKEN + 1];
	const char *why;
	(void)state;
	psd_websess_init(&s, known, 60);
	psd_websess_init(&other, "pbkdf2-sha256$1000$ff", 60);
	assert_int_equal(psd_websess_issue(&s, 1000.4, tok, sizeof tok), 0);
	assert_int_equal(strncmp(tok, "1060.", 5), 0);   /* issued at 1000.4 for 60 s: expires at 1060 */
	assert_int_equal(psd_websess_valid(&s, tok, 1000.4, &why), 1);
	assert_int_equal(psd_websess_valid(&s, tok, 1059.9, &why), 1);
	assert_int_equal(psd_websess_valid(&s, tok, 1060, &why), 0);
	assert_string_equal(why, "expired");
	/* another password's key does not sign it */
	assert_int_equal(psd_websess_valid(&other, tok, 1001, &why), 0);
	assert_string_equal(why, "invalid");
	/* one digit of the signature changed; the expiry pushed later */
	snprintf(bad, sizeof bad, "%s", tok);
	bad[strlen(bad) - 1] = bad[strlen(bad) - 1] == '0' ? '1' : '0';
	assert_int_equal(psd_websess_valid(&s, bad, 1001, &why), 0);
	snprintf(bad, sizeof bad, "9%s", tok);
	assert_int_equal(psd_websess_valid(&s, bad, 1001, &why), 0);
	assert_int_equal(psd_websess_valid(&s, "", 1001, &why), 0);
	assert_int_equal(psd_websess_valid(&s, "1060..", 1001, &why), 0);
	/* logged out: refused though signed and unexpired */
	psd_websess_revoke(&s, tok, 1001);
	assert_int_equal(psd_websess_valid(&s, tok, 1002, &why), 0);
	assert_string_equal(why, "invalid");
}

static void session_guard(void **state)
{
	static struct psd_websess s;
	(void)state;
	psd_websess_init(&s, known, 60);
	for (int i = 1; i < PSD_WEBSESS_FREE_FAILS; i++) {
		psd_websess_outcome(&s, "10.0.0.7", 0, 100);
		assert_true(psd_websess_wait(&s, "10.0.0.7", 100) == 0);
	}
	psd_websess_outcome(&s, "10.0.0.7", 0, 100);   /* the third failure: 1 s */
	assert_true(psd_websess_wait(&s, "10.0.0.7", 100) == 1);
	assert_true(psd_websess_wait(&s, "10.0.0.8", 100) == 0);   /* another address is not held */
	psd_websess_outcome(&s, "10.0.0.7", 0, 101);   /* then 2 s, 4 s ... */
	assert_true(psd_websess_wait(&s, "10.0.0.7", 101) == 2);
	psd_websess_outcome(&s, "10.0.0.7", 0, 103);
	assert_true(psd_websess_wait(&s, "10.0.0.7", 103) == 4);
	for (int i = 0; i < 20; i++)
		psd_websess_outcome(&s, "10.0.0.7", 0, 200);
	assert_true(psd_websess_wait(&s, "10.0.0.7", 200) == PSD_WEBSESS_MAX_DELAY);
	psd_websess_outcome(&s, "10.0.0.7", 1, 300);   /* a good login forgets them */
	assert_true(psd_websess_wait(&s, "10.0.0.7", 300) == 0);
	psd_websess_outcome(&s, "10.0.0.7", 0, 300);
	assert_true(psd_websess_wait(&s, "10.0.0.7", 300) == 0);
}

static void form_fields(void **state)
{
	char v[16];
	(void)state;
	assert_int_equal(psd_webreq_form("a=1&password=p%40ss+word&x", "password", v, sizeof v), 0);
	assert_string_equal(v, "p@ss word");
	assert_int_equal(psd_webreq_form("a=1&password=p%40ss+word&x", "a", v, sizeof v), 0);
	assert_string_equal(v, "1");
	assert_int_equal(psd_webreq_form("a=1&x", "x", v, sizeof v), 0);
	assert_string_equal(v, "");
	assert_int_equal(psd_webreq_form("line=", "line", v, sizeof v), 0);
	assert_string_equal(v, "");
	assert_int_equal(psd_webreq_form("aa=1", "a", v, sizeof v), -1);
	assert_int_equal(psd_webreq_form("xa=1", "a", v, sizeof v), -1);
	assert_int_equal(psd_webreq_form("", "a", v, sizeof v), -1);
	assert_int_equal(psd_webreq_form("a=%zz", "a", v, sizeof v), -1);
	assert_int_equal(psd_webreq_form("a=%4", "a", v, sizeof v), -1);
	assert_int_equal(psd_webreq_form("a=%4&b=1", "a", v, sizeof v), -1);
	assert_int_equal(psd_webreq_form("a=x%00y", "a", v, sizeof v), -1);
	assert_int_equal(psd_webreq_form("a=0123456789abcdef", "a", v, sizeof v), -1);   /* 16 + NUL */
	assert_int_equal(psd_webreq_form("a=0123456789abcde", "a", v, sizeof v), 0);
}

static void cookies(void **state)
{
	char v[16];
	(void)state;
	assert_int_equal(psd_webreq_cookie("a=b; psd_session=XYZ; c=d", "psd_session", v, sizeof v), 0);
	assert_string_equal(v, "XYZ");
	assert_int_equal(psd_webreq_cookie("psd_session=1.2.3", "psd_session", v, sizeof v), 0);
	assert_string_equal(v, "1.2.3");
	assert_int_equal(psd_webreq_cookie("xpsd_session=1; psd_sessionx=2", "psd_session", v, sizeof v), -1);
	assert_int_equal(psd_webreq_cookie("psd_session=0123456789abcdefg", "psd_session", v, sizeof v), -1);
	assert_int_equal(psd_webreq_cookie("", "psd_session", v, sizeof v), -1);
}

static void lines(void **state)
{
	char err[200], big[1100];
	(void)state;
	assert_int_equal(psd_webreq_line_ok("status", err, sizeof err), 0);
	assert_int_equal(psd_webreq_line_ok("override office 1 60", err, sizeof err), 0);
	assert_int_equal(psd_webreq_line_ok("calibrate office lux 812", err, sizeof err), 0);
	assert_int_equal(psd_webreq_line_ok("accept-test office", err, sizeof err), 0);
	assert_int_equal(psd_webreq_line_ok("reload", err, sizeof err), -1);
	assert_non_null(strstr(err, "'reload' is not a request the web console sends"));
	assert_int_equal(psd_webreq_line_ok("dali bus scan", err, sizeof err), -1);
	assert_int_equal(psd_webreq_line_ok("statusx", err, sizeof err), -1);
	assert_int_equal(psd_webreq_line_ok("", err, sizeof err), -1);
	assert_int_equal(psd_webreq_line_ok("status office\nreload", err, sizeof err), -1);
	assert_non_null(strstr(err, "byte 14"));
	memset(big, 'a', sizeof big - 1);
	big[sizeof big - 1] = 0;
	memcpy(big, "status ", 7);
	assert_int_equal(psd_webreq_line_ok(big, err, sizeof err), -1);
	assert_non_null(strstr(err, "at most 1023"));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(pass_known),   cmocka_unit_test(pass_made),   cmocka_unit_test(pass_malformed),
		cmocka_unit_test(session_expiry), cmocka_unit_test(session_guard), cmocka_unit_test(form_fields),
		cmocka_unit_test(cookies),      cmocka_unit_test(lines),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
