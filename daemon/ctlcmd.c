/* SPDX-License-Identifier: ISC */
/* The control socket's commands: one request line in, one JSON line out.
 * Every reply has "ok"; a failed one has "error" too.  psensctl(1) lists
 * the commands; `help` does as well. */
#include <errno.h>
#include <json-c/json.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "accept.h"
#include "cmdtab.h"
#include "loop.h"
#include "ctlcmd.h"
#include "reload.h"
#include "db.h"
#include "errbuf.h"
#include "json.h"
#include "log.h"
#include "points.h"
#include "time.h"

/* A path psensd names to a client, absolute: a relative one (from a
 * relative -f) is relative to psensd's directory, not the client's. */
static void put_path(json_object *o, const char *key, const char *path)
{
	char abs[PATH_MAX], cwd[PATH_MAX];
	if (!path || path[0] == '/')
		psd_json_str(o, key, path);
	else if (realpath(path, abs))
		psd_json_str(o, key, abs);
	else if (getcwd(cwd, sizeof cwd) && (size_t)snprintf(abs, sizeof abs, "%s/%s", cwd, path) < sizeof abs)
		psd_json_str(o, key, abs);
	else
		psd_json_str(o, key, path);
}

static void finish(json_object *o, struct psd_ctl_reply *reply)
{
	const char *text;
	/* 10 significant digits: 0.3 reads 0.3, not 0.29999999999999999 */
	text = psd_json_text(o, 10);
	psd_ctlsock_reply_set(reply, text);
	json_object_put(o);
}

void psd_ctlcmd_error(struct psd_ctl_reply *reply, const char *fmt, ...)
{
	char msg[512];
	va_list ap;
	json_object *o = json_object_new_object();
	va_start(ap, fmt);
	psd_errbuf_va(msg, sizeof msg, fmt, ap);
	va_end(ap);
	json_object_object_add(o, "ok", json_object_new_boolean(0));
	psd_json_str(o, "error", msg);
	finish(o, reply);
}

static json_object *ok_reply(void)
{
	json_object *o = json_object_new_object();
	json_object_object_add(o, "ok", json_object_new_boolean(1));
	return o;
}

void psd_ctlcmd_ok(struct psd_ctl_reply *reply, const char *key, const char *text)
{
	json_object *o = ok_reply();
	if (key)
		psd_json_str(o, key, text);
	finish(o, reply);
}

static void cal_progress(json_object *o, const struct psd_zone *z, double now);

