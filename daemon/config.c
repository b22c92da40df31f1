/* SPDX-License-Identifier: ISC */
#include "config.h"
#include "confcheck.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "registry.h"
#include "roomsetup.h"
#include "time.h"

static const char *const action_names[] = { "none", "occupancy", "override", "calibrate", NULL };

static int hhmm(struct ps_conf *c, struct ps_conf_section *s, const char *key, double def, double *out)
{
	struct ps_conf_kv *kv = ps_conf_kv(s, key);
	*out = def;
	if (!kv)
		return 0;
	if (psd_time_hhmm(kv->value, out) != 0) {
		ps_conf_error(c, kv->line, "%s: '%s' is not HH:MM (00:00 to 23:59)", key, kv->value);
		*out = def;
		return -1;
	}
	return 0;
}

static int line_of(struct ps_conf_section *s, const char *key)
{
	struct ps_conf_kv *kv = ps_conf_kv(s, key);
	return kv ? kv->line : s->line;
}

/* stop_level = hold | safe | a level 0-1 (psensd(8), STOPPING): def when
 * the key is absent; -1 after an error at the key's line. */
static int stop_level(struct ps_conf *c, struct ps_conf_section *s, struct psd_stop def, struct psd_stop *out)
{
	struct ps_conf_kv *kv = ps_conf_kv(s, "stop_level");
	double v;
	*out = def;
	if (!kv)
		return 0;
	if (strcmp(kv->value, "hold") == 0) {
		*out = (struct psd_stop){ .mode = PSD_STOP_HOLD, .level = 0 };
		return 0;
	}
	if (strcmp(kv->value, "safe") == 0) {
		*out = (struct psd_stop){ .mode = PSD_STOP_SAFE, .level = 0 };
		return 0;
	}
	if (ps_conf_parse_double(kv->value, &v) != 0 || !(v >= 0 && v <= 1)) {
		ps_conf_error(c, kv->line, "stop_level: '%s' is none of hold, safe or a level from 0 to 1", kv->value);
		return -1;
	}
	*out = (struct psd_stop){ .mode = PSD_STOP_LEVEL, .level = v };
	return 0;
}

/* Points that read lux (a task meter, a rooftop sensor): valid 0 to 200 klx
 * by default, not the sensor's volts. */
static int lux_role(int role)
{
	return role == PS_ROLE_TASK_LUX || role == PS_ROLE_ROOFTOP;
}

/* Copy every key of s not in `own` (NULL-terminated) into the option pool. */
static void driver_opts(struct psd_config *cf, struct ps_conf_section *s, const char *const *own,
                        struct ps_opts *o)
{
	o->v = cf->optpool + cf->nopt;
	o->n = 0;
	o->file = cf->conf.path;
	for (size_t j = 0; j < s->nkv; j++) {
		int mine = 0;
		for (size_t k = 0; own[k]; k++)
			mine |= strcmp(s->kv[j].key, own[k]) == 0;
		if (mine)
			continue;
		if (cf->nopt >= PSD_MAX_OPTS) {
			ps_conf_error(&cf->conf, s->kv[j].line, "more than %d driver keys in the file",
			              PSD_MAX_OPTS);
			return;
		}
		s->kv[j].used = 1;   /* judged by the driver's table (check_driver_keys) */
		cf->optpool[cf->nopt++] = (struct ps_opt){ s->kv[j].key, s->kv[j].value, s->kv[j].line, 0 };
		o->n++;
	}
}

struct section {
	struct psd_config *cf;
	int line;
};

static void report(void *user, int line, const char *why)
{
	struct section *s = user;
	ps_conf_error(&s->cf->conf, line ? line : s->line, "%s", why);   /* 0: a key missing from it */
}

/* A section's driver keys, judged by the driver's table and check (every
 * error with its line, as for the daemon's own keys). */
static void check_driver_keys(struct psd_config *cf, const struct ps_driver *drv, const struct ps_opts *o,
                              int role, int line)
{
	struct section s = { cf, line };
	if (drv)
		ps_driver_check(drv, o, role, report, &s);
}

