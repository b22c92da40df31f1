/* SPDX-License-Identifier: ISC */
#include "results.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "conf.h"
#include "replace.h"
#include "scene.h"
#include "sum.h"

void ps_results_free(struct ps_results *r)
{
	if (!r)
		return;
	for (size_t i = 0; i < r->ncond; i++) {
		free(r->cond[i].label);
		free(r->cond[i].date);
	}
	free(r->cond);
	free(r->weather);
	ps_year_free(&r->year);
	free(r->scene);
	free(r->scene_hash);
	free(r->sensitivity);
	free(r->reading);
	memset(r, 0, sizeof *r);
}

void ps_results_summarise(struct ps_results *r)
{
	struct ps_sum s, s2;
	int n = 0;
	r->daylight_ratio_mean = r->daylight_ratio_min = r->daylight_ratio_max = NAN;
	r->daylight_ratio_sd = r->electric_ratio = r->task_sensor_ratio = NAN;
	r->electric_sensor_response = r->electric_task_lux = NAN;
	ps_sum_init(&s);
	ps_sum_init(&s2);
	for (size_t i = 0; i < r->ncond; i++) {
		const struct ps_result_cond *c = &r->cond[i];
		if (!c->computed)
			continue;
		if (c->kind == PS_COND_DAYLIGHT) {
			ps_sum_add(&s, c->ratio);
			if (n == 0 || c->ratio < r->daylight_ratio_min)
				r->daylight_ratio_min = c->ratio;
			if (n == 0 || c->ratio > r->daylight_ratio_max)
				r->daylight_ratio_max = c->ratio;
			n++;
		} else if (isnan(r->electric_ratio)) {
			r->electric_ratio = c->ratio;
			r->electric_sensor_response = c->sensor_response;
			r->electric_task_lux = c->task_lux;
		}
	}
	if (n > 0) {
		r->daylight_ratio_mean = ps_sum_get(&s) / n;
		for (size_t i = 0; i < r->ncond; i++)
			if (r->cond[i].computed && r->cond[i].kind == PS_COND_DAYLIGHT) {
				double d = r->cond[i].ratio - r->daylight_ratio_mean;
				ps_sum_add(&s2, d * d);
			}
		r->daylight_ratio_sd = n > 1 ? sqrt(ps_sum_get(&s2) / (n - 1)) : 0.0;
	}
	if (n > 0 && !isnan(r->electric_ratio))
		r->task_sensor_ratio = r->electric_ratio / r->daylight_ratio_mean;
}

static void put_num(FILE *fp, const char *key, double v)
{
	if (isnan(v))
		fprintf(fp, "%s = nan\n", key);
	else
		fprintf(fp, "%s = %.17g\n", key, v);
}

static void write_year(FILE *fp, const struct ps_results *r)
{
	const struct ps_year *y = &r->year;
	fprintf(fp, "\n[year]\nweather = %s\nmf = %d\npatches = %d\npatches_used = %d\n"
	        "steps = %zu\ndark_steps = %zu\nhours = %zu\n", r->weather ? r->weather : "",
	        r->year_mf, y->patches, y->used, y->steps, y->dark, y->n);
	put_num(fp, "mean_ratio", y->mean_ratio);
	if (y->leap)
		fputs("leap = yes\n", fp);
	if (y->have_site)
		fprintf(fp, "latitude = %.17g\nlongitude = %.17g\ntimezone = %.17g\n", y->site.lat,
		        y->site.lon, y->site.tz);
	fprintf(fp, "\n; month day hour(standard time) sensor_response task_lux sky_class epsilon "
	            "horizontal_lux [sensor_response task_lux with the sun in its nearest patch]\n"
	            "[year_hours]\n");
	for (size_t i = 0; i < y->n; i++) {
		const struct ps_year_hour *k = &y->h[i];
		fprintf(fp, "h%zu = %d %d %.17g %.17g %.17g %d %.17g", i + 1, k->month, k->day, k->hour,
		        k->sensor, k->task_lux, k->sky_class, k->epsilon);
		if (!isnan(k->horiz_lux))
			fprintf(fp, " %.17g", k->horiz_lux);
		if (y->have_alt && !isnan(k->horiz_lux))
			fprintf(fp, " %.17g %.17g", k->sensor_alt, k->task_alt);
		fputc('\n', fp);
	}
	fprintf(fp, "\n; task lux per unit of sensor response by month and hour (0 to 23,\n"
	            "; standard time) and sky class; derived from [year_hours], recomputed by readers\n"
	            "[ratio_table]\n");
	for (int c = 0; c < PS_SKY_NCLASS; c++)
		for (int m = 0; m < 12; m++) {
			fprintf(fp, "%s_%02d =", ps_year_class_name(c), m + 1);
			for (int h = 0; h < 24; h++)
				if (isnan(y->ratio[m][h][c]))
					fprintf(fp, " nan");
				else
					fprintf(fp, " %.6g", y->ratio[m][h][c]);
			fputc('\n', fp);
		}
}

