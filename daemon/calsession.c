/* SPDX-License-Identifier: ISC */
/* Calibration sessions (see calsession.h). */
#include "calsession.h"

#include <json-c/json.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cache.h"
#include "clock.h"
#include "config.h"
#include "control.h"
#include "db.h"
#include "errbuf.h"
#include "json.h"
#include "log.h"
#include "results.h"

const double psd_calsession_levels[PSD_CAL_NLEVELS] = { 1.0, 0.75, 0.5, 0.25, 0.1, 0.0 };
const char *const psd_calsession_kind_names[] = { "none", "night", "day", NULL };
const char *const psd_calsession_state_names[] = { "idle", "running", "done", "aborted", "accepted", NULL };

/* The date and time of now for log lines ("YYYY-MM-DD HH:MM"). */
static const char *stamp(const struct psd_calsession_ctx *c, char out[24])
{
	psd_clock_stamp(c->epoch0, c->now, out, 24);
	return out;
}

/* A session's event in the database (a record: a failure is only logged). */
static void event(const struct psd_calsession_ctx *c, const char *kind, const char *text)
{
	char err[512];
	if (c->db && psd_db_event(c->db, c->now, c->zone, kind, text, err, sizeof err) != 0)
		psd_log_warnx("%s", err);
}

int psd_calsession_running(const struct psd_calsession *s)
{
	return s->state == PSD_CAL_RUNNING;
}

static void settle_reset(struct psd_calsession *s, const struct psd_calsession_ctx *c)
{
	psd_calfit_settle_init(&s->settle, c->zc->cal_window, 4, 3.0, c->zc->cal_floor);
	s->step_started = c->now;
	s->nlux = 0;
	s->level_since = INFINITY;   /* readings count once the level is commanded */
	s->commanded = -1;
	s->asked_at = -INFINITY;
}

/* A new session: its state, and its constants from the zone's configuration. */
static void begin(struct psd_calsession *s, const struct psd_calsession_ctx *c, int kind, long long id,
                  double started, double level)
{
	memset(s, 0, sizeof *s);
	s->kind = kind;
	s->state = PSD_CAL_RUNNING;
	s->id = id;
	s->started = started;
	s->settle_timeout = c->zc->cal_timeout;
	s->hold_level = level;
	s->interval = c->zc->cal_day_interval;
	s->want_samples = (int)c->zc->cal_day_samples;
	s->next_sample = c->now;
	s->last_input = c->now;
	s->fed_t = s->fed_lux_t = -INFINITY;
	s->pair_skew = -1;
	s->typed_lux = NAN;
	settle_reset(s, c);
}

/* The full-output electric signal the simulation expects (volts); NAN when
 * the model has no electric condition. */
static double elec_volts(const struct psd_calsession_ctx *c)
{
	double g = c->ctl->sensor_gain * c->ctl->elec_sensor;
	return g > 0 ? g : NAN;
}

/* 1 when the simulation's sun is up at clock time t (and the zone checks it). */
static int sun_up(const struct psd_calsession_ctx *c, double t)
{
	double tod = psd_clock_tod(t);
	return c->zc->cal_night_sun && c->sunset > c->sunrise && tod > c->sunrise && tod < c->sunset;
}

static int sun_refusal(const struct psd_calsession_ctx *c, const char *what, char *err, size_t n)
{
	char t[8], r[8], st[8];
	psd_clock_hhmm(c->now, t);
	psd_clock_hhmm(c->sunrise, r);
	psd_clock_hhmm(c->sunset, st);
	return psd_errbuf(err, n, "zone %s: %s at %s: the simulation's sun is up on %s (sunrise %s, sunset %s), and "
	                "daylight on the sensor would be taken for its offset; run it after %s or before %s "
	                "(cal_night_sun = no for a room no daylight reaches)", c->zone, what, t,
	                c->date && *c->date ? c->date : "the simulated day", r, st, st, r);
}

