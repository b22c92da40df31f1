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

#include "frontend.h"

/* The room's row in the front-end table (frontend.h): [mqtt] wanted, the
 * client started on the engine's log (it connects in the background), the
 * broker's socket in the poll set, the state's "points" read from the
 * point model, "mqtt" in status -j, offline published at its stop. */
extern const struct psd_frontend psd_mqtt_frontend;

#endif
