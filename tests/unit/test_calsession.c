/* SPDX-License-Identifier: ISC */
/* Calibration sessions against an in-memory SQLite database (and a file for
 * the crash): readings made from known constants must give those constants
 * back exactly, every sample must be on record, and the session must say
 * what the zone should do rather than do it. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

#include "calsession.h"
#include "config.h"
#include "control.h"
#include "db.h"
#include "log.h"
#include "results.h"
#include "scene.h"

#define assert_near(a, b, tol) assert_true(fabs((double)(a) - (double)(b)) <= (tol))

/* The room the readings come from: volts = OFFSET + GAIN_E u + daylight,
 * task lux = LUX_E u + RATIO x daylight volts. */
#define OFFSET 0.05
#define GAIN_E 0.547
#define LUX_E 1264.8
#define RATIO 472.5
#define PERIOD 60.0

struct fixture {
	struct psd_db *db;
	struct psd_zone_conf zc;
	struct psd_control ctl;
	struct ps_result_cond cond[2];
	struct ps_results res;
	struct psd_calsession s;
	struct psd_calsession_ctx c;
	double now;
	int have_reading;         /* the zone's last reading, for a start */
	double volts, level;
	const double *volts_t;    /* when the sensor's value was measured (NULL: now) */
};

static void fixture_init(struct fixture *f, struct psd_db *db, int task)
{
	memset(f, 0, sizeof *f);
	f->db = db;
	snprintf(f->zc.name, sizeof f->zc.name, "office");
	f->zc.sensor = 0;
	f->zc.task = task ? 1 : -1;
	f->zc.period = PERIOD;
	f->zc.cal_window = 4 * PERIOD;
	f->zc.cal_timeout = 60 * PERIOD;
	f->zc.cal_floor = 0.001;
	f->zc.cal_day_samples = 5;
	f->zc.cal_day_interval = 600;
	f->zc.cal_min_day_volts = 0.05;
	f->zc.cal_tolerance = 25;
	f->zc.cal_dark_margin = 0.2;
	f->zc.cal_night_sun = 1;
	f->zc.cal_sun_share = 0.05;
	/* the simulation: 1.094 units at full output, a daylight condition at
	 * 15:00 of 236.25 lux per unit */
	f->ctl.sensor_gain = 0.5;
	f->ctl.offset = OFFSET;
	f->ctl.elec_sensor = GAIN_E / 0.5;
	f->ctl.elec_task_lux = LUX_E;
	f->ctl.daylight_ratio = 236.25;
	f->cond[0] = (struct ps_result_cond){ .label = "day_0318", .kind = PS_COND_DAYLIGHT, .date = "03-18",
	                                      .tod_s = 15 * 3600.0, .computed = 1, .ratio = 236.25 };
	f->cond[1] = (struct ps_result_cond){ .label = "elec", .kind = PS_COND_ELECTRIC, .date = "", .tod_s = -1,
	                                      .computed = 1, .ratio = 1156.68 };
	f->res.cond = f->cond;
	f->res.ncond = 2;
	f->res.scene_hash = "0123";
	f->res.electric_sensor_response = GAIN_E / 0.5;
	f->res.electric_task_lux = LUX_E;
	f->now = 21 * 3600.0;
}

static const struct psd_calsession_ctx *ctx(struct fixture *f)
{
	f->c = (struct psd_calsession_ctx){ f->zc.name, &f->zc, &f->ctl, &f->res, f->db, NULL, f->now, "03-18",
		                             6 * 3600.0, 18.5 * 3600.0, f->have_reading, f->volts, f->level, NAN,
		                             f->volts_t ? *f->volts_t : f->now, f->now };
	return &f->c;
}

/* One control step of the zone: the level the session holds, then its
 * reading one period later (as the engine feeds it). */
static void step(struct fixture *f, double daylight_v, struct psd_calsession_ask *ask)
{
	double u = NAN;
	assert_int_equal(psd_calsession_level(&f->s, f->now, &u), 1);
	f->now += PERIOD;
	psd_calsession_feed(&f->s, ctx(f), OFFSET + GAIN_E * u + daylight_v,
	                    f->zc.task >= 0 ? LUX_E * u + RATIO * daylight_v : NAN, u, ask);
}