/* Daylight (or any light but the zone's) in a reading: -1 with the reason
 * when it exceeds what the offset in force and the electric light at level
 * `at` give by more than cal_dark_margin of the full-output signal (gain:
 * that signal, volts).  `commanded` is the output the zone was told; at the
 * start of a session the lamps may still be fading from an earlier level,
 * so there `at` is full output, the most the lights can give. */
static int dark_check(const struct psd_calsession_ctx *c, const char *what, double volts, double at,
                      double commanded, double gain, char *err, size_t n)
{
	double want = c->ctl->offset + gain * at, margin = c->zc->cal_dark_margin * gain;
	if (!(gain > 0) || !isfinite(volts) || volts - want <= margin)
		return 0;
	return psd_errbuf(err, n, "zone %s: %s: the sensor reads %.4f V with the lights at %.0f %%, %.4f V above "
	                "the %.4f V the offset (%.4f V) and the electric light at %.0f %% give, more than "
	                "cal_dark_margin %g of the full-output signal (%.4f V): daylight or another light "
	                "reaches the sensor, and a night calibration would take it for the offset", c->zone, what,
	                volts, 100 * commanded, volts - want, want, c->ctl->offset, 100 * at, c->zc->cal_dark_margin,
	                margin);
}

/* The nearest simulated daylight condition's brightest patch: the sun in
 * the sensor's view when it carries more than cal_sun_share of the
 * response.  Warns (and notes it in the message) once. */
static void sun_in_view(struct psd_calsession *s, const struct psd_calsession_ctx *c, double tod)
{
	const struct ps_result_cond *best = NULL;
	double d = INFINITY;
	char t[8];
	for (size_t i = 0; c->res && i < c->res->ncond; i++) {
		const struct ps_result_cond *rc = &c->res->cond[i];
		if (rc->computed && rc->tod_s >= 0 && fabs(rc->tod_s - tod) < d) {
			d = fabs(rc->tod_s - tod);
			best = rc;
		}
	}
	if (!best || !(c->zc->cal_sun_share > 0) || !(best->brightest_share > c->zc->cal_sun_share))
		return;
	psd_clock_hhmm(tod, t);
	snprintf(s->sun_warning, sizeof s->sun_warning, "the sun falls in the sensor's view near %s (simulated "
	         "%s: its brightest patch gives %.0f %% of the response, above cal_sun_share %g); the ratio "
	         "will swing with the sun and the clouds: prefer a time without it", t, best->label,
	         100 * best->brightest_share, c->zc->cal_sun_share);
	psd_log_warnx("zone %s: %s: day calibration: %s", c->zone, stamp(c, (char[24]){ 0 }), s->sun_warning);
}

int psd_calsession_start(struct psd_calsession *s, const struct psd_calsession_ctx *c, int kind, double level,
                         struct psd_calsession_ask *ask, char *err, size_t n)
{
	char cfg[65] = "", scene[65] = "";
	struct ps_err pe;
	long long id;
	memset(ask, 0, sizeof *ask);
	if (!c->db)
		return psd_errbuf(err, n, "calibration sessions are recorded in the database: set database = in [psensd]");
	if (s->state == PSD_CAL_RUNNING)
		return psd_errbuf(err, n, "zone %s: a %s session is running (abort it first)", c->zone,
		                psd_calsession_kind_names[s->kind]);
	if (kind != PSD_CAL_NIGHT && kind != PSD_CAL_DAY)
		return psd_errbuf(err, n, "no calibration of kind %d", kind);
	if (kind == PSD_CAL_DAY && !(level >= 0 && level <= 1))
		return psd_errbuf(err, n, "level %g is outside 0 to 1", level);
	/* a night session in daylight would fit daylight as the offset */
	if (kind == PSD_CAL_NIGHT && sun_up(c, c->now))
		return sun_refusal(c, "no night session", err, n);
	if (kind == PSD_CAL_NIGHT && c->have_reading &&
	    dark_check(c, "no night session", c->volts, 1.0, c->level, elec_volts(c), err, n) != 0)
		return -1;
	if (!c->config_path || ps_cache_hash_file(c->config_path, cfg, &pe) != 0)
		cfg[0] = 0;
	snprintf(scene, sizeof scene, "%s", c->res && c->res->scene_hash ? c->res->scene_hash : "");
	id = psd_db_cal_begin(c->db, c->zone, psd_calsession_kind_names[kind], c->now, cfg, scene, err, n);
	if (id < 0)
		return -1;
	begin(s, c, kind, id, c->now, level);
	snprintf(s->msg, sizeof s->msg, "%s", kind == PSD_CAL_NIGHT ? "settling at 100 %" :
	         c->zc->task >= 0 ? "sampling the task meter" : "waiting for typed lux (calibrate ZONE lux N)");
	ask->step_now = 1;
	{
		char ts[24], text[96];
		psd_log_info("zone %s: %s: %s calibration session %lld started", c->zone, stamp(c, ts),
		         psd_calsession_kind_names[kind], s->id);
		snprintf(text, sizeof text, "%s session %lld", psd_calsession_kind_names[kind], s->id);
		event(c, "calibration started", text);
	}
	if (kind == PSD_CAL_DAY)
		sun_in_view(s, c, psd_clock_tod(c->now));
	return 0;
}

