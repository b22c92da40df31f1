/* SPDX-License-Identifier: ISC */
/* Prometheus (psensd.conf(5) [prometheus]): the point model written every
 * interval into a textfile for node-exporter's textfile collector, in the
 * text exposition format (psd_points_prometheus, points.h), replaced
 * atomically so the collector never reads half a file.
 *
 * One job: the textfile's writes, on real seconds whatever the clock's
 * speed.  No descriptor: its next write is part of the loop's poll timeout.
 * It reads [prometheus] from the engine's configuration at every turn, so a
 * reload that adds, moves or removes the textfile takes effect at once. */
#ifndef PSD_PROM_H
#define PSD_PROM_H

/* The room's public face is this header: the [prometheus] section the
 * core's configuration holds and judges comes with it. */
#include "promconf.h"

#include "frontend.h"

/* The room's row in the front-end table (frontend.h). */
extern const struct psd_frontend psd_prom_frontend;

#endif
