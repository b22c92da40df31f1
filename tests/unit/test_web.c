/* SPDX-License-Identifier: ISC */
/* The web console's checks (daemon/web/): the password hash against
 * Python's hashlib.pbkdf2_hmac, a login token's signature, expiry and
 * revocation, the growing wait after failed logins, the parsing of what
 * a request carries (form fields, the cookie, the control line a page may
 * send), and the charts' ring (spacing, the window, a renamed zone). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include <json-c/json.h>
#include <math.h>
#include <stdlib.h>

#include "webhist.h"
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

/* A logged-out token stays refused until its own expiry, however many
 * logins are logged out after it: 1000 pairs, far more than any table of
 * revocations holds; a login made after them is good. */
static void session_revoked_many(void **state)
{
	static struct psd_websess s;
	char first[PSD_WEBSESS_TOKEN], tok[PSD_WEBSESS_TOKEN];
	const char *why;
	(void)state;
	psd_websess_init(&s, known, 3600);
	assert_int_equal(psd_websess_issue(&s, 1000, first, sizeof first), 0);
	psd_websess_revoke(&s, first, 1001);
	for (int i = 0; i < 1000; i++) {
		assert_int_equal(psd_websess_issue(&s, 1002 + i, tok, sizeof tok), 0);
		assert_int_equal(psd_websess_valid(&s, tok, 1002 + i, &why), 1);
		psd_websess_revoke(&s, tok, 1002 + i);
		assert_int_equal(psd_websess_valid(&s, tok, 1002 + i, &why), 0);
		if (psd_websess_valid(&s, first, 1002 + i, &why))
			fail_msg("the first logged-out token is good again after %d later logouts", i + 1);
	}
	assert_int_equal(psd_websess_issue(&s, 2100, tok, sizeof tok), 0);
	assert_int_equal(psd_websess_valid(&s, tok, 2100, &why), 1);
}

/* Failures from more addresses than the table holds forgive none: an
 * address with 4 failures, then one failure from each of
 * PSD_WEBSESS_ADDRS others, 3 s apart (so that the global rate does not
 * hold anyone); its fifth failure waits 4 s (1, 2, 4 after the three
 * free), not the nothing of a first failure. */
static void guard_no_forgiving(void **state)
{
	static struct psd_websess s;
	char addr[32];
	double t = 100;
	(void)state;
	psd_websess_init(&s, known, 60);
	for (int i = 0; i < 4; i++)
		psd_websess_outcome(&s, "10.0.0.7", 0, t += 3);
	assert_true(psd_websess_wait(&s, "10.0.0.7", t) == 2);
	for (int i = 0; i < PSD_WEBSESS_ADDRS; i++) {
		snprintf(addr, sizeof addr, "10.1.0.%d", i);
		psd_websess_outcome(&s, addr, 0, t += 3);
	}
	psd_websess_outcome(&s, "10.0.0.7", 0, t += 3);
	assert_true(psd_websess_wait(&s, "10.0.0.7", t) == 4);
	/* the addresses that found no room share one count (the last of the
	 * others is its first failure): 3 free, then 1 s */
	for (int i = 0; i < 2; i++) {
		snprintf(addr, sizeof addr, "10.2.0.%d", i);
		assert_true(psd_websess_wait(&s, addr, t) == 0);
		psd_websess_outcome(&s, addr, 0, t += 3);
	}
	assert_true(psd_websess_wait(&s, "10.2.0.99", t) == 1);
}

/* A global rate over every address: PSD_WEBSESS_BURST failures at one
 * instant from as many addresses (one each, none held on its own); the
 * next login from anywhere waits for one failure to leak away, 1 /
 * PSD_WEBSESS_RATE s, half that a quarter of it later... */