int psd_calsession_abort(struct psd_calsession *s, const struct psd_calsession_ctx *c, const char *why,
                         struct psd_calsession_ask *ask)
{
	char err[512];
	memset(ask, 0, sizeof *ask);
	if (s->state != PSD_CAL_RUNNING)
		return -1;
	s->state = PSD_CAL_ABORTED;
	snprintf(s->msg, sizeof s->msg, "aborted: %s", why);
	if (c->db && psd_db_cal_end(c->db, s->id, "aborted", c->now, NULL, why, err, sizeof err) != 0)
		psd_log_warnx("%s", err);
	{
		char ts[24];
		psd_log_warnx("zone %s: %s: calibration session %lld aborted: %s", c->zone, stamp(c, ts), s->id, why);
		event(c, "calibration aborted", why);
	}
	ask->step_now = 1;
	return 0;
}

/* The nearest daylight condition in time of day: its ratio in lux per volt
 * at the zone's sensor gain. */
static void nearest_condition(struct psd_calsession *s, const struct psd_calsession_ctx *c, double tod)
{
	double best = INFINITY;
	s->sim_ratio = NAN;
	s->sim_condition[0] = 0;
	for (size_t i = 0; c->res && i < c->res->ncond; i++) {
		const struct ps_result_cond *rc = &c->res->cond[i];
		double d = fabs(rc->tod_s - tod);
		if (!rc->computed || rc->tod_s < 0 || !(rc->ratio > 0) || d >= best)
			continue;
		best = d;
		s->sim_ratio = rc->ratio / c->ctl->sensor_gain;
		snprintf(s->sim_condition, sizeof s->sim_condition, "%s", rc->label);
	}
}

static char *results_json(const struct psd_calsession *s, const struct psd_calsession_ctx *c)
{
	json_object *o = json_object_new_object();
	char *out;
#define NUM(k, v) psd_json_num(o, k, v)
	if (s->kind == PSD_CAL_NIGHT) {
		const struct psd_calfit_line *f = &s->night;
		double es = c->res ? c->res->electric_sensor_response : NAN;
		double el = c->res ? c->res->electric_task_lux : NAN;
		NUM("offset", f->offset);
		NUM("offset_se", f->offset_se);
		NUM("gain", f->gain);
		NUM("gain_se", f->gain_se);
		NUM("r2", f->r2);
		NUM("max_resid_pct", f->max_resid_pct);
		NUM("lux_gain", f->lux_gain);
		NUM("lux_gain_se", f->lux_gain_se);
		NUM("sensor_gain", f->gain / es);
		NUM("sensor_gain_se", f->gain_se / es);
		NUM("sim_electric_lux", el);
		NUM("electric_lux_error_pct", psd_calfit_error_pct(el, f->lux_gain));
		json_object_object_add(o, "levels", json_object_new_int(s->npt));
	} else {
		const struct psd_calfit_ratio *f = &s->day;
		NUM("ratio", f->ratio);
		NUM("ratio_se", f->ratio_se);
		NUM("sd", f->sd);
		json_object_object_add(o, "samples", json_object_new_int((int)f->n));
		NUM("mean_tod_s", f->mean_tod);
		if (s->pair_skew >= 0)
			NUM("pair_skew_s", s->pair_skew);
		NUM("sim_ratio", s->sim_ratio);
		json_object_object_add(o, "condition", json_object_new_string(s->sim_condition));
		NUM("error_pct", s->error_pct);
		NUM("sensor_gain", c->ctl->sensor_gain);
		NUM("daylight_ratio", f->ratio * c->ctl->sensor_gain);
		NUM("offset", c->ctl->offset);
		if (s->sun_warning[0])
			json_object_object_add(o, "sun_warning", json_object_new_string(s->sun_warning));
	}
#undef NUM
	out = strdup(psd_json_text(o, 10));
	json_object_put(o);
	return out;
}

