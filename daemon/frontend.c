/* SPDX-License-Identifier: ISC */
/* The front ends' table and the walks over it (frontend.h). */
#include <stddef.h>

#include "frontend.h"
#include "bacnet.h"
#include "mqtt.h"
#include "prom.h"
#include "web.h"

/* One row per front end, in the order they start: MQTT first, so the
 * samples a BACnet or console client sees are already on their way. */
static const struct psd_frontend *const table[] = {
	&psd_mqtt_frontend,
	&psd_bacnet_frontend,
	&psd_web_frontend,
	&psd_prom_frontend,
	NULL,
};

static const struct psd_frontend *const *rows_of(const struct psd_frontend_set *s)
{
	return s->rows ? s->rows : table;
}

int psd_frontend_start(struct psd_frontend_set *s, const struct psd_frontend_env *env,
                       const struct psd_frontend **failed, char *err, size_t errlen)
{
	const struct psd_frontend *const *rows = rows_of(s);
	for (size_t i = 0; rows[i] && i < PSD_FRONTEND_MAX; i++) {
		if (!rows[i]->wanted(env->cf))
			continue;
		if (!(s->fe[i] = rows[i]->start(env, err, errlen))) {
			*failed = rows[i];
			return -1;
		}
	}
	return 0;
}

void psd_frontend_stop(struct psd_frontend_set *s)
{
	const struct psd_frontend *const *rows = rows_of(s);
	size_t n = 0;
	while (rows[n] && n < PSD_FRONTEND_MAX)
		n++;
	while (n-- > 0) {
		if (s->fe[n])
			rows[n]->stop(s->fe[n]);
		s->fe[n] = NULL;
		s->nfd[n] = 0;
	}
}

void psd_frontend_step(struct psd_frontend_set *s, double now)
{
	const struct psd_frontend *const *rows = rows_of(s);
	for (size_t i = 0; rows[i] && i < PSD_FRONTEND_MAX; i++)
		if (s->fe[i] && rows[i]->step)
			rows[i]->step(s->fe[i], now);
}

int psd_frontend_pollfds(struct psd_frontend_set *s, struct pollfd *fds, int max, int *timeout_ms)
{
	const struct psd_frontend *const *rows = rows_of(s);
	int n = 0;
	for (size_t i = 0; rows[i] && i < PSD_FRONTEND_MAX; i++) {
		int w;
		s->nfd[i] = 0;
		if (!s->fe[i])
			continue;
		w = rows[i]->wait_ms ? rows[i]->wait_ms(s->fe[i]) : -1;
		if (rows[i]->pollfds)
			s->nfd[i] = rows[i]->pollfds(s->fe[i], fds + n, max - n);
		n += s->nfd[i];
		if (w >= 0 && (*timeout_ms < 0 || w < *timeout_ms))
			*timeout_ms = w;
	}
	return n;
}

void psd_frontend_service(struct psd_frontend_set *s, const struct pollfd *fds, double now)
{
	const struct psd_frontend *const *rows = rows_of(s);
	int at = 0;
	for (size_t i = 0; rows[i] && i < PSD_FRONTEND_MAX; i++) {
		if (s->fe[i] && rows[i]->service)
			rows[i]->service(s->fe[i], s->nfd[i] ? fds + at : NULL, s->nfd[i], now);
		at += s->nfd[i];
	}
}

void psd_frontend_reload(struct psd_frontend_set *s, const struct psd_config *cf)
{
	const struct psd_frontend *const *rows = rows_of(s);
	for (size_t i = 0; rows[i] && i < PSD_FRONTEND_MAX; i++)
		if (rows[i]->reload)
			rows[i]->reload(s->fe[i], cf);
}

void psd_frontend_status(const struct psd_frontend_set *s, struct json_object *o)
{
	const struct psd_frontend *const *rows = rows_of(s);
	for (size_t i = 0; rows[i] && i < PSD_FRONTEND_MAX; i++)
		if (s->fe[i] && rows[i]->status)
			rows[i]->status(s->fe[i], o);
}