static int find_name(const char *name, const void *base, size_t n, size_t stride)
{
	for (size_t i = 0; i < n; i++)
		if (strcmp((const char *)base + i * stride, name) == 0)
			return (int)i;
	return -1;
}

/* Index of a point by name, -1 if none. */
static int point_index(const struct psd_config *cf, const char *name)
{
	return find_name(name, cf->pt, cf->npt, sizeof cf->pt[0]);
}

/* 1 when tz names a zone in /usr/share/zoneinfo or is a POSIX TZ rule. */
static int timezone_valid(const char *tz)
{
	char path[512];
	struct stat st;
	if (!*tz || strstr(tz, "..") || tz[0] == '/')
		return 0;
	snprintf(path, sizeof path, "/usr/share/zoneinfo/%s", tz);
	if (stat(path, &st) == 0 && S_ISREG(st.st_mode))
		return 1;
	/* a POSIX rule: a name of three letters or more, then an offset */
	return strlen(tz) >= 4 && strpbrk(tz, "0123456789") != NULL && strspn(tz, "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz") >= 3;
}

const char *psd_config_zone_simulated(const struct psd_config *cf, const struct psd_zone_conf *zc)
{
	const struct psd_device_conf *d;
	if (zc->sensor < 0 || (size_t)zc->sensor >= cf->npt)
		return NULL;
	d = &cf->dev[cf->pt[zc->sensor].device];
	if (d->simulated[0])
		return d->simulated;
	if (d->drv && (d->drv->truth || strcmp(d->drv->name, "replay") == 0))
		return d->drv->name;
	return NULL;
}

const char *psd_config_zone_scene(const struct psd_config *cf, const struct psd_zone_conf *zc)
{
	return zc->scene ? zc->scene : zc->results ? NULL : cf->scene;
}

const char *psd_config_zone_results(const struct psd_config *cf, const struct psd_zone_conf *zc)
{
	return zc->results ? zc->results : cf->results;
}

int psd_config_zone(const struct psd_config *cf, const char *name)
{
	return find_name(name, cf->zone, cf->nzone, sizeof cf->zone[0]);
}

static int set_name(struct ps_conf *c, int line, char *dst, size_t size, const char *name, const char *kind)
{
	size_t n = strlen(name);
	if (n == 0 || n >= size || strspn(name, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
	                                        "0123456789_-.") != n) {
		ps_conf_error(c, line, "[%s %s]: a name is 1 to %zu letters, digits, '_', '-' or '.'", kind,
		              name, size - 1);
		return -1;
	}
	memcpy(dst, name, n + 1);
	return 0;
}

static const char *const point_keys[] = { "device", "role",       "action",
	                                   "valid_min", "valid_max", "sensor_saturation", NULL };

static void load_devices(struct psd_config *cf)
{
	struct ps_conf *c = &cf->conf;
	static const char *const own[] = { "driver", "simulated", NULL };
	for (size_t i = 0; i < c->nsec; i++) {
		struct ps_conf_section *s = &c->sec[i];
		const char *name = ps_conf_section_is(s, "device"), *drv;
		struct psd_device_conf *d;
		if (!name)
			continue;
		s->used = 1;
		if (cf->ndev >= PSD_MAX_DEVICES) {
			ps_conf_error(c, s->line, "more than %d devices", PSD_MAX_DEVICES);
			continue;
		}
		d = &cf->dev[cf->ndev];
		if (set_name(c, s->line, d->name, sizeof d->name, name, "device") != 0)
			continue;
		if (find_name(d->name, cf->dev, cf->ndev, sizeof cf->dev[0]) >= 0) {
			ps_conf_error(c, s->line, "[device %s] is defined twice", d->name);
			continue;
		}
		d->line = s->line;
		drv = ps_conf_str(c, s, "driver", NULL);
		if (!drv)
			ps_conf_error(c, s->line, "[device %s] needs 'driver'", d->name);
		else if (!(d->drv = ps_registry_find(drv))) {
			char names[128];
			ps_registry_names(names, sizeof names);
			ps_conf_error(c, line_of(s, "driver"), "driver: no driver '%s' (%s)", drv, names);
		}
		snprintf(d->simulated, sizeof d->simulated, "%s", ps_conf_str(c, s, "simulated", ""));
		driver_opts(cf, s, own, &d->opts);
		check_driver_keys(cf, d->drv, &d->opts, -1, s->line);
		cf->ndev++;
	}
}

