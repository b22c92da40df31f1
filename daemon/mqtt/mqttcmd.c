/* SPDX-License-Identifier: ISC */
#include "mqttcmd.h"

#include <json-c/json.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cmdtab.h"
#include "errbuf.h"
#include "mqttconf.h"

/* A payload's value: absent, a number, a word, or an object of fields. */
struct payload {
	json_object *root;        /* NULL: empty payload */
	const char *word;         /* a bare word or a JSON string */
	int has_num;
	double num;
	char wordbuf[17];
};

static int is_word(const char *s, size_t n)
{
	if (n == 0 || n > 16)
		return 0;
	for (size_t i = 0; i < n; i++)
		if (s[i] < 'a' || s[i] > 'z')
			return 0;
	return 1;
}

static int number_of(json_object *v, double *out)
{
	enum json_type t = json_object_get_type(v);
	if (t != json_type_double && t != json_type_int)
		return -1;
	*out = json_object_get_double(v);
	return isfinite(*out) ? 0 : -1;
}

/* The object's field key as a number: 1 found, 0 absent, -1 wrong type. */
static int field_num(json_object *o, const char *key, double *out, char *err, size_t errlen)
{
	json_object *v;
	if (!o || !json_object_is_type(o, json_type_object) || !json_object_object_get_ex(o, key, &v))
		return 0;
	if (number_of(v, out) != 0)
		return psd_errbuf(err, errlen, "\"%s\" is not a finite number", key);
	return 1;
}

static int field_word(json_object *o, const char *key, const char **out, char *err, size_t errlen)
{
	json_object *v;
	if (!o || !json_object_is_type(o, json_type_object) || !json_object_object_get_ex(o, key, &v))
		return 0;
	if (!json_object_is_type(v, json_type_string) ||
	    !is_word(json_object_get_string(v), (size_t)json_object_get_string_len(v)))
		return psd_errbuf(err, errlen, "\"%s\" is not a word", key);
	*out = json_object_get_string(v);
	return 1;
}

/* Every field of an object must be one the verb takes. */
static int only_fields(json_object *o, const char *const *allowed, char *err, size_t errlen)
{
	if (!o || !json_object_is_type(o, json_type_object))
		return 0;
	json_object_object_foreach(o, key, val) {
		int ok = strcmp(key, "id") == 0 || strcmp(key, "site") == 0;
		(void)val;
		for (size_t i = 0; allowed[i] && !ok; i++)
			ok = strcmp(key, allowed[i]) == 0;
		if (!ok) {
			char shown[40];
			snprintf(shown, sizeof shown, "%s", key);
			return psd_errbuf(err, errlen, "unknown field \"%s\"", shown);
		}
	}
	return 0;
}

static int parse(const void *payload, size_t len, struct payload *p, char *err, size_t errlen)
{
	const char *s = payload;
	char text[PSD_MQTT_MAX_PAYLOAD + 1];
	json_tokener *tok;
	memset(p, 0, sizeof *p);
	if (len > PSD_MQTT_MAX_PAYLOAD)
		return psd_errbuf(err, errlen, "payload of %zu bytes: at most %d", len, PSD_MQTT_MAX_PAYLOAD);
	if (len == 0)
		return 0;
	if (memchr(s, 0, len))
		return psd_errbuf(err, errlen, "payload has a NUL byte");
	if (is_word(s, len)) {       /* a bare word: night, accept, ... */
		memcpy(p->wordbuf, s, len);
		p->wordbuf[len] = 0;
		p->word = p->wordbuf;
		return 0;
	}
	if (!(tok = json_tokener_new_ex(8)))
		return psd_errbuf(err, errlen, "out of memory");
	/* with its terminating NUL, so that a bare number ends where the text does */
	memcpy(text, s, len);
	text[len] = 0;
	p->root = json_tokener_parse_ex(tok, text, (int)len + 1);
	if (!p->root || json_tokener_get_error(tok) != json_tokener_success ||
	    json_tokener_get_parse_end(tok) != len) {
		json_object_put(p->root);
		p->root = NULL;
		json_tokener_free(tok);
		return psd_errbuf(err, errlen, "payload is not JSON (a number, a \"word\" or an object)");
	}
	json_tokener_free(tok);
	switch (json_object_get_type(p->root)) {
	case json_type_object:
		break;
	case json_type_string:
		if (!is_word(json_object_get_string(p->root), (size_t)json_object_get_string_len(p->root)))
			return psd_errbuf(err, errlen, "payload: not a known word");
		p->word = json_object_get_string(p->root);
		break;
	case json_type_int:
	case json_type_double:
		if (number_of(p->root, &p->num) != 0)
			return psd_errbuf(err, errlen, "payload: not a finite number");
		p->has_num = 1;
		break;
	default:
		return psd_errbuf(err, errlen, "payload: a number, a \"word\" or an object, not %s",
		                json_type_to_name(json_object_get_type(p->root)));
	}
	return 0;
}

