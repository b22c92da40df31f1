/* SPDX-License-Identifier: ISC */
/* What psensd publishes over MQTT, as text (psensd-mqtt(7)): a zone's state
 * from a logged sample, and the Home Assistant discovery messages.  No
 * broker here: daemon/mqtt/mqtt.c sends what these build. */
#ifndef PSD_MQTTMSG_H
#define PSD_MQTTMSG_H

#include <json-c/json.h>
#include <stddef.h>

#include "db.h"

struct psd_zone;

/* The state JSON of sample id (logged at utc, UTC seconds); z, when given,
 * adds the zone's live calibration and drift (for a sample just logged);
 * points, when given, is its "points" object (psd_points_json; taken, as
 * json-c's references go).  Returns the length, -1 when it does not fit
 * in n. */
int psd_mqttmsg_state_json(char *buf, size_t n, const char *site, long long id, double utc,
                        const struct psd_sample *s, const struct psd_zone *z, json_object *points);

/* Home Assistant discovery: the k-th entity of a zone (0, 1, ... until -1):
 * its config topic and its retained config payload.  The entities are the
 * point model's (points.h), one per point, and the override's number;
 * has(i): 1 when the zone has point i (else its config is empty, which
 * removes it).  commands: set/override is taken (else the override
 * entity's config is empty).  *point: the point of the entity, -1 none. */
int psd_mqttmsg_discovery(int k, const char *prefix, const char *site, const char *zone,
                       int (*has)(void *user, size_t i), void *user, int commands, char *topic, size_t topiclen,
                       char *payload, size_t paylen, int *point);

/* "2026-11-23T19:42:16.123Z" for UTC seconds t. */
void psd_mqttmsg_iso8601(double t, char *buf, size_t n);

#endif
