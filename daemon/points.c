/* SPDX-License-Identifier: ISC */
/* The point model (points.h). */
#include "points.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "accept.h"
#include "annual.h"
#include "db.h"
#include "engine.h"
#include "errbuf.h"
#include "json.h"

static const char *const control_states[] = { "auto", "override", "calibrating", "fault", "safe", NULL };
static const char *const ratio_sources[] = { "scene", "dated", "sky class", "calibrated", NULL };
static const char *const verdicts[] = { "none", "accepted", "not accepted", "incomplete", NULL };

/* psd_accept_overall's text as the acceptance point's state less one */
static int verdict_of(const char *overall)
{
	return !strcmp(overall, "ACCEPTED") ? 1 : !strcmp(overall, "NOT ACCEPTED") ? 2 : 3;
}

/* What a point needs of a zone. */
enum { NEED_NONE, NEED_METER, NEED_OCCUPANCY, NEED_POWER, NEED_RESULTS };

/* BACnetEngineeringUnits */
enum { U_HOURS = 71, U_KWH = 19, U_LUXES = 37, U_VOLTS = 5, U_PERCENT = 98, U_NONE = 95, U_SECONDS = 73 };

/* What a point's value is read from: the zone, its engine, the model's
 * own state of the zone (NULL: none yet), the clock. */
struct at {
	const struct psd_engine *e;
	const struct psd_zone *z;
	const struct psd_points_zone *s;
	double now;
};

static int control_state(const struct psd_zone *z, double now);
static int ratio_source(const struct psd_engine *e, const struct psd_zone *z);

static double est_task_lux(const struct at *a) { return a->z->in_fault ? NAN : a->z->last.est_task_lux; }
static double sensor_v(const struct at *a) { return a->z->volts; }
static double target_lux(const struct at *a) { return a->z->ctl.target_lux; }
static double level(const struct at *a) { return 100 * a->z->level; }
static double level_actual(const struct at *a) { return 100 * a->z->last.level; }
static double task_lux(const struct at *a) { return a->z->task_lux; }
static double ratio(const struct at *a) { return a->z->ctl.daylight_ratio; }
static double drift_pct(const struct at *a) { return 100 * (exp(a->z->drift.last_ln) - 1); }
static double output_h(const struct at *a) { return a->s->output_h; }
static double energy_kwh(const struct at *a) { return a->s->kwh; }
static double fault(const struct at *a) { return a->z->in_fault != 0; }
static double drift(const struct at *a) { return a->z->drift.flagged != 0; }
static double occupied(const struct at *a) { return psd_points_occupancy(a->z) == 1; }
static double state(const struct at *a) { return control_state(a->z, a->now); }
static double source(const struct at *a) { return ratio_source(a->e, a->z); }
static double acceptance(const struct at *a) { return a->s->verdict + 1; }
static double daylighting(const struct at *a) { return !a->z->daylight_off; }
static double vacancy_hold(const struct at *a) { return a->z->occ.hold; }