static void load_points(struct psd_config *cf)
{
	struct ps_conf *c = &cf->conf;
	for (size_t i = 0; i < c->nsec; i++) {
		struct ps_conf_section *s = &c->sec[i];
		const char *name = ps_conf_section_is(s, "point"), *v;
		struct psd_point_conf *p;
		if (!name)
			continue;
		s->used = 1;
		if (cf->npt >= PSD_MAX_POINTS) {
			ps_conf_error(c, s->line, "more than %d points", PSD_MAX_POINTS);
			continue;
		}
		p = &cf->pt[cf->npt];
		memset(p, 0, sizeof *p);
		if (set_name(c, s->line, p->name, sizeof p->name, name, "point") != 0)
			continue;
		if (point_index(cf, p->name) >= 0) {
			ps_conf_error(c, s->line, "[point %s] is defined twice", p->name);
			continue;
		}
		p->line = s->line;
		p->device = -1;
		v = ps_conf_str(c, s, "device", NULL);
		if (!v)
			ps_conf_error(c, s->line, "[point %s] needs 'device'", p->name);
		else if ((p->device = find_name(v, cf->dev, cf->ndev, sizeof cf->dev[0])) < 0)
			ps_conf_error(c, line_of(s, "device"), "device: no [device %s]", v);
		v = ps_conf_str(c, s, "role", NULL);
		p->role = v ? ps_role_parse(v) : -1;
		if (!v)
			ps_conf_error(c, s->line, "[point %s] needs 'role' (sensor, task, dim, relay, input, rooftop)", p->name);
		else if (p->role < 0)
			ps_conf_error(c, line_of(s, "role"), "role: '%s' is not sensor, task, dim, relay, input or rooftop", v);
		ps_conf_enum(c, s, "action", action_names, PSD_ACT_NONE, &p->action);
		if (p->action != PSD_ACT_NONE && p->role != PS_ROLE_INPUT)
			ps_conf_error(c, line_of(s, "action"), "action: only an input point has an action");
		ps_conf_double(c, s, "valid_min", lux_role(p->role) ? 0 : cf->sensor_min, -1e9, 1e9, &p->min);
		ps_conf_double(c, s, "valid_max", lux_role(p->role) ? 2e5 : cf->sensor_max, -1e9, 1e9, &p->max);
		if (p->min >= p->max)
			ps_conf_error(c, s->line, "[point %s]: valid_min must be below valid_max", p->name);
		ps_conf_double(c, s, "sensor_saturation", p->role == PS_ROLE_SENSOR ? cf->sensor_saturation : 0, 0,
		               1e9, &p->saturation);
		if (p->role == PS_ROLE_SENSOR && p->saturation > 0 && p->saturation <= p->min)
			ps_conf_error(c, line_of(s, ps_conf_kv(s, "sensor_saturation") ? "sensor_saturation" : "valid_min"),
			              "[point %s]: sensor_saturation %g must be above valid_min %g: every reading "
			              "would be a fault", p->name, p->saturation, p->min);
		driver_opts(cf, s, point_keys, &p->opts);
		/* a point whose device or role is wrong was reported above */
		if (p->device >= 0 && p->role >= 0)
			check_driver_keys(cf, cf->dev[p->device].drv, &p->opts, p->role, s->line);
		cf->npt++;
	}
}