static void run_night(struct fixture *f, int levels)
{
	struct psd_calsession_ask ask;
	for (int i = 0; i < 1000 && f->s.npt < levels && psd_calsession_running(&f->s); i++)
		step(f, 0, &ask);
}

struct count {
	int n;
	long long ids[8];
	char states[8][16];   /* copies, not pointers: the struct is returned by value */
};

static void count_session(void *user, const struct psd_db_cal_session *s)
{
	struct count *c = user;
	if (c->n < 8) {
		snprintf(c->states[c->n], sizeof c->states[0], "%s", s->state);
		c->ids[c->n] = s->id;
	}
	c->n++;
}

static void count_sample(void *user, double t, double level, double volts, double se, double lux)
{
	(void)t, (void)level, (void)volts, (void)se, (void)lux;
	(*(int *)user)++;
}

static struct count sessions(struct psd_db *db)
{
	struct count c = { 0 };
	char err[256];
	assert_int_equal(psd_db_cal_sessions(db, "office", count_session, &c, err, sizeof err), 0);
	return c;
}

static int samples_of(struct psd_db *db, long long id)
{
	int n = 0;
	assert_int_equal(psd_db_cal_samples(db, id, count_sample, &n), 0);
	return n;
}

/* A night session settles at each of the six levels, fits the line the
 * readings were made from, records every level, and on accept gives the
 * constants for the engine to apply. */
static void night_to_done_and_accepted(void **state)
{
	char err[512];
	struct fixture f;
	struct psd_calsession_ask ask;
	struct psd_db *db = psd_db_open(":memory:", err, sizeof err);
	(void)state;
	assert_non_null(db);
	fixture_init(&f, db, 1);
	assert_int_equal(psd_calsession_start(&f.s, ctx(&f), PSD_CAL_NIGHT, 0, &ask, err, sizeof err), 0);
	assert_int_equal(ask.step_now, 1);
	assert_int_equal(ask.napply, 0);
	assert_int_equal(f.s.state, PSD_CAL_RUNNING);
	/* a second start is refused and changes nothing */
	assert_int_equal(psd_calsession_start(&f.s, ctx(&f), PSD_CAL_DAY, 0.3, &ask, err, sizeof err), -1);
	assert_non_null(strstr(err, "a night session is running"));
	run_night(&f, PSD_CAL_NLEVELS);
	assert_int_equal(f.s.state, PSD_CAL_DONE);
	assert_int_equal(f.s.npt, PSD_CAL_NLEVELS);
	for (int i = 0; i < PSD_CAL_NLEVELS; i++)
		assert_near(f.s.pt[i].level, psd_calsession_levels[i], 0);
	assert_near(f.s.night.offset, OFFSET, 1e-9);
	assert_near(f.s.night.gain, GAIN_E, 1e-9);
	assert_near(f.s.night.lux_gain, LUX_E, 1e-6);
	assert_int_equal(samples_of(db, f.s.id), PSD_CAL_NLEVELS);
	assert_string_equal(sessions(db).states[0], "done");
	/* the lights are no longer held */
	assert_int_equal(psd_calsession_level(&f.s, f.now, &(double){ 0 }), 0);
	assert_int_equal(psd_calsession_accept(&f.s, ctx(&f), &ask, err, sizeof err), 0);
	assert_int_equal(f.s.state, PSD_CAL_ACCEPTED);
	assert_int_equal(ask.napply, 1);
	assert_int_equal(ask.apply[0].kind, PSD_CAL_NIGHT);
	assert_int_equal(ask.apply[0].id, f.s.id);
	assert_near(ask.apply[0].offset, OFFSET, 1e-9);
	assert_near(ask.apply[0].sensor_gain, 0.5, 1e-9);   /* GAIN_E over the simulated response */
	assert_near(ask.apply[0].elec_task_lux, LUX_E, 1e-6);
	assert_true(isnan(ask.apply[0].daylight_ratio));
	assert_string_equal(sessions(db).states[0], "accepted");
	/* the session never wrote into the zone's constants */
	assert_near(f.ctl.sensor_gain, 0.5, 0);
	assert_near(f.ctl.elec_task_lux, LUX_E, 0);
	psd_db_close(db);
}

/* A day session with a task meter and one typed reading: the measured
 * ratio is the one the readings were made from, compared with the
 * simulated condition nearest in time of day. */
