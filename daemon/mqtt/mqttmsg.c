/* SPDX-License-Identifier: ISC */
#include "mqttmsg.h"

#include <json-c/json.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "engine.h"
#include "json.h"
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
                        const struct psd_sample *s, const struct psd_zone *z)
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

struct entity {
	const char *component, *key, *name, *unit, *device_class, *template;
	int task_only, number;
};

static const struct entity entities[] = {
	{ "sensor", "est_task_lux", "estimated task illuminance", "lx", "illuminance",
	  "{{ value_json.est_task_lux }}", 0, 0 },
	{ "sensor", "task_lux", "measured task illuminance", "lx", "illuminance", "{{ value_json.task_lux }}", 1, 0 },
	{ "sensor", "sensor_v", "photosensor", "V", "voltage", "{{ value_json.sensor_v }}", 0, 0 },
	{ "sensor", "level", "light level", "%", NULL, "{{ (value_json.level * 100) | round(1) }}", 0, 0 },
	{ "binary_sensor", "fault", "fault", NULL, "problem", "{{ 'ON' if value_json.fault else 'OFF' }}", 0, 0 },
	{ "number", "override", "override level", NULL, NULL, "{{ value_json.level }}", 0, 1 },
};

int psd_mqttmsg_discovery(int k, const char *prefix, const char *site, const char *zone, int has_task, int commands,
                       char *topic, size_t topiclen, char *payload, size_t paylen)
{
	const struct entity *en;
	json_object *o, *dev, *ids;
	char node[128], uid[192], base[160], text[256];
	if (k < 0 || (size_t)k >= sizeof entities / sizeof entities[0])
		return -1;
	en = &entities[k];
	node_id(node, sizeof node, site, zone);
	snprintf(topic, topiclen, "%s/%s/%s/%s/config", prefix, en->component, node, en->key);
	if ((en->task_only && !has_task) || (en->number && !commands)) {
		payload[0] = 0;     /* not this zone's: an empty config removes it */
		return 0;
	}
	snprintf(base, sizeof base, "psensd/%s/%s", site, zone);
	snprintf(uid, sizeof uid, "%s_%s", node, en->key);
	o = json_object_new_object();
	snprintf(text, sizeof text, "%s %s", zone, en->name);
	psd_json_str(o, "name", text);
	psd_json_str(o, "unique_id", uid);
	psd_json_str(o, "object_id", uid);
	snprintf(text, sizeof text, "%s/state", base);
	psd_json_str(o, "state_topic", text);
	psd_json_str(o, "value_template", en->template);
	snprintf(text, sizeof text, "psensd/%s/status", site);
	psd_json_str(o, "availability_topic", text);
	psd_json_str(o, "payload_available", "online");
	psd_json_str(o, "payload_not_available", "offline");
	if (en->unit)
		psd_json_str(o, "unit_of_measurement", en->unit);
	if (en->device_class)
		psd_json_str(o, "device_class", en->device_class);
	if (strcmp(en->component, "sensor") == 0)
		psd_json_str(o, "state_class", "measurement");
	if (en->number) {
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
