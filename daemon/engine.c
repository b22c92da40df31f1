/* SPDX-License-Identifier: ISC */
#include "engine.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "accept.h"
#include "clock.h"
#include "errbuf.h"
#include "log.h"
#include "roomsetup.h"
#include "time.h"
#include "dated.h"

static void start_io(struct psd_engine *e, const struct psd_clock *clock);
static void stop_io(struct psd_engine *e);

static void on_event(void *user, struct ps_dev *dev, struct ps_point *pt, double now, double value);
static int command(struct psd_engine *e, struct psd_zone *z, double now, double level, char *why, size_t n);

/* Zone i's results: its own, else [psensd]'s (NULL: none). */
static const struct ps_results *zone_res(const struct psd_engine *e, size_t i)
{
	return e->have_zres[i] ? &e->zres[i] : e->have_res ? &e->res : NULL;
}

/* The results a device's room plays: those of the first zone whose sensor
 * is on the device, else [psensd]'s; *path names them for messages. */
static const struct ps_results *device_res(const struct psd_engine *e, const struct ps_dev *d, const char **path)
{
	const struct psd_config *cf = e->cf;
	int di = (int)(d - e->dev);
	for (size_t i = 0; i < cf->nzone; i++)
		if (cf->pt[cf->zone[i].sensor].device == di) {
			*path = psd_config_zone_results(cf, &cf->zone[i]);
			return zone_res(e, i);
		}
	*path = cf->results;
	return e->have_res ? &e->res : NULL;
}

/* A simulated device's room, built from the results (daemon/roomsetup.c). */
static int setup_room(struct psd_engine *e, struct ps_dev *d, double now, char *err, size_t n)
{
	const struct psd_config *cf = e->cf;
	const char *path = NULL;
	const struct ps_results *res = device_res(e, d, &path);
	struct ps_room_params *room = !res ? NULL
	                              : cf->sim_year ? psd_roomsetup_new_year(res, cf->date, psd_clock_dst_shift_day(cf->date, e->utc0))
	                                             : psd_roomsetup_new(res, cf->date, cf->sunrise, cf->sunset);
	int rc;
	if (!room && cf->sim_year)
		return psd_errbuf(err, n, "device %s: [simulate] year = yes needs results with a year and an "
		                "electric condition (a weather file in the scene: psscene(5)); %s has %s",
		                d->name, path, res && res->have_year ? "no electric condition" : "no year");
	if (!room)
		return psd_errbuf(err, n, "device %s: the %s room needs results with a daylight and an electric "
		                "condition (%s)", d->name, d->drv->name, path);
	rc = d->drv->setup(d, room, now);
	psd_roomsetup_free(room);
	return rc == 0 ? 0 : psd_errbuf(err, n, "device %s: %s", d->name, d->err);
}

static int open_devices(struct psd_engine *e, double now, char *err, size_t n)
{
	struct psd_config *cf = e->cf;
	for (size_t i = 0; i < cf->ndev; i++) {
		struct ps_dev *d = &e->dev[i];
		memset(d, 0, sizeof *d);
		d->drv = cf->dev[i].drv;
		snprintf(d->name, sizeof d->name, "%s", cf->dev[i].name);
		d->on_event = on_event;
		d->event_user = e;
		e->dev_open[i] = 1;
		/* the keys were judged by the configuration's check (the driver's table) */
		if (d->drv->open(d, &cf->dev[i].opts) != 0)
			return psd_errbuf(err, n, "device %s: %s", d->name, d->err);
		if (d->drv->setup && setup_room(e, d, now, err, n) != 0)
			return -1;
	}
	for (size_t i = 0; i < cf->npt; i++) {
		struct psd_point_conf *pc = &cf->pt[i];
		struct ps_dev *d = &e->dev[pc->device];
		struct ps_point *p = &e->pt[i];
		memset(p, 0, sizeof *p);
		snprintf(p->name, sizeof p->name, "%s", pc->name);
		p->role = pc->role;
		if (d->drv->add_point(d, p, &pc->opts) != 0)
			return psd_errbuf(err, n, "point %s: %s", p->name, d->err);
		/* the driver's own range: a sensor reading at its input's full scale
		 * is saturated whatever sensor_saturation says */
		e->full_scale[i] = NAN;   /* none (nor is 0) */
		if (p->role == PS_ROLE_SENSOR && d->drv->full_scale &&
		    (d->drv->full_scale(d, p, &e->full_scale[i]) != 0 || !(e->full_scale[i] > 0)))
			e->full_scale[i] = NAN;
	}
	return 0;
}

/* When point p's value was measured, on the daemon's clock: now for a
 * point read anew at each read (and for any a device's I/O thread reads:
 * the step's prefetch reads it), earlier for a value the device reported
 * by itself (driver.h, age). */
static double pt_measured(const struct psd_engine *e, int p, double now)
{
	const struct ps_dev *d;
	double age;
	if (p < 0 || e->io[e->cf->pt[p].device])
		return now;
	d = &e->dev[e->cf->pt[p].device];
	if (!d->drv->age)
		return now;
	age = d->drv->age((struct ps_dev *)d, (struct ps_point *)&e->pt[p], psd_time_mono());
	return now - (age >= 0 ? age * e->speed : 0);
}

/* Ask point p's device for a value measured from now on (driver.h). */
static void pt_refresh(struct psd_engine *e, int p, double now)
{
	struct ps_dev *d;
	if (p < 0 || e->io[e->cf->pt[p].device])
		return;
	d = &e->dev[e->cf->pt[p].device];
	if (d->drv->refresh && d->drv->refresh(d, &e->pt[p], now, psd_time_mono()) != 0)
		psd_log_debug("%s: %s", e->pt[p].name, d->err);
}

/* What a calibration session may see of its zone (calsession.h). */
static struct psd_calsession_ctx cal_ctx(const struct psd_engine *e, const struct psd_zone *z, double now)
{
	const struct psd_calsession_ctx c = {
		.zone = z->zc->name,
		.zc = z->zc,
		.ctl = &z->ctl,
		.res = z->res,
		.db = e->db,
		.config_path = e->cf->conf.path,
		.now = now,
		.date = e->cf->date,
		.sunrise = e->cf->sunrise,
		.sunset = e->cf->sunset,
		.have_reading = !z->in_fault && isfinite(z->volts),
		.volts = z->volts,
		.level = z->level,
		.epoch0 = e->utc0,
		.volts_t = z->volts_t,
		.lux_t = z->task_t,
	};
	return c;
}

/* Do what a session asked: a step now, fresh readings, accepted constants
 * in force. */
static void cal_act(struct psd_engine *e, struct psd_zone *z, double now, const struct psd_calsession_ask *ask)
{
	if (ask->step_now)
		z->asap = 1;
	if (ask->refresh_sensor)
		pt_refresh(e, z->zc->sensor, now);
	if (ask->refresh_task)
		pt_refresh(e, z->zc->task, now);
	for (int i = 0; i < ask->napply; i++) {
		const struct psd_calsession_consts *k = &ask->apply[i];
		if (isfinite(k->offset))
			z->ctl.offset = k->offset;
		if (k->sensor_gain > 0)
			z->ctl.sensor_gain = k->sensor_gain;
		if (k->elec_task_lux > 0)
			z->ctl.elec_task_lux = k->elec_task_lux;
		if (k->daylight_ratio > 0)
			z->ctl.daylight_ratio = k->daylight_ratio;
		if (k->kind == PSD_CAL_NIGHT)
			z->cal_night_id = k->id;
		else
			z->cal_day_id = k->id;
	}
}