static void day_with_meter_and_typed(void **state)
{
	char err[512];
	struct fixture f;
	struct psd_calsession_ask ask;
	struct psd_db *db = psd_db_open(":memory:", err, sizeof err);
	const double u = 0.3;
	(void)state;
	assert_non_null(db);
	fixture_init(&f, db, 1);
	f.now = 10 * 3600.0;
	assert_int_equal(psd_calsession_start(&f.s, ctx(&f), PSD_CAL_DAY, 1.5, &ask, err, sizeof err), -1);
	assert_non_null(strstr(err, "level 1.5 is outside 0 to 1"));
	assert_int_equal(psd_calsession_start(&f.s, ctx(&f), PSD_CAL_DAY, u, &ask, err, sizeof err), 0);
	/* typed: a hand-held meter's reading waits for the zone's next
	 * reading (a step at once), 1.0 V of daylight as the loop's first */
	assert_int_equal(psd_calsession_typed_lux(&f.s, ctx(&f), LUX_E * u + RATIO * 1.0, OFFSET + GAIN_E * u + 2.0, u,
	                                          &ask, err, sizeof err),
	                 0);
	assert_int_equal(ask.step_now, 1);
	assert_int_equal(f.s.nds, 0);
	assert_non_null(strstr(f.s.msg, "waits for the sensor's next reading"));
	assert_int_equal(psd_calsession_typed_lux(&f.s, ctx(&f), 1e6, 1, u, &ask, err, sizeof err), -1);
	assert_non_null(strstr(err, "outside 0 to 200000"));
	assert_int_equal(psd_calsession_typed_lux(&f.s, ctx(&f), 800, NAN, u, &ask, err, sizeof err), -1);
	assert_non_null(strstr(err, "no good reading"));
	/* the meter every 600 s until five samples in all */
	for (int i = 0; i < 200 && psd_calsession_running(&f.s); i++) {
		double u_held;
		assert_int_equal(psd_calsession_level(&f.s, f.now, &u_held), 1);
		assert_near(u_held, u, 0);
		step(&f, 1.0 + 0.01 * i, &ask);
	}
	assert_int_equal(f.s.state, PSD_CAL_DONE);
	assert_int_equal(f.s.nds, 5);
	assert_int_equal(samples_of(db, f.s.id), 5);
	assert_near(f.s.day.ratio, RATIO, 1e-9);
	assert_near(f.s.day.ratio_se, 0, 1e-9);
	assert_string_equal(f.s.sim_condition, "day_0318");
	assert_near(f.s.sim_ratio, 236.25 / 0.5, 1e-12);
	assert_near(f.s.error_pct, 100 * (236.25 / 0.5 - RATIO) / RATIO, 1e-9);
	assert_int_equal(psd_calsession_accept(&f.s, ctx(&f), &ask, err, sizeof err), 0);
	assert_int_equal(ask.napply, 1);
	assert_near(ask.apply[0].daylight_ratio, RATIO * 0.5, 1e-9);
	assert_true(isnan(ask.apply[0].offset) && isnan(ask.apply[0].sensor_gain));
	psd_db_close(db);
}

/* A sensor that reports by itself, as a DALI-2 304 does: its value is the
 * room's when it was last measured, every `every` seconds at a step, or
 * `lag` seconds after the session asked for a fresh one (the driver's poll
 * answered, and the zone stepped on it at once).  refresh 0: the asks are
 * ignored, as by a driver that cannot poll. */
struct reporter {
	double every, lag, t, v;
	int refresh, asks;
};

static double no_daylight(double t)
{
	(void)t;
	return 0;
}

/* the morning sun on the sensor: 1 V at 10:00, rising 1 V an hour */
static double morning(double t)
{
	return 1.0 + (t - 10 * 3600.0) / 3600.0;
}

static void measure(struct fixture *f, struct reporter *r, double u, double (*daylight)(double))
{
	r->t = f->now;
	r->v = OFFSET + GAIN_E * u + daylight(f->now);
}

static void feed_reported(struct fixture *f, struct reporter *r, double u, double (*daylight)(double),
                          struct psd_calsession_ask *ask)
{
	f->volts_t = &r->t;
	psd_calsession_feed(&f->s, ctx(f), r->v, f->zc.task >= 0 ? LUX_E * u + RATIO * daylight(f->now) : NAN, u,
	                    ask);
}