/* An implicit point "DEVICE.ROLE" for the zone shorthand `device = NAME`. */
static int implicit_point(struct psd_config *cf, int dev, int role, int line)
{
	char name[96];
	struct psd_point_conf *p;
	int i;
	snprintf(name, sizeof name, "%s.%s", cf->dev[dev].name, ps_role_name(role));
	if ((i = point_index(cf, name)) >= 0)
		return i;
	if (cf->npt >= PSD_MAX_POINTS) {
		ps_conf_error(&cf->conf, line, "more than %d points", PSD_MAX_POINTS);
		return -1;
	}
	if (strlen(name) >= sizeof p->name) {
		ps_conf_error(&cf->conf, line, "device name too long for its implicit point %s", name);
		return -1;
	}
	p = &cf->pt[cf->npt];
	memset(p, 0, sizeof *p);
	memcpy(p->name, name, strlen(name) + 1);
	p->device = dev;
	p->role = role;
	p->min = lux_role(role) ? 0 : cf->sensor_min;
	p->max = lux_role(role) ? 2e5 : cf->sensor_max;
	p->saturation = role == PS_ROLE_SENSOR ? cf->sensor_saturation : 0;
	p->opts.file = cf->conf.path;
	p->line = line;
	return (int)cf->npt++;
}

/* "a, b c" -> point indices of the wanted role; returns the count. */
static int point_list(struct psd_config *cf, struct ps_conf_section *s, const char *key, int role,
                      int *out, int max)
{
	struct ps_conf_kv *kv = ps_conf_kv(s, key);
	char *copy, *save = NULL;
	int n = 0;
	if (!kv)
		return 0;
	if (!(copy = strdup(kv->value))) {
		ps_conf_error(&cf->conf, kv->line, "out of memory");
		return 0;
	}
	for (char *w = strtok_r(copy, ", \t", &save); w; w = strtok_r(NULL, ", \t", &save)) {
		int i = point_index(cf, w);
		if (i < 0)
			ps_conf_error(&cf->conf, kv->line, "%s: no [point %s]", key, w);
		else if (cf->pt[i].role >= 0 && cf->pt[i].role != role)
			ps_conf_error(&cf->conf, kv->line, "%s: point %s has role %s, not %s", key, w,
			              ps_role_name(cf->pt[i].role), ps_role_name(role));
		else if (n >= max)
			ps_conf_error(&cf->conf, kv->line, "%s: more than %d points", key, max);
		else
			out[n++] = i;   /* one whose role is wrong too: reported at the point, not again here */
	}
	free(copy);
	return n;
}

/* The shortest period or calibration step psensd takes.  A DALI query and
 * its answer hold the bus about 30 ms and a Modbus RTU poll at 9600 baud
 * about 20 ms, so a shorter step asks faster than the devices answer; and
 * every step logs a sample row per zone (864,000 a day at 0.1 s).  Below it
 * the value is a typo: 0.001 meant 1 or 60. */
#define PSD_MIN_STEP 0.1

static void duration(struct ps_conf *c, struct ps_conf_section *s, const char *key, double def, double max,
                     double *out)
{
	struct ps_conf_kv *kv = ps_conf_kv(s, key);
	if (ps_conf_double(c, s, key, def, 0, max, out) != 0 || !kv || *out >= PSD_MIN_STEP)
		return;
	ps_conf_error(c, kv->line, "%s: %g s is shorter than %g s: faster than a device answers (a DALI query "
	              "takes about 30 ms), and the log takes a sample row per zone each step (864,000 a day "
	              "at %g s)",
	              key, *out, PSD_MIN_STEP, PSD_MIN_STEP);
	*out = def;
}

