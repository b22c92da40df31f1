/* SPDX-License-Identifier: ISC */
/* The [mqtt] section of psensd.conf (psensd.conf(5), psensd-mqtt(7)): where
 * the broker is, who psensd is there, and how fast a backlog may go.  Read
 * and judged with the rest of the file (every error as file:line), so that
 * `psensd -n` judges it too, in a build with or without MQTT.  A file with
 * no [mqtt] section leaves `enabled` 0: psensd then opens no connection. */
#ifndef PSD_MQTTCONF_H
#define PSD_MQTTCONF_H

#include "conf.h"

enum { PSD_MQTT_NAME = 48 };

/* What commands psensd takes from the broker ([mqtt] commands): none (it
 * does not subscribe), override (override, release, status), all. */
enum { PSD_MQTT_COMMANDS_NONE, PSD_MQTT_COMMANDS_OVERRIDE, PSD_MQTT_COMMANDS_ALL };

struct psd_mqtt_conf {
	int enabled;              /* an [mqtt] section is there */
	int line;                 /* its line */
	char *host;               /* malloc'd: the broker's address */
	long port;                /* default 1883, 8883 with a cafile */
	char site[PSD_MQTT_NAME]; /* psensd/<site>/...; default: the host name */
	char *user;               /* malloc'd or NULL */
	char *password_file;      /* malloc'd or NULL: read at load, first line */
	char *password;           /* malloc'd or NULL */
	char *cafile, *certfile, *keyfile;   /* malloc'd or NULL: TLS when cafile is set */
	long keepalive;           /* s */
	double rate;              /* messages per second at most (the catch-up's bound) */
	long inflight;            /* QoS 1 messages awaiting PUBACK at most */
	int discovery;            /* Home Assistant discovery messages */
	char discovery_prefix[64];/* default "homeassistant" */
	int commands;             /* PSD_MQTT_COMMANDS_*, default none */
};

/* Read [mqtt] of c into m (errors go to c).  A password file that cannot be
 * read, that others may read, or that its group or others may write, is an
 * error at its line. */
void psd_mqttconf_load(struct psd_mqtt_conf *m, struct ps_conf *c);
void psd_mqttconf_free(struct psd_mqtt_conf *m);

/* A topic level psensd writes (a site or a zone name): 1 to 47 of
 * [A-Za-z0-9_.-].  1 when good. */
int psd_mqttconf_level_ok(const char *s);

#endif