static void step_reported(struct fixture *f, struct reporter *r, double (*daylight)(double),
                          struct psd_calsession_ask *ask)
{
	double u = NAN;
	assert_int_equal(psd_calsession_level(&f->s, f->now, &u), 1);
	f->now += PERIOD;
	if (f->now - r->t >= r->every)
		measure(f, r, u, daylight);
	feed_reported(f, r, u, daylight, ask);
	if (!ask->refresh_sensor || !psd_calsession_running(&f->s))
		return;
	r->asks++;
	if (!r->refresh)
		return;
	f->now += r->lag;
	measure(f, r, u, daylight);
	assert_int_equal(psd_calsession_level(&f->s, f->now, &u), 1);
	feed_reported(f, r, u, daylight, ask);
	assert_int_equal(ask->refresh_sensor, 0);   /* one ask, one answer: no poll storm */
}

/* A night session on a sensor that reports only on its own (every 30
 * minutes: the events of each level change lost): each level's value is
 * polled once it is commanded, each measurement counts once, and the line
 * comes out exact.  A session that took the repeated old value would
 * record the previous level's volts at each step and settle on them at
 * once (a repeated value has no spread). */
static void night_polls_a_reporting_sensor(void **state)
{
	char err[512];
	struct fixture f;
	struct psd_calsession_ask ask = { 0 };
	struct psd_db *db = psd_db_open(":memory:", err, sizeof err);
	struct reporter r = { 1800, 0.05, 0, 0, 1, 0 };
	(void)state;
	assert_non_null(db);
	fixture_init(&f, db, 0);
	measure(&f, &r, 1, no_daylight);   /* its last report: the lights at full output */
	assert_int_equal(psd_calsession_start(&f.s, ctx(&f), PSD_CAL_NIGHT, 0, &ask, err, sizeof err), 0);
	for (int i = 0; i < 1000 && psd_calsession_running(&f.s); i++)
		step_reported(&f, &r, no_daylight, &ask);
	assert_int_equal(f.s.state, PSD_CAL_DONE);
	assert_int_equal(f.s.npt, PSD_CAL_NLEVELS);
	for (int i = 0; i < PSD_CAL_NLEVELS; i++)
		assert_near(f.s.pt[i].volts, OFFSET + GAIN_E * psd_calsession_levels[i], 1e-12);
	assert_near(f.s.night.offset, OFFSET, 1e-9);
	assert_near(f.s.night.gain, GAIN_E, 1e-9);
	/* a poll at each step but the first of each level's (the one that
	 * commands it): the settling test's 4 readings and no more */
	assert_true(r.asks >= 4 * PSD_CAL_NLEVELS && r.asks <= 6 * PSD_CAL_NLEVELS);
	psd_db_close(db);
}

/* Without a poll (a driver that cannot) the night session waits for the
 * sensor's own reports, every 5 periods, and still counts each once: the
 * same exact line, in more time.  Four repeats of the old level's report
 * would have settled at once on that level's volts. */
static void night_waits_for_reports(void **state)
{
	char err[512];
	struct fixture f;
	struct psd_calsession_ask ask = { 0 };
	struct psd_db *db = psd_db_open(":memory:", err, sizeof err);
	struct reporter r = { 5 * PERIOD, 0, 0, 0, 0, 0 };
	(void)state;
	assert_non_null(db);
	fixture_init(&f, db, 0);
	f.zc.cal_window = 30 * PERIOD;
	measure(&f, &r, 1, no_daylight);
	assert_int_equal(psd_calsession_start(&f.s, ctx(&f), PSD_CAL_NIGHT, 0, &ask, err, sizeof err), 0);
	for (int i = 0; i < 1000 && psd_calsession_running(&f.s); i++)
		step_reported(&f, &r, no_daylight, &ask);
	assert_int_equal(f.s.state, PSD_CAL_DONE);
	for (int i = 0; i < PSD_CAL_NLEVELS; i++)
		assert_near(f.s.pt[i].volts, OFFSET + GAIN_E * psd_calsession_levels[i], 1e-12);
	assert_near(f.s.night.offset, OFFSET, 1e-9);
	assert_near(f.s.night.gain, GAIN_E, 1e-9);
	psd_db_close(db);
}