static void load_control(struct ps_conf *c, struct ps_conf_section *s, struct psd_control *k)
{
	long steps;
	memset(k, 0, sizeof *k);
	ps_conf_enum(c, s, "algorithm", psd_control_algorithm_names, PSD_ALG_SETPOINT, &k->algorithm);
	ps_conf_double(c, s, "target_lux", 500, 0, 1e6, &k->target_lux);
	ps_conf_double(c, s, "min_level", 0.1, 0, 1, &k->min_level);
	ps_conf_double(c, s, "max_step", 0, 0, 1, &k->max_step);
	ps_conf_double(c, s, "hysteresis", 0, 0, 1, &k->hysteresis);
	ps_conf_double(c, s, "sensor_gain", 1, 1e-12, 1e12, &k->sensor_gain);
	ps_conf_double(c, s, "s_full", 0, 0, 1e6, &k->s_full);
	ps_conf_double(c, s, "s_set", 0, 0, 1e6, &k->s_set);
	ps_conf_double(c, s, "ki", 1, 0, 100, &k->ki);
	ps_conf_double(c, s, "s_off", 1e9, 0, 1e9, &k->s_off);
	ps_conf_double(c, s, "s_on", 0, 0, 1e9, &k->s_on);
	ps_conf_double(c, s, "delay", 300, 0, 86400, &k->delay);
	ps_conf_int(c, s, "steps", 1, 1, 16, &steps);
	k->steps = (int)steps;
	if (k->s_on > k->s_off)
		ps_conf_error(c, s->line, "[%s]: s_on must not exceed s_off (the deadband)", s->name);
}

