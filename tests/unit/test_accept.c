/* SPDX-License-Identifier: ISC */
/* Acceptance tests (daemon/accept.h) on logs made to known numbers: every
 * figure checked against the analytic answer, every verdict both ways. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "accept.h"
#include "db.h"

#define assert_near(a, b, tol) assert_true(fabs((double)(a) - (double)(b)) <= (tol))

/* target 500 lx, electric 1000 lx at full output */
#define TARGET 500.0
#define ELEC 1000.0

static void add(struct psd_db *db, double t, double output, double task, double est)
{
	char err[256];
	struct psd_sample s = { t, t, 1.0, output, est, task, 0, 0, "daylight_mean", 236, NULL, "office", NAN, NULL, -1, NAN };
	assert_int_equal(psd_db_add(db, &s, err, sizeof err), 0);
}

static void params(struct psd_accept_params *p)
{
	psd_accept_defaults(p);
	p->target_lux = TARGET;
	p->elec_task_lux = ELEC;
	p->delay = 300;
	p->min_samples = 4;
}

/* A zone that passes: the estimate 2 % high throughout; a sample's
 * daylight is its meter less the electric light at the step before's
 * output.  Dark (daylight 0) at 50 %, 500 lx; bright (1000 lx, 200 %) at
 * 10 %; mid (300 lx, 60 %) at 60 %; one swing down and one up 600 s apart. */
static void passes(void **state)
{
	char err[256];
	struct psd_db *db = psd_db_open(":memory:", err, sizeof err);
	struct psd_accept_params p;
	struct psd_accept_result r[PSD_ACCEPT_NTESTS];
	(void)state;
	assert_non_null(db);
	add(db, 0, 0.5, 500, 510);              /* the first: no step before */
	add(db, 60, 0.5, 500, 510);             /* dark */
	add(db, 120, 0.5, 500, 510);
	add(db, 600, 0.1, 1500, 1530);          /* 1000 lx + 1000 x 0.5: 200 %, answered with 10 % */
	add(db, 660, 0.1, 1100, 1122);
	add(db, 720, 0.1, 1100, 1122);
	add(db, 1200, 0.6, 400, 408);           /* 300 lx + 1000 x 0.1: 60 %, answered with 60 % */
	add(db, 1260, 0.6, 900, 918);
	psd_db_commit(db, err, sizeof err);
	params(&p);
	assert_int_equal(psd_accept_run(db, "office", &p, r, err, sizeof err), 0);
	assert_string_equal(r[0].test, "verification");
	assert_int_equal(r[0].verdict, PSD_ACCEPT_PASS);
	assert_int_equal(r[0].samples, 7);
	assert_near(r[0].value, 2.0, 1e-9);
	assert_non_null(strstr(r[0].measured, "below 50 % of the target in 2, 50-150 % in 2, 150 % and more in 3"));
	assert_int_equal(r[1].verdict, PSD_ACCEPT_PASS);
	assert_int_equal(r[1].samples, 3);
	assert_near(r[1].value, 10, 1e-9);
	assert_int_equal(r[2].verdict, PSD_ACCEPT_PASS);
	assert_int_equal(r[2].samples, 2);
	assert_near(r[2].value, 100, 1e-9);
	/* 0.5 -> 0.1 at 600 s, 0.1 -> 0.6 at 1200 s: one reversal, 600 s apart */
	assert_int_equal(r[3].verdict, PSD_ACCEPT_PASS);
	assert_int_equal(r[3].samples, 1);
	assert_near(r[3].value, 600, 1e-9);
	psd_db_close(db);
}

/* A zone that fails each test: the estimate 30 % off once, the lights at
 * 40 % in full daylight (the wrong night calibration held them at
 * 40 %), 440 lx in the dark (88 %), swings 60 s apart. */
