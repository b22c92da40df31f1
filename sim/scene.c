/* SPDX-License-Identifier: ISC */
#include "scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "conf.h"
#include "integrate.h"
#include "sensor.h"

void ps_scene_free(struct ps_scene *s)
{
	if (!s)
		return;
	for (size_t i = 0; i < s->ncond; i++) {
		free(s->cond[i].label);
		free(s->cond[i].date);
		free(s->cond[i].sensor_pic);
		free(s->cond[i].task_pic);
		free(s->cond[i].octree);
	}
	for (size_t i = 0; i < s->nref; i++)
		free(s->ref[i].label);
	for (size_t i = 0; i < s->nvar; i++) {
		free(s->var[i].label);
		free(s->var[i].of);
		free(s->var[i].sensor_pic);
		free(s->var[i].task_pic);
	}
	free(s->dc.sensor_pattern);
	free(s->dc.task_pattern);
	free(s->dc.task_matrix);
	free(s->dc.task_points);
	free(s->dc.weather);
	free(s->var);
	free(s->cond);
	free(s->ref);
	free(s->path);
	free(s->name);
	free(s->sensitivity);
	free(s->filter);
	free(s->render_options);
	free(s->cache_dir);
	memset(s, 0, sizeof *s);
}

static char *dup_or_null(const char *v)
{
	return v ? strdup(v) : NULL;
}

static void read_vec(struct ps_conf *c, struct ps_conf_section *sec, const char *key,
                     const double *def, double out[3], int *have)
{
	struct ps_conf_kv *kv = ps_conf_kv(sec, key);
	memcpy(out, def, 3 * sizeof *out);
	if (!kv)
		return;
	if (sscanf(kv->value, "%lf %lf %lf", &out[0], &out[1], &out[2]) != 3 ||
	    !isfinite(out[0]) || !isfinite(out[1]) || !isfinite(out[2]))
		ps_conf_error(c, kv->line, "%s: '%s' is not three numbers", key, kv->value);
	else if (have)
		*have = 1;
}

static void read_place(struct ps_conf *c, struct ps_conf_section *sec, struct ps_marks_place *p,
                       const double *dir)
{
	static const double zero[3] = { 0, 0, 0 }, up[3] = { 0, 1, 0 };
	read_vec(c, sec, "position", zero, p->pos, &p->have);
	read_vec(c, sec, "direction", dir, p->dir, NULL);
	read_vec(c, sec, "up", up, p->up, NULL);
}

/* "15:00" or "15:00:30" -> seconds */
static int parse_time(const char *t, double *out)
{
	int h, m, s = 0, n = 0;
	if ((sscanf(t, "%d:%d:%d%n", &h, &m, &s, &n) == 3 || sscanf(t, "%d:%d%n", &h, &m, &n) == 2) &&
	    t[n] == '\0' && h >= 0 && h < 24 && m >= 0 && m < 60 && s >= 0 && s < 60) {
		*out = h * 3600.0 + m * 60.0 + s;
		return 0;
	}
	return -1;
}

static int parse_date(const char *d)
{
	int mo, dy, n = 0;
	return sscanf(d, "%d-%d%n", &mo, &dy, &n) == 2 && d[n] == '\0' && mo >= 1 && mo <= 12 &&
	       dy >= 1 && dy <= 31 ? 0 : -1;
}