/* The order is BACnet's instance numbering (bacobj.c): append, never insert. */
static const struct {
	struct psd_points_def d;
	int need;
	double (*get)(const struct at *a);
	int stateful; /* read from the model's own state of the zone */
} table[] = {
	{ { "est_task_lux", "task lux estimate", "lx", PSD_POINTS_ANALOG, 0,
	    "the task illuminance estimated from the sensor at this step", NULL, U_LUXES, "illuminance", 0, 0 },
	  NEED_NONE, est_task_lux, 0 },
	{ { "sensor_v", "sensor signal", "V", PSD_POINTS_ANALOG, 0, "the photosensor's signal", NULL, U_VOLTS,
	    "voltage", 0, 0 },
	  NEED_NONE, sensor_v, 0 },
	{ { "target_lux", "target lux", "lx", PSD_POINTS_ANALOG, 1, "the task illuminance the control holds", NULL,
	    U_LUXES, "illuminance", 0, 5000 },
	  NEED_NONE, target_lux, 0 },
	{ { "level", "light level", "%", PSD_POINTS_ANALOG, 1, "the light output commanded", NULL, U_PERCENT,
	    NULL, 0, 0 },
	  NEED_NONE, level, 0 },
	{ { "level_actual", "actual light level", "%", PSD_POINTS_ANALOG, 0,
	    "the light output while the sensor was read", NULL, U_PERCENT, NULL, 0, 0 },
	  NEED_NONE, level_actual, 0 },
	{ { "task_lux", "measured task lux", "lx", PSD_POINTS_ANALOG, 0, "the task meter's illuminance", NULL,
	    U_LUXES, "illuminance", 0, 0 },
	  NEED_METER, task_lux, 0 },
	{ { "ratio", "daylight ratio", "lx", PSD_POINTS_ANALOG, 0,
	    "the simulated task lux per unit of sensor response in force", NULL, U_LUXES, NULL, 0, 0 },
	  NEED_RESULTS, ratio, 0 },
	{ { "drift_pct", "drift", "%", PSD_POINTS_ANALOG, 0, "the measured ratio against the simulated one",
	    NULL, U_PERCENT, NULL, 0, 0 },
	  NEED_METER, drift_pct, 0 },
	{ { "output_h", "light-output hours", "h", PSD_POINTS_ANALOG, 0,
	    "hours at full output since psensd started", NULL, U_HOURS, NULL, 0, 0 },
	  NEED_NONE, output_h, 1 },
	{ { "energy_kwh", "energy", "kWh", PSD_POINTS_ANALOG, 0,
	    "input energy since psensd started, through the power curve", NULL, U_KWH, "energy", 0, 0 },
	  NEED_POWER, energy_kwh, 1 },
	{ { "fault", "fault", NULL, PSD_POINTS_BINARY, 0, "the zone is at its safe level on a fault", NULL, 0,
	    "problem", 0, 0 },
	  NEED_NONE, fault, 0 },
	{ { "drift", "drift flag", NULL, PSD_POINTS_BINARY, 0, "the drift held out of bounds past its hold",
	    NULL, 0, "problem", 0, 0 },
	  NEED_METER, drift, 0 },
	{ { "occupied", "occupancy", NULL, PSD_POINTS_BINARY, 0, "the occupancy input's state", NULL, 0,
	    "occupancy", 0, 0 },
	  NEED_OCCUPANCY, occupied, 0 },
	{ { "state", "control state", NULL, PSD_POINTS_MULTISTATE, 0, "what holds the light level",
	    control_states, 0, "enum", 0, 0 },
	  NEED_NONE, state, 0 },
	{ { "ratio_source", "ratio source", NULL, PSD_POINTS_MULTISTATE, 0, "where the ratio in force comes from",
	    ratio_sources, 0, "enum", 0, 0 },
	  NEED_RESULTS, source, 0 },
	{ { "acceptance", "acceptance verdict", NULL, PSD_POINTS_MULTISTATE, 0,
	    "the verdict of the zone's last acceptance run in the log", verdicts, 0, "enum", 0, 0 },
	  NEED_METER, acceptance, 1 },
	{ { "daylighting", "daylight control", NULL, PSD_POINTS_BINARY, 1,
	    "on: the control holds the target with the daylight; off: the level that meets the target "
	    "without daylight",
	    NULL, 0, NULL, 0, 1 },
	  NEED_NONE, daylighting, 0 },
	{ { "vacancy_hold", "vacancy hold", "s", PSD_POINTS_ANALOG, 1,
	    "vacant this long, the zone goes to its vacant level", NULL, U_SECONDS, "duration", 0, 86400 },
	  NEED_OCCUPANCY, vacancy_hold, 0 },
};
#define NPOINTS (sizeof table / sizeof table[0])

size_t psd_points_count(void)
{
	return NPOINTS;
}

const struct psd_points_def *psd_points_def(size_t i)
{
	return i < NPOINTS ? &table[i].d : NULL;
}

int psd_points_find(const char *key)
{
	for (size_t i = 0; i < NPOINTS; i++)
		if (strcmp(table[i].d.key, key) == 0)
			return (int)i;
	return -1;
}