static void fails(void **state)
{
	char err[256];
	struct psd_db *db = psd_db_open(":memory:", err, sizeof err);
	struct psd_accept_params p;
	struct psd_accept_result r[PSD_ACCEPT_NTESTS];
	(void)state;
	assert_non_null(db);
	add(db, 0, 0.5, 440, 500);              /* dark, 88 % (a weak lamp); estimate +13.6 % */
	add(db, 60, 0.4, 1400, 1400);           /* daylight 1000 lx at 40 % */
	add(db, 120, 0.5, 440, 440);
	add(db, 180, 0.4, 1400, 1820);          /* +30 % */
	psd_db_commit(db, err, sizeof err);
	params(&p);
	assert_int_equal(psd_accept_run(db, "office", &p, r, err, sizeof err), 0);
	assert_int_equal(r[0].verdict, PSD_ACCEPT_FAIL);
	assert_non_null(strstr(r[0].measured, "worst 30.00 %"));
	assert_int_equal(r[0].samples, 3);   /* the first has no step before */
	assert_near(r[0].value, 100 * sqrt(pow(0.3, 2) / 3), 1e-9);
	assert_int_equal(r[1].verdict, PSD_ACCEPT_FAIL);
	assert_near(r[1].value, 40, 1e-9);
	assert_non_null(strstr(r[1].measured, "at most 40.0 % (at most 35 %)"));
	assert_int_equal(r[2].verdict, PSD_ACCEPT_FAIL);
	assert_near(r[2].value, 88, 1e-9);
	assert_int_equal(r[3].verdict, PSD_ACCEPT_FAIL);
	assert_near(r[3].value, 60, 1e-9);
	assert_int_equal(r[3].samples, 2);
	psd_db_close(db);
}

/* No sample in a test's range: NOT TESTED, never a pass; a window after
 * every sample judges none. */
static void not_tested(void **state)
{
	char err[256];
	struct psd_db *db = psd_db_open(":memory:", err, sizeof err);
	struct psd_accept_params p;
	struct psd_accept_result r[PSD_ACCEPT_NTESTS];
	(void)state;
	assert_non_null(db);
	add(db, 0, 0.6, 900, 900);              /* 60 % daylight only */
	add(db, 60, 0.6, 900, 900);
	psd_db_commit(db, err, sizeof err);
	params(&p);
	assert_int_equal(psd_accept_run(db, "office", &p, r, err, sizeof err), 0);
	assert_int_equal(r[0].verdict, PSD_ACCEPT_FAIL);   /* one sample judged, one band */
	assert_int_equal(r[0].samples, 1);
	assert_int_equal(r[1].verdict, PSD_ACCEPT_NOT_TESTED);
	assert_int_equal(r[2].verdict, PSD_ACCEPT_NOT_TESTED);
	p.since_utc = 1e12;
	assert_int_equal(psd_accept_run(db, "office", &p, r, err, sizeof err), 0);
	assert_int_equal(r[0].verdict, PSD_ACCEPT_NOT_TESTED);
	psd_db_close(db);
}

/* Every test judges the control, not a calibration session that held the
 * lights nor the fade out of it: a day session at 50 % in full daylight
 * (and the jumps into and out of it) and the settle_s (60 s) after it are
 * left out of every test, the verification among them, and the
 * verification says so.  The session runs from 600 to 1200 s; at 1200.2 s
 * the lamps are still at the session's level while the control's estimate
 * is for its own (the estimate 2.4 times the meter, as a real log showed). */
