/* SPDX-License-Identifier: ISC */
#include "mqttmsg.h"

#include <json-c/json.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "engine.h"
#include "json.h"
#include "points.h"
#include "time.h"

static int emit(json_object *o, char *buf, size_t n)
{
	const char *text;
	size_t len;
	text = psd_json_text(o, 10);
	len = strlen(text);
	if (len >= n) {
		json_object_put(o);
		return -1;
	}
	memcpy(buf, text, len + 1);
	json_object_put(o);
	return (int)len;
}

void psd_mqttmsg_iso8601(double t, char *buf, size_t n)
{
	if (psd_time_utc_text(t, PSD_TIME_ISO_MS, buf, n) != 0)
		snprintf(buf, n, "unknown");
}

int psd_mqttmsg_state_json(char *buf, size_t n, const char *site, long long id, double utc,
                        const struct psd_sample *s, const struct psd_zone *z, json_object *points)
{
	json_object *o = json_object_new_object();
	char iso[40];
	psd_mqttmsg_iso8601(utc, iso, sizeof iso);
	json_object_object_add(o, "id", json_object_new_int64(id));
	psd_json_str(o, "utc", iso);
	psd_json_str(o, "site", site);
	psd_json_str(o, "zone", s->zone);
	psd_json_num(o, "t", s->t);
	psd_json_num(o, "sensor_v", s->sensor_v);
	psd_json_num(o, "est_task_lux", s->est_task_lux);
	psd_json_num(o, "task_lux", s->task_lux);
	psd_json_num(o, "daylight_lux", s->daylight_lux);
	psd_json_num(o, "level", s->output);
	/* relative power: the commanded output is the fraction of full power */
	psd_json_num(o, "power_frac", s->output);
	psd_json_str(o, "fault", s->fault);
	if (z) {
		json_object *cal = json_object_new_object();
		psd_json_str(cal, "state", psd_calsession_state_names[z->cal.state]);
		psd_json_str(cal, "kind", z->cal.id ? psd_calsession_kind_names[z->cal.kind] : NULL);
		json_object_object_add(cal, "session", z->cal.id ? json_object_new_int64(z->cal.id) : NULL);
		json_object_object_add(cal, "night", z->cal_night_id ? json_object_new_int64(z->cal_night_id) : NULL);
		json_object_object_add(cal, "day", z->cal_day_id ? json_object_new_int64(z->cal_day_id) : NULL);
		json_object_object_add(o, "calibration", cal);
		if (z->zc->task >= 0) {
			json_object *dr = json_object_new_object();
			json_object_object_add(dr, "flagged", json_object_new_boolean(z->drift.flagged));
			psd_json_num(dr, "pct", 100 * (exp(z->drift.last_ln) - 1));
			json_object_object_add(o, "drift", dr);
		} else {
			json_object_object_add(o, "drift", NULL);
		}
		psd_json_num(o, "target_lux", z->ctl.target_lux);
	}
	if (points)
		json_object_object_add(o, "points", points);
	return emit(o, buf, n);
}

/* HA node ids take [a-zA-Z0-9_-]: a '.' of a site or zone name becomes '_'. */
static void node_id(char *out, size_t n, const char *a, const char *b)
{
	snprintf(out, n, "psensd_%s_%s", a, b);
	for (char *c = out; *c; c++)
		if (*c == '.')
			*c = '_';
}

/* The entities whose key and template predate the point model: their
 * unique ids stay; name and unit come from the point of the same key. */
struct entity {
	const char *component, *key, *template;
};

static const struct entity fixed[] = {
	{ "sensor", "est_task_lux", "{{ value_json.est_task_lux }}" },
	{ "sensor", "task_lux", "{{ value_json.task_lux }}" },
	{ "sensor", "sensor_v", "{{ value_json.sensor_v }}" },
	{ "sensor", "level", "{{ (value_json.level * 100) | round(1) }}" },
	{ "binary_sensor", "fault", "{{ 'ON' if value_json.fault else 'OFF' }}" },
	{ "number", "override", "{{ value_json.level }}" },
};
enum { NFIXED = sizeof fixed / sizeof fixed[0] };

static int is_fixed(const char *key)
{
	for (size_t i = 0; i < NFIXED; i++)
		if (strcmp(fixed[i].key, key) == 0)
			return 1;
	return 0;
}