/* "id" (a string of up to 64 printable characters or an integer) and "site". */
static int common(const struct payload *p, const char *site, struct psd_mqtt_cmd *out, char *err, size_t errlen)
{
	json_object *v;
	if (!p->root || !json_object_is_type(p->root, json_type_object))
		return 0;
	if (json_object_object_get_ex(p->root, "site", &v)) {
		if (!json_object_is_type(v, json_type_string))
			return psd_errbuf(err, errlen, "\"site\" is not a string");
		if (strcmp(json_object_get_string(v), site) != 0) {
			char shown[PSD_MQTT_NAME];
			snprintf(shown, sizeof shown, "%s", json_object_get_string(v));
			return psd_errbuf(err, errlen, "command for site '%s' refused: this is site '%s'", shown, site);
		}
	}
	if (json_object_object_get_ex(p->root, "id", &v)) {
		const char *s;
		if (json_object_is_type(v, json_type_int)) {
			snprintf(out->id, sizeof out->id, "%lld", (long long)json_object_get_int64(v));
			return 0;
		}
		if (!json_object_is_type(v, json_type_string) ||
		    (size_t)json_object_get_string_len(v) >= sizeof out->id)
			return psd_errbuf(err, errlen, "\"id\" is not a string of at most %d characters or an integer",
			                PSD_MQTT_REQ_ID - 1);
		s = json_object_get_string(v);
		for (const char *c = s; *c; c++)
			if ((unsigned char)*c < 0x20 || *c == 0x7f)
				return psd_errbuf(err, errlen, "\"id\" has a control character");
		snprintf(out->id, sizeof out->id, "%s", s);
	}
	return 0;
}

/* The payload must be empty or an object with no fields but id and site. */
static int no_value(const struct payload *p, const char *verb, char *err, size_t errlen)
{
	static const char *const none[] = { NULL };
	if (p->word || p->has_num)
		return psd_errbuf(err, errlen, "set/%s takes no value", verb);
	return only_fields(p->root, none, err, errlen);
}

/* A number given bare or as the object's field key. */
static int one_number(const struct payload *p, const char *key, double *out, char *err, size_t errlen)
{
	int rc;
	if (p->has_num) {
		*out = p->num;
		return 0;
	}
	if (p->word || !p->root)
		return psd_errbuf(err, errlen, "needs a number (or {\"%s\": N})", key);
	if ((rc = field_num(p->root, key, out, err, errlen)) < 0)
		return -1;
	return rc ? 0 : psd_errbuf(err, errlen, "needs \"%s\"", key);
}