/* At open: the accepted calibrations in force, a session left running resumed. */
static void cal_load(struct psd_engine *e, struct psd_zone *z, double now)
{
	struct psd_calsession_ctx c = cal_ctx(e, z, now);
	struct psd_calsession_ask ask;
	psd_calsession_accepted(&c, &ask);
	cal_act(e, z, now, &ask);
	if (z->cal_night_id || z->cal_day_id)
		psd_log_info("zone %s: calibrated (night session %lld, day session %lld): sensor gain %.5g, offset "
		         "%.4g V, daylight ratio %.5g", z->zc->name, z->cal_night_id, z->cal_day_id, z->ctl.sensor_gain,
		         z->ctl.offset, z->ctl.daylight_ratio);
	psd_calsession_resume(&z->cal, &c, z->level, &ask);
	cal_act(e, z, now, &ask);
}

static void zone_init(struct psd_engine *e, struct psd_zone *z, const struct psd_zone_conf *zc, double now,
                      const struct psd_engine *prev)
{
	const struct ps_dev *sd = &e->dev[e->cf->pt[zc->sensor].device];
	memset(z, 0, sizeof *z);
	z->zc = zc;
	z->ctl = zc->ctl;
	z->res = zone_res(e, (size_t)(zc - e->cf->zone));
	if (z->res) {
		z->ctl.daylight_ratio = z->res->daylight_ratio_mean;
		z->ctl.elec_sensor = z->res->electric_sensor_response;
		z->ctl.elec_task_lux = z->res->electric_task_lux;
	}
	z->ctl.level = 1.0;
	z->ctl.pending_since = -1;
	z->level = 1.0;
	z->next = now;
	z->started = now;
	z->last_ok = now;
	z->volts = z->task_lux = z->last_volts = NAN;
	z->last.t = NAN;
	z->sky_class = -1;
	z->same_since = now;
	z->override_level = NAN;
	z->override_until = -INFINITY;
	z->occupancy = -1;
	for (int i = 0; i < zc->ninput; i++) {
		if (e->cf->pt[zc->input[i]].action == PSD_ACT_OCCUPANCY)
			z->occupancy = 1;   /* occupied until an input says otherwise */
		z->occ_in[i] = -1;
		z->occ_ok[i] = now;
	}
	psd_occupancy_init(&z->occ, zc->vacancy_s, zc->vacant_level, now);
	z->verify_at = INFINITY;
	if (sd->drv->truth) {
		struct ps_truth t;
		z->sim = (struct ps_dev *)sd;
		if (sd->drv->truth(z->sim, now, &t) == 0)
			z->st.energy0 = t.energy;
	}
	z->st.energy_last = z->st.energy0;
	z->st.since = now;
	z->st.cal_until = -INFINITY;
	z->st.worst_lux = INFINITY;
	if (prev) {
		for (size_t i = 0; i < prev->nzone; i++) {
			const struct psd_zone *o = &prev->zone[i];
			if (strcmp(o->zc->name, zc->name) != 0)
				continue;
			z->ctl.level = z->level = o->level;
			z->override_level = o->override_level;
			z->override_until = o->override_until;
			z->daylight_off = o->daylight_off;
			if (z->occupancy >= 0 && o->occupancy >= 0) {   /* the room is as it was */
				z->occ = o->occ;
				z->occ.hold = zc->vacancy_s;
				z->occ.vacant_level = zc->vacant_level;
				z->occupancy = o->occupancy;
				if (zc->ninput == o->zc->ninput) {   /* the inputs' last reports */
					memcpy(z->occ_in, o->occ_in, sizeof z->occ_in);
					memcpy(z->occ_ok, o->occ_ok, sizeof z->occ_ok);
				}
			}
			z->next = o->next;
			if (z->ctl.target_lux == o->zc->ctl.target_lux)
				z->ctl.target_lux = o->ctl.target_lux;   /* a target set at run time survives */
			/* the statistics run on over the reload: the reopened room
			 * counts its energy afresh, so what the old one used up to
			 * the zone's last step is carried, so that the summary's
			 * numerator and its denominator both span the reload */
			if (z->sim && o->sim) {
				double e0 = z->st.energy0;
				z->st = o->st;
				z->st.energy_prior = psd_engine_zone_energy(&o->st, o->st.energy_last);
				z->st.energy0 = z->st.energy_last = e0;
			}
		}
	}
}

/* The zone's design constants for the acceptance tests (daemon/accept.h). */
static void record_consts(struct psd_engine *e, const struct psd_zone *z)
{
	char err[512];
	if (e->db && (psd_db_zone_consts_set(e->db, z->zc->name, z->ctl.target_lux, z->ctl.elec_task_lux,
	                                     z->ctl.delay, err, sizeof err) != 0 ||
	              (z->occupancy >= 0 && psd_db_zone_occupancy_set(e->db, z->zc->name, z->occ.hold,
	                                                               z->occ.vacant_level, err, sizeof err) != 0))) {
		e->log_errors++;   /* rare (a start, an accepted session): each said */
		psd_log_warnx("%s: %s", e->cf->database, err);
	}
}

/* The log cannot be opened: before the start is refused, every zone's
 * outputs to its safe level (the lights may be wherever a crash left
 * them). */
static void safe_without_log(struct psd_engine *e, double now, const struct psd_engine *prev)
{
	for (size_t i = 0; i < e->cf->nzone; i++) {
		struct psd_zone *z = &e->zone[i];
		char why[256];
		zone_init(e, z, &e->cf->zone[i], now, prev);
		if (command(e, z, now, z->zc->safe_level, why, sizeof why) != 0)
			psd_log_errx("zone %s: the log cannot be opened, and the safe level cannot be reached: %s", z->zc->name,
			         why);
		else
			psd_log_errx("zone %s: the log cannot be opened: lights at the safe level %.0f %%", z->zc->name,
			         100 * z->zc->safe_level);
	}
}

int psd_engine_open(struct psd_engine *e, struct psd_config *cf, double now, int db_batch,
                    const struct psd_engine *prev, char *err, size_t errlen)
{
	return psd_engine_open_io(e, cf, now, db_batch, prev, NULL, err, errlen);
}