size_t psd_points_nstates(size_t i)
{
	size_t n = 0;
	if (i < NPOINTS && table[i].d.states)
		while (table[i].d.states[n])
			n++;
	return n;
}

int psd_points_occupancy(const struct psd_zone *z)
{
	return z->occupancy;
}

int psd_points_has(const struct psd_engine *e, size_t zi, size_t i)
{
	const struct psd_zone *z = &e->zone[zi];
	if (i >= NPOINTS || zi >= e->nzone)
		return 0;
	switch (table[i].need) {
	case NEED_METER: return z->zc->task >= 0;
	case NEED_OCCUPANCY: return psd_points_occupancy(z) >= 0;
	case NEED_POWER: return e->cf->lamp_watts > 0;
	case NEED_RESULTS: return z->res != NULL;
	default: return 1;
	}
}

/* The control state, 1-based in control_states. */
static int control_state(const struct psd_zone *z, double now)
{
	if (z->in_fault)
		return 4;
	if (psd_calsession_running(&z->cal))
		return 3;
	if (now < z->override_until)
		return 2;
	if (z->steps == 0)
		return 5; /* held at the safe level until the first step */
	return 1;
}

/* The ratio's source, 1-based in ratio_sources (the engine's rule: a day
 * calibration's own ratio, else the dated estimate by sky class or typical,
 * else the scene's mean). */
static int ratio_source(const struct psd_engine *e, const struct psd_zone *z)
{
	if (z->cal_day_id)
		return 4;
	if (!(z->res->have_year && e->cf->dated_estimate))
		return 1;
	return z->sky_class >= 0 ? 3 : 2;
}

static const struct psd_points_zone *state_of(const struct psd_points *p, const char *name)
{
	for (size_t i = 0; p && i < PSD_MAX_ZONES && p->zone[i].name[0]; i++)
		if (strcmp(p->zone[i].name, name) == 0)
			return &p->zone[i];
	return NULL;
}

/* The state of the engine's zone zi: where psd_points_update last put it,
 * else by name. */
static const struct psd_points_zone *state_for(const struct psd_points *p, const struct psd_engine *e, size_t zi)
{
	int k = p ? p->slot[zi] - 1 : -1;
	if (k >= 0 && strcmp(p->zone[k].name, e->zone[zi].zc->name) == 0)
		return &p->zone[k];
	return state_of(p, e->zone[zi].zc->name);
}

int psd_points_value(const struct psd_points *p, const struct psd_engine *e, size_t zi, size_t i, double now,
                     double *v)
{
	struct at a;
	if (!psd_points_has(e, zi, i))
		return -1;
	a = (struct at){ e, &e->zone[zi], state_for(p, e, zi), now };
	if (table[i].stateful && !a.s)
		return -1;
	*v = table[i].get(&a);
	return 0;
}

int psd_points_default(const struct psd_engine *e, size_t zi, size_t i, double *v)
{
	const struct psd_zone_conf *zc;
	if (!psd_points_has(e, zi, i) || !table[i].d.writable)
		return -1;
	zc = e->zone[zi].zc;
	if (table[i].get == target_lux)
		*v = zc->ctl.target_lux;
	else if (table[i].get == daylighting)
		*v = 1;
	else if (table[i].get == vacancy_hold)
		*v = zc->vacancy_s;
	else
		return -1;
	return 0;
}

int psd_points_write(struct psd_engine *e, size_t zi, size_t i, double v, char *err, size_t n)
{
	const struct psd_points_def *d = psd_points_def(i);
	double was;
	if (!psd_points_has(e, zi, i) || psd_points_default(e, zi, i, &was) != 0) {
		return psd_errbuf(err, n, "%s is not a point zone %zu can be written", d ? d->key : "?", zi);
	}
	if (!(v >= d->min && v <= d->max) || (d->kind != PSD_POINTS_ANALOG && v != floor(v))) {
		return psd_errbuf(err, n, "%s %g is outside %g to %g", d->key, v, d->min, d->max);
	}
	if (table[i].get == target_lux)
		return psd_engine_set_target(&e->zone[zi], v, err, n);
	if (table[i].get == daylighting) {
		psd_engine_set_daylighting(&e->zone[zi], v != 0);
		return 0;
	}
	return psd_engine_set_vacancy_hold(&e->zone[zi], v, err, n);
}