/* HH:MM:SS of a clock time */
static void hhmmss(double t, char out[16])
{
	long s = (long)floor(psd_clock_tod(t) + 0.5) % 86400;
	snprintf(out, 16, "%02ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
}

/* The zone's last step: every value of one moment (engine.h, psd_zone_sample). */
static json_object *sample_json(const struct psd_zone *z)
{
	const struct psd_zone_sample *s = &z->last;
	json_object *o = json_object_new_object();
	char t[16];
	if (!isfinite(s->t)) {
		json_object_put(o);
		return NULL;
	}
	hhmmss(s->t, t);
	psd_json_num(o, "t", s->t);
	psd_json_str(o, "time", t);
	psd_json_num(o, "level", s->level);
	psd_json_num(o, "sensor_v", s->volts);
	psd_json_num(o, "daylight_v", s->daylight_v);
	psd_json_num(o, "est_task_lux", s->est_task_lux);
	psd_json_num(o, "task_lux", s->task_lux);
	psd_json_num(o, "true_task_lux", s->true_task_lux);
	psd_json_num(o, "commanded", s->commanded);
	json_object_object_add(o, "fault", json_object_new_boolean(s->fault));
	return o;
}

static json_object *zone_json(const struct psd_points *pts, const struct psd_engine *e, const struct psd_zone *z,
                              double now)
{
	json_object *o = json_object_new_object();
	const struct psd_config *cf = e->cf;
	psd_json_str(o, "name", z->zc->name);
	psd_json_str(o, "algorithm", psd_control_algorithm_names[z->ctl.algorithm]);
	psd_json_num(o, "target_lux", z->ctl.target_lux);
	psd_json_num(o, "level", z->level);
	json_object_object_add(o, "sample", sample_json(z));
	psd_json_str(o, "sensor", cf->pt[z->zc->sensor].name);
	/* what the record calls it (loop.c logs it as the zone's "simulated" event) */
	psd_json_str(o, "simulated", psd_config_zone_simulated(cf, z->zc));
	psd_json_str(o, "fault", z->in_fault ? z->why : NULL);
	psd_json_num(o, "safe_level", z->zc->safe_level);
	psd_json_num(o, "period", z->zc->period);
	if (now < z->override_until) {
		json_object *ov = json_object_new_object();
		psd_json_num(ov, "level", z->override_level);
		psd_json_num(ov, "remaining_s", z->override_until - now);
		json_object_object_add(o, "override", ov);
	} else {
		json_object_object_add(o, "override", NULL);
	}
	if (psd_engine_zone_occupied(z) >= 0) {
		/* the occupancy's state machine (daemon/occupancy.h) */
		json_object *oc = json_object_new_object();
		json_object_object_add(o, "occupied", json_object_new_boolean(psd_engine_zone_occupied(z)));
		psd_json_str(oc, "input", z->occ.input < 0 ? NULL : z->occ.input ? "occupied" : "vacant");
		psd_json_str(oc, "fault", z->occ.fault ? z->occ_why : NULL);
		psd_json_num(oc, "vacant_s", z->occupancy ? NAN : now - z->occ.vacant_since);
		json_object_object_add(oc, "at_vacant_level", json_object_new_boolean(psd_occupancy_vacant(&z->occ, now)));
		psd_json_num(oc, "hold_s", z->occ.hold);
		psd_json_num(oc, "vacant_level", z->occ.vacant_level);
		json_object_object_add(o, "occupancy", oc);
	}
	json_object_object_add(o, "steps", json_object_new_int64((int64_t)z->steps));
	json_object_object_add(o, "fault_steps", json_object_new_int64((int64_t)z->fault_steps));
	if (z->zc->task >= 0) {
		json_object_object_add(o, "drift", json_object_new_boolean(z->drift.flagged));
		psd_json_num(o, "drift_pct", 100 * (exp(z->drift.last_ln) - 1));
		/* why drift may be false beside a large drift_pct: how long the
		 * ratio has been out (null: it is not), against the hold */
		psd_json_num(o, "drift_out_s", z->drift.out_since >= 0 ? now - z->drift.out_since : NAN);
		psd_json_num(o, "drift_hold_s", z->drift.hold);
	}
	psd_json_num(o, "sensor_gain", z->ctl.sensor_gain);
	psd_json_num(o, "offset", z->ctl.offset);
	psd_json_num(o, "daylight_ratio", z->ctl.daylight_ratio);
	psd_json_num(o, "electric_task_lux", z->ctl.elec_task_lux);
	json_object_object_add(o, "calibrated_night", z->cal_night_id ? json_object_new_int64(z->cal_night_id) : NULL);
	json_object_object_add(o, "calibrated_day", z->cal_day_id ? json_object_new_int64(z->cal_day_id) : NULL);
	/* a session under way and its progress (psensctl watch shows it); its
	 * levels or samples stay in calibrate status: ten zones' day sessions
	 * would not fit a status reply */
	if (psd_calsession_running(&z->cal)) {
		json_object *c = json_object_new_object();
		psd_json_str(c, "kind", psd_calsession_kind_names[z->cal.kind]);
		psd_json_str(c, "message", z->cal.msg[0] ? z->cal.msg : NULL);
		cal_progress(c, z, now);
		json_object_object_add(o, "calibration", c);
	} else {
		json_object_object_add(o, "calibration", NULL);
	}
	/* the point model (points.h): every point the zone has, in its unit */
	json_object_object_add(o, "points", psd_points_json(pts, e, (size_t)(z - e->zone), now));
	return o;
}

/* A running session's progress: what is left and, at the pace so far (or
 * the configured window and interval before the first point), how long. */
static void cal_progress(json_object *o, const struct psd_zone *z, double now)
{
	const struct psd_calsession *c = &z->cal;
	double remaining = NAN;
	int left;
	if (c->state != PSD_CAL_RUNNING) {
		json_object_object_add(o, "remaining_s", NULL);
		return;
	}
	psd_json_num(o, "elapsed_s", now - c->started);
	if (c->kind == PSD_CAL_NIGHT) {
		left = PSD_CAL_NLEVELS - c->npt;
		json_object_object_add(o, "levels_left", json_object_new_int(left));
		remaining = c->npt > 0 ? (now - c->started) / c->npt * left : left * z->zc->cal_window;
	} else {
		left = c->want_samples - c->nds;
		if (left < 0)
			left = 0;
		json_object_object_add(o, "samples_left", json_object_new_int(left));
		remaining = left > 0 ? fmax(0, c->next_sample - now) + (left - 1) * c->interval : 0;
	}
	psd_json_num(o, "remaining_s", remaining);
}

static json_object *cal_json(const struct psd_zone *z, double now)
{
	const struct psd_calsession *c = &z->cal;
	json_object *o = json_object_new_object(), *pts = json_object_new_array();
	psd_json_str(o, "zone", z->zc->name);
	psd_json_str(o, "kind", psd_calsession_kind_names[c->kind]);
	psd_json_str(o, "state", psd_calsession_state_names[c->state]);
	json_object_object_add(o, "session", c->id ? json_object_new_int64(c->id) : NULL);
	psd_json_str(o, "message", c->msg[0] ? c->msg : NULL);
	cal_progress(o, z, now);
	if (c->kind == PSD_CAL_NIGHT) {
		for (int i = 0; i < c->npt; i++) {
			json_object *p = json_object_new_object();
			psd_json_num(p, "level", c->pt[i].level);
			psd_json_num(p, "volts", c->pt[i].volts);
			psd_json_num(p, "volts_se", c->pt[i].volts_se);
			psd_json_num(p, "lux", c->pt[i].lux);
			json_object_array_add(pts, p);
		}
		json_object_object_add(o, "levels", pts);
		if (c->state == PSD_CAL_DONE || c->state == PSD_CAL_ACCEPTED) {
			psd_json_num(o, "offset", c->night.offset);
			psd_json_num(o, "offset_se", c->night.offset_se);
			psd_json_num(o, "gain", c->night.gain);
			psd_json_num(o, "gain_se", c->night.gain_se);
			psd_json_num(o, "r2", c->night.r2);
			psd_json_num(o, "max_resid_pct", c->night.max_resid_pct);
			psd_json_num(o, "lux_gain", c->night.lux_gain);
		}
	} else {
		for (int i = 0; i < c->nds; i++) {
			json_object *p = json_object_new_object();
			psd_json_num(p, "tod_s", c->ds[i].t);
			psd_json_num(p, "level", c->ds[i].level);
			psd_json_num(p, "volts", c->ds[i].volts);
			psd_json_num(p, "lux", c->ds[i].lux);
			json_object_array_add(pts, p);
		}
		json_object_object_add(o, "samples", pts);
		if (c->pair_skew >= 0)
			psd_json_num(o, "pair_skew_s", c->pair_skew);
		if (c->state == PSD_CAL_DONE || c->state == PSD_CAL_ACCEPTED) {
			psd_json_num(o, "ratio", c->day.ratio);
			psd_json_num(o, "ratio_se", c->day.ratio_se);
			psd_json_num(o, "sim_ratio", c->sim_ratio);
			psd_json_str(o, "condition", c->sim_condition);
			psd_json_num(o, "error_pct", c->error_pct);
		}
	}
	return o;
}

/* The zone a request names, resolved once; NULL after the error reply. */
static struct psd_zone *zone_arg(struct psd_daemon *d, const char *name, struct psd_ctl_reply *reply)
{
	struct psd_zone *z = psd_engine_zone(&d->engine, name);
	if (!z)
		psd_ctlcmd_error(reply, "no zone '%s'", name);
	return z;
}

static const char cal_usage[] = "usage: calibrate ZONE night|day [LEVEL]|lux N|finish|status|accept|abort";

void psd_ctlcmd_calibrate(struct psd_daemon *d, const struct psd_cmdtab_args *args, struct psd_ctl_reply *reply)
{
	struct psd_engine *e = &d->engine;
	int argc = args->argc;
	char **argv = args->argv;
	struct psd_zone *z;
	double now = psd_clock_now(&d->clock), a;
	char err[512], *end;
	int rc = 0;
	if (argc < 3) {
		psd_ctlcmd_error(reply, "%s", cal_usage);
		return;
	}
	if (!(z = zone_arg(d, argv[1], reply)))
		return;
	if (strcmp(argv[2], "night") == 0 && argc == 3) {
		rc = psd_engine_cal_start(e, z, PSD_CAL_NIGHT, 0, now, err, sizeof err);
	} else if (strcmp(argv[2], "day") == 0 && argc <= 4) {
		a = z->level;
		if (argc == 4) {
			a = strtod(argv[3], &end);
			if (*end || end == argv[3]) {
				psd_ctlcmd_error(reply, "calibrate ZONE day [LEVEL]: '%s' is not a level", argv[3]);
				return;
			}
		}
		rc = psd_engine_cal_start(e, z, PSD_CAL_DAY, a, now, err, sizeof err);
	} else if (strcmp(argv[2], "lux") == 0 && argc == 4) {
		a = strtod(argv[3], &end);
		if (*end || end == argv[3]) {
			psd_ctlcmd_error(reply, "calibrate ZONE lux N: '%s' is not a number", argv[3]);
			return;
		}
		rc = psd_engine_cal_lux(e, z, a, now, err, sizeof err);
	} else if (strcmp(argv[2], "finish") == 0 && argc == 3) {
		rc = psd_engine_cal_finish(e, z, now, err, sizeof err);
	} else if (strcmp(argv[2], "accept") == 0 && argc == 3) {
		rc = psd_engine_cal_accept(e, z, now, err, sizeof err);
	} else if (strcmp(argv[2], "abort") == 0 && argc == 3) {
		rc = psd_engine_cal_abort(e, z, now, "by request", err, sizeof err);
	} else if (strcmp(argv[2], "status") != 0 || argc != 3) {
		psd_ctlcmd_error(reply, "%s", cal_usage);
		return;
	}
	if (rc != 0) {
		psd_ctlcmd_error(reply, "%s", err);
		return;
	}
	{
		json_object *o = ok_reply();
		json_object_object_add(o, "calibration", cal_json(z, psd_clock_now(&d->clock)));
		finish(o, reply);
	}
}

/* dali DEVICE REQUEST...: a DALI interface's own requests (commissioning),
 * answered by its driver's command method; verify ZONE hands it the zone's
 * outputs on that interface. */
void psd_ctlcmd_dali(struct psd_daemon *d, const struct psd_cmdtab_args *args, struct psd_ctl_reply *reply)
{
	struct psd_engine *e = &d->engine;
	int argc = args->argc;
	char **argv = args->argv;
	struct ps_dev *dev = NULL;
	struct ps_point *pts[2 * PSD_MAX_ZONE_OUT];
	int npts = 0, di = -1;
	size_t outlen = (size_t)1 << 16;   /* a driver's reply: a bus scan's 64 devices fit */
	char *out;
	json_object *o, *res;
	if (argc < 3) {
		psd_ctlcmd_error(reply, "usage: dali DEVICE scan|address [new|all]|group ADDRESS add|remove GROUP|"
		                        "identify SHORT [SECONDS]|verify ZONE|status|abort");
		return;
	}
	for (size_t i = 0; e->cf && i < e->cf->ndev; i++)
		if (e->dev_open[i] && strcmp(e->dev[i].name, argv[1]) == 0)
			di = (int)i;
	if (di < 0) {
		psd_ctlcmd_error(reply, "no device '%s'", argv[1]);
		return;
	}
	dev = &e->dev[di];
	if (!dev->drv->command || strncmp(dev->drv->name, "dali", 4) != 0) {
		psd_ctlcmd_error(reply, "device %s (driver %s) is not a DALI interface", argv[1], dev->drv->name);
		return;
	}
	if (strcmp(argv[2], "verify") == 0 && argc == 4) {
		const struct psd_zone *z = zone_arg(d, argv[3], reply);
		const struct psd_zone_conf *zc;
		if (!z)
			return;
		zc = z->zc;
		for (int k = 0; k < zc->ndim + zc->nrelay; k++) {
			int p = k < zc->ndim ? zc->dim[k] : zc->relay[k - zc->ndim];
			if (e->cf->pt[p].device == di)
				pts[npts++] = &e->pt[p];
		}
		if (!npts) {
			psd_ctlcmd_error(reply, "zone %s has no outputs on %s", argv[3], argv[1]);
			return;
		}
	}
	if (!(out = malloc(outlen))) {
		psd_ctlcmd_error(reply, "out of memory");
		return;
	}
	if (dev->drv->command(dev, argc - 2, argv + 2, pts, npts, psd_clock_now(&d->clock), psd_time_mono(), out,
	                      outlen) != 0) {
		psd_ctlcmd_error(reply, "%s", dev->err);
		free(out);
		return;
	}
	res = json_tokener_parse(out);
	free(out);
	if (!res) {
		psd_ctlcmd_error(reply, "device %s: its driver's reply is not JSON", argv[1]);
		return;
	}
	if (strcmp(argv[2], "status") != 0) {
		char words[160] = "";
		size_t k = 0;
		for (int i = 2; i < argc && k < sizeof words; i++)
			k += (size_t)snprintf(words + k, sizeof words - k, "%s%s", i > 2 ? " " : "", argv[i]);
		psd_log_info("device %s: dali %s", argv[1], words);
	}
	o = ok_reply();
	json_object_object_add(o, "dali", res);
	finish(o, reply);
}

/* status [ZONE]: the table's parser has judged the words and the zone. */
void psd_ctlcmd_status(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply)
{
	struct psd_engine *e = &d->engine;
	double now = psd_clock_now(&d->clock);
	json_object *o, *zones;
	char t[8];
	o = ok_reply();
	zones = json_object_new_array();
	psd_clock_hhmm(now, t);
	psd_json_num(o, "now", now);
	psd_json_str(o, "time", t);
	psd_json_str(o, "clock", d->clock.simulated ? "simulated" : "real");
	json_object_object_add(o, "pid", json_object_new_int((int)getpid()));
	put_path(o, "config", d->config_path);
	json_object_object_add(o, "logged", json_object_new_int64((int64_t)e->logged));
	if (e->log) {   /* the sample log's writer (dbwriter.h): ok, or degraded with what it holds */
		struct psd_dbwriter_stats ls;
		json_object *lo = json_object_new_object();
		psd_dbwriter_stats(e->log, &ls);
		psd_json_str(lo, "state", ls.degraded ? "degraded" : "ok");
		json_object_object_add(lo, "held", json_object_new_int64((int64_t)ls.held));
		json_object_object_add(lo, "dropped", json_object_new_int64((int64_t)ls.dropped));
		json_object_object_add(lo, "errors", json_object_new_int64((int64_t)ls.errors));
		if (ls.degraded)
			psd_json_str(lo, "cause", ls.cause);
		json_object_object_add(o, "log", lo);
	}
	psd_json_num(o, "latency_max_s", e->lat_n ? e->lat_max : NAN);
	psd_json_num(o, "latency_mean_s", e->lat_n ? e->lat_sum / (double)e->lat_n : NAN);
	psd_json_num(o, "late_max_s", e->late_max);
	json_object_object_add(o, "reloads", json_object_new_int64((int64_t)d->reloads));
	json_object_object_add(o, "requests", json_object_new_int64((int64_t)d->ctl.requests));
	json_object_object_add(o, "rejected", json_object_new_int64((int64_t)d->ctl.rejected));
	{   /* each I/O thread (devio.h): seconds in its current transaction, 0 idle */
		json_object *io = json_object_new_object();
		for (size_t i = 0; e->cf && i < e->cf->ndev; i++)
			if (e->io[i])
				psd_json_num(io, e->dev[i].name, psd_devio_busy(e->io[i]));
		json_object_object_add(o, "io_busy_s", io);
	}
	psd_frontend_status(&d->fronts, o);   /* each front end its part: [mqtt] the publisher's state */
	for (size_t i = 0; i < e->nzone; i++)
		if (!a->zone || a->zone == &e->zone[i])
			json_object_array_add(zones, zone_json(&d->points, e, &e->zone[i], now));
	json_object_object_add(o, "zones", zones);
	finish(o, reply);
}

/* ratios [ZONE]: [psensd]'s results, or the zone's own simulation. */
void psd_ctlcmd_ratios(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply)
{
	const struct ps_results *r = d->engine.have_res ? &d->engine.res : NULL;
	const char *path = d->engine.cf->results;
	json_object *o, *conds;
	if (a->zone) {
		const struct psd_zone *z = a->zone;
		r = z->res;
		path = psd_config_zone_results(d->engine.cf, z->zc);
	}
	if (!r) {
		psd_ctlcmd_error(reply, "no results loaded");
		return;
	}
	o = ok_reply();
	conds = json_object_new_array();
	psd_json_str(o, "results", path);
	psd_json_str(o, "scene", r->scene);
	psd_json_str(o, "scene_sha256", r->scene_hash);
	psd_json_num(o, "daylight_ratio_mean", r->daylight_ratio_mean);
	psd_json_num(o, "daylight_ratio_sd", r->daylight_ratio_sd);
	psd_json_num(o, "electric_ratio", r->electric_ratio);
	psd_json_num(o, "task_sensor_ratio", r->task_sensor_ratio);
	for (size_t i = 0; i < r->ncond; i++) {
		json_object *c = json_object_new_object();
		psd_json_str(c, "label", r->cond[i].label);
		psd_json_str(c, "date", r->cond[i].date);
		psd_json_num(c, "tod_s", r->cond[i].tod_s >= 0 ? r->cond[i].tod_s : NAN);
		json_object_object_add(c, "computed", json_object_new_boolean(r->cond[i].computed));
		psd_json_num(c, "sensor_response", r->cond[i].computed ? r->cond[i].sensor_response : NAN);
		psd_json_num(c, "task_lux", r->cond[i].computed ? r->cond[i].task_lux : NAN);
		psd_json_num(c, "ratio", r->cond[i].computed ? r->cond[i].ratio : NAN);
		json_object_array_add(conds, c);
	}
	json_object_object_add(o, "conditions", conds);
	finish(o, reply);
}

/* reload: now, and the outcome in the reply: ok, or ok false with the
 * reasons (each file:line) and the running configuration kept. */
void psd_ctlcmd_reload(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply)
{
	struct psd_reload_why *w = malloc(sizeof *w);   /* 6 kB: not on the handler's stack */
	json_object *o, *arr;
	char msg[512];
	(void)a;
	if (!w) {
		psd_ctlcmd_error(reply, "reload: out of memory");
		return;
	}
	if (psd_reload_explain(d, w) == 0) {
		o = ok_reply();
		put_path(o, "reloaded", d->config_path);
		finish(o, reply);
		free(w);
		return;
	}
	o = json_object_new_object();
	arr = json_object_new_array();
	json_object_object_add(o, "ok", json_object_new_boolean(0));
	snprintf(msg, sizeof msg, "%s: reload refused (%d error(s)): the running configuration stays",
	         d->config_path, w->n);
	psd_json_str(o, "error", msg);
	for (int i = 0; i < w->n; i++)
		json_object_array_add(arr, json_object_new_string(w->line[i]));
	json_object_object_add(o, "reasons", arr);
	finish(o, reply);
	free(w);
}

static const char accept_usage[] = "usage: accept-test ZONE [--since YYYY-MM-DD] [--samples N]";

/* accept-test: the zone's acceptance tests (accept.h) on psensd's own log,
 * stored and committed at once so that a report (another reader) sees
 * them.  psensd runs them because it is the log's one writer: its open
 * batch holds the newest samples, and psensctl -d could not write beside
 * it. */
void psd_ctlcmd_accept_test(struct psd_daemon *d, const struct psd_cmdtab_args *args, struct psd_ctl_reply *reply)
{
	struct psd_engine *e = &d->engine;
	int argc = args->argc;
	char **argv = args->argv;
	struct psd_accept_params p;
	struct psd_accept_result r[PSD_ACCEPT_NTESTS];
	struct psd_accept_summary sum;
	json_object *o, *a, *tests;
	char err[512], stamp[24];
	psd_accept_defaults(&p);
	if (argc < 2) {
		psd_ctlcmd_error(reply, "%s", accept_usage);
		return;
	}
	for (int i = 2; i < argc; i += 2) {
		int rc = i + 1 < argc ? psd_accept_option(&p, argv[i], argv[i + 1], err, sizeof err) : 0;
		if (rc <= 0) {
			psd_ctlcmd_error(reply, "%s", rc < 0 ? err : accept_usage);
			return;
		}
	}
	if (!zone_arg(d, argv[1], reply))
		return;
	if (!e->db) {
		psd_ctlcmd_error(reply, "psensd keeps no database: the acceptance tests judge its log");
		return;
	}
	if (psd_accept_zone(e->db, argv[1], &p, floor(psd_time_wall()), r, &sum, err, sizeof err) != 0 ||
	    psd_db_commit(e->db, err, sizeof err) != 0) {
		psd_ctlcmd_error(reply, "accept-test %s: %s", argv[1], err);
		return;
	}
	psd_points_set_verdict(&d->points, argv[1], psd_accept_overall(&sum));
	psd_engine_stamp(e, psd_clock_now(&d->clock), stamp, sizeof stamp);
	psd_log_info("zone %s: %s: acceptance tests: %s (%d of %d run, %d failed)", argv[1], stamp,
	         psd_accept_overall(&sum), sum.tested, sum.count, sum.failed);
	o = ok_reply();
	a = json_object_new_object();
	psd_json_str(a, "zone", argv[1]);
	psd_json_num(a, "target_lux", p.target_lux);
	psd_json_num(a, "elec_task_lux", p.elec_task_lux);
	psd_json_num(a, "delay", p.delay);
	tests = json_object_new_array();
	for (int i = 0; i < PSD_ACCEPT_NTESTS; i++) {
		json_object *t;
		if (!r[i].test)
			continue;   /* not the zone's */
		t = json_object_new_object();
		psd_json_str(t, "test", r[i].test);
		psd_json_str(t, "verdict", psd_accept_verdict_names[r[i].verdict + 1]);
		psd_json_num(t, "value", r[i].value);
		psd_json_num(t, "limit", r[i].limit);
		psd_json_str(t, "unit", r[i].unit);
		psd_json_str(t, "bound", r[i].bound);
		json_object_object_add(t, "samples", json_object_new_int64(r[i].samples));
		psd_json_str(t, "measured", r[i].measured);
		json_object_array_add(tests, t);
	}
	json_object_object_add(a, "tests", tests);
	psd_json_str(a, "verdict", psd_accept_overall(&sum));
	json_object_object_add(a, "tested", json_object_new_int(sum.tested));
	json_object_object_add(a, "failed", json_object_new_int(sum.failed));
	json_object_object_add(o, "accept", a);
	finish(o, reply);
}

void psd_ctlcmd_ping(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply)
{
	json_object *o = ok_reply();
	(void)d;
	(void)a;
	json_object_object_add(o, "pid", json_object_new_int((int)getpid()));
	finish(o, reply);
}

void psd_ctlcmd_log(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply)
{
	json_object *o = ok_reply();
	(void)a;
	put_path(o, "database", d->engine.cf->database);
	json_object_object_add(o, "logged", json_object_new_int64((int64_t)d->engine.logged));
	finish(o, reply);
}

void psd_ctlcmd_target(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply)
{
	char err[512];
	(void)d;
	if (psd_engine_set_target(a->zone, a->num[0], err, sizeof err) != 0)
		psd_ctlcmd_error(reply, "%s", err);
	else
		finish(ok_reply(), reply);
}

void psd_ctlcmd_off(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply)
{
	(void)d;
	psd_engine_off(a->zone);
	finish(ok_reply(), reply);
}