int psd_engine_open_io(struct psd_engine *e, struct psd_config *cf, double now, int db_batch,
                       const struct psd_engine *prev, const struct psd_clock *clock, char *err, size_t errlen)
{
	struct ps_err pe;
	memset(e, 0, sizeof *e);
	e->cf = cf;
	e->db_batch = db_batch > 0 ? db_batch : 1;
	e->speed = clock && !clock->simulated && clock->speed > 0 ? clock->speed : 1;
	e->utc0 = prev ? prev->utc0 : NAN;   /* the daemon sets it after the first open */
	if (prev)
		e->logged = e->logged_base = prev->logged;   /* counted across reloads */
	/* the dated estimate's month: the simulated date's (psensd sets today's
	 * on a real-time clock unless the room plays the year) */
	e->month = psd_dated_month(cf->date);
	e->doy = psd_dated_day(cf->date);
	if (prev && !cf->sim_year) {
		e->month = prev->month;
		e->doy = prev->doy;
	}
	if (cf->results) {
		if (ps_results_read(&e->res, cf->results, &pe) != 0) {
			psd_errbuf(err, errlen, "%s", pe.msg);
			goto bad;
		}
		e->have_res = 1;
	}
	/* zones with their own simulation */
	for (size_t i = 0; i < cf->nzone; i++) {
		const char *r = psd_config_zone_results(cf, &cf->zone[i]);
		if (!r || (cf->results && strcmp(r, cf->results) == 0))
			continue;
		if (ps_results_read(&e->zres[i], r, &pe) != 0) {
			psd_errbuf(err, errlen, "zone %s: %s", cf->zone[i].name, pe.msg);
			goto bad;
		}
		e->have_zres[i] = 1;
	}
	if (open_devices(e, now, err, errlen) != 0)
		goto bad;
	/* the log: its own thread writes it (dbwriter.h); a simulated clock
	 * waits for room in the queue rather than drop a sample.  A log that
	 * cannot be opened refuses the start, after the lights are safe */
	/* a reload on the same database keeps the writer and what it holds
	 * (reload.c leaves it open), so the reload waits for no lock */
	if (cf->database && prev && prev->log && prev->cf && prev->cf->database &&
	    strcmp(prev->cf->database, cf->database) == 0) {
		e->log = prev->log;
		e->log_borrowed = 1;
		e->logged_base = prev->logged_base;   /* the writer counts on from where it was */
	}
	if (cf->database && (!(e->db = psd_db_open(cf->database, err, errlen)) ||
	                     (!e->log && !(e->log = psd_dbwriter_open(cf->database, (size_t)cf->log_hold,
	                                                              !clock || clock->simulated, err, errlen))))) {
		/* a start: the lights safe before it is refused; a reload
		 * (prev) reopens the running configuration, which takes the
		 * outputs back at their level: the safe level between would be
		 * a flash of every zone */
		if (!prev)
			safe_without_log(e, now, prev);
		goto bad;
	}
	if (e->db) {
		psd_db_set_batch(e->db, e->db_batch);
		psd_db_set_epoch(e->db, e->utc0);
		psd_dbwriter_set_epoch(e->log, e->utc0);
		/* the control thread's own writes (calibration records, MQTT's
		 * cursor) wait for a lock only briefly: they fail and are retried */
		psd_db_set_busy(e->db, 50);
	}
	for (size_t i = 0; i < cf->nzone; i++) {
		zone_init(e, &e->zone[i], &cf->zone[i], now, prev);
		if ((cf->zone[i].ctl.algorithm == PSD_ALG_SETPOINT ||
		     cf->zone[i].ctl.algorithm == PSD_ALG_CLOSED_PROPORTIONAL) &&
		    !(e->zone[i].ctl.daylight_ratio > 0 && e->zone[i].ctl.elec_task_lux > 0)) {
			psd_errbuf(err, errlen, "zone %s: %s control needs the simulated daylight and electric ratios (%s)",
			     cf->zone[i].name, psd_control_algorithm_names[cf->zone[i].ctl.algorithm],
			     psd_config_zone_results(cf, &cf->zone[i]));
			goto bad;
		}
	}
	e->nzone = cf->nzone;
	for (size_t i = 0; i < e->nzone; i++)
		psd_calfit_drift_init(&e->zone[i].drift, cf->zone[i].drift_margin, cf->zone[i].drift_hold,
		               cf->zone[i].cal_min_day_volts);
	for (size_t i = 0; i < e->nzone; i++)
		cal_load(e, &e->zone[i], now);
	for (size_t i = 0; i < e->nzone; i++)
		record_consts(e, &e->zone[i]);
	/* the I/O threads before the first commands: a slow module must not
	 * hold the loop at start or at a reload either */
	if (clock && !clock->simulated)
		start_io(e, clock);
	/* the outputs start where the control believes they are (full output,
	 * or the level before a reload) */
	for (size_t i = 0; i < e->nzone; i++) {
		char why[256];
		if (command(e, &e->zone[i], now, e->zone[i].level, why, sizeof why) != 0)
			psd_log_warnx("zone %s: %s", e->zone[i].zc->name, why);
	}
	e->log_borrowed = 0;   /* the writer is this engine's now */
	return 0;
bad:
	psd_engine_close(e);
	return -1;
}

struct psd_config *psd_engine_close(struct psd_engine *e)
{
	struct psd_config *cf = e->cf;
	stop_io(e);
	if (!e->log_borrowed)   /* what is held, written while there is time */
		psd_dbwriter_close(e->log, 2.0);
	e->log = NULL;
	psd_db_close(e->db);
	e->db = NULL;
	for (size_t i = 0; cf && i < cf->ndev; i++)
		if (e->dev_open[i] && e->dev[i].drv && e->dev[i].drv->close)
			e->dev[i].drv->close(&e->dev[i]);
	if (e->have_res)
		ps_results_free(&e->res);
	for (size_t i = 0; i < PSD_MAX_ZONES; i++)
		if (e->have_zres[i])
			ps_results_free(&e->zres[i]);
	memset(e, 0, sizeof *e);
	return cf;
}

void psd_engine_set_epoch(struct psd_engine *e, double epoch0)
{
	e->utc0 = epoch0;   /* the one clock date: samples.utc and every dated row */
	if (e->db)
		psd_db_set_epoch(e->db, epoch0);
	if (e->log)
		psd_dbwriter_set_epoch(e->log, epoch0);
}

void psd_engine_stamp(const struct psd_engine *e, double t, char *out, size_t n)
{
	psd_clock_stamp(e->utc0, t, out, n);
}

/* An event in the database's events table, through the writer (which
 * reports its failures). */
void psd_engine_event(struct psd_engine *e, double now, const char *zone, const char *kind, const char *text)
{
	if (e->log)
		psd_dbwriter_event(e->log, now, zone, kind, text);
}

static void event(struct psd_engine *e, double now, const char *zone, const char *kind, const char *text)
{
	psd_engine_event(e, now, zone, kind, text);
}

static struct ps_dev *dev_of(struct psd_engine *e, int point)
{
	return &e->dev[e->cf->pt[point].device];
}

static struct psd_devio *io_of(struct psd_engine *e, int point)
{
	return e->io[e->cf->pt[point].device];
}

/* A point's read or write, through its device's I/O thread when it has one;
 * on failure errno is the driver's and e->ioerr its message. */
static int pt_read(struct psd_engine *e, int p, double now, double *v)
{
	struct ps_dev *d = dev_of(e, p);
	struct psd_devio *io = io_of(e, p);
	int rc, er;
	if (io)
		return psd_devio_take(io, (size_t)p, now, v, e->ioerr, sizeof e->ioerr);
	rc = d->drv->read(d, &e->pt[p], now, psd_time_mono(), v);
	er = errno;
	if (rc)
		snprintf(e->ioerr, sizeof e->ioerr, "%s", d->err);
	errno = er;
	return rc;
}

static int pt_write(struct psd_engine *e, int p, double now, double v)
{
	struct ps_dev *d = dev_of(e, p);
	struct psd_devio *io = io_of(e, p);
	int rc, er;
	if (io)
		return psd_devio_write(io, (size_t)p, now, v, e->ioerr, sizeof e->ioerr);
	rc = d->drv->write(d, &e->pt[p], now, psd_time_mono(), v);
	er = errno;
	if (rc)
		snprintf(e->ioerr, sizeof e->ioerr, "%s", d->err);
	errno = er;
	return rc;
}

/* Real time: give each device with blocking I/O its I/O thread. */
static void start_io(struct psd_engine *e, const struct psd_clock *clock)
{
	for (size_t i = 0; e->cf && i < e->cf->ndev; i++) {
		if (e->io[i] || !e->dev_open[i] || !psd_devio_wanted(e->dev[i].drv))
			continue;
		if (!(e->io[i] = psd_devio_start(&e->dev[i], e->pt, e->cf->npt, clock)))
			psd_log_warnx("device %s: no I/O thread (%s): its I/O runs in the event loop", e->dev[i].name,
			          strerror(errno));
	}
}

/* Stop and join every I/O thread: the drivers are called in the loop again. */
static void stop_io(struct psd_engine *e)
{
	for (size_t i = 0; i < PSD_MAX_DEVICES; i++) {
		psd_devio_stop(e->io[i]);
		e->io[i] = NULL;
	}
	for (size_t i = 0; i < e->nzone; i++)
		e->zone[i].waiting = 0;
}