/* The last acceptance run on record (the results sharing the latest time). */
struct last_run {
	double utc;
	int rows, tested, failed;   /* the run's tests on record (those that apply), run, failed */
};

static void accept_row(void *user, const struct psd_db_accept *a)
{
	struct last_run *r = user;
	if (a->utc != r->utc)
		*r = (struct last_run){ a->utc, 0, 0, 0 };
	r->rows++;
	r->tested += strcmp(a->verdict, psd_accept_verdict_names[0]) != 0; /* not NOT TESTED */
	r->failed += strcmp(a->verdict, psd_accept_verdict_names[1]) == 0; /* FAIL */
}

/* The verdict of the zone's last acceptance run in the log: 0 none. */
static int logged_verdict(const struct psd_engine *e, const char *zone)
{
	struct last_run r = { NAN, 0, 0, 0 };
	struct psd_accept_summary sum;
	char err[256];
	if (!e->db || psd_db_accept_results(e->db, zone, accept_row, &r, err, sizeof err) != 0 || isnan(r.utc))
		return 0;
	sum = (struct psd_accept_summary){ .count = r.rows, .tested = r.tested, .failed = r.failed };
	return verdict_of(psd_accept_overall(&sum));
}

static int in_engine(const struct psd_engine *e, const char *name)
{
	for (size_t i = 0; i < e->nzone; i++)
		if (strcmp(e->zone[i].zc->name, name) == 0)
			return 1;
	return 0;
}

void psd_points_update(struct psd_points *p, const struct psd_engine *e, double now)
{
	for (size_t i = 0; i < e->nzone; i++) {
		const struct psd_zone *z = &e->zone[i];
		struct psd_points_zone *s = (struct psd_points_zone *)state_for(p, e, i);
		double level = z->level, dt;
		if (!s) { /* a new zone: the slot of one gone, or a free one */
			size_t k;
			for (k = 0; k < PSD_MAX_ZONES && p->zone[k].name[0]; k++)
				if (!in_engine(e, p->zone[k].name))
					break;
			if (k == PSD_MAX_ZONES)
				continue;
			s = &p->zone[k];
			*s = (struct psd_points_zone){ .t = now, .verdict = logged_verdict(e, z->zc->name) };
			snprintf(s->name, sizeof s->name, "%s", z->zc->name);
			p->slot[i] = (int)k + 1;
			continue;
		}
		p->slot[i] = (int)(s - p->zone) + 1;
		dt = now - s->t;
		s->t = now;
		if (!(dt > 0) || !(level >= 0 && level <= 1))
			continue;
		s->output_h += level * dt / 3600;
		if (e->cf->lamp_watts > 0) {
			if (s->curve_of != e->cf) { /* read once per configuration */
				char what[200], err[200];
				s->curve_of = e->cf;
				s->have_curve = psd_annual_devices(e->cf, z->zc, &s->curve, what, sizeof what, err,
				                                   sizeof err) == 0;
			}
			if (s->have_curve)
				s->kwh += psd_annual_power(&s->curve, level) * s->curve.watts * dt / 3600 / 1000;
		}
	}
}

void psd_points_set_verdict(struct psd_points *p, const char *zone, const char *overall)
{
	struct psd_points_zone *s = (struct psd_points_zone *)state_of(p, zone);
	if (!s)
		return;
	s->verdict = verdict_of(overall);
}