/* A day session with the morning sun rising 1 V an hour on a sensor that
 * reports every 9 minutes: each sample is the meter paired with the
 * sensor's value polled for it, so the ratio is exact; a report up to 9
 * minutes old would be up to 0.15 V low and the ratio some 5 % high. */
static void day_pairs_the_meter_with_a_fresh_reading(void **state)
{
	char err[512];
	struct fixture f;
	struct psd_calsession_ask ask = { 0 };
	struct psd_db *db = psd_db_open(":memory:", err, sizeof err);
	struct reporter r = { 540, 0.05, 0, 0, 1, 0 };
	const double u = 0.3;
	(void)state;
	assert_non_null(db);
	fixture_init(&f, db, 1);
	f.now = 10 * 3600.0;
	measure(&f, &r, 1, morning);
	assert_int_equal(psd_calsession_start(&f.s, ctx(&f), PSD_CAL_DAY, u, &ask, err, sizeof err), 0);
	for (int i = 0; i < 200 && psd_calsession_running(&f.s); i++)
		step_reported(&f, &r, morning, &ask);
	assert_int_equal(f.s.state, PSD_CAL_DONE);
	assert_int_equal(f.s.nds, 5);
	assert_near(f.s.day.ratio, RATIO, 1e-9);
	assert_near(f.s.pair_skew, 0, 1e-9);   /* the meter read at the step the poll's answer made */
	assert_true(r.asks >= 4 && r.asks <= 5);   /* the first sample's report may be fresh */
	psd_db_close(db);
}

/* Lux typed 30 s after the sensor's last report: the typed sample waits
 * for a fresh value, polled for it, not the report. */
static void typed_lux_waits_for_a_fresh_reading(void **state)
{
	char err[512];
	struct fixture f;
	struct psd_calsession_ask ask = { 0 };
	struct psd_db *db = psd_db_open(":memory:", err, sizeof err);
	struct reporter r = { 540, 0.05, 0, 0, 1, 0 };
	const double u = 0.3;
	double held;
	(void)state;
	assert_non_null(db);
	fixture_init(&f, db, 0);
	f.now = 10 * 3600.0;
	measure(&f, &r, u, morning);
	f.volts_t = &r.t;
	assert_int_equal(psd_calsession_start(&f.s, ctx(&f), PSD_CAL_DAY, u, &ask, err, sizeof err), 0);
	assert_int_equal(psd_calsession_level(&f.s, f.now, &held), 1);
	f.now += 30;
	assert_int_equal(psd_calsession_typed_lux(&f.s, ctx(&f), LUX_E * u + RATIO * morning(f.now + r.lag), r.v, u,
	                                          &ask, err, sizeof err),
	                 0);
	assert_int_equal(ask.step_now, 1);
	feed_reported(&f, &r, u, morning, &ask);   /* the step at once: still the old report */
	assert_int_equal(ask.refresh_sensor, 1);
	assert_int_equal(f.s.nds, 0);
	f.now += r.lag;
	measure(&f, &r, u, morning);
	feed_reported(&f, &r, u, morning, &ask);   /* the poll's answer */
	assert_int_equal(f.s.nds, 1);
	assert_near(f.s.ds[0].volts, OFFSET + GAIN_E * u + morning(f.now), 1e-12);
	assert_near(f.s.ds[0].lux, LUX_E * u + RATIO * morning(f.now), 1e-9);
	psd_db_close(db);
}

/* A fault aborts a running session: on record with the reason, the lights
 * no longer held, and the zone asked to step at once. */