static void sessions_left_out(void **state)
{
	char err[256];
	struct psd_db *db = psd_db_open(":memory:", err, sizeof err);
	struct psd_accept_params p;
	struct psd_accept_result r[PSD_ACCEPT_NTESTS];
	long long id;
	(void)state;
	assert_non_null(db);
	psd_db_set_epoch(db, 0);
	add(db, 0, 0.1, 1100, 1100);            /* first: no step before */
	add(db, 60, 0.1, 1100, 1100);           /* 1000 lx daylight, 200 %, at 10 % */
	id = psd_db_cal_begin(db, "office", "day", 600, NULL, NULL, err, sizeof err);
	assert_true(id > 0);
	add(db, 660, 0.5, 1100, 1100);          /* held at 50 %: answered to 10 % */
	add(db, 720, 0.5, 1500, 1500);          /* 1000 lx + 500: held at 50 % */
	add(db, 780, 0.5, 1500, 1500);
	assert_int_equal(psd_db_cal_end(db, id, "done", 1200, NULL, NULL, err, sizeof err), 0);
	add(db, 1200.2, 0.1, 1500, 3600);       /* the fade: readings at 50 %, the estimate for 10 % */
	add(db, 1260, 0.1, 1500, 1500);         /* still within 60 s of the end */
	add(db, 1320, 0.1, 1100, 1100);         /* the control again, at 10 % since 1200 */
	add(db, 1380, 0.1, 1100, 1122);         /* 2 % high */
	psd_db_commit(db, err, sizeof err);
	params(&p);
	assert_int_equal(psd_accept_run(db, "office", &p, r, err, sizeof err), 0);
	assert_int_equal(r[0].samples, 3);      /* 60, 1320, 1380 */
	assert_near(r[0].value, 100 * sqrt(0.02 * 0.02 / 3), 1e-9);
	assert_non_null(strstr(r[0].measured, "; 5 samples in 1 calibration session and the 60 s after each left out"));
	assert_int_equal(r[1].verdict, PSD_ACCEPT_PASS);
	assert_int_equal(r[1].samples, 3);      /* 60, 1320, 1380 (daylight 1000 lx at 10 %) */
	assert_near(r[1].value, 10, 1e-9);
	assert_int_equal(r[3].verdict, PSD_ACCEPT_PASS);
	assert_int_equal(r[3].samples, 0);      /* up into the session and down out of it: no reversal */
	/* no settling asked: the fade sample is judged, and it fails the verification */
	p.settle_s = 0;
	assert_int_equal(psd_accept_run(db, "office", &p, r, err, sizeof err), 0);
	assert_int_equal(r[0].samples, 5);
	assert_true(r[0].value > 50);
	psd_db_close(db);
}

/* Two runs of psensd on one log: a new run starts its lights from its
 * own initial level and its clock from its own day, so the step from the
 * last sample of one run to the first of the next is neither the
 * control's cycling nor a sample whose lights' level is known.  Run A
 * ends at 10 % at 19:27 on day 0; run B starts on a later day at 10:00
 * (its clock t lower than A's) at full output and dims to 10 %. */
static void runs_apart(void **state)
{
	char err[256];
	struct psd_db *db = psd_db_open(":memory:", err, sizeof err);
	struct psd_accept_params p;
	struct psd_accept_result r[PSD_ACCEPT_NTESTS];
	(void)state;
	assert_non_null(db);
	psd_db_set_epoch(db, 0);
	assert_int_equal(psd_db_event(db, 69000, NULL, "start", "run A", err, sizeof err), 0);
	add(db, 70000, 0.5, 500, 500);          /* first of run A */
	add(db, 70060, 0.1, 1500, 1500);        /* down */
	add(db, 70120, 0.1, 1100, 1100);
	psd_db_set_epoch(db, 200000);
	assert_int_equal(psd_db_event(db, 36000, NULL, "start", "run B", err, sizeof err), 0);
	add(db, 36000, 1.0, 1100, 1100);        /* first of run B: up, but not an answer to anything */
	add(db, 36060, 0.1, 2000, 2000);        /* down */
	add(db, 36120, 0.1, 1100, 1100);
	psd_db_commit(db, err, sizeof err);
	params(&p);
	assert_int_equal(psd_accept_run(db, "office", &p, r, err, sizeof err), 0);
	assert_int_equal(r[0].samples, 4);      /* 70060, 70120, 36060, 36120 */
	assert_int_equal(r[3].verdict, PSD_ACCEPT_PASS);
	assert_int_equal(r[3].samples, 0);      /* no reversal inside either run */
	assert_non_null(strstr(r[3].measured, "no reversal"));

	/* rows from before dates (no utc, no events): the clock going back
	 * is the only sign of a new run, and it is enough */
	psd_db_close(db);
	db = psd_db_open(":memory:", err, sizeof err);
	assert_non_null(db);
	add(db, 70000, 0.5, 500, 500);
	add(db, 70060, 0.1, 1500, 1500);
	add(db, 36000, 1.0, 1100, 1100);
	add(db, 36060, 0.1, 2000, 2000);
	psd_db_commit(db, err, sizeof err);
	assert_int_equal(psd_accept_run(db, "office", &p, r, err, sizeof err), 0);
	assert_int_equal(r[0].samples, 2);
	assert_int_equal(r[3].samples, 0);
	psd_db_close(db);
}