json_object *psd_points_json(const struct psd_points *p, const struct psd_engine *e, size_t zi, double now)
{
	json_object *o = json_object_new_object();
	for (size_t i = 0; i < NPOINTS; i++) {
		const struct psd_points_def *d = &table[i].d;
		double v;
		if (psd_points_value(p, e, zi, i, now, &v) != 0)
			continue;
		if (d->kind == PSD_POINTS_BINARY)
			json_object_object_add(o, d->key, isnan(v) ? NULL : json_object_new_boolean(v != 0));
		else if (d->kind == PSD_POINTS_MULTISTATE)
			psd_json_str(o, d->key, v >= 1 && v <= (double)psd_points_nstates(i) ? d->states[(int)v - 1] : NULL);
		else
			psd_json_num(o, d->key, v);
	}
	return o;
}

/* A growing string. */
struct text {
	char *s;
	size_t len, cap;
	int failed;
};

static void add(struct text *t, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

static void add(struct text *t, const char *fmt, ...)
{
	va_list ap;
	int n;
	if (t->failed)
		return;
	for (;;) {
		va_start(ap, fmt);
		n = vsnprintf(t->s ? t->s + t->len : NULL, t->s ? t->cap - t->len : 0, fmt, ap);
		va_end(ap);
		if (n < 0) {
			t->failed = 1;
			return;
		}
		if (t->s && t->len + (size_t)n < t->cap) {
			t->len += (size_t)n;
			return;
		}
		{
			size_t cap = (t->cap ? 2 * t->cap : 4096) + (size_t)n;
			char *s = realloc(t->s, cap);
			if (!s) {
				t->failed = 1;
				return;
			}
			t->s = s, t->cap = cap;
		}
	}
}

/* A label value: backslash, quote and newline escaped (the format's rule). */
static void add_label(struct text *t, const char *v)
{
	for (; *v; v++) {
		if (*v == '\\' || *v == '"')
			add(t, "\\%c", *v);
		else if (*v == '\n')
			add(t, "\\n");
		else
			add(t, "%c", *v);
	}
}

/* Point i's metric name (Prometheus' base units: a point in hours, key
 * X_h, is psensd_X_seconds) and the factor from the point's unit. */
static double metric_name(const struct psd_points_def *d, char *name, size_t n)
{
	size_t len = strlen(d->key);
	if (d->unit && !strcmp(d->unit, "h") && len > 2 && !strcmp(d->key + len - 2, "_h")) {
		snprintf(name, n, "psensd_%.*s_seconds", (int)(len - 2), d->key);
		return 3600;
	}
	snprintf(name, n, "psensd_%s", d->key);
	return 1;
}

char *psd_points_prometheus(const struct psd_points *p, const struct psd_engine *e, double now)
{
	struct text t = { 0 };
	for (size_t i = 0; i < NPOINTS; i++) {
		const struct psd_points_def *d = &table[i].d;
		char name[80];
		double scale = metric_name(d, name, sizeof name);
		const char *unit = scale == 3600 ? "s" : d->unit;
		add(&t, "# HELP %s %s: %s%s%s%s\n", name, d->name, d->description, unit ? " (" : "", unit ? unit : "",
		    unit ? ")" : "");
		add(&t, "# TYPE %s gauge\n", name);
		for (size_t zi = 0; zi < e->nzone; zi++) {
			double v;
			if (psd_points_value(p, e, zi, i, now, &v) != 0 || isnan(v))
				continue;
			if (d->kind == PSD_POINTS_MULTISTATE) {
				for (size_t k = 0; k < psd_points_nstates(i); k++) {
					add(&t, "%s{zone=\"", name);
					add_label(&t, e->zone[zi].zc->name);
					add(&t, "\",state=\"%s\"} %d\n", d->states[k], (int)v == (int)k + 1);
				}
				continue;
			}
			v *= scale;
			add(&t, "%s{zone=\"", name);
			add_label(&t, e->zone[zi].zc->name);
			add(&t, "\"} %.17g\n", isinf(v) ? (v > 0 ? 1e308 : -1e308) : v);
		}
	}
	if (!t.s && !t.failed)
		add(&t, "%s", "");
	if (t.failed) {
		free(t.s);
		errno = ENOMEM;
		return NULL;
	}
	return t.s;
}