/* ", sensor and meter at most X s apart" for meter samples, else "" */
static const char *skew_text(const struct psd_calsession *s, char *out, size_t n)
{
	if (s->pair_skew >= 0)
		snprintf(out, n, ", sensor and meter at most %.2f s apart", s->pair_skew);
	return out;
}

static int finish(struct psd_calsession *s, const struct psd_calsession_ctx *c, struct psd_calsession_ask *ask,
                  char *err, size_t n)
{
	const struct psd_control *k = c->ctl;
	char *json;
	int rc, outside = 0;   /* a day session off the design by more than cal_tolerance */
	if (s->kind == PSD_CAL_NIGHT) {
		if (psd_calfit_night(s->pt, (size_t)s->npt, &s->night, err, n) != 0)
			return -1;
	} else {
		if (psd_calfit_day(s->ds, (size_t)s->nds, k->offset, k->sensor_gain * k->elec_sensor, k->elec_task_lux,
		                   c->zc->cal_min_day_volts, &s->day, err, n) != 0)
			return -1;
		nearest_condition(s, c, s->day.mean_tod);
		if (!s->sun_warning[0])
			sun_in_view(s, c, s->day.mean_tod);
		s->error_pct = psd_calfit_error_pct(s->sim_ratio, s->day.ratio);
		outside = !(fabs(s->error_pct) <= c->zc->cal_tolerance);
	}
	if (!(json = results_json(s, c)))
		return psd_errbuf(err, n, "out of memory");
	rc = psd_db_cal_end(c->db, s->id, "done", c->now, json, NULL, err, n);
	free(json);
	if (rc != 0)
		return -1;
	s->state = PSD_CAL_DONE;
	if (s->kind == PSD_CAL_NIGHT)
		snprintf(s->msg, sizeof s->msg, "done: offset %.4f V, %.4f V at full output (se %.4f), "
		         "R2 %.6f; accept to use it", s->night.offset, s->night.gain, s->night.gain_se, s->night.r2);
	else
		snprintf(s->msg, sizeof s->msg, "done: %.2f lux per volt (se %.2f) from %zu samples%s; "
		         "simulated %.2f (%s): %+.1f %%, %s the %g %% tolerance%s", s->day.ratio, s->day.ratio_se,
		         s->day.n, skew_text(s, (char[64]){ 0 }, 64), s->sim_ratio, s->sim_condition, s->error_pct,
		         outside ? "outside" : "within",
		         c->zc->cal_tolerance,
		         outside ? " (the sensor moved or covered, the wrong filter, or a scene unlike the room?); "
		                   "accept to use it anyway" : "; accept to use it");
	if (s->kind == PSD_CAL_DAY && s->sun_warning[0])
		snprintf(s->msg + strlen(s->msg), sizeof s->msg - strlen(s->msg), " (sun in the sensor's view)");
	{
		char ts[24];
		if (outside)
			psd_log_warnx("zone %s: %s: calibration session %lld %s", c->zone, stamp(c, ts), s->id, s->msg);
		else
			psd_log_info("zone %s: %s: calibration session %lld %s", c->zone, stamp(c, ts), s->id, s->msg);
		event(c, "calibration done", s->msg);
	}
	ask->step_now = 1;
	return 0;
}

