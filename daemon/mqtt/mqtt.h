/* SPDX-License-Identifier: ISC */
/* MQTT (psensd-mqtt(7)): psensd's samples, events and availability
 * published to a broker, commands taken from it, Home Assistant discovery.
 *
 * One job: the client.  It publishes from the SQLite sample log, in id
 * order at QoS 1, and keeps a cursor there (mqtt_cursor) that moves only
 * over samples whose every message the broker has acknowledged (PUBACK), so
 * a broker away for hours or a kill -9 loses nothing: what was not
 * acknowledged is published again (a consumer drops duplicates by id).
 *
 * The broker's socket is one more descriptor in psensd's poll() (no thread):
 * libmosquitto's non-blocking connect, read, write and keepalive run in the
 * loop's turn, each turn publishing at most what the rate bound and the
 * in-flight window allow, so neither the control nor the control socket
 * ever waits on the broker; commands run in the same thread as socket
 * requests, through the same function (psd_cmdtab_request), with no hand-off.
 * (Resolving the host name is the one blocking call: give an address or a
 * name in /etc/hosts.)  Built only WITH_MQTT; daemon/mqtt/mqtt_off.c otherwise. */
#ifndef PSD_MQTT_H
#define PSD_MQTT_H

#include <poll.h>
#include <stddef.h>

/* The room's public face is this header: the [mqtt] section the core's
 * configuration holds and judges comes with it. */
#include "mqttconf.h"

struct psd_engine;
struct psd_mqtt;
struct psd_points;

/* A control request: what psd_cmdtab_request does. */
typedef void (*psd_mqtt_request_fn)(void *user, char *line, char *reply, size_t len);
/* The front ends a set/ verb's command grants (psd_cmdtab_verb_fronts):
 * the command table, handed in so that the room calls no core function. */
typedef unsigned (*psd_mqtt_grants_fn)(const char *verb);

struct psd_mqtt_stats {
	int connected;
	long long cursor;            /* last sample id acknowledged */
	long long sent;              /* last sample id published */
	unsigned long published, acked, commands, refused, connects;
	double turn_max;             /* the longest psd_mqtt_service, wall seconds */
	double turn_cpu_max;         /* the most CPU time one took (the rest: waiting for the CPU) */
};

/* Start the client for the engine's log (the engine must have a database);
 * it connects in the background.  pts: the point model's state (points.h)
 * the state messages' "points" read.  NULL with a message in err. */
struct psd_mqtt *psd_mqtt_open(const struct psd_mqtt_conf *c, struct psd_engine *e, const struct psd_points *pts,
                               psd_mqtt_request_fn fn, psd_mqtt_grants_fn grants, void *user, char *err,
                               size_t errlen);
/* The broker's descriptor for poll(): 1 written, 0 none now. */
int psd_mqtt_pollfd(struct psd_mqtt *m, struct pollfd *pfd);
/* Do what is due: the socket's I/O (pfd from psd_mqtt_pollfd, or NULL),
 * keepalive, reconnecting, publishing the log's new samples within the
 * bounds, live events.  now: the daemon's clock. */
void psd_mqtt_service(struct psd_mqtt *m, const struct pollfd *pfd, double now);
/* Wall milliseconds until the client wants a turn (a backlog, a retry). */
int psd_mqtt_wait_ms(const struct psd_mqtt *m);
/* The engine was reopened (SIGHUP): announce the zones again, remove the
 * ones that left, publish a reload event. */
void psd_mqtt_reload(struct psd_mqtt *m);
void psd_mqtt_stats(const struct psd_mqtt *m, struct psd_mqtt_stats *st);
/* Publish offline (retained), disconnect, free. */
void psd_mqtt_close(struct psd_mqtt *m);

#endif
