#include "engine.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "log.h"
#include "loopback.h"
#include "room.h"
#include "roomsetup.h"

void psd_hhmm(double t, char out[8])
{
	double tod = ps_room_tod(t);
	int m = (int)floor(tod / 60 + 1e-9);
	snprintf(out, 8, "%02d:%02d", (m / 60) % 24, m % 60);
}

static double wall(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void on_event(void *user, struct ps_dev *dev, struct ps_point *pt, double now, double value);
static int command(struct psd_engine *e, struct psd_zone *z, double now, double level, char *why, size_t n);

static int fail(char *err, size_t n, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static int fail(char *err, size_t n, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(err, n, fmt, ap);
	va_end(ap);
	return -1;
}

/* Report driver keys nobody used: a typo must not pass silently. */
static int unused_keys(const struct ps_opts *o, const char *driver, char *err, size_t n)
{
	for (size_t i = 0; i < o->n; i++)
		if (!o->v[i].used)
			return fail(err, n, "%s:%d: unknown key '%s' for driver %s", o->file, o->v[i].line,
			            o->v[i].key, driver);
	return 0;
}

static int open_devices(struct psd_engine *e, double now, char *err, size_t n)
{
	struct psd_config *cf = e->cf;
	struct ps_room_daypoint day[PSD_DAY_POINTS];
	struct ps_room_params rp;
	int have_day = e->have_res && psd_room_from_results(&e->res, psd_day_of_year(cf->date), cf->sunrise,
	                                                   cf->sunset, day, &rp) == 0;
	for (size_t i = 0; i < cf->ndev; i++) {
		struct ps_dev *d = &e->dev[i];
		memset(d, 0, sizeof *d);
		d->drv = cf->dev[i].drv;
		snprintf(d->name, sizeof d->name, "%s", cf->dev[i].name);
		d->on_event = on_event;
		d->event_user = e;
		e->dev_open[i] = 1;
		if (d->drv->open(d, &cf->dev[i].opts) != 0)
			return fail(err, n, "device %s: %s", d->name, d->err);
		if (unused_keys(&cf->dev[i].opts, d->drv->name, err, n) != 0)
			return -1;
		if (strcmp(d->drv->name, "loopback") == 0) {
			if (!have_day)
				return fail(err, n, "device %s: the loopback room needs results with a daylight and "
				            "an electric condition (%s)", d->name, cf->results);
			if (ps_loopback_set_room(d, &rp, now) != 0)
				return fail(err, n, "device %s: %s", d->name, d->err);
		}
	}
	for (size_t i = 0; i < cf->npt; i++) {
		struct psd_point_conf *pc = &cf->pt[i];
		struct ps_dev *d = &e->dev[pc->device];
		struct ps_point *p = &e->pt[i];
		memset(p, 0, sizeof *p);
		snprintf(p->name, sizeof p->name, "%s", pc->name);
		p->role = pc->role;
		if (d->drv->add_point(d, p, &pc->opts) != 0)
			return fail(err, n, "point %s: %s", p->name, d->err);
		if (unused_keys(&pc->opts, d->drv->name, err, n) != 0)
			return -1;
	}
	return 0;
}

static void zone_init(struct psd_engine *e, struct psd_zone *z, const struct psd_zone_conf *zc, double now,
                      const struct psd_engine *prev)
{
	const struct ps_dev *sd = &e->dev[e->cf->pt[zc->sensor].device];
	memset(z, 0, sizeof *z);
	z->zc = zc;
	z->ctl = zc->ctl;
	if (e->have_res) {
		z->ctl.daylight_ratio = e->res.daylight_ratio_mean;
		z->ctl.elec_sensor = e->res.electric_sensor_response;
		z->ctl.elec_task_lux = e->res.electric_task_lux;
	}
	z->ctl.level = 1.0;
	z->ctl.pending_since = -1;
	z->level = 1.0;
	z->next = now;
	z->started = now;
	z->last_ok = now;
	z->volts = z->task_lux = z->last_volts = NAN;
	z->same_since = now;
	z->override_level = NAN;
	z->override_until = -INFINITY;
	z->occupancy = -1;
	for (int i = 0; i < zc->ninput; i++)
		if (e->cf->pt[zc->input[i]].action == PSD_ACT_OCCUPANCY)
			z->occupancy = 1;   /* occupied until an input says otherwise */
	z->vacant_since = now;
	z->verify_at = INFINITY;
	if (strcmp(sd->drv->name, "loopback") == 0 && (z->room = ps_loopback_room((struct ps_dev *)sd)))
		z->st.energy0 = ps_room_energy(z->room, now);
	z->st.worst_lux = INFINITY;
	if (prev) {
		for (size_t i = 0; i < prev->nzone; i++) {
			const struct psd_zone *o = &prev->zone[i];
			if (strcmp(o->zc->name, zc->name) != 0)
				continue;
			z->ctl.level = z->level = o->level;
			z->override_level = o->override_level;
			z->override_until = o->override_until;
			z->next = o->next;
			if (z->ctl.target_lux == o->zc->ctl.target_lux)
				z->ctl.target_lux = o->ctl.target_lux;   /* a target set at run time survives */
		}
	}
}

int psd_engine_open(struct psd_engine *e, struct psd_config *cf, double now, int db_batch,
                    const struct psd_engine *prev, char *err, size_t errlen)
{
	struct ps_err pe;
	memset(e, 0, sizeof *e);
	e->cf = cf;
	e->db_batch = db_batch > 0 ? db_batch : 1;
	if (prev)
		e->logged = e->logged_base = prev->logged;   /* counted across reloads */
	if (cf->results) {
		if (ps_results_read(&e->res, cf->results, &pe) != 0) {
			fail(err, errlen, "%s", pe.msg);
			goto bad;
		}
		e->have_res = 1;
	}
	if (open_devices(e, now, err, errlen) != 0)
		goto bad;
	if (cf->database && !(e->db = psd_db_open(cf->database, err, errlen)))
		goto bad;
	if (e->db)
		psd_db_set_batch(e->db, e->db_batch);
	for (size_t i = 0; i < cf->nzone; i++) {
		zone_init(e, &e->zone[i], &cf->zone[i], now, prev);
		if ((cf->zone[i].ctl.algorithm == PSD_ALG_SETPOINT ||
		     cf->zone[i].ctl.algorithm == PSD_ALG_CLOSED_PROPORTIONAL) &&
		    !(e->zone[i].ctl.daylight_ratio > 0 && e->zone[i].ctl.elec_task_lux > 0)) {
			fail(err, errlen, "zone %s: %s control needs the simulated daylight and electric ratios (%s)",
			     cf->zone[i].name, psd_algorithm_names[cf->zone[i].ctl.algorithm], cf->results);
			goto bad;
		}
	}
	e->nzone = cf->nzone;
	for (size_t i = 0; i < e->nzone; i++)
		psd_drift_init(&e->zone[i].drift, cf->zone[i].drift_margin, cf->zone[i].drift_hold,
		               cf->zone[i].cal_min_day_volts);
	psd_cal_load(e, now);
	/* the outputs start where the control believes they are (full output,
	 * or the level before a reload) */
	for (size_t i = 0; i < e->nzone; i++) {
		char why[256];
		if (command(e, &e->zone[i], now, e->zone[i].level, why, sizeof why) != 0)
			log_warnx("zone %s: %s", e->zone[i].zc->name, why);
	}
	return 0;
bad:
	psd_engine_close(e);
	return -1;
}

struct psd_config *psd_engine_close(struct psd_engine *e)
{
	struct psd_config *cf = e->cf;
	psd_db_close(e->db);
	e->db = NULL;
	for (size_t i = 0; cf && i < cf->ndev; i++)
		if (e->dev_open[i] && e->dev[i].drv && e->dev[i].drv->close)
			e->dev[i].drv->close(&e->dev[i]);
	if (e->have_res)
		ps_results_free(&e->res);
	memset(e, 0, sizeof *e);
	return cf;
}

static struct ps_dev *dev_of(struct psd_engine *e, int point)
{
	return &e->dev[e->cf->pt[point].device];
}

/* Command every output of the zone; returns -1 (with why) when one fails. */
static int command(struct psd_engine *e, struct psd_zone *z, double now, double level, char *why, size_t n)
{
	const struct psd_zone_conf *zc = z->zc;
	int rc = 0;
	for (int i = 0; i < zc->ndim; i++) {
		struct ps_dev *d = dev_of(e, zc->dim[i]);
		if (d->drv->write(d, &e->pt[zc->dim[i]], now, level) != 0 && rc == 0) {
			snprintf(why, n, "%s", d->err);
			rc = -1;
		}
	}
	/* relay k of n closes above k/n: n relays are the steps of a stepped
	 * system, one relay switches a dimmed circuit off at level 0 */
	for (int i = 0; i < zc->nrelay; i++) {
		struct ps_dev *d = dev_of(e, zc->relay[i]);
		double on = level > (double)i / zc->nrelay + 1e-9;
		if (d->drv->write(d, &e->pt[zc->relay[i]], now, on) != 0 && rc == 0) {
			snprintf(why, n, "%s", d->err);
			rc = -1;
		}
	}
	z->level = level;
	return rc;
}

static void enter_fault(struct psd_engine *e, struct psd_zone *z, double now, const char *why)
{
	char t[8], ignored[256];
	psd_hhmm(now, t);
	if (!z->in_fault)
		log_warnx("zone %s: %s fault: %s: lights to the safe level %.0f %%", z->zc->name, t, why,
		          100 * z->zc->safe_level);
	else if (strcmp(z->why, why) != 0)
		log_debug("zone %s: %s fault now: %s", z->zc->name, t, why);
	z->in_fault = 1;
	snprintf(z->why, sizeof z->why, "%s", why);
	if (z->cal.state == PSD_CAL_RUNNING)
		psd_cal_abort(e, z, now, why);
	command(e, z, now, z->zc->safe_level, ignored, sizeof ignored);
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
	struct ps_dev *d = dev_of(e, zc->sensor);
	double v = NAN;
	if (d->drv->read(d, &e->pt[zc->sensor], now, &v) != 0) {
		z->volts = NAN;
		/* a lost device or a reading out of its range is a fault at once;
		 * a missed or garbled reply only once the last good reading is
		 * older than stale_after */
		/* EOVERFLOW: a counting sensor lost edges; its value would be low */
		int at_once = errno == ENODEV || errno == ENOTSUP || errno == EINVAL || errno == ERANGE ||
		              errno == EOVERFLOW;
		if (at_once || now - z->last_ok >= zc->stale_after) {
			if (at_once)
				snprintf(why, n, "%s", d->err);
			else {
				char since[8];
				psd_hhmm(z->last_ok, since);
				snprintf(why, n, "no reading since %s (%s)", since, d->err);
			}
			return -1;
		}
		log_debug("zone %s: %s (holding the level)", zc->name, d->err);
		return 1;
	}
	z->volts = v;
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

/* A ballast that did not follow the last command: read the dim points back. */
static int verify_outputs(struct psd_engine *e, struct psd_zone *z, double now, char *why, size_t n)
{
	const struct psd_zone_conf *zc = z->zc;
	if (zc->verify_tolerance <= 0 || now < z->verify_at)
		return 0;
	for (int i = 0; i < zc->ndim; i++) {
		struct ps_dev *d = dev_of(e, zc->dim[i]);
		double got;
		if (d->drv->read(d, &e->pt[zc->dim[i]], now, &got) != 0) {
			snprintf(why, n, "%s: cannot read the output back: %s", e->pt[zc->dim[i]].name, d->err);
			return -1;
		}
		if (fabs(got - z->level) > zc->verify_tolerance &&
		    !(z->level < z->ctl.min_level && got <= z->level + zc->verify_tolerance)) {
			snprintf(why, n, "ballast %s not responding: at %.0f %%, commanded %.0f %%",
			         e->pt[zc->dim[i]].name, 100 * got, 100 * z->level);
			return -1;
		}
	}
	return 0;
}

static void log_sample(struct psd_engine *e, struct psd_zone *z, double now)
{
	char err[512];
	int fault = z->in_fault;
	double dl = z->ctl.daylight_ratio * z->ctl.daylight_volts / z->ctl.sensor_gain;
	struct psd_sample s = {
		now, ps_room_tod(now), z->volts, z->level,
		fault ? NAN : z->ctl.est_task_lux, z->task_lux,
		fault ? NAN : z->ctl.daylight_volts,
		fault ? NAN : dl,
		e->have_res ? "daylight_mean" : NULL, z->ctl.daylight_ratio, fault ? z->why : NULL,
		z->zc->name,
	};
	if (!e->db)
		return;
	if (psd_db_add(e->db, &s, err, sizeof err) != 0) {
		/* the log is a record, not the control: say so and go on */
		if (e->log_errors++ == 0)
			log_warnx("%s: %s", e->cf->database, err);
		return;
	}
	e->logged = e->logged_base + psd_db_committed(e->db);
}

static void truth(struct psd_engine *e, struct psd_zone *z, double now)
{
	double t;
	struct psd_zone_stats *s = &z->st;
	if (!z->room)
		return;
	if (!z->in_fault && !isnan(z->ctl.est_task_lux)) {
		t = ps_room_true_task_lux(z->room, now);
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
	t = ps_room_true_task_lux(z->room, now + z->zc->period * 0.999);
	if (t < z->ctl.target_lux * (1 - e->cf->tolerance))
		s->below++;
	if (t < s->worst_lux)
		s->worst_lux = t;
	s->samples++;
}

static void zone_step(struct psd_engine *e, struct psd_zone *z, double now)
{
	const struct psd_zone_conf *zc = z->zc;
	char why[256], t[8];
	double level, t0;
	int rc;
	z->steps++;
	if (zc->task >= 0) {
		struct ps_dev *d = dev_of(e, zc->task);
		if (d->drv->read(d, &e->pt[zc->task], now, &z->task_lux) != 0)
			z->task_lux = NAN;   /* a meter is a record, not the control */
	} else {
		z->task_lux = NAN;
	}
	rc = read_sensor(e, z, now, why, sizeof why);
	t0 = wall();
	if (rc == 0)
		rc = verify_outputs(e, z, now, why, sizeof why);
	if (rc < 0) {
		enter_fault(e, z, now, why);
	} else if (rc == 0 || !z->in_fault) {
		if (rc == 0 && zc->readback && zc->ndim > 0) {
			/* the lamps' actual output, not the last command: it matters
			 * when the period is short against the ballast's fade */
			struct ps_dev *d = dev_of(e, zc->dim[0]);
			double out;
			if (d->drv->read(d, &e->pt[zc->dim[0]], now, &out) == 0 && out >= 0 && out <= 1)
				z->ctl.level = out;
		}
		if (rc == 0) {
			psd_drift_step(e, z, now);
			psd_cal_feed(e, z, now, z->volts, z->task_lux);
		}
		if (psd_cal_level(e, z, now, &level))
			;   /* a calibration session holds the lights */
		else if (rc == 0)
			level = psd_control_step(&z->ctl, z->volts, now);
		else
			level = z->level;   /* a missed reading: hold until it is stale */
		if (z->cal.state == PSD_CAL_RUNNING)
			;
		else if (now < z->override_until)
			level = z->override_level;
		else if (z->occupancy == 0 && now - z->vacant_since >= zc->vacancy_s)
			level = 0;
		z->ctl.level = level;   /* what the lights are told, whoever decided it */
		if (level != z->level)
			z->verify_at = now + zc->period * 0.999;
		if (command(e, z, now, level, why, sizeof why) != 0) {
			/* an output that cannot be commanded keeps the zone in its fault */
			enter_fault(e, z, now, why);
		} else {
			if (z->in_fault) {
				psd_hhmm(now, t);
				log_info("zone %s: %s fault cleared: control resumes", zc->name, t);
				z->in_fault = 0;
				z->why[0] = 0;
			}
			if (rc == 0) {
				double lat = wall() - t0;
				e->lat_sum += lat;
				e->lat_n++;
				if (lat > e->lat_max)
					e->lat_max = lat;
			}
		}
	}
	log_sample(e, z, now);
	truth(e, z, now);
}

void psd_engine_step(struct psd_engine *e, double now, double scheduled_late)
{
	(void)scheduled_late;
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

double psd_engine_deadline(const struct psd_engine *e)
{
	double t = INFINITY;
	for (size_t i = 0; i < e->nzone; i++) {
		if (e->zone[i].next < t)
			t = e->zone[i].next;
		if (e->zone[i].asap)
			t = -INFINITY;   /* now */
	}
	for (size_t i = 0; e->cf && i < e->cf->ndev; i++) {
		const struct ps_dev *d = &e->dev[i];
		if (d->drv->deadline) {
			double dl = d->drv->deadline((struct ps_dev *)d);
			if (dl < t)
				t = dl;
		}
	}
	return t;
}

int psd_engine_pollfds(struct psd_engine *e, struct pollfd *fds, int *fd_dev, int max)
{
	int n = 0;
	for (size_t i = 0; e->cf && i < e->cf->ndev && n < max; i++) {
		struct ps_dev *d = &e->dev[i];
		int fd = d->drv->fd ? d->drv->fd(d) : -1;
		if (fd < 0)
			continue;
		fds[n] = (struct pollfd){ fd, POLLIN, 0 };
		fd_dev[n++] = (int)i;
	}
	return n;
}

void psd_engine_service(struct psd_engine *e, double now, const struct pollfd *fds, const int *fd_dev, int nfds)
{
	for (size_t i = 0; e->cf && i < e->cf->ndev; i++) {
		struct ps_dev *d = &e->dev[i];
		int due = 0;
		if (!d->drv->service)
			continue;
		for (int k = 0; k < nfds; k++)
			due |= fd_dev[k] == (int)i && (fds[k].revents & (POLLIN | POLLERR | POLLHUP));
		if (d->drv->deadline && d->drv->deadline(d) <= now)
			due = 1;
		if (due && d->drv->service(d, now) != 0)
			log_warnx("device %s: %s", d->name, d->err);
	}
}

void psd_engine_safe(struct psd_engine *e, double now, const char *why)
{
	char err[256];
	for (size_t i = 0; i < e->nzone; i++) {
		struct psd_zone *z = &e->zone[i];
		if (command(e, z, now, z->zc->safe_level, err, sizeof err) != 0)
			log_warnx("zone %s: cannot reach the safe level: %s", z->zc->name, err);
		else
			log_info("zone %s: %s: lights at the safe level %.0f %%", z->zc->name, why,
			         100 * z->zc->safe_level);
	}
	if (e->db) {
		char dberr[512];
		if (psd_db_commit(e->db, dberr, sizeof dberr) != 0)
			log_warnx("%s: %s", e->cf->database, dberr);
		e->logged = e->logged_base + psd_db_committed(e->db);
	}
}

/* Inputs: occupancy sensors and buttons (override, calibration step). */
static void on_event(void *user, struct ps_dev *dev, struct ps_point *pt, double now, double value)
{
	struct psd_engine *e = user;
	int p = (int)(pt - e->pt);
	(void)dev;
	if (p < 0 || (size_t)p >= e->cf->npt)
		return;
	for (size_t i = 0; i < e->nzone; i++) {
		struct psd_zone *z = &e->zone[i];
		for (int k = 0; k < z->zc->ninput; k++) {
			if (z->zc->input[k] != p)
				continue;
			switch (e->cf->pt[p].action) {
			case PSD_ACT_OCCUPANCY:
				if (value > 0.5)
					z->occupancy = 1;
				else if (z->occupancy != 0) {
					z->occupancy = 0;
					z->vacant_since = now;
				}
				log_info("zone %s: %s", z->zc->name, value > 0.5 ? "occupied" : "vacant");
				z->asap = 1;   /* act on it now, off the schedule */
				break;
			case PSD_ACT_OVERRIDE:
				if (value < 0.5)
					break;
				if (now < z->override_until) {
					z->override_until = -INFINITY;
					log_info("zone %s: button: override released", z->zc->name);
				} else {
					z->override_level = 1.0;
					z->override_until = now + z->zc->override_s;
					log_info("zone %s: button: full output for %.0f s", z->zc->name, z->zc->override_s);
				}
				z->asap = 1;
				break;
			case PSD_ACT_CALIBRATE:
				if (value > 0.5)
					log_info("zone %s: button: calibration step requested", z->zc->name);
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

int psd_engine_set_target(struct psd_engine *e, const char *zone, double lux, char *err, size_t n)
{
	struct psd_zone *z = psd_engine_zone(e, zone);
	if (!z)
		return fail(err, n, "no zone '%s'", zone);
	if (!(lux >= 0 && lux <= 1e6))
		return fail(err, n, "target %g lx is outside 0 to 1e6", lux);
	z->ctl.target_lux = lux;
	log_info("zone %s: target %g lx", zone, lux);
	return 0;
}

int psd_engine_override(struct psd_engine *e, const char *zone, double level, double seconds, double now,
                        char *err, size_t n)
{
	struct psd_zone *z = psd_engine_zone(e, zone);
	if (!z)
		return fail(err, n, "no zone '%s'", zone);
	if (!(level >= 0 && level <= 1))
		return fail(err, n, "level %g is outside 0 to 1", level);
	if (!(seconds > 0 && seconds <= 7 * 86400))
		return fail(err, n, "duration %g s is outside 0 to 7 days", seconds);
	z->override_level = level;
	z->override_until = now + seconds;
	z->asap = 1;   /* at once, not at the next period */
	log_info("zone %s: override %.0f %% for %g s", zone, 100 * level, seconds);
	return 0;
}

int psd_engine_release(struct psd_engine *e, const char *zone, char *err, size_t n)
{
	struct psd_zone *z = psd_engine_zone(e, zone);
	if (!z)
		return fail(err, n, "no zone '%s'", zone);
	z->override_until = -INFINITY;
	z->asap = 1;
	log_info("zone %s: override released", zone);
	return 0;
}