/* Finish, or abort when the fit fails: what a session does when it has
 * every sample it wants. */
static void finish_or_abort(struct psd_calsession *s, const struct psd_calsession_ctx *c,
                            struct psd_calsession_ask *ask)
{
	char err[512];
	if (finish(s, c, ask, err, sizeof err) != 0)
		psd_calsession_abort(s, c, err, ask);
}

static int running_day(const struct psd_calsession *s, const struct psd_calsession_ctx *c, char *err, size_t n)
{
	if (s->state != PSD_CAL_RUNNING || s->kind != PSD_CAL_DAY)
		return psd_errbuf(err, n, "zone %s has no running day session", c->zone);
	return 0;
}

int psd_calsession_finish(struct psd_calsession *s, const struct psd_calsession_ctx *c,
                          struct psd_calsession_ask *ask, char *err, size_t n)
{
	memset(ask, 0, sizeof *ask);
	if (running_day(s, c, err, n) != 0)
		return -1;
	return finish(s, c, ask, err, n);
}

static int record(struct psd_calsession *s, const struct psd_calsession_ctx *c, double level, double volts,
                  double se, double lux, const char *source, char *err, size_t n)
{
	int seq = s->kind == PSD_CAL_NIGHT ? s->npt : s->nds;
	return psd_db_cal_sample(c->db, s->id, seq, c->now, level, volts, se, lux, source, err, n);
}

int psd_calsession_typed_lux(struct psd_calsession *s, const struct psd_calsession_ctx *c, double lux,
                             double volts, double level, struct psd_calsession_ask *ask, char *err, size_t n)
{
	memset(ask, 0, sizeof *ask);
	if (running_day(s, c, err, n) != 0)
		return -1;
	if (!(lux >= 0 && lux < 2e5))
		return psd_errbuf(err, n, "%g lux is outside 0 to 200000", lux);
	if (!isfinite(volts))
		return psd_errbuf(err, n, "zone %s has no good reading to pair with it", c->zone);
	if (s->nds >= PSD_CAL_MAX_DAY)
		return psd_errbuf(err, n, "%d samples already: finish the session", PSD_CAL_MAX_DAY);
	(void)level;
	s->typed_lux = lux;
	s->typed_t = c->now;
	s->last_input = c->now;
	ask->step_now = 1;
	snprintf(s->msg, sizeof s->msg, "%g lx typed: the typed sample waits for the sensor's next reading", lux);
	return 0;
}

/* A typed lux meets a sensor reading measured at t: one taken no earlier
 * than the skew before the typing (the installer read the meter first). */
static void take_typed(struct psd_calsession *s, const struct psd_calsession_ctx *c, double volts, double level,
                       struct psd_calsession_ask *ask)
{
	char err[512];
	if (!(c->volts_t >= s->typed_t - PSD_CAL_PAIR_SKEW && c->volts_t > s->level_since)) {
		if (!(s->asked_at >= s->typed_t))
			s->asked_at = c->now, ask->refresh_sensor = 1;
		return;
	}
	if (record(s, c, level, volts, NAN, s->typed_lux, "typed", err, sizeof err) != 0) {
		psd_calsession_abort(s, c, err, ask);
		return;
	}
	s->ds[s->nds++] = (struct psd_calfit_sample){ psd_clock_tod(c->now), level, volts, s->typed_lux };
	s->typed_lux = NAN;
	s->asked_at = -INFINITY;
	snprintf(s->msg, sizeof s->msg, "%d typed sample(s); finish when done", s->nds);
}