static int add_condition(struct ps_scene *s, struct ps_conf *c, struct ps_conf_section *sec,
                         const char *label)
{
	static const char *const kinds[] = { "daylight", "electric", NULL };
	struct ps_condition *grown = realloc(s->cond, (s->ncond + 1) * sizeof *grown), *k;
	const char *t;
	if (!grown)
		return -1;
	s->cond = grown;
	k = &s->cond[s->ncond++];
	memset(k, 0, sizeof *k);
	k->label = strdup(label);
	k->line = sec->line;
	k->tod_s = -1;
	if (!*label)
		ps_conf_error(c, sec->line, "[condition] needs a label: [condition day_0318]");
	ps_conf_required(c, sec, "kind");
	ps_conf_enum(c, sec, "kind", kinds, PS_COND_DAYLIGHT, &k->kind);
	k->date = strdup(ps_conf_str(c, sec, "date", ""));
	if (*k->date && parse_date(k->date) != 0)
		ps_conf_error(c, ps_conf_kv(sec, "date")->line, "date: '%s' is not MM-DD", k->date);
	if ((t = ps_conf_str(c, sec, "time", NULL)) && parse_time(t, &k->tod_s) != 0)
		ps_conf_error(c, ps_conf_kv(sec, "time")->line, "time: '%s' is not HH:MM", t);
	if (k->kind == PS_COND_DAYLIGHT && k->tod_s < 0)
		ps_conf_error(c, sec->line, "[condition %s]: a daylight condition needs a time", label);
	ps_conf_required(c, sec, "sensor_picture");
	ps_conf_required(c, sec, "task_picture");
	k->sensor_pic = ps_conf_path(c, sec, "sensor_picture");
	k->task_pic = ps_conf_path(c, sec, "task_picture");
	k->octree = ps_conf_path(c, sec, "octree");
	ps_conf_bool(c, sec, "optional", 0, &k->optional);
	ps_conf_double(c, sec, "reference_sensor_response", NAN, 0, 1e30, &k->ref_sensor);
	ps_conf_double(c, sec, "reference_task_irradiance", NAN, 0, 1e30, &k->ref_task);
	return k->label && k->date ? 0 : -1;
}

static int add_variant(struct ps_scene *s, struct ps_conf *c, struct ps_conf_section *sec,
                       const char *label)
{
	struct ps_variant *grown = realloc(s->var, (s->nvar + 1) * sizeof *grown), *v;
	if (!grown)
		return -1;
	s->var = grown;
	v = &s->var[s->nvar++];
	memset(v, 0, sizeof *v);
	v->label = strdup(label);
	v->line = sec->line;
	ps_conf_required(c, sec, "of");
	v->of = strdup(ps_conf_str(c, sec, "of", ""));
	ps_conf_required(c, sec, "sensor_picture");
	ps_conf_required(c, sec, "task_picture");
	v->sensor_pic = ps_conf_path(c, sec, "sensor_picture");
	v->task_pic = ps_conf_path(c, sec, "task_picture");
	ps_conf_double(c, sec, "render_seconds", NAN, 0, 1e9, &v->render_seconds);
	return v->label && v->of ? 0 : -1;
}

static int add_reference(struct ps_scene *s, struct ps_conf *c, struct ps_conf_section *sec,
                         const char *label)
{
	struct ps_reference *grown = realloc(s->ref, (s->nref + 1) * sizeof *grown), *r;
	if (!grown)
		return -1;
	s->ref = grown;
	r = &s->ref[s->nref++];
	r->label = strdup(*label ? label : "reference");
	ps_conf_double(c, sec, "daylight_ratio", NAN, 0, 1e12, &r->daylight_ratio);
	ps_conf_double(c, sec, "electric_ratio", NAN, 0, 1e12, &r->electric_ratio);
	ps_conf_double(c, sec, "task_sensor_ratio", NAN, 0, 1e12, &r->task_sensor_ratio);
	ps_conf_double(c, sec, "electric_task_lux", NAN, 0, 1e12, &r->electric_task_lux);
	ps_conf_double(c, sec, "electric_sensor_lux", NAN, 0, 1e12, &r->electric_sensor_lux);
	return r->label ? 0 : -1;
}

static void read_dcview(struct ps_conf *c, struct ps_conf_section *sec, const char *key,
                        struct ps_view *v)
{
	struct ps_conf_kv *kv = ps_conf_kv(sec, key);
	struct ps_err e;
	char where[600];
	ps_view_default(v);
	ps_conf_required(c, sec, key);
	if (!kv)
		return;
	snprintf(where, sizeof where, "%s", key);
	if (ps_view_parse(v, kv->value, where, &e) != 0 ||
	    ps_view_check_fisheye(v, where, &e) != 0)
		ps_conf_error(c, kv->line, "%s", e.msg);
}