static void load_zones(struct psd_config *cf)
{
	struct ps_conf *c = &cf->conf;
	for (size_t i = 0; i < c->nsec; i++) {
		struct ps_conf_section *s = &c->sec[i];
		const char *name = ps_conf_section_is(s, "zone"), *v;
		struct psd_zone_conf *z;
		int n;
		if (!name)
			continue;
		s->used = 1;
		if (cf->nzone >= PSD_MAX_ZONES) {
			ps_conf_error(c, s->line, "more than %d zones", PSD_MAX_ZONES);
			continue;
		}
		z = &cf->zone[cf->nzone];
		memset(z, 0, sizeof *z);
		if (set_name(c, s->line, z->name, sizeof z->name, name, "zone") != 0)
			continue;
		if (psd_config_zone(cf, z->name) >= 0) {
			ps_conf_error(c, s->line, "[zone %s] is defined twice", z->name);
			continue;
		}
		z->line = s->line;
		z->sensor = z->task = -1;
		if ((v = ps_conf_str(c, s, "device", NULL))) {
			int d = find_name(v, cf->dev, cf->ndev, sizeof cf->dev[0]);
			if (d < 0) {
				ps_conf_error(c, line_of(s, "device"), "device: no [device %s]", v);
			} else {
				z->sensor = implicit_point(cf, d, PS_ROLE_SENSOR, line_of(s, "device"));
				z->dim[0] = implicit_point(cf, d, PS_ROLE_DIM, line_of(s, "device"));
				z->ndim = z->dim[0] >= 0;
			}
		}
		if (point_list(cf, s, "sensor", PS_ROLE_SENSOR, &z->sensor, 1) == 0 && z->sensor < 0)
			ps_conf_error(c, s->line, "[zone %s] needs 'sensor' (a point with role sensor) or 'device'",
			              z->name);
		point_list(cf, s, "task", PS_ROLE_TASK_LUX, &z->task, 1);
		z->rooftop = -1;
		point_list(cf, s, "rooftop", PS_ROLE_ROOFTOP, &z->rooftop, 1);
		n = point_list(cf, s, "dim", PS_ROLE_DIM, z->dim + z->ndim, PSD_MAX_ZONE_OUT - z->ndim);
		z->ndim += n;
		z->nrelay = point_list(cf, s, "relay", PS_ROLE_RELAY, z->relay, PSD_MAX_ZONE_OUT);
		z->ninput = point_list(cf, s, "input", PS_ROLE_INPUT, z->input, PSD_MAX_ZONE_OUT);
		if (z->ndim + z->nrelay == 0)
			ps_conf_error(c, s->line, "[zone %s] needs an output: 'dim' or 'relay' points", z->name);
		load_control(c, s, &z->ctl);
		duration(c, s, "period", cf->period, 86400, &z->period);
		ps_conf_double(c, s, "safe_level", cf->safe_level, 0, 1, &z->safe_level);
		stop_level(c, s, cf->stop, &z->stop);
		ps_conf_double(c, s, "stale_after", cf->stale_after > 0 ? cf->stale_after : 2.5 * z->period,
		               0, 86400 * 7, &z->stale_after);
		ps_conf_double(c, s, "stuck_after", cf->stuck_after, 0, 86400 * 7, &z->stuck_after);
		ps_conf_double(c, s, "verify_tolerance", 0, 0, 1, &z->verify_tolerance);
		ps_conf_bool(c, s, "readback", 0, &z->readback);
		ps_conf_double(c, s, "override_time", 3600, 1, 86400 * 7, &z->override_s);
		/* occupancy (daemon/occupancy.h): vacancy_delay is the same key */
		if (ps_conf_kv(s, "vacancy_hold") && ps_conf_kv(s, "vacancy_delay"))
			ps_conf_error(c, line_of(s, "vacancy_delay"), "vacancy_delay: the same as vacancy_hold: give one");
		ps_conf_double(c, s, ps_conf_kv(s, "vacancy_delay") ? "vacancy_delay" : "vacancy_hold", 900, 0, 86400,
		               &z->vacancy_s);
		ps_conf_double(c, s, "vacant_level", 0, 0, 1, &z->vacant_level);
		duration(c, s, "cal_window", 4 * z->period, 86400, &z->cal_window);
		duration(c, s, "cal_timeout", 60 * z->period, 86400 * 7, &z->cal_timeout);
		ps_conf_double(c, s, "cal_floor", 0.001, 0, 10, &z->cal_floor);
		ps_conf_int(c, s, "cal_day_samples", 5, 2, 64, &z->cal_day_samples);
		duration(c, s, "cal_day_interval", 600, 86400, &z->cal_day_interval);
		ps_conf_double(c, s, "cal_min_day_volts", 0.05, 0, 100, &z->cal_min_day_volts);
		ps_conf_double(c, s, "cal_tolerance", 25, 0, 1000, &z->cal_tolerance);
		ps_conf_double(c, s, "cal_dark_margin", 0.2, 0, 100, &z->cal_dark_margin);
		ps_conf_bool(c, s, "cal_night_sun", 1, &z->cal_night_sun);
		ps_conf_double(c, s, "cal_sun_share", 0.05, 0, 1, &z->cal_sun_share);
		ps_conf_double(c, s, "drift_margin", 0.25, 0.001, 10, &z->drift_margin);
		ps_conf_double(c, s, "drift_hold", 3600, 0, 86400 * 30, &z->drift_hold);
		z->scene = ps_conf_path(c, s, "scene");
		z->results = ps_conf_path(c, s, "results");
		if (z->scene && !z->results && cf->results) {
			/* beside [psensd]'s results, named after the scene */
			const char *base = strrchr(z->scene, '/'), *rs = strrchr(cf->results, '/');
			size_t nb, nd = rs ? (size_t)(rs - cf->results + 1) : 0;
			base = base ? base + 1 : z->scene;
			nb = strlen(base);
			if (nb > 6 && strcmp(base + nb - 6, ".scene") == 0)
				nb -= 6;
			if ((z->results = malloc(nd + nb + 9)))
				snprintf(z->results, nd + nb + 9, "%.*s%.*s.results", (int)nd, cf->results, (int)nb, base);
		}
		cf->nzone++;
	}
	if (cf->nzone == 0)
		ps_conf_error(c, 0, "no [zone NAME] section: psensd has nothing to control");
}

/* A point used by two zones would be commanded twice: refuse it. */
static void check_sharing(struct psd_config *cf)
{
	int owner[PSD_MAX_POINTS];
	for (size_t i = 0; i < PSD_MAX_POINTS; i++)
		owner[i] = -1;
	for (size_t z = 0; z < cf->nzone; z++) {
		struct psd_zone_conf *zc = &cf->zone[z];
		int all[2 * PSD_MAX_ZONE_OUT], n = 0;
		for (int i = 0; i < zc->ndim; i++)
			all[n++] = zc->dim[i];
		for (int i = 0; i < zc->nrelay; i++)
			all[n++] = zc->relay[i];
		for (int i = 0; i < n; i++) {
			if (all[i] < 0)
				continue;
			if (owner[all[i]] >= 0 && owner[all[i]] != (int)z)
				ps_conf_error(&cf->conf, zc->line, "[zone %s]: output %s already belongs to zone %s",
				              zc->name, cf->pt[all[i]].name, cf->zone[owner[all[i]]].name);
			owner[all[i]] = (int)z;
		}
	}
}