static int build(const struct payload *p, const char *zone, const char *verb, double override_s,
                 struct psd_mqtt_cmd *out, char *err, size_t errlen)
{
	double a, b;
	int rc;
	if (strcmp(verb, "target") == 0) {
		static const char *const f[] = { "lux", NULL };
		if (only_fields(p->root, f, err, errlen) || one_number(p, "lux", &a, err, errlen))
			return -1;
		snprintf(out->line, sizeof out->line, "target %s %.17g", zone, a);
	} else if (strcmp(verb, "override") == 0) {
		static const char *const f[] = { "level", "seconds", NULL };
		if (only_fields(p->root, f, err, errlen) || one_number(p, "level", &a, err, errlen))
			return -1;
		b = override_s;
		if ((rc = field_num(p->root, "seconds", &b, err, errlen)) < 0)
			return -1;
		snprintf(out->line, sizeof out->line, "override %s %.17g %.17g", zone, a, b);
	} else if (strcmp(verb, "lux") == 0) {
		static const char *const f[] = { "lux", NULL };
		if (only_fields(p->root, f, err, errlen) || one_number(p, "lux", &a, err, errlen))
			return -1;
		snprintf(out->line, sizeof out->line, "calibrate %s lux %.17g", zone, a);
	} else if (strcmp(verb, "calibrate") == 0) {
		static const char *const f[] = { "step", "level", "lux", NULL };
		static const char *const steps[] = { "night", "day", "lux", "finish", "accept", "abort", "status", NULL };
		const char *step = p->word;
		int known = 0;
		if (p->has_num || (!p->root && !p->word))
			return psd_errbuf(err, errlen, "set/calibrate needs a step: \"night\", \"day\", \"finish\", "
			                             "\"accept\", \"abort\", \"status\" or {\"step\": ...}");
		if (only_fields(p->root, f, err, errlen) || field_word(p->root, "step", &step, err, errlen) < 0)
			return -1;
		for (size_t i = 0; step && steps[i]; i++)
			known |= strcmp(step, steps[i]) == 0;
		if (!known)
			return psd_errbuf(err, errlen, "set/calibrate: no step %s%s%s", step ? "'" : "", step ? step : "given",
			                step ? "'" : "");
		if ((rc = field_num(p->root, "level", &a, err, errlen)) < 0)
			return -1;
		if (rc && strcmp(step, "day") != 0)
			return psd_errbuf(err, errlen, "set/calibrate: \"level\" belongs to the day step");
		if (strcmp(step, "lux") == 0) {
			if ((rc = field_num(p->root, "lux", &b, err, errlen)) <= 0)
				return rc < 0 ? -1 : psd_errbuf(err, errlen, "set/calibrate lux needs \"lux\"");
			snprintf(out->line, sizeof out->line, "calibrate %s lux %.17g", zone, b);
		} else if (field_num(p->root, "lux", &b, err, errlen) != 0) {
			return psd_errbuf(err, errlen, "set/calibrate: \"lux\" belongs to the lux step");
		} else if (rc) {
			snprintf(out->line, sizeof out->line, "calibrate %s day %.17g", zone, a);
		} else {
			snprintf(out->line, sizeof out->line, "calibrate %s %s", zone, step);
		}
	} else if (strcmp(verb, "accept") == 0 || strcmp(verb, "finish") == 0 || strcmp(verb, "abort") == 0) {
		if (no_value(p, verb, err, errlen))
			return -1;
		snprintf(out->line, sizeof out->line, "calibrate %s %s", zone, verb);
	} else if (strcmp(verb, "release") == 0 || strcmp(verb, "status") == 0) {
		if (no_value(p, verb, err, errlen))
			return -1;
		snprintf(out->line, sizeof out->line, "%s %s", verb, zone);
	} else {
		char shown[24];
		snprintf(shown, sizeof shown, "%s", verb);
		return psd_errbuf(err, errlen, "no command set/%s (target, override, release, calibrate, lux, finish, "
		                "accept, abort, status)", shown);
	}
	return 0;
}

int psd_mqttcmd_scope(unsigned fronts)
{
	if (fronts & PSD_CMDTAB_MQTT_OVERRIDE)
		return PSD_MQTT_COMMANDS_OVERRIDE;
	if (fronts & PSD_CMDTAB_MQTT_ALL)
		return PSD_MQTT_COMMANDS_ALL;
	return PSD_MQTT_COMMANDS_NONE;
}

int psd_mqttcmd_parse(const char *site, const char *zone, const char *verb, const void *payload, size_t len,
                       double override_s, struct psd_mqtt_cmd *out, char *err, size_t errlen)
{
	struct payload p;
	int rc;
	memset(out, 0, sizeof *out);
	/* the zone goes into a request line: one word of the names psensd.conf allows */
	if (!psd_mqttconf_level_ok(zone))
		return psd_errbuf(err, errlen, "'%.*s' is not a zone name", 47, zone);
	if (parse(payload, len, &p, err, errlen) != 0) {
		json_object_put(p.root);
		return -1;
	}
	rc = common(&p, site, out, err, errlen);
	if (rc == 0)
		rc = build(&p, zone, verb, override_s, out, err, errlen);
	json_object_put(p.root);
	return rc;
}