/* Before a step, the zone's reads on devices with an I/O thread are asked
 * for; the step runs when they are all answered (the thread wakes the
 * loop) or, for those still out, at its next scheduled step as missed
 * replies (a slow device is a queue: an answer late in the period is still
 * fresher than none).
 * 1: not yet. */
static int prefetch(struct psd_engine *e, struct psd_zone *z, double now)
{
	const struct psd_zone_conf *zc = z->zc;
	int pts[2 + 2 * PSD_MAX_ZONE_OUT], n = 0, pending = 0;
	if (zc->task >= 0)
		pts[n++] = zc->task;
	for (int i = 0; i < zc->ninput; i++)
		if (e->cf->pt[zc->input[i]].action == PSD_ACT_OCCUPANCY)
			pts[n++] = zc->input[i];
	pts[n++] = zc->sensor;
	if (zc->verify_tolerance > 0 && now >= z->verify_at)
		for (int i = 0; i < zc->ndim; i++)
			pts[n++] = zc->dim[i];
	else if (zc->readback && zc->ndim > 0)
		pts[n++] = zc->dim[0];
	for (int i = 0; i < n; i++) {
		struct psd_devio *io = io_of(e, pts[i]);
		if (!io)
			continue;
		if (!z->waiting) {   /* a new step: a fresh read (an answer left over is dropped) */
			double junk;
			char err[8];
			if (psd_devio_ask(io, (size_t)pts[i], now) == 0)
				psd_devio_take(io, (size_t)pts[i], now, &junk, err, sizeof err);
			psd_devio_ask(io, (size_t)pts[i], now);
			pending = 1;
		} else if (psd_devio_ask(io, (size_t)pts[i], now) != 0) {
			pending = 1;
		}
	}
	if (!pending) {
		z->waiting = 0;
		return 0;
	}
	if (!z->waiting) {
		z->waiting = 1;
		z->wait_since = now;
		return 1;
	}
	if (now - z->wait_since < zc->period * 0.95)
		return 1;
	z->waiting = 0;   /* what is still out counts as no reply */
	return 0;
}

/* Command every output of the zone; returns -1 (with why) when one fails. */
static int command(struct psd_engine *e, struct psd_zone *z, double now, double level, char *why, size_t n)
{
	const struct psd_zone_conf *zc = z->zc;
	int rc = 0;
	for (int i = 0; i < zc->ndim; i++) {
		if (pt_write(e, zc->dim[i], now, level) != 0 && rc == 0) {
			snprintf(why, n, "%s", e->ioerr);
			rc = -1;
		}
	}
	/* relay k of n closes above k/n: n relays are the steps of a stepped
	 * system, one relay switches a dimmed circuit off at level 0 */
	for (int i = 0; i < zc->nrelay; i++) {
		double on = level > (double)i / zc->nrelay + 1e-9;
		if (pt_write(e, zc->relay[i], now, on) != 0 && rc == 0) {
			snprintf(why, n, "%s", e->ioerr);
			rc = -1;
		}
	}
	z->level = level;
	return rc;
}

static void enter_fault(struct psd_engine *e, struct psd_zone *z, double now, const char *why)
{
	char t[24], err[256];
	psd_engine_stamp(e, now, t, sizeof t);
	if (!z->in_fault) {
		psd_log_warnx("zone %s: %s fault: %s: lights to the safe level %.0f %%", z->zc->name, t, why,
		          100 * z->zc->safe_level);
		event(e, now, z->zc->name, "fault", why);
	}
	else if (strcmp(z->why, why) != 0)
		psd_log_debug("zone %s: %s fault now: %s", z->zc->name, t, why);
	z->in_fault = 1;
	snprintf(z->why, sizeof z->why, "%s", why);
	if (psd_calsession_running(&z->cal)) {
		struct psd_calsession_ctx c = cal_ctx(e, z, now);
		struct psd_calsession_ask ask;
		psd_calsession_abort(&z->cal, &c, why, &ask);
		cal_act(e, z, now, &ask);
	}
	/* an output that cannot be commanded even to the safe level needs a
	 * person: said once, until the safe level is reached */
	if (command(e, z, now, z->zc->safe_level, err, sizeof err) != 0) {
		if (!z->unsafe)
			psd_log_errx("zone %s: %s cannot reach the safe level: %s", z->zc->name, t, err);
		z->unsafe = 1;
	} else {
		z->unsafe = 0;
	}
	z->ctl.level = z->zc->safe_level;
	z->ctl.pending_dir = 0;
	z->fault_steps++;
	z->st.fault_steps++;
}

/* The sensor reading, checked: -1 with why when it is a fault. */
static int read_sensor(struct psd_engine *e, struct psd_zone *z, double now, char *why, size_t n)
{
	const struct psd_zone_conf *zc = z->zc;
	const struct psd_point_conf *pc = &e->cf->pt[zc->sensor];
	double v = NAN;
	if (pt_read(e, zc->sensor, now, &v) != 0) {
		z->volts = NAN;
		/* a lost device or a wrong value is a fault at once; a missed or
		 * garbled reply only once the last good reading is stale (driver.h) */
		int at_once = ps_dev_fault_at_once(errno);
		if (at_once || now - z->last_ok >= zc->stale_after) {
			if (at_once)
				snprintf(why, n, "%s", e->ioerr);
			else {
				char since[8];
				psd_clock_hhmm(z->last_ok, since);
				snprintf(why, n, "no reading since %s (%.200s)", since, e->ioerr);
			}
			return -1;
		}
		psd_log_debug("zone %s: %s (holding the level)", zc->name, e->ioerr);
		return 1;
	}
	z->volts = v;
	z->volts_t = pt_measured(e, zc->sensor, now);
	/* saturation is the sensor's own limit, apart from the control range:
	 * a reading at it says only "this much or more" */
	if (pc->saturation > 0 && v >= pc->saturation) {
		snprintf(why, n, "sensor saturated: reads %.3f V, at or above its saturation %g V", v,
		         pc->saturation);
		return -1;
	}
	if (e->full_scale[zc->sensor] > 0 && v >= e->full_scale[zc->sensor] * (1 - 1e-9)) {
		snprintf(why, n, "sensor saturated: reads %.3f V, at its input's full scale %g V (%s)", v,
		         e->full_scale[zc->sensor], e->dev[pc->device].drv->name);
		return -1;
	}
	/* below the range with the lights commanded off (a vacancy, a manual
	 * off): a dark room, not an open circuit, which shows when they are
	 * next on; off at a safe level of 0, the fault stands */
	if (v < pc->min && z->level <= 0 && !z->in_fault && isfinite(v)) {
		z->last_ok = now;
		z->same_since = now;
		return 0;
	}
	if (!(v >= pc->min && v <= pc->max)) {
		snprintf(why, n, "sensor reads %.3f V, outside %g to %g V", v, pc->min, pc->max);
		return -1;
	}
	if (v != z->last_volts) {
		z->last_volts = v;
		z->same_since = now;
	} else if (zc->stuck_after > 0 && now - z->same_since >= zc->stuck_after) {
		snprintf(why, n, "sensor stuck at %.4f V for %.0f s", v, now - z->same_since);
		return -1;
	}
	z->last_ok = now;
	return 0;
}

/* A ballast that did not follow the last command: read the dim points back.
 * 0 followed, -1 a fault (why), 1 not judged yet: a driver whose read says
 * EAGAIN has no level read since the command and its fade (a DALI answer to
 * a query sent before the command is the level from before it). */