static void abort_on_fault(void **state)
{
	char err[512];
	struct fixture f;
	struct psd_calsession_ask ask;
	struct psd_db *db = psd_db_open(":memory:", err, sizeof err);
	struct count c;
	(void)state;
	fixture_init(&f, db, 0);
	assert_int_equal(psd_calsession_abort(&f.s, ctx(&f), "nothing runs", &ask), -1);
	assert_int_equal(psd_calsession_start(&f.s, ctx(&f), PSD_CAL_NIGHT, 0, &ask, err, sizeof err), 0);
	run_night(&f, 2);
	assert_int_equal(f.s.npt, 2);
	assert_int_equal(psd_calsession_abort(&f.s, ctx(&f), "sensor reads 0.000 V", &ask), 0);
	assert_int_equal(ask.step_now, 1);
	assert_int_equal(f.s.state, PSD_CAL_ABORTED);
	assert_non_null(strstr(f.s.msg, "sensor reads 0.000 V"));
	assert_int_equal(psd_calsession_level(&f.s, f.now, &(double){ 0 }), 0);
	c = sessions(db);
	assert_int_equal(c.n, 1);
	assert_string_equal(c.states[0], "aborted");
	assert_int_equal(psd_calsession_accept(&f.s, ctx(&f), &ask, err, sizeof err), -1);
	assert_non_null(strstr(err, "no finished session to accept (aborted)"));
	/* without a database no session starts */
	f.db = NULL;
	assert_int_equal(psd_calsession_start(&f.s, ctx(&f), PSD_CAL_NIGHT, 0, &ask, err, sizeof err), -1);
	assert_non_null(strstr(err, "set database ="));
	psd_db_close(db);
}

/* psensd killed in the middle of a night session: the next start finds it
 * running in the file, resumes with the levels it had, and finishes with
 * the same line. */
static void resume_after_crash(void **state)
{
	char err[512], path[] = "/tmp/test_calsession.XXXXXX";
	struct fixture f, g;
	struct psd_calsession_ask ask;
	struct psd_db *db;
	int fd = mkstemp(path);
	long long id;
	(void)state;
	assert_true(fd >= 0);
	close(fd);
	db = psd_db_open(path, err, sizeof err);
	assert_non_null(db);
	fixture_init(&f, db, 0);
	assert_int_equal(psd_calsession_start(&f.s, ctx(&f), PSD_CAL_NIGHT, 0, &ask, err, sizeof err), 0);
	run_night(&f, 3);
	assert_int_equal(f.s.npt, 3);
	id = f.s.id;
	psd_db_close(db);   /* the process is gone: nothing ended the session */

	db = psd_db_open(path, err, sizeof err);
	assert_non_null(db);
	fixture_init(&g, db, 0);
	g.now = f.now + 3600;
	psd_calsession_resume(&g.s, ctx(&g), 1.0, &ask);
	assert_int_equal(g.s.state, PSD_CAL_RUNNING);
	assert_int_equal(g.s.id, id);
	assert_int_equal(g.s.kind, PSD_CAL_NIGHT);
	assert_int_equal(g.s.npt, 3);
	assert_int_equal(g.s.step, 3);
	run_night(&g, PSD_CAL_NLEVELS);
	assert_int_equal(g.s.state, PSD_CAL_DONE);
	assert_near(g.s.night.offset, OFFSET, 1e-9);
	assert_near(g.s.night.gain, GAIN_E, 1e-9);
	assert_int_equal(samples_of(db, id), PSD_CAL_NLEVELS);
	assert_int_equal(sessions(db).n, 1);
	psd_db_close(db);
	unlink(path);
}

/* Accepting a second night session supersedes the first, which stays in
 * the history; at the next open the second one's constants are in force. */
static void accept_supersedes(void **state)
{
	char err[512];
	struct fixture f;
	struct psd_calsession_ask ask;
	struct psd_db *db = psd_db_open(":memory:", err, sizeof err);
	long long first, second;
	struct count c;
	(void)state;
	fixture_init(&f, db, 0);
	for (int k = 0; k < 2; k++) {
		assert_int_equal(psd_calsession_start(&f.s, ctx(&f), PSD_CAL_NIGHT, 0, &ask, err, sizeof err), 0);
		run_night(&f, PSD_CAL_NLEVELS);
		assert_int_equal(psd_calsession_accept(&f.s, ctx(&f), &ask, err, sizeof err), 0);
		if (k == 0)
			first = f.s.id;
		else
			second = f.s.id;
	}
	c = sessions(db);
	assert_int_equal(c.n, 2);
	assert_int_equal(c.ids[0], first);
	assert_string_equal(c.states[0], "superseded");
	assert_int_equal(c.ids[1], second);
	assert_string_equal(c.states[1], "accepted");
	psd_calsession_accepted(ctx(&f), &ask);
	assert_int_equal(ask.napply, 1);
	assert_int_equal(ask.apply[0].id, second);
	assert_int_equal(ask.apply[0].kind, PSD_CAL_NIGHT);
	assert_near(ask.apply[0].offset, OFFSET, 1e-9);
	assert_near(ask.apply[0].sensor_gain, 0.5, 1e-9);
	psd_db_close(db);
}

