/* Calibration sessions on a running engine (see calsession.h). */
#include <errno.h>
#include <json-c/json.h>
#include <math.h>
#include <sqlite3.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cache.h"
#include "calstore.h"
#include "engine.h"
#include "log.h"
#include "room.h"

const double psd_cal_levels[PSD_CAL_NLEVELS] = { 1.0, 0.75, 0.5, 0.25, 0.1, 0.0 };
const char *const psd_cal_kind_names[] = { "none", "night", "day", NULL };
const char *const psd_cal_state_names[] = { "idle", "running", "done", "aborted", "accepted", NULL };

static int fail(char *err, size_t n, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static int fail(char *err, size_t n, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(err, n, fmt, ap);
	va_end(ap);
	return -1;
}

static sqlite3 *db(struct psd_engine *e)
{
	return e->db ? psd_db_sqlite(e->db) : NULL;
}

/* The engine's sample batch may hold a transaction open (a simulated day):
 * a calibration record is committed with it, else at once. */
static void note_error(const char *err)
{
	log_warnx("%s", err);
}

static void settle_reset(struct psd_zone *z, double now)
{
	const struct psd_zone_conf *zc = z->zc;
	psd_settle_init(&z->cal.settle, zc->cal_window, 4, 3.0, zc->cal_floor);
	z->cal.step_started = now;
	z->cal.nlux = 0;
	z->cal.level_since = INFINITY;   /* readings count once the level is commanded */
	z->cal.commanded = -1;
}

int psd_cal_start(struct psd_engine *e, const char *zone, int kind, double level, double now, char *err, size_t n)
{
	struct psd_zone *z = psd_engine_zone(e, zone);
	char cfg[65] = "", scene[65] = "";
	struct ps_err pe;
	if (!z)
		return fail(err, n, "no zone '%s'", zone);
	if (!db(e))
		return fail(err, n, "calibration sessions are recorded in the database: set database = in [psensd]");
	if (z->cal.state == PSD_CAL_RUNNING)
		return fail(err, n, "zone %s: a %s session is running (abort it first)", zone,
		            psd_cal_kind_names[z->cal.kind]);
	if (z->in_fault)
		return fail(err, n, "zone %s is at its safe level: %s", zone, z->why);
	if (kind == PSD_CAL_DAY && !(level >= 0 && level <= 1))
		return fail(err, n, "level %g is outside 0 to 1", level);
	if (ps_hash_file(e->cf->conf.path, cfg, &pe) != 0)
		cfg[0] = 0;
	snprintf(scene, sizeof scene, "%s", e->have_res && e->res.scene_hash ? e->res.scene_hash : "");
	memset(&z->cal, 0, sizeof z->cal);
	z->cal.id = psd_calstore_begin(db(e), zone, psd_cal_kind_names[kind], now, cfg, scene, err, n);
	if (z->cal.id < 0)
		return -1;
	z->cal.kind = kind;
	z->cal.state = PSD_CAL_RUNNING;
	z->cal.started = now;
	z->cal.settle_timeout = z->zc->cal_timeout;
	z->cal.hold_level = level;
	z->cal.interval = z->zc->cal_day_interval;
	z->cal.want_samples = (int)z->zc->cal_day_samples;
	z->cal.next_sample = now;
	settle_reset(z, now);
	snprintf(z->cal.msg, sizeof z->cal.msg, "%s", kind == PSD_CAL_NIGHT ? "settling at 100 %" :
	         z->zc->task >= 0 ? "sampling the task meter" : "waiting for typed lux (calibrate ZONE lux N)");
	z->asap = 1;
	log_info("zone %s: %s calibration session %lld started", zone, psd_cal_kind_names[kind], z->cal.id);
	return 0;
}

int psd_cal_abort(struct psd_engine *e, struct psd_zone *z, double now, const char *why)
{
	char err[512];
	if (z->cal.state != PSD_CAL_RUNNING)
		return -1;
	z->cal.state = PSD_CAL_ABORTED;
	snprintf(z->cal.msg, sizeof z->cal.msg, "aborted: %s", why);
	if (db(e) && psd_calstore_end(db(e), z->cal.id, "aborted", now, NULL, why, err, sizeof err) != 0)
		note_error(err);
	log_warnx("zone %s: calibration session %lld aborted: %s", z->zc->name, z->cal.id, why);
	z->asap = 1;
	return 0;
}

/* The nearest daylight condition in time of day: its ratio in lux per volt
 * at the zone's sensor gain. */
static void nearest_condition(struct psd_engine *e, struct psd_zone *z, double tod)
{
	double best = INFINITY;
	z->cal.sim_ratio = NAN;
	z->cal.sim_condition[0] = 0;
	for (size_t i = 0; e->have_res && i < e->res.ncond; i++) {
		const struct ps_result_cond *c = &e->res.cond[i];
		double d = fabs(c->tod_s - tod);
		if (!c->computed || c->tod_s < 0 || !(c->ratio > 0) || d >= best)
			continue;
		best = d;
		z->cal.sim_ratio = c->ratio / z->ctl.sensor_gain;
		snprintf(z->cal.sim_condition, sizeof z->cal.sim_condition, "%s", c->label);
	}
}

static char *results_json(struct psd_engine *e, struct psd_zone *z)
{
	json_object *o = json_object_new_object();
	char *out;
	json_c_set_serialization_double_format("%.10g", JSON_C_OPTION_THREAD);
#define NUM(k, v) json_object_object_add(o, k, isfinite(v) ? json_object_new_double(v) : NULL)
	if (z->cal.kind == PSD_CAL_NIGHT) {
		const struct psd_night_fit *f = &z->cal.night;
		double es = e->have_res ? e->res.electric_sensor_response : NAN;
		double el = e->have_res ? e->res.electric_task_lux : NAN;
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
		NUM("electric_lux_error_pct", psd_ratio_error_pct(el, f->lux_gain));
		json_object_object_add(o, "levels", json_object_new_int(z->cal.npt));
	} else {
		const struct psd_day_fit *f = &z->cal.day;
		NUM("ratio", f->ratio);
		NUM("ratio_se", f->ratio_se);
		NUM("sd", f->sd);
		json_object_object_add(o, "samples", json_object_new_int((int)f->n));
		NUM("mean_tod_s", f->mean_tod);
		NUM("sim_ratio", z->cal.sim_ratio);
		json_object_object_add(o, "condition", json_object_new_string(z->cal.sim_condition));
		NUM("error_pct", z->cal.error_pct);
		NUM("sensor_gain", z->ctl.sensor_gain);
		NUM("daylight_ratio", f->ratio * z->ctl.sensor_gain);
		NUM("offset", z->ctl.offset);
	}
#undef NUM
	out = strdup(json_object_to_json_string_ext(o, JSON_C_TO_STRING_PLAIN));
	json_object_put(o);
	return out;
}

static int finish(struct psd_engine *e, struct psd_zone *z, double now, char *err, size_t n)
{
	char *json;
	int rc, outside = 0;   /* a day session off the design by more than cal_tolerance */
	if (z->cal.kind == PSD_CAL_NIGHT) {
		if (psd_night_fit(z->cal.pt, (size_t)z->cal.npt, &z->cal.night, err, n) != 0)
			return -1;
	} else {
		double gain_e = z->ctl.sensor_gain * z->ctl.elec_sensor;
		if (psd_day_fit(z->cal.ds, (size_t)z->cal.nds, z->ctl.offset, gain_e, z->ctl.elec_task_lux,
		                z->zc->cal_min_day_volts, &z->cal.day, err, n) != 0)
			return -1;
		nearest_condition(e, z, z->cal.day.mean_tod);
		z->cal.error_pct = psd_ratio_error_pct(z->cal.sim_ratio, z->cal.day.ratio);
		outside = !(fabs(z->cal.error_pct) <= z->zc->cal_tolerance);
	}
	json = results_json(e, z);
	rc = psd_calstore_end(db(e), z->cal.id, "done", now, json, NULL, err, n);
	free(json);
	if (rc != 0)
		return -1;
	z->cal.state = PSD_CAL_DONE;
	if (z->cal.kind == PSD_CAL_NIGHT)
		snprintf(z->cal.msg, sizeof z->cal.msg, "done: offset %.4f V, %.4f V at full output (se %.4f), "
		         "R2 %.6f; accept to use it", z->cal.night.offset, z->cal.night.gain, z->cal.night.gain_se,
		         z->cal.night.r2);
	else
		snprintf(z->cal.msg, sizeof z->cal.msg, "done: %.2f lux per volt (se %.2f) from %zu samples; "
		         "simulated %.2f (%s): %+.1f %%, %s the %g %% tolerance%s", z->cal.day.ratio,
		         z->cal.day.ratio_se, z->cal.day.n, z->cal.sim_ratio, z->cal.sim_condition, z->cal.error_pct,
		         outside ? "outside" : "within", z->zc->cal_tolerance,
		         outside ? " (the sensor moved or covered, the wrong filter, or a scene unlike the room?); accept to use it anyway"
		         : "; accept to use it");
	if (outside)
		log_warnx("zone %s: calibration session %lld %s", z->zc->name, z->cal.id, z->cal.msg);
	else
		log_info("zone %s: calibration session %lld %s", z->zc->name, z->cal.id, z->cal.msg);
	z->asap = 1;
	return 0;
}

int psd_cal_finish(struct psd_engine *e, const char *zone, double now, char *err, size_t n)
{
	struct psd_zone *z = psd_engine_zone(e, zone);
	if (!z)
		return fail(err, n, "no zone '%s'", zone);
	if (z->cal.state != PSD_CAL_RUNNING || z->cal.kind != PSD_CAL_DAY)
		return fail(err, n, "zone %s has no running day session", zone);
	return finish(e, z, now, err, n);
}

static int sample(struct psd_engine *e, struct psd_zone *z, double t, double level, double volts, double se,
                  double lux, const char *source, char *err, size_t n)
{
	int seq = z->cal.kind == PSD_CAL_NIGHT ? z->cal.npt : z->cal.nds;
	return psd_calstore_sample(db(e), z->cal.id, seq, t, level, volts, se, lux, source, err, n);
}

int psd_cal_lux(struct psd_engine *e, const char *zone, double lux, double now, char *err, size_t n)
{
	struct psd_zone *z = psd_engine_zone(e, zone);
	if (!z)
		return fail(err, n, "no zone '%s'", zone);
	if (z->cal.state != PSD_CAL_RUNNING || z->cal.kind != PSD_CAL_DAY)
		return fail(err, n, "zone %s has no running day session", zone);
	if (!(lux >= 0 && lux < 2e5))
		return fail(err, n, "%g lux is outside 0 to 200000", lux);
	if (!isfinite(z->volts) || z->in_fault)
		return fail(err, n, "zone %s has no good reading to pair with it", zone);
	if (z->cal.nds >= PSD_CAL_MAX_DAY)
		return fail(err, n, "%d samples already: finish the session", PSD_CAL_MAX_DAY);
	if (sample(e, z, now, z->level, z->volts, NAN, lux, "typed", err, n) != 0)
		return -1;
	z->cal.ds[z->cal.nds++] = (struct psd_day_sample){ ps_room_tod(now), z->level, z->volts, lux };
	snprintf(z->cal.msg, sizeof z->cal.msg, "%d typed sample(s); finish when done", z->cal.nds);
	return 0;
}

int psd_cal_accept(struct psd_engine *e, const char *zone, char *err, size_t n)
{
	struct psd_zone *z = psd_engine_zone(e, zone);
	if (!z)
		return fail(err, n, "no zone '%s'", zone);
	if (z->cal.state != PSD_CAL_DONE)
		return fail(err, n, "zone %s has no finished session to accept (%s)", zone,
		            psd_cal_state_names[z->cal.state]);
	if (psd_calstore_accept(db(e), z->cal.id, err, n) != 0)
		return -1;
	z->cal.state = PSD_CAL_ACCEPTED;
	if (z->cal.kind == PSD_CAL_NIGHT) {
		z->ctl.offset = z->cal.night.offset;
		if (z->ctl.elec_sensor > 0)
			z->ctl.sensor_gain = z->cal.night.gain / z->ctl.elec_sensor;
		if (isfinite(z->cal.night.lux_gain) && z->cal.night.lux_gain > 0)
			z->ctl.elec_task_lux = z->cal.night.lux_gain;
		z->cal_night_id = z->cal.id;
	} else {
		z->ctl.daylight_ratio = z->cal.day.ratio * z->ctl.sensor_gain;
		z->cal_day_id = z->cal.id;
	}
	snprintf(z->cal.msg, sizeof z->cal.msg, "accepted: the zone's control now runs on it");
	log_info("zone %s: calibration session %lld accepted (sensor gain %.5g V per unit, offset %.4g V, "
	         "daylight ratio %.5g, electric task lux %.5g)", zone, z->cal.id, z->ctl.sensor_gain, z->ctl.offset,
	         z->ctl.daylight_ratio, z->ctl.elec_task_lux);
	return 0;
}

int psd_cal_level(struct psd_engine *e, struct psd_zone *z, double now, double *level)
{
	(void)e;
	(void)now;
	if (z->cal.state != PSD_CAL_RUNNING)
		return 0;
	*level = z->cal.kind == PSD_CAL_NIGHT ? psd_cal_levels[z->cal.step] : z->cal.hold_level;
	if (z->cal.commanded != z->cal.step) {
		z->cal.commanded = z->cal.step;
		z->cal.level_since = now;
	}
	return 1;
}

void psd_cal_feed(struct psd_engine *e, struct psd_zone *z, double now, double volts, double lux)
{
	struct psd_cal *c = &z->cal;
	char err[512];
	double mean, se;
	if (c->state != PSD_CAL_RUNNING)
		return;
	/* a reading counts only once the session's level was commanded at an
	 * earlier step: the one taken as the command goes out is the old level's */
	if (!(now > c->level_since))
		return;
	if (c->kind == PSD_CAL_DAY) {
		if (z->zc->task < 0 || !isfinite(lux) || now < c->next_sample)
			return;
		if (sample(e, z, now, z->level, volts, NAN, lux, "meter", err, sizeof err) != 0) {
			psd_cal_abort(e, z, now, err);
			return;
		}
		c->ds[c->nds++] = (struct psd_day_sample){ ps_room_tod(now), z->level, volts, lux };
		c->next_sample = now + c->interval;
		snprintf(c->msg, sizeof c->msg, "%d of %d meter samples", c->nds, c->want_samples);
		if (c->nds >= c->want_samples || c->nds >= PSD_CAL_MAX_DAY) {
			if (finish(e, z, now, err, sizeof err) != 0)
				psd_cal_abort(e, z, now, err);
		}
		return;
	}
	if (isfinite(lux)) {
		if (c->nlux == PSD_SETTLE_MAX) {
			memmove(c->lux_t, c->lux_t + 1, (PSD_SETTLE_MAX - 1) * sizeof c->lux_t[0]);
			memmove(c->lux_v, c->lux_v + 1, (PSD_SETTLE_MAX - 1) * sizeof c->lux_v[0]);
			c->nlux--;
		}
		c->lux_t[c->nlux] = now;
		c->lux_v[c->nlux++] = lux;
	}
	if (!psd_settle_add(&c->settle, now, volts, &mean, &se)) {
		if (now - c->step_started > c->settle_timeout)
			psd_cal_abort(e, z, now, "the sensor did not settle (cal_timeout)");
		return;
	}
	{
		/* the meter over the same settled window as the sensor */
		double sum = 0, m = 0;
		for (int i = 0; i < c->nlux; i++)
			if (c->lux_t[i] >= c->settle.t[0] && now - c->lux_t[i] <= c->settle.window) {
				sum += c->lux_v[i];
				m++;
			}
		c->pt[c->npt] = (struct psd_night_point){ psd_cal_levels[c->step], mean, se, m ? sum / m : NAN };
	}
	if (sample(e, z, now, psd_cal_levels[c->step], mean, se, c->pt[c->npt].lux, "settled", err, sizeof err) != 0) {
		psd_cal_abort(e, z, now, err);
		return;
	}
	log_info("zone %s: night level %.0f %%: %.5f V (se %.5f) after %.0f s", z->zc->name,
	         100 * psd_cal_levels[c->step], mean, se, now - c->step_started);
	c->npt++;
	if (++c->step == PSD_CAL_NLEVELS) {
		if (finish(e, z, now, err, sizeof err) != 0)
			psd_cal_abort(e, z, now, err);
		return;
	}
	settle_reset(z, now);
	snprintf(c->msg, sizeof c->msg, "settling at %.0f %%", 100 * psd_cal_levels[c->step]);
}

struct resume {
	struct psd_zone *z;
};

static void resume_sample(void *user, double t, double level, double volts, double se, double lux)
{
	struct psd_zone *z = ((struct resume *)user)->z;
	struct psd_cal *c = &z->cal;
	if (c->kind == PSD_CAL_NIGHT && c->npt < PSD_CAL_NLEVELS) {
		c->pt[c->npt++] = (struct psd_night_point){ level, volts, se, lux };
		c->step = c->npt;
	} else if (c->kind == PSD_CAL_DAY && c->nds < PSD_CAL_MAX_DAY) {
		c->ds[c->nds++] = (struct psd_day_sample){ ps_room_tod(t), level, volts, lux };
		c->hold_level = level;
	}
}

/* Apply an accepted calibration's constants to a zone's control. */
static void apply(struct psd_zone *z, const char *json, int kind)
{
	json_object *o = json_tokener_parse(json), *v;
	if (!o)
		return;
#define GET(k) (json_object_object_get_ex(o, k, &v) && v ? json_object_get_double(v) : NAN)
	if (kind == PSD_CAL_NIGHT) {
		double off = GET("offset"), sg = GET("sensor_gain"), lg = GET("lux_gain");
		if (isfinite(off))
			z->ctl.offset = off;
		if (sg > 0)
			z->ctl.sensor_gain = sg;
		if (lg > 0)
			z->ctl.elec_task_lux = lg;
	} else {
		double dr = GET("daylight_ratio");
		if (dr > 0)
			z->ctl.daylight_ratio = dr;
	}
#undef GET
	json_object_put(o);
}

void psd_cal_load(struct psd_engine *e, double now)
{
	char err[512], kind[16];
	if (!db(e))
		return;
	if (psd_calstore_init(db(e), err, sizeof err) != 0) {
		log_warnx("%s", err);
		return;
	}
	for (size_t i = 0; i < e->nzone; i++) {
		struct psd_zone *z = &e->zone[i];
		struct resume r = { z };
		long long id;
		double started;
		char *json;
		for (int k = PSD_CAL_NIGHT; k <= PSD_CAL_DAY; k++)
			if ((json = psd_calstore_accepted(db(e), z->zc->name, psd_cal_kind_names[k], &id))) {
				apply(z, json, k);
				if (k == PSD_CAL_NIGHT)
					z->cal_night_id = id;
				else
					z->cal_day_id = id;
				free(json);
			}
		if (z->cal_night_id || z->cal_day_id)
			log_info("zone %s: calibrated (night session %lld, day session %lld): sensor gain %.5g, offset "
			         "%.4g V, daylight ratio %.5g", z->zc->name, z->cal_night_id, z->cal_day_id,
			         z->ctl.sensor_gain, z->ctl.offset, z->ctl.daylight_ratio);
		if (psd_calstore_running(db(e), z->zc->name, &id, kind, sizeof kind, &started) != 0)
			continue;
		memset(&z->cal, 0, sizeof z->cal);
		z->cal.kind = strcmp(kind, "night") == 0 ? PSD_CAL_NIGHT : PSD_CAL_DAY;
		z->cal.state = PSD_CAL_RUNNING;
		z->cal.id = id;
		z->cal.started = started;
		z->cal.settle_timeout = z->zc->cal_timeout;
		z->cal.interval = z->zc->cal_day_interval;
		z->cal.want_samples = (int)z->zc->cal_day_samples;
		z->cal.next_sample = now;
		z->cal.hold_level = z->level;
		psd_calstore_samples(db(e), id, resume_sample, &r);
		settle_reset(z, now);
		snprintf(z->cal.msg, sizeof z->cal.msg, "resumed with %d level(s), %d sample(s)", z->cal.npt, z->cal.nds);
		log_info("zone %s: %s calibration session %lld resumed (%d level(s), %d sample(s) kept)", z->zc->name,
		         kind, id, z->cal.npt, z->cal.nds);
		if (z->cal.kind == PSD_CAL_NIGHT && z->cal.step >= PSD_CAL_NLEVELS && finish(e, z, now, err, sizeof err) != 0)
			psd_cal_abort(e, z, now, err);
	}
}

void psd_drift_step(struct psd_engine *e, struct psd_zone *z, double now)
{
	double gain_e, vd, ed;
	int r;
	(void)e;
	if (z->zc->task < 0 || !isfinite(z->task_lux) || !isfinite(z->volts) || z->cal.state == PSD_CAL_RUNNING)
		return;
	gain_e = z->ctl.sensor_gain * z->ctl.elec_sensor;
	vd = z->volts - z->ctl.offset - gain_e * z->ctl.level;
	ed = z->task_lux - z->ctl.elec_task_lux * z->ctl.level;
	r = psd_drift_update(&z->drift, now, vd, ed, z->ctl.daylight_ratio / z->ctl.sensor_gain);
	if (r > 0) {
		char t[8];
		psd_hhmm(now, t);
		log_warnx("zone %s: %s drift: the measured task/sensor ratio is %.0f %% off the simulated one for "
		          "%.0f s (sensor obstructed, dirty or moved, or the room changed?)", z->zc->name, t,
		          100 * (exp(z->drift.last_ln) - 1), now - z->drift.out_since);
	} else if (r < 0) {
		log_info("zone %s: drift cleared: the measured ratio is back within %.0f %%", z->zc->name,
		         100 * (exp(z->zc->drift_margin / 2) - 1));
	}
}