static int verify_outputs(struct psd_engine *e, struct psd_zone *z, double now, char *why, size_t n)
{
	const struct psd_zone_conf *zc = z->zc;
	int judged = 1;
	if (zc->verify_tolerance <= 0 || now < z->verify_at)
		return 0;
	for (int i = 0; i < zc->ndim; i++) {
		double got;
		if (pt_read(e, zc->dim[i], now, &got) != 0) {
			if (errno == EAGAIN) {
				psd_log_debug("zone %s: %s", zc->name, e->ioerr);
				judged = 0;
				continue;
			}
			snprintf(why, n, "%s: cannot read the output back: %.180s", e->pt[zc->dim[i]].name, e->ioerr);
			return -1;
		}
		if (fabs(got - z->level) > zc->verify_tolerance &&
		    !(z->level < z->ctl.min_level && got <= z->level + zc->verify_tolerance)) {
			snprintf(why, n, "ballast %s not responding: at %.0f %%, commanded %.0f %%",
			         e->pt[zc->dim[i]].name, 100 * got, 100 * z->level);
			return -1;
		}
	}
	return judged ? 0 : 1;
}

/* The dated estimate (dated.h): the month's and hour's expected ratio, unless
 * a day calibration measured the zone's own. */
static void dated_ratio(struct psd_engine *e, struct psd_zone *z, double now)
{
	double q = NAN;
	z->sky_class = -1;
	/* the table is in the weather's standard time, the clock local */
	double tod = psd_clock_tod(now - psd_clock_dst_shift(e->utc0 + now));
	if (!z->res || !z->res->have_year || !e->cf->dated_estimate || z->cal_day_id)
		return;
	if (z->zc->rooftop >= 0) {
		/* the sky now from the rooftop sensor, else the typical class */
		struct ps_dev *d = dev_of(e, z->zc->rooftop);
		double lux;
		if (d->drv->read(d, &e->pt[z->zc->rooftop], now, psd_time_mono(), &lux) == 0) {
			z->rooftop_failed = 0;
			z->sky_class = psd_dated_rooftop_class(z->res, e->doy, tod, lux);
			if (z->sky_class >= 0)
				q = psd_dated_ratio_class(z->res, e->month, tod, z->sky_class);
			if (!(q > 0))
				z->sky_class = -1;   /* no hour of that class there: the typical one */
		} else if (!z->rooftop_failed++) {
			psd_log_warnx("zone %s: rooftop %s: %s; the typical sky class until it reads", z->zc->name,
			          e->pt[z->zc->rooftop].name, d->err);
		}
	}
	if (!(q > 0))
		q = psd_dated_ratio(z->res, e->month, tod, NULL);
	if (q > 0)
		z->ctl.daylight_ratio = q;
}

/* The samples' name of the ratio in force. */
static const char *ratio_name(const struct psd_engine *e, const struct psd_zone *z)
{
	static const char *const rooftop[PS_SKY_NCLASS] = { "daylight_rooftop_clear", "daylight_rooftop_intermediate",
	                                                     "daylight_rooftop_overcast" };
	if (!z->res)
		return NULL;
	if (!(z->res->have_year && e->cf->dated_estimate && !z->cal_day_id))
		return "daylight_mean";
	return z->sky_class >= 0 && z->sky_class < PS_SKY_NCLASS ? rooftop[z->sky_class] : "daylight_dated";
}

static void log_sample(struct psd_engine *e, struct psd_zone *z, double now)
{
	int fault = z->in_fault;
	/* the step's own estimate (snapshot): none when the control did not run */
	double dl = z->ctl.daylight_ratio * z->last.daylight_v / z->ctl.sensor_gain;
	struct psd_sample s = {
		now, psd_clock_tod(now), z->volts, z->level,
		fault ? NAN : z->last.est_task_lux, z->task_lux,
		fault ? NAN : z->last.daylight_v,
		fault ? NAN : dl,
		ratio_name(e, z), z->ctl.daylight_ratio, fault ? z->why : NULL,
		z->zc->name, e->utc0 + now, NULL,   /* utc: the clock's; local from it (db.c) */
		z->occupancy, z->last.true_task_lux,
	};
	if (!e->log)
		return;
	/* queued: the writer thread writes it and reports its faults */
	psd_dbwriter_sample(e->log, &s);
	e->logged = e->logged_base + psd_dbwriter_committed(e->log);
}

int psd_engine_truth(const struct psd_zone *z, double now, struct ps_truth *t)
{
	return z->sim && z->sim->drv->truth(z->sim, now, t) == 0 ? 0 : -1;
}

double psd_engine_zone_energy(const struct psd_zone_stats *s, double energy_now)
{
	return s->energy_prior + (energy_now - s->energy0);
}

static void truth(struct psd_engine *e, struct psd_zone *z, double now)
{
	struct ps_truth tr;
	double t;
	struct psd_zone_stats *s = &z->st;
	if (!z->sim)
		return;
	if (psd_engine_truth(z, now, &tr) == 0)
		s->energy_last = tr.energy;
	/* a calibration session's periods and the fade after it judge the
	 * session, not the control: counted apart, with their spans */
	if (psd_calsession_running(&z->cal)) {
		if (!s->in_cal && s->ncal < PSD_STATS_MAX_CAL)
			s->cal_from[s->ncal++] = now;
		if (s->ncal > 0)
			s->cal_to[s->ncal - 1] = now;
		s->in_cal = 1;
		s->cal_steps++;
		return;
	}
	if (s->in_cal) {
		s->in_cal = 0;
		s->cal_until = now + PSD_ACCEPT_SETTLE_S;
	}
	if (now <= s->cal_until) {
		s->cal_steps++;
		return;
	}
	/* a zone with occupancy is judged while occupied: an empty room's
	 * light is nobody's (its periods counted apart) */
	if (z->occupancy == 0) {
		s->vacant_steps++;
		return;
	}
	if (!z->in_fault && !isnan(z->ctl.est_task_lux) && psd_engine_truth(z, now, &tr) == 0) {
		t = tr.task_lux;
		if (t > 0) {
			double err = (z->ctl.est_task_lux - t) / t;
			s->err_sum += err;
			s->err2_sum += err * err;
			s->err_n++;
			if (fabs(err) > s->err_max)
				s->err_max = fabs(err);
		}
	}
	/* what the occupants get just before the next reading */
	if (psd_engine_truth(z, now + z->zc->period * 0.999, &tr) != 0)
		return;
	t = tr.task_lux;
	if (t < z->ctl.target_lux * (1 - e->cf->tolerance))
		s->below++;
	if (t < s->worst_lux)
		s->worst_lux = t;
	s->samples++;
}

/* Drift of the measured ratio, per good step with a task meter. */
static void drift_step(struct psd_engine *e, struct psd_zone *z, double now)
{
	double gain_e, vd, ed;
	int r;
	if (z->zc->task < 0 || !isfinite(z->task_lux) || !isfinite(z->volts) || psd_calsession_running(&z->cal))
		return;
	gain_e = z->ctl.sensor_gain * z->ctl.elec_sensor;
	vd = z->volts - z->ctl.offset - gain_e * z->ctl.level;
	ed = z->task_lux - z->ctl.elec_task_lux * z->ctl.level;
	r = psd_calfit_drift_update(&z->drift, now, vd, ed, z->ctl.daylight_ratio / z->ctl.sensor_gain);
	if (r > 0) {
		char t[24];
		psd_engine_stamp(e, now, t, sizeof t);
		psd_log_warnx("zone %s: %s drift: the measured task/sensor ratio is %.0f %% off the simulated one for "
		          "%.0f s (sensor obstructed, dirty or moved, or the room changed?)", z->zc->name, t,
		          100 * (exp(z->drift.last_ln) - 1), now - z->drift.out_since);
	} else if (r < 0) {
		psd_log_info("zone %s: drift cleared: the measured ratio is back within %.0f %%", z->zc->name,
		         100 * (exp(z->zc->drift_margin / 2) - 1));
	}
}