/* The constants a finished session gives (NAN: keep the one in force). */
static struct psd_calsession_consts consts_of(const struct psd_calsession *s, const struct psd_control *k)
{
	struct psd_calsession_consts out = { s->kind, s->id, NAN, NAN, NAN, NAN };
	if (s->kind == PSD_CAL_NIGHT) {
		out.offset = s->night.offset;
		if (k->elec_sensor > 0)
			out.sensor_gain = s->night.gain / k->elec_sensor;
		out.elec_task_lux = s->night.lux_gain;
	} else {
		out.daylight_ratio = s->day.ratio * k->sensor_gain;
	}
	return out;
}

int psd_calsession_accept(struct psd_calsession *s, const struct psd_calsession_ctx *c,
                          struct psd_calsession_ask *ask, char *err, size_t n)
{
	memset(ask, 0, sizeof *ask);
	if (s->state != PSD_CAL_DONE)
		return psd_errbuf(err, n, "zone %s has no finished session to accept (%s)", c->zone,
		                psd_calsession_state_names[s->state]);
	if (psd_db_cal_accept(c->db, s->id, err, n) != 0)
		return -1;
	s->state = PSD_CAL_ACCEPTED;
	snprintf(s->msg, sizeof s->msg, "accepted: the zone's control now runs on it");
	ask->apply[ask->napply++] = consts_of(s, c->ctl);
	return 0;
}

int psd_calsession_level(struct psd_calsession *s, double now, double *level)
{
	if (s->state != PSD_CAL_RUNNING)
		return 0;
	*level = s->kind == PSD_CAL_NIGHT ? psd_calsession_levels[s->step] : s->hold_level;
	if (s->commanded != s->step) {
		s->commanded = s->step;
		s->level_since = now;
	}
	return 1;
}

/* A reading measured at t is fresh for a day sample: within the skew of
 * now, or measured after the session asked for fresh readings. */
static int day_fresh(const struct psd_calsession *s, const struct psd_calsession_ctx *c, double t)
{
	return t > s->level_since && (c->now - t <= PSD_CAL_PAIR_SKEW || (s->asked_at > -INFINITY && t >= s->asked_at));
}

/* 1 when the sensor's and the meter's readings make a day sample's pair;
 * else fresh ones are asked for (once) and the sample waits for them. */
static int day_pair(struct psd_calsession *s, const struct psd_calsession_ctx *c, struct psd_calsession_ask *ask)
{
	int sensor_ok = day_fresh(s, c, c->volts_t), meter_ok = day_fresh(s, c, c->lux_t);
	if (sensor_ok && meter_ok)
		return 1;
	if (s->asked_at == -INFINITY) {
		s->asked_at = c->now;
		ask->refresh_sensor = !sensor_ok;
		ask->refresh_task = !meter_ok;
	}
	return 0;
}

static void feed_day(struct psd_calsession *s, const struct psd_calsession_ctx *c, double volts, double lux,
                     double level, struct psd_calsession_ask *ask)
{
	char err[512];
	/* a day session does not wait forever: no sample (typed or from the
	 * meter) for cal_timeout ends it, with what it waited for */
	if (c->now - s->last_input > s->settle_timeout) {
		snprintf(err, sizeof err, "no %s for %.0f s (cal_timeout)%s", c->zc->task >= 0 ? "task meter reading" :
		         "typed lux", c->now - s->last_input, c->zc->task >= 0 ? "" :
		         ": this zone has no task meter, so a day session needs `calibrate ZONE lux N` from a hand-held meter");
		psd_calsession_abort(s, c, err, ask);
		return;
	}
	if (isfinite(s->typed_lux)) {
		take_typed(s, c, volts, level, ask);
		return;
	}
	if (c->zc->task < 0 || !isfinite(lux) || c->now < s->next_sample || !day_pair(s, c, ask))
		return;
	s->last_input = c->now;
	s->asked_at = -INFINITY;
	if (record(s, c, level, volts, NAN, lux, "meter", err, sizeof err) != 0) {
		psd_calsession_abort(s, c, err, ask);
		return;
	}
	s->ds[s->nds++] = (struct psd_calfit_sample){ psd_clock_tod(c->now), level, volts, lux };
	s->next_sample = c->now + s->interval;
	s->pair_skew = fmax(s->pair_skew, fabs(c->lux_t - c->volts_t));
	snprintf(s->msg, sizeof s->msg, "%d of %d meter samples (sensor and meter at most %.2f s apart)", s->nds,
	         s->want_samples, s->pair_skew);
	if (s->nds >= s->want_samples || s->nds >= PSD_CAL_MAX_DAY)
		finish_or_abort(s, c, ask);
}