int ps_results_write(const struct ps_results *r, const char *path, struct ps_err *e)
{
	struct ps_replace_mem m;
	FILE *fp;
	if (!(fp = ps_replace_mem_open(&m, e)))
		return -1;
	fprintf(fp, "; psscene results: the simulated task-sensor ratios psensd runs on.\n"
	            "; Written by psscene; see psscene(5).\n[psresults]\nversion = %d\n",
	        PS_RESULTS_VERSION);
	fprintf(fp, "scene = %s\nscene_hash = %s\nsensitivity = %s\n", r->scene ? r->scene : "",
	        r->scene_hash ? r->scene_hash : "", r->sensitivity ? r->sensitivity : "");
	put_num(fp, "rotation", r->rotation);
	fprintf(fp, "reading = %s\nrgb = %.17g %.17g %.17g\n", r->reading ? r->reading : "linear",
	        r->rgb[0], r->rgb[1], r->rgb[2]);
	for (size_t i = 0; i < r->ncond; i++) {
		const struct ps_result_cond *c = &r->cond[i];
		if (c->computed && !(isfinite(c->sensor_response) && isfinite(c->task_irradiance) &&
		                     isfinite(c->task_lux) && isfinite(c->ratio))) {
			ps_replace_mem_abort(&m);
			return ps_err_set(e, PS_ERANGE, "%s: condition %s: not written: its %s is not finite",
			                  path, c->label,
			                  !isfinite(c->sensor_response) ? "sensor response"
			                  : !isfinite(c->task_irradiance) ? "task irradiance"
			                  : !isfinite(c->task_lux) ? "task illuminance" : "task-sensor ratio");
		}
		fprintf(fp, "\n[condition %s]\nkind = %s\n", c->label,
		        c->kind == PS_COND_ELECTRIC ? "electric" : "daylight");
		if (c->date && *c->date)
			fprintf(fp, "date = %s\n", c->date);
		put_num(fp, "tod_s", c->tod_s);
		fprintf(fp, "computed = %s\n", c->computed ? "yes" : "no");
		put_num(fp, "sensor_response", c->sensor_response);
		put_num(fp, "task_irradiance", c->task_irradiance);
		put_num(fp, "task_lux", c->task_lux);
		put_num(fp, "ratio", c->ratio);
		put_num(fp, "brightest_share", c->brightest_share);
	}
	fprintf(fp, "\n[summary]\n");
	put_num(fp, "daylight_ratio_mean", r->daylight_ratio_mean);
	put_num(fp, "daylight_ratio_min", r->daylight_ratio_min);
	put_num(fp, "daylight_ratio_max", r->daylight_ratio_max);
	put_num(fp, "daylight_ratio_sd", r->daylight_ratio_sd);
	put_num(fp, "electric_ratio", r->electric_ratio);
	put_num(fp, "electric_sensor_response", r->electric_sensor_response);
	put_num(fp, "electric_task_lux", r->electric_task_lux);
	put_num(fp, "task_sensor_ratio", r->task_sensor_ratio);
	if (r->have_year)
		write_year(fp, r);
	/* the old file stays whole until the new one is complete */
	return ps_replace_mem_commit(&m, path, 0644, e);
}

static double num(struct ps_conf *c, struct ps_conf_section *s, const char *key)
{
	struct ps_conf_kv *kv = ps_conf_kv(s, key);
	double v;
	if (!kv) {
		ps_conf_error(c, s ? s->line : 0, "[%s] needs '%s'", s ? s->name : "", key);
		return NAN;
	}
	if (strcmp(kv->value, "nan") == 0)
		return NAN;
	if (ps_conf_parse_double(kv->value, &v) != 0) {
		ps_conf_error(c, kv->line, "%s: '%s' is not a number", key, kv->value);
		return NAN;
	}
	if (!isfinite(v)) {
		ps_conf_error(c, kv->line, "%s: '%s' is not a finite number", key, kv->value);
		return NAN;
	}
	return v;
}

/* A number a computed condition must have: finite ("nan" only marks a
 * condition left out). */
static double finite_num(struct ps_conf *c, struct ps_conf_section *s, const char *key)
{
	double v = num(c, s, key);
	struct ps_conf_kv *kv = ps_conf_kv(s, key);
	if (isnan(v) && kv && strcmp(kv->value, "nan") == 0)
		ps_conf_error(c, kv->line, "%s: a computed condition's %s must be a finite number, not "
		              "'nan': run psscene again", key, key);
	return v;
}