/* A night session in daylight must not take the sun for the offset.  At
 * 11:00 the simulation's sun is up: refused, nothing recorded.  In a room the check
 * of the sun is off for, a reading 3 V above the electric light refuses it
 * too; started without a reading, the settled reading with the lights off
 * (3 V of daylight over the 0.05 V offset) aborts it with the reason. */
static void night_refused_in_daylight(void **state)
{
	char err[512];
	struct fixture f;
	struct psd_calsession_ask ask;
	struct psd_db *db = psd_db_open(":memory:", err, sizeof err);
	(void)state;
	assert_non_null(db);
	fixture_init(&f, db, 1);
	f.now = 11 * 3600.0;
	assert_int_equal(psd_calsession_start(&f.s, ctx(&f), PSD_CAL_NIGHT, 0, &ask, err, sizeof err), -1);
	assert_non_null(strstr(err, "no night session at 11:00: the simulation's sun is up on 03-18 (sunrise 06:00, "
	                            "sunset 18:30)"));
	assert_int_equal(f.s.state, PSD_CAL_IDLE);
	assert_int_equal(sessions(db).n, 0);
	/* the reading: 0.05 + 0.547 x 0.4 + 3 V against at most 0.05 + 0.547 V
	 * (the lamps may still be fading down); the margin 0.2 x 0.547 V */
	f.zc.cal_night_sun = 0;
	f.have_reading = 1;
	f.level = 0.4;
	f.volts = OFFSET + GAIN_E * 0.4 + 3.0;
	assert_int_equal(psd_calsession_start(&f.s, ctx(&f), PSD_CAL_NIGHT, 0, &ask, err, sizeof err), -1);
	assert_non_null(strstr(err, "the sensor reads 3.2688 V with the lights at 40 %, 2.6718 V above the 0.5970 V "
	                            "the offset (0.0500 V) and the electric light at 100 % give"));
	assert_int_equal(sessions(db).n, 0);
	/* just inside the margin it starts */
	f.volts = OFFSET + GAIN_E + 0.19 * GAIN_E;
	assert_int_equal(psd_calsession_start(&f.s, ctx(&f), PSD_CAL_NIGHT, 0, &ask, err, sizeof err), 0);
	psd_calsession_abort(&f.s, ctx(&f), "test", &ask);
	/* no reading yet: the session runs, and the lights-off level aborts it */
	f.have_reading = 0;
	assert_int_equal(psd_calsession_start(&f.s, ctx(&f), PSD_CAL_NIGHT, 0, &ask, err, sizeof err), 0);
	for (int i = 0; i < 1000 && psd_calsession_running(&f.s); i++)
		step(&f, 3.0, &ask);
	assert_int_equal(f.s.state, PSD_CAL_ABORTED);
	assert_int_equal(f.s.npt, PSD_CAL_NLEVELS - 1);
	assert_non_null(strstr(f.s.msg, "daylight in the night session: the sensor reads 3.0500 V with the lights at 0 %, "
	                                "3.0000 V above the 0.0500 V the offset (0.0500 V) and the electric light at 0 % give"));
	assert_string_equal(sessions(db).states[1], "aborted");
	psd_db_close(db);
}

/* A night session begun before sunrise is aborted when the simulation's
 * sun rises, with the time in the reason. */
static void night_aborted_at_sunrise(void **state)
{
	char err[512];
	struct fixture f;
	struct psd_calsession_ask ask;
	struct psd_db *db = psd_db_open(":memory:", err, sizeof err);
	(void)state;
	assert_non_null(db);
	fixture_init(&f, db, 0);
	f.now = 5 * 3600.0 + 50 * 60;
	assert_int_equal(psd_calsession_start(&f.s, ctx(&f), PSD_CAL_NIGHT, 0, &ask, err, sizeof err), 0);
	for (int i = 0; i < 1000 && psd_calsession_running(&f.s); i++)
		step(&f, 0, &ask);
	assert_int_equal(f.s.state, PSD_CAL_ABORTED);
	assert_true(f.now > 6 * 3600.0 && f.now <= 6 * 3600.0 + PERIOD);
	assert_non_null(strstr(f.s.msg, "night session aborted at 06:01: the simulation's sun is up"));
	psd_db_close(db);
}