/* The meter's mean over the settled window of the sensor (NAN: none). */
static double settled_lux(const struct psd_calsession *s, double now)
{
	double sum = 0, m = 0;
	for (int i = 0; i < s->nlux; i++)
		if (s->lux_t[i] >= s->settle.t[0] && now - s->lux_t[i] <= s->settle.window) {
			sum += s->lux_v[i];
			m++;
		}
	return m ? sum / m : NAN;
}

static void feed_night(struct psd_calsession *s, const struct psd_calsession_ctx *c, double volts, double lux,
                       struct psd_calsession_ask *ask)
{
	char err[512];
	double mean, se, now = c->now, at = psd_calsession_levels[s->step];
	if (sun_up(c, now)) {
		sun_refusal(c, "night session aborted", err, sizeof err);
		psd_calsession_abort(s, c, err, ask);
		return;
	}
	/* each measurement counts once, and only one taken after the level
	 * was commanded; a sensor that repeats an old value is polled */
	if (!(c->volts_t > s->level_since) || !(c->volts_t > s->fed_t)) {
		if (!(s->asked_at > fmax(s->fed_t, s->level_since))) {
			s->asked_at = now;
			ask->refresh_sensor = 1;
		}
		return;
	}
	s->fed_t = c->volts_t;
	if (isfinite(lux) && c->lux_t > s->fed_lux_t && c->lux_t > s->level_since) {
		s->fed_lux_t = c->lux_t;
		if (s->nlux == PSD_CALFIT_SETTLE_MAX) {
			memmove(s->lux_t, s->lux_t + 1, (PSD_CALFIT_SETTLE_MAX - 1) * sizeof s->lux_t[0]);
			memmove(s->lux_v, s->lux_v + 1, (PSD_CALFIT_SETTLE_MAX - 1) * sizeof s->lux_v[0]);
			s->nlux--;
		}
		s->lux_t[s->nlux] = c->lux_t;
		s->lux_v[s->nlux++] = lux;
	}
	if (!psd_calfit_settle_add(&s->settle, c->volts_t, volts, &mean, &se)) {
		if (now - s->step_started > s->settle_timeout)
			psd_calsession_abort(s, c, "the sensor did not settle (cal_timeout)", ask);
		return;
	}
	/* the lights at their lowest: what is left is the offset, or daylight */
	if (at == psd_calsession_levels[PSD_CAL_NLEVELS - 1]) {
		double g = elec_volts(c);
		if (!(g > 0) && s->npt > 0)
			g = (s->pt[0].volts - mean) / s->pt[0].level;   /* the session's own full-output signal */
		if (dark_check(c, "daylight in the night session", mean, at, at, g, err, sizeof err) != 0) {
			psd_calsession_abort(s, c, err, ask);
			return;
		}
	}
	s->pt[s->npt] = (struct psd_calfit_level){ at, mean, se, settled_lux(s, now) };
	if (record(s, c, at, mean, se, s->pt[s->npt].lux, "settled", err, sizeof err) != 0) {
		psd_calsession_abort(s, c, err, ask);
		return;
	}
	psd_log_info("zone %s: %s: night level %.0f %%: %.5f V (se %.5f) after %.0f s", c->zone, stamp(c, (char[24]){ 0 }),
	         100 * at, mean, se,
	         now - s->step_started);
	s->npt++;
	if (++s->step == PSD_CAL_NLEVELS) {
		finish_or_abort(s, c, ask);
		return;
	}
	settle_reset(s, c);
	snprintf(s->msg, sizeof s->msg, "settling at %.0f %%", 100 * psd_calsession_levels[s->step]);
}

