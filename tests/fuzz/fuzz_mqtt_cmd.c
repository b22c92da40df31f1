/* SPDX-License-Identifier: ISC */
/* Fuzz MQTT command payloads (daemon/mqtt/mqttcmd.c).  The first byte picks the
 * verb, the second the zone name, the rest is the payload.  Invariants: the
 * parser answers 0 or -1 with a terminated message; an accepted payload
 * gives one request line of printable words that the control socket's
 * splitter takes, whose second word is the zone and nothing more (no
 * payload can add a word or a request). */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ctlsock.h"
#include "mqttcmd.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static const char *const verbs[] = { "target", "override", "release", "calibrate", "lux", "finish",
	                             "accept", "abort", "status", "reboot", "" };
static const char *const zones[] = { "office", "a.b-c_d", "office x", "", "nowhere" };

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct psd_mqtt_cmd cmd;
	char err[512], line[sizeof cmd.line], *argv[PSD_CTL_MAX_WORDS];
	const char *verb, *zone;
	int rc, argc;
	if (size < 2)
		return 0;
	verb = verbs[data[0] % (sizeof verbs / sizeof verbs[0])];
	zone = zones[data[1] % (sizeof zones / sizeof zones[0])];
	memset(err, 'x', sizeof err);
	rc = psd_mqttcmd_parse("lab", zone, verb, data + 2, size - 2, 3600, &cmd, err, sizeof err);
	if (rc != 0) {
		if (rc != -1 || !memchr(err, 0, sizeof err) || !err[0])
			abort();
		return 0;
	}
	if (!memchr(cmd.id, 0, sizeof cmd.id))
		abort();
	for (const char *c = cmd.line; *c; c++)
		if ((unsigned char)*c < 0x20 || (unsigned char)*c >= 0x7f)
			abort();
	memcpy(line, cmd.line, sizeof line);
	argc = psd_ctlsock_split(line, argv, err, sizeof err);
	if (argc < 2 || argc > 4 || strcmp(argv[1], zone) != 0)
		abort();
	return 0;
}