/* A day session warns when the simulated condition's brightest patch (the
 * sun) carries more than cal_sun_share of the response, and not otherwise. */
static void day_warns_of_sun_in_view(void **state)
{
	char err[512];
	struct fixture f;
	struct psd_calsession_ask ask;
	struct psd_db *db = psd_db_open(":memory:", err, sizeof err);
	(void)state;
	assert_non_null(db);
	fixture_init(&f, db, 1);
	f.now = 14 * 3600.0;
	f.cond[0].brightest_share = 0.0002;   /* the example scene's: sky only */
	assert_int_equal(psd_calsession_start(&f.s, ctx(&f), PSD_CAL_DAY, 0.3, &ask, err, sizeof err), 0);
	assert_string_equal(f.s.sun_warning, "");
	psd_calsession_abort(&f.s, ctx(&f), "test", &ask);
	f.cond[0].brightest_share = 0.3;
	assert_int_equal(psd_calsession_start(&f.s, ctx(&f), PSD_CAL_DAY, 0.3, &ask, err, sizeof err), 0);
	assert_non_null(strstr(f.s.sun_warning, "the sun falls in the sensor's view near 14:00 (simulated day_0318: its "
	                                        "brightest patch gives 30 % of the response"));
	for (int i = 0; i < 200 && psd_calsession_running(&f.s); i++)
		step(&f, 1.0, &ask);
	assert_int_equal(f.s.state, PSD_CAL_DONE);
	assert_non_null(strstr(f.s.msg, "(sun in the sensor's view)"));
	psd_db_close(db);
}

/* A day session without a task meter waits for typed lux, but not
 * forever: after cal_timeout with none it is aborted and says why; a typed
 * reading restarts the wait. */
static void day_without_input_ends(void **state)
{
	char err[512];
	struct fixture f;
	struct psd_calsession_ask ask;
	struct psd_db *db = psd_db_open(":memory:", err, sizeof err);
	(void)state;
	assert_non_null(db);
	fixture_init(&f, db, 0);
	f.now = 10 * 3600.0;
	f.zc.cal_timeout = 30 * PERIOD;
	assert_int_equal(psd_calsession_start(&f.s, ctx(&f), PSD_CAL_DAY, 0.3, &ask, err, sizeof err), 0);
	for (int i = 0; i < 20; i++)
		step(&f, 1.0, &ask);
	assert_int_equal(psd_calsession_typed_lux(&f.s, ctx(&f), 800, 1.2, 0.3, &ask, err, sizeof err), 0);
	for (int i = 0; i < 30; i++)
		step(&f, 1.0, &ask);
	assert_int_equal(f.s.state, PSD_CAL_RUNNING);   /* 30 periods since the typed one: not yet over */
	step(&f, 1.0, &ask);
	assert_int_equal(f.s.state, PSD_CAL_ABORTED);
	assert_non_null(strstr(f.s.msg, "no typed lux for 1860 s (cal_timeout): this zone has no task meter"));
	psd_db_close(db);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(night_to_done_and_accepted),
		cmocka_unit_test(day_with_meter_and_typed),
		cmocka_unit_test(night_polls_a_reporting_sensor),
		cmocka_unit_test(night_waits_for_reports),
		cmocka_unit_test(day_pairs_the_meter_with_a_fresh_reading),
		cmocka_unit_test(typed_lux_waits_for_a_fresh_reading),
		cmocka_unit_test(abort_on_fault),
		cmocka_unit_test(resume_after_crash),
		cmocka_unit_test(accept_supersedes),
		cmocka_unit_test(night_refused_in_daylight),
		cmocka_unit_test(night_aborted_at_sunrise),
		cmocka_unit_test(day_warns_of_sun_in_view),
		cmocka_unit_test(day_without_input_ends),
	};
	psd_log_init(1, PSD_LOG_WARN, "test_calsession");
	return cmocka_run_group_tests(tests, NULL, NULL);
}