static void read_dc(struct ps_scene *s, struct ps_conf *c, struct ps_conf_section *sec)
{
	static const double ground[3] = { 0.2, 0.2, 0.2 };
	long mf;
	struct ps_dcspec *d = &s->dc;
	d->have = 1;
	d->line = sec->line;
	ps_conf_int(c, sec, "mf", 0, 0, 64, &mf);
	d->mf = (int)mf;
	ps_conf_required(c, sec, "sensor_pictures");
	d->sensor_pattern = ps_conf_path(c, sec, "sensor_pictures");
	read_dcview(c, sec, "sensor_view", &d->sensor_view);
	/* the task: its pictures, or a work-plane grid's matrix */
	d->task_matrix = ps_conf_path(c, sec, "task_matrix");
	if (d->task_matrix) {
		const char *pts = ps_conf_str(c, sec, "task_points", NULL);
		if (ps_conf_kv(sec, "task_pictures") || ps_conf_kv(sec, "task_view"))
			ps_conf_error(c, ps_conf_kv(sec, "task_matrix")->line,
			              "task_matrix: the task is a grid or pictures, not both (task_pictures, task_view)");
		if (pts) {
			const char *q = pts;
			while (*q) {
				char *end;
				long i = strtol(q, &end, 10);
				if (end == q || i < 1 || (*end && *end != ',')) {
					ps_conf_error(c, ps_conf_kv(sec, "task_points")->line,
					              "task_points: '%s' is not a list of rows from 1 (1,4,7)", pts);
					break;
				}
				q = *end ? end + 1 : end;
			}
			d->task_points = strdup(pts);
		}
	} else {
		ps_conf_required(c, sec, "task_pictures");
		d->task_pattern = ps_conf_path(c, sec, "task_pictures");
		read_dcview(c, sec, "task_view", &d->task_view);
	}
	d->weather = ps_conf_path(c, sec, "weather");
	ps_conf_bool(c, sec, "weather_illuminance", 0, &d->weather_illum);
	read_vec(c, sec, "ground_reflectance", ground, d->ground, NULL);
	for (int k = 0; k < 3; k++)
		if (d->ground[k] < 0 || d->ground[k] > 1)
			ps_conf_error(c, ps_conf_kv(sec, "ground_reflectance")->line,
			              "ground_reflectance: %g is not 0 to 1", d->ground[k]);
}

