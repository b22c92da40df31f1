/* SPDX-License-Identifier: ISC */
/* MQTT command payloads (psensd-mqtt(7)): a message on
 * psensd/<site>/<zone>/set/<verb> becomes the control-socket request that
 * does the same (psensctl(1)), so that it is judged by the very code that
 * judges socket requests (psd_cmdtab_request).  Only the payload's shape is
 * checked here: its JSON, its types, its size; the values' ranges and the
 * zone's existence are the request's business. */
#ifndef PSD_MQTTCMD_H
#define PSD_MQTTCMD_H

#include <stddef.h>

enum { PSD_MQTT_MAX_PAYLOAD = 512, PSD_MQTT_REQ_ID = 65 };

struct psd_mqtt_cmd {
	char line[256];              /* the control-socket request */
	char id[PSD_MQTT_REQ_ID];    /* the payload's "id", echoed in the reply ("" none) */
};

/* Build the request for verb (target, override, release, calibrate, lux,
 * finish, accept, abort, status) on zone from payload (len bytes, not
 * terminated).  site: this psensd's; a payload naming another is refused.
 * override_s: an override's seconds when the payload gives none.  0, or -1
 * with a message in err. */
int psd_mqttcmd_parse(const char *site, const char *zone, const char *verb, const void *payload, size_t len,
                       double override_s, struct psd_mqtt_cmd *out, char *err, size_t errlen);

/* The [mqtt] commands scope (PSD_MQTT_COMMANDS_*) a verb needs, from the
 * front ends its command table row grants (fronts, PSD_CMDTAB_* bits, as
 * psd_cmdtab_verb_fronts gives them): override for a row granted
 * MQTT_OVERRIDE (override, release, status), all for one granted MQTT_ALL
 * alone; none for no MQTT bit, a verb that is no command
 * (psd_mqttcmd_parse refuses it with its own words). */
int psd_mqttcmd_scope(unsigned fronts);

#endif