static void read_year(struct ps_conf *c, struct ps_results *r)
{
	struct ps_conf_section *s = ps_conf_section(c, "year"), *hs, *t;
	struct ps_year *y = &r->year;
	long v;
	size_t alt = 0;
	r->have_year = 1;
	r->weather = strdup(ps_conf_str(c, s, "weather", ""));
	ps_conf_int(c, s, "mf", 1, 1, 64, &v);
	r->year_mf = (int)v;
	ps_conf_int(c, s, "patches", 0, 0, 1000000, &v);
	y->patches = (int)v;
	ps_conf_int(c, s, "patches_used", 0, 0, 1000000, &v);
	y->used = (int)v;
	ps_conf_int(c, s, "steps", 0, 0, PS_WX_MAX_STEPS, &v);
	y->steps = (size_t)v;
	ps_conf_int(c, s, "dark_steps", 0, 0, PS_WX_MAX_STEPS, &v);
	y->dark = (size_t)v;
	ps_conf_int(c, s, "hours", 0, 0, PS_WX_MAX_STEPS, &v);
	(void)num(c, s, "mean_ratio");   /* recomputed */
	ps_conf_bool(c, s, "leap", 0, &y->leap);
	/* the site: optional (files before it have none) */
	if (ps_conf_kv(s, "latitude") || ps_conf_kv(s, "longitude") || ps_conf_kv(s, "timezone")) {
		ps_conf_double(c, s, "latitude", 0, -90, 90, &y->site.lat);
		ps_conf_double(c, s, "longitude", 0, -180, 180, &y->site.lon);
		ps_conf_double(c, s, "timezone", 0, -14, 14, &y->site.tz);
		y->have_site = ps_conf_required(c, s, "latitude") == 0 && ps_conf_required(c, s, "longitude") == 0 &&
		               ps_conf_required(c, s, "timezone") == 0;
	}
	hs = ps_conf_section(c, "year_hours");
	if ((size_t)v && (!hs || hs->nkv != (size_t)v)) {
		ps_conf_error(c, s->line, "[year] says hours = %ld, [year_hours] has %zu", v,
		              hs ? hs->nkv : (size_t)0);
		return;
	}
	y->h = v ? calloc((size_t)v, sizeof *y->h) : NULL;
	if (v && !y->h) {
		ps_conf_error(c, s->line, "out of memory for %ld hours", v);
		return;
	}
	for (size_t i = 0; hs && i < hs->nkv && i < (size_t)v; i++) {
		struct ps_conf_kv *kv = &hs->kv[i];
		struct ps_year_hour *k = &y->h[i];
		char want[32];
		int n = 0, n7 = 0;
		kv->used = 1;
		snprintf(want, sizeof want, "h%zu", i + 1);
		if (strcmp(kv->key, want) != 0) {
			ps_conf_error(c, kv->line, "'%s' where %s was due", kv->key, want);
			return;
		}
		k->horiz_lux = k->sensor_alt = k->task_alt = NAN;
		if (sscanf(kv->value, "%d %d %lf %lf %lf %d %lf %n", &k->month, &k->day, &k->hour,
		           &k->sensor, &k->task_lux, &k->sky_class, &k->epsilon, &n7) == 7) {
			/* then horizontal lux, and the sensor and task with the sun
			 * in its nearest patch (both or neither), all optional */
			double *opt[3] = { &k->horiz_lux, &k->sensor_alt, &k->task_alt };
			int nf = 0;
			n = n7;
			while (kv->value[n] && nf < 3) {
				int m = 0;
				if (sscanf(kv->value + n, "%lf %n", opt[nf], &m) != 1 || !(*opt[nf] >= 0 && *opt[nf] < 1e30)) {
					n = -1;   /* a field that is no illuminance or response */
					break;
				}
				n += m;
				nf++;
			}
			if (nf == 2)
				n = -1;   /* a sensor with the sun moved and no task */
			if (nf == 3)
				alt++;
		}
		if (n < 0 || sscanf(kv->value, "%d %d %lf %lf %lf %d %lf", &k->month, &k->day, &k->hour,
		                    &k->sensor, &k->task_lux, &k->sky_class, &k->epsilon) != 7 ||
		    kv->value[n] != '\0' || k->month < 1 || k->month > 12 || k->day < 1 || k->day > 31 ||
		    !(k->hour >= 0 && k->hour <= 24) || !(k->sensor >= 0 && k->sensor < 1e30) ||
		    !(k->task_lux >= 0 && k->task_lux < 1e30) || k->sky_class < 0 ||
		    k->sky_class >= PS_SKY_NCLASS || !(k->epsilon >= 0 && k->epsilon < 1e6)) {
			ps_conf_error(c, kv->line, "%s: '%s' is not month day hour sensor task_lux "
			              "class epsilon [horizontal_lux [sensor_alt task_alt]]", kv->key, kv->value);
			return;
		}
	}
	y->n = (size_t)v;
	y->have_alt = y->n > 0 && alt == y->n;
	if ((t = ps_conf_section(c, "ratio_table")))
		for (size_t j = 0; j < t->nkv; j++)
			t->kv[j].used = 1;   /* derived: recomputed, not trusted */
	ps_year_tabulate(y);
}