/* The scene from a loaded file c (freed here). */
static int scene_from_conf(struct ps_scene *s, struct ps_conf *cp, const char *path, struct ps_err *e)
{
	static const double down[3] = { 0, 0, -1 }, upward[3] = { 0, 0, 1 };
	struct ps_conf c = *cp;
	struct ps_conf_section *sec;
	const char *v;
	long res;
	s->path = strdup(path);
	sec = ps_conf_section(&c, "scene");
	s->name = dup_or_null(ps_conf_str(&c, sec, "name", "scene"));
	s->cache_dir = ps_conf_path(&c, sec, "cache");
	sec = ps_conf_section(&c, "sensor");
	if (!sec)
		ps_conf_error(&c, 0, "no [sensor] section");
	v = ps_conf_str(&c, sec, "sensitivity", "builtin:cosine");
	s->sensitivity = strncmp(v, "builtin:", 8) == 0 ? strdup(v) : ps_conf_path(&c, sec, "sensitivity");
	ps_conf_double(&c, sec, "rotation", 0, -1e6, 1e6, &s->rotation);
	{
		static const char *const readings[] = { "linear", "cell", NULL };
		ps_conf_enum(&c, sec, "reading", readings, PS_READ_LINEAR, &s->reading);
	}
	s->rgb[0] = PS_RGB_DEFAULT_R;
	s->rgb[1] = PS_RGB_DEFAULT_G;
	s->rgb[2] = PS_RGB_DEFAULT_B;
	{
		struct ps_conf_kv *kv = ps_conf_kv(sec, "rgb");
		if (kv && (sscanf(kv->value, "%lf %lf %lf", &s->rgb[0], &s->rgb[1], &s->rgb[2]) != 3 ||
		           !isfinite(s->rgb[0] + s->rgb[1] + s->rgb[2])))
			ps_conf_error(&c, kv->line, "rgb: '%s' is not three numbers", kv->value);
		s->filter = ps_conf_path(&c, sec, "filter");
		if (kv && s->filter)
			ps_conf_error(&c, kv->line, "give either rgb or filter, not both");
	}
	read_place(&c, sec, &s->sensor_at, down);
	ps_conf_int(&c, sec, "resolution", 256, 8, 8192, &res);
	s->resolution = (int)res;
	s->render_options = dup_or_null(ps_conf_str(&c, sec, "render_options", NULL));
	sec = ps_conf_section(&c, "task");
	read_place(&c, sec, &s->task_at, upward);
	if ((sec = ps_conf_section(&c, "daylight_coefficients")))
		read_dc(s, &c, sec);
	for (size_t i = 0; i < c.nsec; i++) {
		const char *label;
		if ((label = ps_conf_section_is(&c.sec[i], "condition"))) {
			c.sec[i].used = 1;
			if (add_condition(s, &c, &c.sec[i], label) != 0)
				goto oom;
		} else if ((label = ps_conf_section_is(&c.sec[i], "variant"))) {
			c.sec[i].used = 1;
			if (add_variant(s, &c, &c.sec[i], label) != 0)
				goto oom;
		} else if ((label = ps_conf_section_is(&c.sec[i], "reference"))) {
			c.sec[i].used = 1;
			if (add_reference(s, &c, &c.sec[i], label) != 0)
				goto oom;
		}
	}
	if (s->ncond == 0 && !s->dc.have)
		ps_conf_error(&c, 0, "no [condition NAME] sections (nor [daylight_coefficients])");
	for (size_t i = 0; i < s->ncond; i++)
		for (size_t j = 0; j < i; j++)
			if (strcmp(s->cond[i].label, s->cond[j].label) == 0)
				ps_conf_error(&c, s->cond[i].line, "condition '%s' appears twice", s->cond[i].label);
	for (size_t i = 0; i < s->nvar; i++) {
		size_t k = 0;
		while (k < s->ncond && strcmp(s->cond[k].label, s->var[i].of) != 0)
			k++;
		if (k == s->ncond && *s->var[i].of)
			ps_conf_error(&c, s->var[i].line, "[variant %s]: no condition '%s'", s->var[i].label,
			              s->var[i].of);
	}
	ps_conf_check_unused(&c);
	if (c.nerrors) {
		size_t used = 0;
		e->code = PS_EFORMAT;
		e->msg[0] = '\0';
		for (size_t i = 0; i < c.nerrors && used + 2 < sizeof e->msg; i++)
			used += (size_t)snprintf(e->msg + used, sizeof e->msg - used, "%s%s", i ? "\n" : "",
			                         c.errors[i]);
		ps_conf_free(&c);
		ps_scene_free(s);
		return -1;
	}
	ps_conf_free(&c);
	return 0;
oom:
	ps_conf_free(&c);
	ps_scene_free(s);
	return ps_err_set(e, PS_ENOMEM, "%s: out of memory", path);
}

int ps_scene_read(struct ps_scene *s, const char *path, struct ps_err *e)
{
	struct ps_conf c;
	memset(s, 0, sizeof *s);
	if (ps_conf_load(&c, path, e) != 0)
		return -1;
	return scene_from_conf(s, &c, path, e);
}

int ps_scene_parse(struct ps_scene *s, const char *text, const char *name, struct ps_err *e)
{
	struct ps_conf c;
	memset(s, 0, sizeof *s);
	if (ps_conf_load_string(&c, text, name, e) != 0)
		return -1;
	return scene_from_conf(s, &c, name, e);
}
