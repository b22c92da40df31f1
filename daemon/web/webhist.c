/* SPDX-License-Identifier: ISC */
#include "webhist.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json.h"

void psd_webhist_record(struct psd_webhist *h, const struct psd_engine *e)
{
	for (size_t i = 0; i < e->nzone && i < PSD_MAX_ZONES; i++) {
		const struct psd_zone *z = &e->zone[i];
		struct psd_webhist_zone *k = &h->zone[i];
		double t = z->last.t;
		if (strcmp(k->name, z->zc->name) != 0) {
			memset(k, 0, sizeof *k);
			snprintf(k->name, sizeof k->name, "%s", z->zc->name);
			k->last_t = -INFINITY;
		}
		if (!isfinite(t) || t < k->last_t + PSD_WEBHIST_HOURS * 3600.0 / PSD_WEBHIST_POINTS)
			continue;
		k->p[k->head].t = t;
		k->p[k->head].tod = psd_clock_tod(t);
		k->p[k->head].level = z->last.level;
		k->p[k->head].est = z->last.est_task_lux;
		k->p[k->head].meas = z->last.task_lux;
		k->head = (k->head + 1) % PSD_WEBHIST_POINTS;
		if (k->n < PSD_WEBHIST_POINTS)
			k->n++;
		k->last_t = t;
	}
	for (size_t i = e->nzone; i < PSD_MAX_ZONES; i++)
		h->zone[i].name[0] = 0;
}

static json_object *num_or_null(double v)
{
	return isfinite(v) ? json_object_new_double(v) : NULL;
}

char *psd_webhist_json(const struct psd_webhist *h, const char *zone)
{
	json_object *o, *t, *tod, *lv, *est, *meas;
	char *text;
	int i = -1;
	for (int k = 0; k < PSD_MAX_ZONES && i < 0; k++)
		if (h->zone[k].name[0] && strcmp(h->zone[k].name, zone) == 0)
			i = k;
	if (i < 0)
		return NULL;
	o = json_object_new_object();
	t = json_object_new_array();
	tod = json_object_new_array();
	lv = json_object_new_array();
	est = json_object_new_array();
	meas = json_object_new_array();
	for (size_t k = 0; k < h->zone[i].n; k++) {
		size_t j = (h->zone[i].head + PSD_WEBHIST_POINTS - h->zone[i].n + k) % PSD_WEBHIST_POINTS;
		if (h->zone[i].p[j].t < h->zone[i].last_t - PSD_WEBHIST_HOURS * 3600.0)
			continue;
		json_object_array_add(t, json_object_new_double(h->zone[i].p[j].t));
		json_object_array_add(tod, json_object_new_double(h->zone[i].p[j].tod));
		json_object_array_add(lv, num_or_null(h->zone[i].p[j].level));
		json_object_array_add(est, num_or_null(h->zone[i].p[j].est));
		json_object_array_add(meas, num_or_null(h->zone[i].p[j].meas));
	}
	json_object_object_add(o, "ok", json_object_new_boolean(1));
	psd_json_str(o, "zone", h->zone[i].name);
	json_object_object_add(o, "t", t);
	json_object_object_add(o, "tod_s", tod);
	json_object_object_add(o, "level", lv);
	json_object_object_add(o, "est_task_lux", est);
	json_object_object_add(o, "task_lux", meas);
	text = strdup(psd_json_text(o, 10));   /* a second in a run of years */
	json_object_put(o);
	return text;
}