/* The results from a loaded file c (freed here). */
static int results_from_conf(struct ps_results *r, struct ps_conf *cp, const char *path, struct ps_err *e)
{
	struct ps_conf c = *cp;
	struct ps_conf_section *s;
	long version;
	s = ps_conf_section(&c, "psresults");
	if (!s) {
		ps_conf_free(&c);
		return ps_err_set(e, PS_EFORMAT, "%s: not a psscene results file (no [psresults])", path);
	}
	ps_conf_int(&c, s, "version", 0, 0, 1000000, &version);
	if (version < 1 || version > PS_RESULTS_VERSION) {
		int line = ps_conf_kv(s, "version") ? ps_conf_kv(s, "version")->line : s->line;
		ps_conf_free(&c);
		return ps_err_set(e, PS_EUNSUPPORTED, "%s:%d: results version %ld, this psensd reads 1 to %d: "
		                  "run psscene again", path, line, version, PS_RESULTS_VERSION);
	}
	r->version = (int)version;
	r->scene = strdup(ps_conf_str(&c, s, "scene", ""));
	r->scene_hash = strdup(ps_conf_str(&c, s, "scene_hash", ""));
	r->sensitivity = strdup(ps_conf_str(&c, s, "sensitivity", ""));
	r->reading = strdup(ps_conf_str(&c, s, "reading", "linear"));
	r->rotation = num(&c, s, "rotation");
	if (sscanf(ps_conf_str(&c, s, "rgb", ""), "%lf %lf %lf", &r->rgb[0], &r->rgb[1], &r->rgb[2]) != 3)
		ps_conf_error(&c, s->line, "[psresults] needs rgb = R G B");
	for (size_t i = 0; i < c.nsec; i++) {
		const char *label = ps_conf_section_is(&c.sec[i], "condition");
		struct ps_result_cond *grown, *k;
		static const char *const kinds[] = { "daylight", "electric", NULL };
		int computed;
		if (!label)
			continue;
		c.sec[i].used = 1;
		grown = realloc(r->cond, (r->ncond + 1) * sizeof *grown);
		if (!grown)
			break;
		r->cond = grown;
		k = &r->cond[r->ncond++];
		memset(k, 0, sizeof *k);
		k->label = strdup(label);
		ps_conf_enum(&c, &c.sec[i], "kind", kinds, 0, &k->kind);
		k->date = strdup(ps_conf_str(&c, &c.sec[i], "date", ""));
		k->tod_s = num(&c, &c.sec[i], "tod_s");
		ps_conf_bool(&c, &c.sec[i], "computed", 1, &computed);
		k->computed = computed;
		{
			double (*get)(struct ps_conf *, struct ps_conf_section *, const char *) =
				computed ? finite_num : num;
			k->sensor_response = get(&c, &c.sec[i], "sensor_response");
			k->task_irradiance = get(&c, &c.sec[i], "task_irradiance");
			k->task_lux = get(&c, &c.sec[i], "task_lux");
			k->ratio = get(&c, &c.sec[i], "ratio");
		}
		k->brightest_share = num(&c, &c.sec[i], "brightest_share");
	}
	if (ps_conf_section(&c, "summary")) {
		/* derived from the conditions: recomputed, not trusted */
		struct ps_conf_section *sum = ps_conf_section(&c, "summary");
		for (size_t j = 0; j < sum->nkv; j++)
			sum->kv[j].used = 1;
	}
	if (version >= 2 && ps_conf_section(&c, "year"))
		read_year(&c, r);
	ps_conf_check_unused(&c);
	if (c.nerrors) {
		ps_err_set(e, PS_EFORMAT, "%s%s", c.errors[0], c.nerrors > 1 ? " (and more)" : "");
		ps_conf_free(&c);
		ps_results_free(r);
		return -1;
	}
	ps_conf_free(&c);
	ps_results_summarise(r);
	return 0;
}

int ps_results_read(struct ps_results *r, const char *path, struct ps_err *e)
{
	struct ps_conf c;
	memset(r, 0, sizeof *r);
	if (ps_conf_load(&c, path, e) != 0)
		return -1;
	return results_from_conf(r, &c, path, e);
}

int ps_results_parse(struct ps_results *r, const char *text, const char *name, struct ps_err *e)
{
	struct ps_conf c;
	memset(r, 0, sizeof *r);
	if (ps_conf_load_string(&c, text, name, e) != 0)
		return -1;
	return results_from_conf(r, &c, name, e);
}