static void guard_global(void **state)
{
	static struct psd_websess s;
	char addr[32];
	(void)state;
	psd_websess_init(&s, known, 60);
	for (int i = 0; i < PSD_WEBSESS_BURST - 1; i++) {
		snprintf(addr, sizeof addr, "10.3.0.%d", i);
		psd_websess_outcome(&s, addr, 0, 100);
	}
	assert_true(psd_websess_wait_all(&s, 100) == 0);
	psd_websess_outcome(&s, "10.4.0.1", 0, 100);
	assert_true(fabs(psd_websess_wait_all(&s, 100) - 1 / PSD_WEBSESS_RATE) < 1e-9);
	assert_true(fabs(psd_websess_wait_all(&s, 100 + 0.5 / PSD_WEBSESS_RATE) - 0.5 / PSD_WEBSESS_RATE) < 1e-9);
	assert_true(psd_websess_wait_all(&s, 100 + 1 / PSD_WEBSESS_RATE) == 0);
	assert_true(psd_websess_wait(&s, "10.4.0.1", 100) == 0);   /* one failure: not held on its own */
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

/* The chart's arrays of a zone, parsed back. */
static json_object *chart(const struct psd_webhist *h, const char *zone)
{
	char *text = psd_webhist_json(h, zone);
	json_object *o;
	assert_non_null(text);
	o = json_tokener_parse(text);
	free(text);
	assert_non_null(o);
	return o;
}

static double at(json_object *o, const char *key, size_t i)
{
	json_object *a, *v;
	assert_true(json_object_object_get_ex(o, key, &a));
	v = json_object_array_get_idx(a, i);
	return v ? json_object_get_double(v) : NAN;
}

static size_t count(json_object *o)
{
	json_object *a;
	assert_true(json_object_object_get_ex(o, "t", &a));
	return json_object_array_length(a);
}

static void step(struct psd_webhist *h, struct psd_engine *e, double t, double level, double est, double meas)
{
	e->zone[0].last.t = t;
	e->zone[0].last.level = level;
	e->zone[0].last.est_task_lux = est;
	e->zone[0].last.task_lux = meas;
	psd_webhist_record(h, e);
}

static void charts(void **state)
{
	static struct psd_engine e;
	static struct psd_zone_conf zc = { .name = "office" };
	static struct psd_webhist h;
	const double gap = PSD_WEBHIST_HOURS * 3600.0 / PSD_WEBHIST_POINTS;   /* 7.03 s */
	json_object *o;
	(void)state;
	e.nzone = 1;
	e.zone[0].zc = &zc;
	e.zone[0].last.t = NAN;
	psd_webhist_record(&h, &e);   /* no sample yet: nothing kept */
	o = chart(&h, "office");
	assert_int_equal(count(o), 0);
	json_object_put(o);
	assert_null(psd_webhist_json(&h, "hall"));
	step(&h, &e, 36000, 0.5, 480, 490);
	step(&h, &e, 36000 + gap / 2, 0.6, 470, 480);   /* too soon after it: skipped */
	step(&h, &e, 36000 + gap, 0.7, NAN, 500);     /* a fault: no estimate */
	o = chart(&h, "office");
	assert_int_equal(count(o), 2);
	assert_true(at(o, "t", 0) == 36000 && at(o, "level", 0) == 0.5 && at(o, "est_task_lux", 0) == 480);
	assert_true(at(o, "level", 1) == 0.7 && isnan(at(o, "est_task_lux", 1)) && at(o, "task_lux", 1) == 500);
	assert_true(at(o, "tod_s", 1) == 36000 + gap);
	json_object_put(o);
	/* five hours on, a point a minute: the last four hours are shown */
	for (int m = 1; m <= 300; m++)
		step(&h, &e, 36000 + gap + 60 * m, 0.5, 500, 500);
	o = chart(&h, "office");
	assert_int_equal(count(o), 241);   /* minutes 60 to 300 */
	assert_true(at(o, "t", 0) == 36000 + gap + 3600);
	json_object_put(o);
	/* the zone renamed by a reload: its slot starts again; one gone, freed */
	strcpy(zc.name, "hall");
	step(&h, &e, 60000, 0.2, 300, 310);
	assert_null(psd_webhist_json(&h, "office"));
	o = chart(&h, "hall");
	assert_int_equal(count(o), 1);
	json_object_put(o);
	e.nzone = 0;
	psd_webhist_record(&h, &e);
	assert_null(psd_webhist_json(&h, "hall"));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(pass_known),   cmocka_unit_test(pass_made),   cmocka_unit_test(pass_malformed),
		cmocka_unit_test(session_expiry), cmocka_unit_test(session_guard), cmocka_unit_test(session_revoked_many),
		cmocka_unit_test(guard_no_forgiving), cmocka_unit_test(guard_global), cmocka_unit_test(form_fields),
		cmocka_unit_test(cookies),      cmocka_unit_test(lines),       cmocka_unit_test(charts),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
