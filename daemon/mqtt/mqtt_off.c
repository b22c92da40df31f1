/* SPDX-License-Identifier: ISC */
/* MQTT in a build without libmosquitto (WITH_MQTT=no, or auto without it):
 * the [mqtt] section is still read and judged, and a file that has one is
 * refused at start rather than run without its telemetry. */
#include <stddef.h>

#include "errbuf.h"
#include "mqtt.h"

struct psd_mqtt *psd_mqtt_open(const struct psd_mqtt_conf *c, struct psd_engine *e, const struct psd_points *pts,
                               psd_mqtt_request_fn fn, psd_mqtt_grants_fn grants, void *user, char *err,
                               size_t errlen)
{
	(void)c;
	(void)e;
	(void)pts;
	(void)fn;
	(void)grants;
	(void)user;
	psd_errbuf(err, errlen, "[mqtt]: this psensd was built without MQTT (WITH_MQTT=no or no libmosquitto)");
	return NULL;
}

int psd_mqtt_pollfd(struct psd_mqtt *m, struct pollfd *pfd)
{
	(void)m;
	(void)pfd;
	return 0;
}

void psd_mqtt_service(struct psd_mqtt *m, const struct pollfd *pfd, double now)
{
	(void)m;
	(void)pfd;
	(void)now;
}

int psd_mqtt_wait_ms(const struct psd_mqtt *m)
{
	(void)m;
	return -1;
}

void psd_mqtt_reload(struct psd_mqtt *m)
{
	(void)m;
}

void psd_mqtt_stats(const struct psd_mqtt *m, struct psd_mqtt_stats *st)
{
	(void)m;
	*st = (struct psd_mqtt_stats){ 0 };
}

void psd_mqtt_close(struct psd_mqtt *m)
{
	(void)m;
}