/* The point of the k-th entity past the fixed ones, -1 past the last. */
static int point_of(int k)
{
	for (size_t i = 0; i < psd_points_count(); i++)
		if (!is_fixed(psd_points_def(i)->key) && k-- == 0)
			return (int)i;
	return -1;
}

int psd_mqttmsg_discovery(int k, const char *prefix, const char *site, const char *zone,
                       int (*has)(void *user, size_t i), void *user, int commands, char *topic, size_t topiclen,
                       char *payload, size_t paylen, int *point)
{
	const struct psd_points_def *d = NULL;
	const char *component, *key;
	json_object *o, *dev, *ids;
	char node[128], uid[192], base[160], text[256];
	int pt = -1, number = 0;
	if (k < 0)
		return -1;
	if (k < NFIXED) {
		component = fixed[k].component, key = fixed[k].key;
		number = strcmp(key, "override") == 0;
		pt = psd_points_find(key);
	} else if ((pt = point_of(k - NFIXED)) >= 0) {
		d = psd_points_def((size_t)pt);
		key = d->key;
		component = d->kind == PSD_POINTS_BINARY ? "binary_sensor" : "sensor";
	} else {
		return -1;
	}
	if (pt >= 0)
		d = psd_points_def((size_t)pt);
	*point = pt;
	node_id(node, sizeof node, site, zone);
	snprintf(topic, topiclen, "%s/%s/%s/%s/config", prefix, component, node, key);
	if ((pt >= 0 && !has(user, (size_t)pt)) || (number && !commands)) {
		payload[0] = 0;     /* not this zone's: an empty config removes it */
		return 0;
	}
	snprintf(base, sizeof base, "psensd/%s/%s", site, zone);
	snprintf(uid, sizeof uid, "%s_%s", node, key);
	o = json_object_new_object();
	snprintf(text, sizeof text, "%s %s", zone, d ? d->name : "override level");
	psd_json_str(o, "name", text);
	psd_json_str(o, "unique_id", uid);
	psd_json_str(o, "object_id", uid);
	snprintf(text, sizeof text, "%s/state", base);
	psd_json_str(o, "state_topic", text);
	if (k < NFIXED)
		psd_json_str(o, "value_template", fixed[k].template);
	else if (d->kind == PSD_POINTS_BINARY)
		snprintf(text, sizeof text,
		         "{%% if value_json.points is defined %%}{{ 'ON' if value_json.points.%s else 'OFF' }}{%% endif %%}",
		         key);
	else
		snprintf(text, sizeof text, "{%% if value_json.points is defined %%}{{ value_json.points.%s }}{%% endif %%}",
		         key);
	if (k >= NFIXED)
		psd_json_str(o, "value_template", text);
	snprintf(text, sizeof text, "psensd/%s/status", site);
	psd_json_str(o, "availability_topic", text);
	psd_json_str(o, "payload_available", "online");
	psd_json_str(o, "payload_not_available", "offline");
	if (d && d->unit && !number)
		psd_json_str(o, "unit_of_measurement", d->unit);
	if (d && d->ha_class && !number)
		psd_json_str(o, "device_class", d->ha_class);
	if (d && d->kind == PSD_POINTS_MULTISTATE) {
		json_object *opt = json_object_new_array();
		for (size_t i = 0; d->states[i]; i++)
			json_object_array_add(opt, json_object_new_string(d->states[i]));
		json_object_object_add(o, "options", opt);
	} else if (strcmp(component, "sensor") == 0) {
		psd_json_str(o, "state_class",
		             !strcmp(key, "output_h") || !strcmp(key, "energy_kwh") ? "total_increasing" : "measurement");
	}
	if (number) {
		snprintf(text, sizeof text, "%s/set/override", base);
		psd_json_str(o, "command_topic", text);
		psd_json_num(o, "min", 0);
		psd_json_num(o, "max", 1);
		psd_json_num(o, "step", 0.01);
		psd_json_str(o, "mode", "slider");
		json_object_object_add(o, "qos", json_object_new_int(1));
	}
	dev = json_object_new_object();
	ids = json_object_new_array();
	json_object_array_add(ids, json_object_new_string(node));
	json_object_object_add(dev, "identifiers", ids);
	snprintf(text, sizeof text, "psensd %s %s", site, zone);
	psd_json_str(dev, "name", text);
	psd_json_str(dev, "manufacturer", "psensd");
	psd_json_str(dev, "model", "daylight-harvesting zone");
	json_object_object_add(o, "device", dev);
	return emit(o, payload, paylen) < 0 ? -1 : 0;
}