static int load(struct psd_config *cf, int files)
{
	struct ps_conf *c = &cf->conf;
	struct ps_conf_section *s = ps_conf_section(c, "psensd");
	char *mode;
	long maxc;
	cf->results = ps_conf_path(c, s, "results");
	cf->scene = ps_conf_path(c, s, "scene");
	cf->database = ps_conf_path(c, s, "database");
	cf->socket_path = ps_conf_path(c, s, "socket");
	if (!s)
		ps_conf_error(c, 0, "no [psensd] section");
	else if (!cf->results)
		ps_conf_error(c, s->line, "[psensd] needs 'results' (a psscene results file)");
	duration(c, s, "period", 60, 86400, &cf->period);
	ps_conf_double(c, s, "safe_level", 1.0, 0, 1, &cf->safe_level);
	stop_level(c, s, (struct psd_stop){ .mode = PSD_STOP_SAFE, .level = 0 }, &cf->stop);
	ps_conf_double(c, s, "sensor_min", 0.01, -100, 100, &cf->sensor_min);
	ps_conf_double(c, s, "sensor_max", 9.9, -100, 1000, &cf->sensor_max);
	ps_conf_double(c, s, "sensor_saturation", 10, 0, 1000, &cf->sensor_saturation);
	ps_conf_double(c, s, "stale_after", 0, 0, 86400 * 7, &cf->stale_after);
	ps_conf_double(c, s, "stuck_after", 0, 0, 86400 * 7, &cf->stuck_after);
	ps_conf_int(c, s, "max_clients", 32, 1, 1024, &maxc);
	cf->max_clients = maxc;
	ps_conf_int(c, s, "log_hold", 4096, 16, 1048576, &cf->log_hold);
	cf->timezone = ps_conf_str(c, s, "timezone", NULL);
	if (cf->timezone && !timezone_valid(cf->timezone))
		ps_conf_error(c, line_of(s, "timezone"), "timezone: '%s' is neither a zone in /usr/share/zoneinfo nor a "
		              "POSIX rule such as CET-1CEST,M3.5.0,M10.5.0/3", cf->timezone);
	cf->socket_mode = 0660;
	if ((mode = (char *)ps_conf_str(c, s, "socket_mode", NULL))) {
		char *end;
		long m = strtol(mode, &end, 8);
		if (*end || m < 0 || m > 0777 || (m & 0007))
			ps_conf_error(c, line_of(s, "socket_mode"), "socket_mode: '%s' is not octal permission "
			              "bits without access for others (e.g. 0660)", mode);
		else
			cf->socket_mode = (double)m;
	}
	s = ps_conf_section(c, "simulate");
	snprintf(cf->date, sizeof cf->date, "%s", ps_conf_str(c, s, "date", "03-18"));
	if (psd_roomsetup_day_of_year(cf->date) < 0)
		ps_conf_error(c, s ? line_of(s, "date") : 0, "date: '%s' is not a day of the year (MM-DD)", cf->date);
	ps_conf_int(c, s, "run_year", 0, 0, 9999, &cf->run_year);
	if (cf->run_year != 0 && cf->run_year < 1970)
		ps_conf_error(c, s ? line_of(s, "run_year") : 0, "run_year: %ld is before 1970", cf->run_year);
	hhmm(c, s, "start", 6 * 3600.0, &cf->start);
	hhmm(c, s, "end", 20 * 3600.0, &cf->end);
	hhmm(c, s, "sunrise", 6 * 3600.0, &cf->sunrise);
	hhmm(c, s, "sunset", 18 * 3600.0, &cf->sunset);
	ps_conf_double(c, s, "tolerance", 0.02, 0, 1, &cf->tolerance);
	ps_conf_bool(c, s, "year", 0, &cf->sim_year);
	hhmm(c, s, "occupied_from", 8 * 3600.0, &cf->occ_from);
	hhmm(c, s, "occupied_to", 18 * 3600.0, &cf->occ_to);
	/* psensd -Y's power curve: -1 = power proportional to light */
	ps_conf_double(c, s, "power_at_min", -1, -1, 1, &cf->power_at_min);
	if (cf->power_at_min < 0 && cf->power_at_min != -1)
		ps_conf_error(c, s ? line_of(s, "power_at_min") : 0, "power_at_min: a fraction 0 to 1");
	ps_conf_double(c, s, "lamp_watts", 0, 0, 1e6, &cf->lamp_watts);
	if (cf->occ_to <= cf->occ_from)
		ps_conf_error(c, s ? s->line : 0, "[simulate]: occupied_to must be after occupied_from");
	{
		static const char *const estimates[] = { "mean", "dated", NULL };
		/* default: dated when the room plays the year, else mean */
		ps_conf_enum(c, ps_conf_section(c, "psensd"), "estimate", estimates, cf->sim_year,
		             &cf->dated_estimate);
	}
	if (cf->end <= cf->start)
		ps_conf_error(c, s ? s->line : 0, "[simulate]: end must be after start");
	if (cf->sunset <= cf->sunrise)
		ps_conf_error(c, s ? s->line : 0, "[simulate]: sunset must be after sunrise");
	load_devices(cf);
	load_points(cf);
	load_zones(cf);
	check_sharing(cf);
	psd_mqttconf_load(&cf->mqtt, c);
	psd_bacconf_load(&cf->bacnet, c);
	psd_webconf_load(&cf->web, c);
	psd_promconf_load(&cf->prom, c);
	if (cf->mqtt.enabled && !cf->database)
		ps_conf_error(c, cf->mqtt.line, "[mqtt] publishes the sample log: set database in [psensd]");
	psd_confcheck_ranges(cf);
	if (files)
		psd_confcheck_files(cf);
	if (files > 1)
		psd_confcheck_outputs(cf);
	ps_conf_check_unused(c);
	return c->nerrors ? -1 : 0;
}