/* The step's values, all of one moment, for status and watch. */
static void snapshot(struct psd_zone *z, double now, double level_in, int estimated)
{
	struct ps_truth tr;
	struct psd_zone_sample *s = &z->last;
	s->t = now;
	s->level = level_in;
	s->volts = z->volts;
	s->fault = z->in_fault;
	/* a step the control did not run (a calibration session holds the
	 * lights, a missed reading) has no estimate of its own: not the last one */
	s->est_task_lux = z->in_fault || !estimated ? NAN : z->ctl.est_task_lux;
	s->daylight_v = z->in_fault || !estimated ? NAN : z->ctl.daylight_volts;
	s->task_lux = z->task_lux;
	s->true_task_lux = psd_engine_truth(z, now, &tr) == 0 ? tr.task_lux : NAN;
	s->commanded = z->level;
	s->occupied = z->occupancy;
}

/* The zone's occupancy inputs together: occupied when any reports occupied
 * or has not reported yet, vacant when every one reports vacant. */
static int occ_inputs(const struct psd_engine *e, const struct psd_zone *z)
{
	const struct psd_zone_conf *zc = z->zc;
	for (int i = 0; i < zc->ninput; i++)
		if (e->cf->pt[zc->input[i]].action == PSD_ACT_OCCUPANCY && z->occ_in[i] != 0)
			return 1;
	return 0;
}

/* The inputs' state to the state machine: a change is logged and acted on
 * at once; an arrival ends a manual off. */
static void occ_update(struct psd_engine *e, struct psd_zone *z, double now)
{
	int first = z->occ.input < 0, ch = psd_occupancy_report(&z->occ, now, occ_inputs(e, z));
	if (ch != 0 || (first && z->occ.input >= 0)) {
		char t[24];
		psd_engine_stamp(e, now, t, sizeof t);
		psd_log_info("zone %s: %s %s", z->zc->name, t, z->occ.input ? "occupied" : "vacant");
		z->asap = 1;   /* act on it now, off the schedule */
	}
	if (now < z->override_until && psd_occupancy_ends_override(&z->occ, ch, z->override_level)) {
		z->override_until = -INFINITY;
		psd_log_info("zone %s: the manual off ends: occupied again", z->zc->name);
	}
	z->occupancy = psd_occupancy_occupied(&z->occ);
}

/* Each step reads the occupancy inputs too (events can be missed): a read
 * that fails as a fault at once, or fails for stale_after, is the input's
 * fault; the zone then counts as occupied (the daylight control runs),
 * logged and in the events, until the input reads again. */
static void occ_poll(struct psd_engine *e, struct psd_zone *z, double now)
{
	const struct psd_zone_conf *zc = z->zc;
	char why[256] = "", t[24];
	int bad = 0;
	if (z->occupancy < 0)
		return;
	for (int i = 0; i < zc->ninput; i++) {
		int p = zc->input[i], rc;
		double v = NAN;
		if (e->cf->pt[p].action != PSD_ACT_OCCUPANCY)
			continue;
		rc = pt_read(e, p, now, &v);
		if (rc == 0 && isfinite(v)) {
			z->occ_in[i] = v > 0.5;
			z->occ_ok[i] = now;
			continue;
		}
		if (rc == 0)
			snprintf(e->ioerr, sizeof e->ioerr, "reads %g", v);
		if ((rc == 0 || ps_dev_fault_at_once(errno) || now - z->occ_ok[i] >= zc->stale_after) && !bad++)
			snprintf(why, sizeof why, "occupancy input %s: %.200s", e->pt[p].name, e->ioerr);
	}
	if (psd_occupancy_fault(&z->occ, now, bad > 0)) {
		psd_engine_stamp(e, now, t, sizeof t);
		if (bad) {
			psd_log_warnx("zone %s: %s fault: %s: taken as occupied (the daylight control runs)", zc->name, t,
			              why);
			snprintf(z->occ_why, sizeof z->occ_why, "%s", why);
			event(e, now, zc->name, "fault", why);
		} else {
			psd_log_info("zone %s: %s fault cleared: %s", zc->name, t, z->occ_why);
			event(e, now, zc->name, "fault cleared", z->occ_why);
			z->occ_why[0] = 0;
		}
	}
	occ_update(e, z, now);
}

/* What rules the lights after the control (or a session) gave level: an
 * override, the occupancy, or the control itself. */
static double decide(struct psd_zone *z, double now, double level)
{
	int drop, on = now < z->override_until;
	if (psd_calsession_running(&z->cal))
		return level;
	if (z->occupancy < 0)
		return on ? z->override_level : level;
	switch (psd_occupancy_rule(&z->occ, now, on, z->override_level, &drop)) {
	case PSD_OCC_OVERRIDE:
		return z->override_level;
	case PSD_OCC_VACANT:
		if (drop) {
			z->override_until = -INFINITY;
			psd_log_info("zone %s: override ends: vacant for %.0f s", z->zc->name, z->occ.hold);
		}
		return z->occ.vacant_level;
	default:
		return level;
	}
}

/* Daylight control off: the level that meets the target with no daylight. */
static double fixed_level(const struct psd_zone *z)
{
	double u = z->ctl.target_lux / z->ctl.elec_task_lux;
	if (!(z->ctl.elec_task_lux > 0) || !isfinite(u) || u > 1)
		return 1;
	return u < z->ctl.min_level ? z->ctl.min_level : u;
}

static void zone_step(struct psd_engine *e, struct psd_zone *z, double now)
{
	const struct psd_zone_conf *zc = z->zc;
	char why[256], t[24];
	double level, t0, level_in = z->level, law = NAN;   /* law: the daylight control's own level */
	int rc, estimated = 0;   /* the control estimated the task lux from this reading */
	if (prefetch(e, z, now))
		return;   /* woken when the I/O threads answer */
	z->steps++;
	if (zc->task >= 0) {
		if (pt_read(e, zc->task, now, &z->task_lux) != 0)
			z->task_lux = NAN;   /* a meter is a record, not the control */
		z->task_t = pt_measured(e, zc->task, now);
	} else {
		z->task_lux = NAN;
	}
	occ_poll(e, z, now);
	rc = read_sensor(e, z, now, why, sizeof why);
	t0 = psd_time_mono();
	if (rc == 0) {
		int vr = verify_outputs(e, z, now, why, sizeof why);
		/* not judged yet: control goes on, but a fault is not cleared on
		 * a read-back that has not seen the gear since the command */
		if (vr < 0 || (vr > 0 && z->in_fault))
			rc = vr;
	}
	if (rc < 0) {
		enter_fault(e, z, now, why);
	} else if (rc == 0 || !z->in_fault) {
		if (rc == 0 && zc->readback && zc->ndim > 0) {
			/* the lamps' actual output, not the last command: it matters
			 * when the period is short against the ballast's fade */
			double out;
			if (pt_read(e, zc->dim[0], now, &out) == 0 && out >= 0 && out <= 1)
				z->ctl.level = level_in = out;
		}
		if (rc == 0) {
			struct psd_calsession_ctx c = cal_ctx(e, z, now);
			struct psd_calsession_ask ask;
			drift_step(e, z, now);
			psd_calsession_feed(&z->cal, &c, z->volts, z->task_lux, z->level, &ask);
			cal_act(e, z, now, &ask);
		}
		if (psd_calsession_level(&z->cal, now, &level)) {
			/* a calibration session holds the lights; in a day
			 * session the estimate still follows the room (it must
			 * not freeze); a night session's steps, measuring the
			 * constants the estimate uses, have none */
			if (rc == 0) {
				psd_control_estimate(&z->ctl, z->volts);
				estimated = z->cal.kind != PSD_CAL_NIGHT;
			}
		} else if (rc == 0) {
			dated_ratio(e, z, now);
			estimated = 1;
			level = psd_control_step(&z->ctl, z->volts, now);
			if (z->daylight_off)
				level = fixed_level(z);
			law = level;
		}
		else
			level = z->level;   /* a missed reading: hold until it is stale */
		level = decide(z, now, level);
		z->ctl.level = level;   /* what the lights are told, whoever decided it */
		if (level != z->level)
			z->verify_at = now + zc->period * 0.999;
		if (command(e, z, now, level, why, sizeof why) != 0) {
			/* an output that cannot be commanded keeps the zone in its fault */
			enter_fault(e, z, now, why);
		} else {
			if (z->in_fault) {
				psd_engine_stamp(e, now, t, sizeof t);
				psd_log_info("zone %s: %s fault cleared: control resumes", zc->name, t);
				event(e, now, zc->name, "fault cleared", z->why);
				z->in_fault = 0;
				z->why[0] = 0;
			}
			if (rc == 0) {
				double lat = psd_time_mono() - t0;
				e->lat_sum += lat;
				e->lat_n++;
				if (lat > e->lat_max)
					e->lat_max = lat;
			}
		}
	}
	if (z->occupancy >= 0)
		psd_occupancy_account(&z->occ, now, law, z->level);
	snapshot(z, now, level_in, estimated);
	log_sample(e, z, now);
	truth(e, z, now);
}