static void add_occ(struct psd_db *db, double t, double output, int occupied)
{
	char err[256];
	struct psd_sample s = { t, t, 1.0, output, 500, 500, 0, 0, "daylight_mean", 236, NULL, "office", NAN, NULL,
		                occupied, NAN };
	assert_int_equal(psd_db_add(db, &s, err, sizeof err), 0);
}

/* The occupancy test (hold 900 s, vacant level 0, steps every 60 s): a
 * vacancy at 1000 s is judged at the first sample at or after 1900 s, an
 * arrival by its own sample; a zone with no occupancy in its log has no
 * such test (four apply), one with it five.  The failing log keeps the
 * lights at 0.4 at the first step after the hold, and leaves them off at
 * an arrival; a hold of 1500 s is past the codes' 20 minutes. */
static void occupancy(void **state)
{
	char err[256];
	struct psd_db *db = psd_db_open(":memory:", err, sizeof err), *bad = psd_db_open(":memory:", err, sizeof err);
	struct psd_accept_params p;
	struct psd_accept_result r[PSD_ACCEPT_NTESTS];
	struct psd_accept_summary sum;
	(void)state;
	assert_non_null(db);
	assert_non_null(bad);
	for (double t = 0; t <= 4000; t += 60) {
		int occ = !(t >= 1000 && t < 3000);
		/* the vacancy's own sample at 1000 s, off from 1900 s, on at the arrival */
		add_occ(db, t, occ ? 0.4 : t >= 1900 ? 0 : 0.4, occ);
		add_occ(bad, t, occ ? (t >= 3000 && t < 3100 ? 0 : 0.4) : t >= 1960 ? 0 : 0.4, occ);
		if (t == 960) {
			add_occ(db, 1000, 0.4, 0);
			add_occ(bad, 1000, 0.4, 0);
		}
	}
	psd_db_commit(db, err, sizeof err);
	psd_db_commit(bad, err, sizeof err);
	params(&p);
	/* no occupancy constants: no occupancy test, whatever the log */
	assert_int_equal(psd_accept_run(db, "office", &p, r, err, sizeof err), 0);
	assert_null(r[4].test);
	psd_accept_summarize(r, &sum);
	assert_int_equal(sum.count, 4);
	p.vacancy_hold = 900;
	p.vacant_level = 0;
	assert_int_equal(psd_accept_run(db, "office", &p, r, err, sizeof err), 0);
	assert_string_equal(r[4].test, "occupancy");
	assert_int_equal(r[4].verdict, PSD_ACCEPT_PASS);
	assert_near(r[4].value, 1900 - 1000 + 20, 1e-9);   /* first sample at or after 1900: 1920 */
	assert_int_equal(r[4].samples, 2);                  /* one vacancy, one arrival */
	psd_accept_summarize(r, &sum);
	assert_int_equal(sum.count, 5);
	assert_int_equal(psd_accept_run(bad, "office", &p, r, err, sizeof err), 0);
	assert_int_equal(r[4].verdict, PSD_ACCEPT_FAIL);
	assert_non_null(strstr(r[4].measured, "in 0 of 1 vacancies"));
	assert_non_null(strstr(r[4].measured, "the lights on at 0 of 1 arrivals"));
	p.vacancy_hold = 1500;   /* judged at 2520: off, but the hold is too long */
	assert_int_equal(psd_accept_run(db, "office", &p, r, err, sizeof err), 0);
	assert_int_equal(r[4].verdict, PSD_ACCEPT_FAIL);
	psd_db_close(db);
	psd_db_close(bad);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(passes),
		cmocka_unit_test(fails),
		cmocka_unit_test(not_tested),
		cmocka_unit_test(occupancy),
		cmocka_unit_test(sessions_left_out),
		cmocka_unit_test(runs_apart),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