static int load_file(struct psd_config *cf, const char *path, int files);

int psd_config_load(struct psd_config *cf, const char *path)
{
	return load_file(cf, path, 1);
}

int psd_config_load_judged(struct psd_config *cf, const char *path)
{
	return load_file(cf, path, 2);
}

int psd_config_load_keys(struct psd_config *cf, const char *path)
{
	return load_file(cf, path, 0);
}

static int load_file(struct psd_config *cf, const char *path, int files)
{
	struct ps_err e;
	memset(cf, 0, sizeof *cf);
	if (ps_conf_load(&cf->conf, path, &e) != 0) {
		/* e.msg already names the file */
		cf->conf.errors = malloc(sizeof *cf->conf.errors);
		if (cf->conf.errors && (cf->conf.errors[0] = strdup(e.msg)))
			cf->conf.nerrors = 1;
		return -1;
	}
	return load(cf, files);
}

int psd_config_load_string(struct psd_config *cf, const char *text, const char *path)
{
	struct ps_err e;
	memset(cf, 0, sizeof *cf);
	if (ps_conf_load_string(&cf->conf, text, path, &e) != 0) {
		ps_conf_error(&cf->conf, 0, "%s", e.msg);
		return -1;
	}
	return load(cf, 0);
}

void psd_config_free(struct psd_config *cf)
{
	free(cf->results);
	free(cf->scene);
	free(cf->database);
	free(cf->socket_path);
	for (size_t i = 0; i < cf->npath; i++)
		free(cf->path[i]);
	for (size_t i = 0; i < cf->nzone; i++) {
		free(cf->zone[i].scene);
		free(cf->zone[i].results);
	}
	psd_mqttconf_free(&cf->mqtt);
	psd_promconf_free(&cf->prom);
	ps_conf_free(&cf->conf);
	memset(cf, 0, sizeof *cf);
}