void psd_engine_step(struct psd_engine *e, double now)
{
	for (size_t i = 0; i < e->nzone; i++) {
		struct psd_zone *z = &e->zone[i];
		if (z->next > now) {
			if (z->asap) {   /* an event's step keeps the schedule */
				z->asap = 0;
				zone_step(e, z, now);
			}
			continue;
		}
		z->asap = 0;
		if (now - z->next > e->late_max)
			e->late_max = now - z->next;
		zone_step(e, z, now);
		/* the schedule, not the last step, sets the next one: no drift */
		z->next += z->zc->period;
		if (z->next <= now)
			z->next = now + z->zc->period;
	}
}

/* The earliest deadline of the devices the loop services itself (an I/O
 * thread keeps its own device's): on the daemon's clock, returned, and on
 * the monotonic clock, in *mono; only those with a descriptor when
 * fd_only. */
static double dev_deadline(const struct psd_engine *e, int fd_only, double *mono)
{
	double t = INFINITY;
	*mono = INFINITY;
	for (size_t i = 0; e->cf && i < e->cf->ndev; i++) {
		const struct ps_dev *d = &e->dev[i];
		if (d->drv->deadline && !e->io[i] && (!fd_only || d->drv->fd)) {
			double m = INFINITY, dl = d->drv->deadline((struct ps_dev *)d, &m);
			if (dl < t)
				t = dl;
			if (m < *mono)
				*mono = m;
		}
	}
	return t;
}

double psd_engine_deadline(const struct psd_engine *e, double *mono)
{
	double t = dev_deadline(e, 0, mono);
	for (size_t i = 0; i < e->nzone; i++) {
		if (e->zone[i].next < t)
			t = e->zone[i].next;
		if (e->zone[i].asap)
			t = -INFINITY;   /* now */
	}
	return t;
}

double psd_engine_io_deadline(const struct psd_engine *e, double *mono)
{
	return dev_deadline(e, 1, mono);
}

int psd_engine_pollfds(struct psd_engine *e, struct pollfd *fds, int *fd_dev, int max)
{
	int n = 0;
	for (size_t i = 0; e->cf && i < e->cf->ndev && n < max; i++) {
		struct ps_dev *d = &e->dev[i];
		int fd = e->io[i] ? psd_devio_fd(e->io[i]) : d->drv->fd ? d->drv->fd(d) : -1;
		if (fd < 0)
			continue;
		fds[n] = (struct pollfd){ fd, POLLIN, 0 };
		fd_dev[n++] = (int)i;
	}
	return n;
}

void psd_engine_service(struct psd_engine *e, double now, const struct pollfd *fds, const int *fd_dev, int nfds)
{
	double mono = psd_time_mono();
	for (size_t i = 0; e->cf && i < e->cf->ndev; i++) {
		struct ps_dev *d = &e->dev[i];
		double m = INFINITY;
		int due = 0;
		if (e->io[i]) {   /* its thread answered: events, and the zones waiting on it */
			for (int k = 0; k < nfds; k++)
				due |= fd_dev[k] == (int)i && (fds[k].revents & POLLIN);
			if (!due)
				continue;
			psd_devio_drain(e->io[i]);
			for (size_t z = 0; z < e->nzone; z++)
				if (e->zone[z].waiting)
					e->zone[z].asap = 1;
			continue;
		}
		if (!d->drv->service)
			continue;
		for (int k = 0; k < nfds; k++)
			due |= fd_dev[k] == (int)i && (fds[k].revents & (POLLIN | POLLERR | POLLHUP));
		if (d->drv->deadline && (d->drv->deadline(d, &m) <= now || m <= mono))
			due = 1;
		if (due && d->drv->service(d, now, mono) != 0)
			psd_log_warnx("device %s: %s", d->name, d->err);
	}
}

/* The level a planned stop leaves zone z at (psensd(8), STOPPING), NAN:
 * nothing commanded.  A fault or a calibration session (its levels are
 * not the control's) is no planned state: the safe level.  A vacant zone
 * keeps the level the control gave it unless stop_level names a level. */
static double stop_target(const struct psd_zone *z, double now)
{
	const struct psd_stop *st = &z->zc->stop;
	if (z->in_fault || psd_calsession_running(&z->cal))
		return z->zc->safe_level;
	if (st->mode == PSD_STOP_LEVEL)
		return st->level;
	if (st->mode == PSD_STOP_HOLD || (z->occupancy >= 0 && psd_occupancy_vacant(&z->occ, now)))
		return NAN;
	return z->zc->safe_level;
}

/* Every zone to its stop level (planned) or its safe level; the count of
 * zones whose outputs could not be commanded. */
static int stop_zones(struct psd_engine *e, double now, const char *why, int planned)
{
	char err[256];
	int failed = 0;
	for (size_t i = 0; i < e->nzone; i++) {
		struct psd_zone *z = &e->zone[i];
		double level = planned ? stop_target(z, now) : z->zc->safe_level;
		const char *what = level == z->zc->safe_level ? "the safe level" : "the stop level";
		if (isnan(level)) {
			const char *vac = z->zc->stop.mode == PSD_STOP_HOLD ? "" : " (vacant)";
			if (isfinite(z->level))
				psd_log_info("zone %s: %s: lights held at %.0f %%%s", z->zc->name, why, 100 * z->level, vac);
			else
				psd_log_info("zone %s: %s: lights left as they are%s", z->zc->name, why, vac);
			continue;
		}
		if (command(e, z, now, level, err, sizeof err) != 0) {
			psd_log_errx("zone %s: cannot reach %s: %s", z->zc->name, what, err);
			failed++;
		} else
			psd_log_info("zone %s: %s: lights at %s %.0f %%", z->zc->name, why, what, 100 * level);
	}
	return failed;
}

static int engine_end(struct psd_engine *e, double now, const char *why, int planned)
{
	int failed;
	stop_io(e);   /* the last commands wait for their outcome */
	failed = stop_zones(e, now, why, planned);
	if (e->log) {
		/* what is queued, written: a simulated day waits for it; real
		 * time, or a failing log, at most 2 s (psd_engine_close tries
		 * again) */
		struct psd_dbwriter_stats ls;
		psd_dbwriter_stats(e->log, &ls);
		if (psd_dbwriter_sync(e->log, e->db_batch > 1 && !ls.degraded ? 30 : 2) != 0)
			psd_log_warnx("%s: samples still held in memory: the log is not written yet", e->cf->database);
		e->logged = e->logged_base + psd_dbwriter_committed(e->log);
	}
	return failed;
}