void psd_calsession_feed(struct psd_calsession *s, const struct psd_calsession_ctx *c, double volts, double lux,
                         double level, struct psd_calsession_ask *ask)
{
	memset(ask, 0, sizeof *ask);
	if (s->state != PSD_CAL_RUNNING)
		return;
	/* a reading counts only once the session's level was commanded at an
	 * earlier step: the one taken as the command goes out is the old level's */
	if (!(c->now > s->level_since))
		return;
	if (s->kind == PSD_CAL_DAY)
		feed_day(s, c, volts, lux, level, ask);
	else
		feed_night(s, c, volts, lux, ask);
}

/* An accepted session's constants from its stored results. */
static int consts_from_json(const char *json, int kind, long long id, struct psd_calsession_consts *k)
{
	json_object *o = json_tokener_parse(json), *v;
	if (!o)
		return -1;
#define GET(key) (json_object_object_get_ex(o, key, &v) && v ? json_object_get_double(v) : NAN)
	*k = (struct psd_calsession_consts){ kind, id, NAN, NAN, NAN, NAN };
	if (kind == PSD_CAL_NIGHT) {
		k->offset = GET("offset");
		k->sensor_gain = GET("sensor_gain");
		k->elec_task_lux = GET("lux_gain");
	} else {
		k->daylight_ratio = GET("daylight_ratio");
	}
#undef GET
	json_object_put(o);
	return 0;
}

void psd_calsession_accepted(const struct psd_calsession_ctx *c, struct psd_calsession_ask *ask)
{
	memset(ask, 0, sizeof *ask);
	for (int kind = PSD_CAL_NIGHT; c->db && kind <= PSD_CAL_DAY; kind++) {
		long long id;
		char *json = psd_db_cal_accepted(c->db, c->zone, psd_calsession_kind_names[kind], &id);
		if (json && consts_from_json(json, kind, id, &ask->apply[ask->napply]) == 0)
			ask->napply++;
		free(json);
	}
}

struct resume {
	struct psd_calsession *s;
};

static void resume_sample(void *user, double t, double level, double volts, double se, double lux)
{
	struct psd_calsession *s = ((struct resume *)user)->s;
	if (s->kind == PSD_CAL_NIGHT && s->npt < PSD_CAL_NLEVELS) {
		s->pt[s->npt++] = (struct psd_calfit_level){ level, volts, se, lux };
		s->step = s->npt;
	} else if (s->kind == PSD_CAL_DAY && s->nds < PSD_CAL_MAX_DAY) {
		s->ds[s->nds++] = (struct psd_calfit_sample){ psd_clock_tod(t), level, volts, lux };
		s->hold_level = level;
	}
}

void psd_calsession_resume(struct psd_calsession *s, const struct psd_calsession_ctx *c, double level,
                           struct psd_calsession_ask *ask)
{
	struct resume r = { s };
	char kind[16];
	long long id;
	double started;
	memset(ask, 0, sizeof *ask);
	if (!c->db || psd_db_cal_running(c->db, c->zone, &id, kind, sizeof kind, &started) != 0)
		return;
	begin(s, c, strcmp(kind, "night") == 0 ? PSD_CAL_NIGHT : PSD_CAL_DAY, id, started, level);
	psd_db_cal_samples(c->db, id, resume_sample, &r);
	settle_reset(s, c);
	snprintf(s->msg, sizeof s->msg, "resumed with %d level(s), %d sample(s)", s->npt, s->nds);
	psd_log_info("zone %s: %s: %s calibration session %lld resumed (%d level(s), %d sample(s) kept)", c->zone,
	         stamp(c, (char[24]){ 0 }), kind, id,
	         s->npt, s->nds);
	if (s->kind == PSD_CAL_NIGHT && s->step >= PSD_CAL_NLEVELS)
		finish_or_abort(s, c, ask);
}
