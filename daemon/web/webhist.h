/* SPDX-License-Identifier: ISC */
/* The web console's charts: each zone's last PSD_WEBHIST_HOURS hours of
 * samples (output, estimated and measured task lux), kept in memory from
 * the engine's last step, at most PSD_WEBHIST_POINTS a zone (a restart
 * starts them again). */
#ifndef PSD_WEBHIST_H
#define PSD_WEBHIST_H

#include "engine.h"

enum { PSD_WEBHIST_POINTS = 2048, PSD_WEBHIST_HOURS = 4 };

struct psd_webhist_zone {
	char name[64];            /* "" a free slot */
	size_t n, head;           /* points kept; the next one's index */
	double last_t;            /* the clock time of the last kept */
	struct { double t, tod, level, est, meas; } p[PSD_WEBHIST_POINTS];
};

struct psd_webhist {
	struct psd_webhist_zone zone[PSD_MAX_ZONES];   /* slot i: the engine's zone i */
};

/* Take each zone's last sample when it is new and at least HOURS h /
 * POINTS after the one kept before it; a slot whose zone changed name (a
 * reload) starts again, one left without a zone is freed. */
void psd_webhist_record(struct psd_webhist *h, const struct psd_engine *e);
/* The zone's chart as JSON ({"ok":true,"zone":..,"t":[..],"tod_s":[..],
 * "level":[..],"est_task_lux":[..],"task_lux":[..]}, null where a value is
 * unknown), malloc'd; NULL when no such zone. */
char *psd_webhist_json(const struct psd_webhist *h, const char *zone);

#endif