int psd_engine_safe(struct psd_engine *e, double now, const char *why)
{
	return engine_end(e, now, why, 0);
}

int psd_engine_stop(struct psd_engine *e, double now, const char *why)
{
	return engine_end(e, now, why, 1);
}

/* Inputs (occupancy sensors and buttons: override, calibration step), and
 * a sensor that reports a new reading by itself (a DALI-2 light sensor's
 * event): its zone acts on it at once instead of at its next period. */
static void on_event(void *user, struct ps_dev *dev, struct ps_point *pt, double now, double value)
{
	struct psd_engine *e = user;
	int p = (int)(pt - e->pt);
	(void)dev;
	if (p < 0 || (size_t)p >= e->cf->npt)
		return;
	for (size_t i = 0; i < e->nzone; i++) {
		struct psd_zone *z = &e->zone[i];
		if (z->zc->sensor == p)
			z->asap = 1;
		for (int k = 0; k < z->zc->ninput; k++) {
			if (z->zc->input[k] != p)
				continue;
			switch (e->cf->pt[p].action) {
			case PSD_ACT_OCCUPANCY:
				z->occ_in[k] = value > 0.5;
				z->occ_ok[k] = now;
				occ_update(e, z, now);
				break;
			case PSD_ACT_OVERRIDE:
				if (value < 0.5)
					break;
				if (now < z->override_until) {
					z->override_until = -INFINITY;
					psd_log_info("zone %s: button: override released", z->zc->name);
				} else {
					z->override_level = 1.0;
					z->override_until = now + z->zc->override_s;
					psd_log_info("zone %s: button: full output for %.0f s", z->zc->name, z->zc->override_s);
				}
				z->asap = 1;
				break;
			case PSD_ACT_CALIBRATE:
				if (value > 0.5)
					psd_log_info("zone %s: button: calibration step requested", z->zc->name);
				break;
			default:
				break;
			}
		}
	}
}

struct psd_zone *psd_engine_zone(struct psd_engine *e, const char *name)
{
	for (size_t i = 0; i < e->nzone; i++)
		if (strcmp(e->zone[i].zc->name, name) == 0)
			return &e->zone[i];
	return NULL;
}

int psd_engine_set_target(struct psd_zone *z, double lux, char *err, size_t n)
{
	if (!(lux >= 0 && lux <= 1e6))
		return psd_errbuf(err, n, "target %g lx is outside 0 to 1e6", lux);
	z->ctl.target_lux = lux;
	psd_log_info("zone %s: target %g lx", z->zc->name, lux);
	return 0;
}

int psd_engine_override(struct psd_zone *z, double level, double seconds, double now, char *err, size_t n)
{
	if (!(level >= 0 && level <= 1))
		return psd_errbuf(err, n, "level %g is outside 0 to 1", level);
	if (!(seconds > 0 && seconds <= 7 * 86400))
		return psd_errbuf(err, n, "duration %g s is outside 0 to 7 days", seconds);
	z->override_level = level;
	z->override_until = now + seconds;
	z->asap = 1;   /* at once, not at the next period */
	psd_log_info("zone %s: override %.0f %% for %g s", z->zc->name, 100 * level, seconds);
	return 0;
}

void psd_engine_off(struct psd_zone *z)
{
	z->override_level = 0;
	z->override_until = INFINITY;
	z->asap = 1;
	psd_log_info("zone %s: off until release%s", z->zc->name,
	             z->occupancy >= 0 ? " or the next arrival after a vacancy" : "");
}

int psd_engine_zone_occupied(const struct psd_zone *z)
{
	return z->occupancy;
}

void psd_engine_set_daylighting(struct psd_zone *z, int on)
{
	if (z->daylight_off == !on)
		return;
	z->daylight_off = !on;
	z->asap = 1;
	psd_log_info("zone %s: daylight control %s", z->zc->name,
	             on ? "on" : "off: the level that meets the target without daylight");
}

int psd_engine_set_vacancy_hold(struct psd_zone *z, double seconds, char *err, size_t n)
{
	if (!(seconds >= 0 && seconds <= 86400))
		return psd_errbuf(err, n, "vacancy hold %g s is outside 0 to 86400", seconds);
	z->occ.hold = seconds;
	psd_log_info("zone %s: vacancy hold %g s", z->zc->name, seconds);
	return 0;
}

void psd_engine_release(struct psd_zone *z)
{
	z->override_until = -INFINITY;
	z->asap = 1;
	psd_log_info("zone %s: override released", z->zc->name);
}

int psd_engine_cal_start(struct psd_engine *e, struct psd_zone *z, int kind, double level, double now, char *err,
                         size_t n)
{
	struct psd_calsession_ctx c = cal_ctx(e, z, now);
	struct psd_calsession_ask ask;
	if (z->in_fault && !psd_calsession_running(&z->cal))
		return psd_errbuf(err, n, "zone %s is at its safe level: %s", z->zc->name, z->why);
	if (psd_calsession_start(&z->cal, &c, kind, level, &ask, err, n) != 0)
		return -1;
	cal_act(e, z, now, &ask);
	return 0;
}

int psd_engine_cal_lux(struct psd_engine *e, struct psd_zone *z, double lux, double now, char *err, size_t n)
{
	struct psd_calsession_ctx c = cal_ctx(e, z, now);
	struct psd_calsession_ask ask;
	if (psd_calsession_typed_lux(&z->cal, &c, lux, z->in_fault ? NAN : z->volts, z->level, &ask, err, n) != 0)
		return -1;
	cal_act(e, z, now, &ask);
	return 0;
}

int psd_engine_cal_finish(struct psd_engine *e, struct psd_zone *z, double now, char *err, size_t n)
{
	struct psd_calsession_ctx c = cal_ctx(e, z, now);
	struct psd_calsession_ask ask;
	if (psd_calsession_finish(&z->cal, &c, &ask, err, n) != 0)
		return -1;
	cal_act(e, z, now, &ask);
	return 0;
}

int psd_engine_cal_accept(struct psd_engine *e, struct psd_zone *z, double now, char *err, size_t n)
{
	struct psd_calsession_ctx c = cal_ctx(e, z, now);
	struct psd_calsession_ask ask;
	if (psd_calsession_accept(&z->cal, &c, &ask, err, n) != 0)
		return -1;
	cal_act(e, z, now, &ask);
	record_consts(e, z);
	{
		char t[24], text[64];
		psd_engine_stamp(e, now, t, sizeof t);
		snprintf(text, sizeof text, "session %lld", z->cal.id);
		event(e, now, z->zc->name, "calibration accepted", text);
		psd_log_info("zone %s: %s: calibration session %lld accepted (sensor gain %.5g V per unit, offset %.4g V, "
		         "daylight ratio %.5g, electric task lux %.5g)", z->zc->name, t, z->cal.id, z->ctl.sensor_gain,
		         z->ctl.offset, z->ctl.daylight_ratio, z->ctl.elec_task_lux);
	}
	return 0;
}

int psd_engine_cal_abort(struct psd_engine *e, struct psd_zone *z, double now, const char *why, char *err,
                         size_t n)
{
	struct psd_calsession_ctx c = cal_ctx(e, z, now);
	struct psd_calsession_ask ask;
	if (psd_calsession_abort(&z->cal, &c, why, &ask) != 0)
		return psd_errbuf(err, n, "zone %s has no running session", z->zc->name);
	cal_act(e, z, now, &ask);
	return 0;
}
