/* SPDX-License-Identifier: ISC */
/* MQTT in a build without libmosquitto (WITH_MQTT=no, or auto without it):
 * the [mqtt] section is still read and judged, and a file that has one is
 * refused at start rather than run without its telemetry.  The row never
 * starts, so it needs no other hook. */
#include <stddef.h>

#include "config.h"
#include "errbuf.h"
#include "mqtt.h"

static int wanted(const struct psd_config *cf)
{
	return cf->mqtt.enabled;
}

static void *start(const struct psd_frontend_env *env, char *err, size_t errlen)
{
	(void)env;
	psd_errbuf(err, errlen, "[mqtt]: this psensd was built without MQTT (WITH_MQTT=no or no libmosquitto)");
	return NULL;
}

static void stop(void *fe)
{
	(void)fe;
}

const struct psd_frontend psd_mqtt_frontend = {
	.name = "mqtt",
	.refused = "MQTT cannot start",
	.wanted = wanted,
	.start = start,
	.stop = stop,
};
