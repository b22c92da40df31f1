/* SPDX-License-Identifier: ISC */
/* Rendering the candidates' missing pictures with Radiance, for users who
 * have it: each pose's daylight-coefficient pictures with rfluxmtx (rays
 * from vwrays -ff through the room's octree to the sky patches' receiver
 * file, one RGBE picture a patch by -ffc and -o dc_%03d.hdr) and its
 * electric picture with rpict (render.h's command line), several renderers
 * at once, into the shared cache directory (cache.h's): a picture set's
 * folder is named by the SHA-256 of every input's bytes (octree, receiver)
 * and every option (view, size, rendering options), so a rerun renders
 * only what is missing or changed.  A set is rendered into a temporary
 * folder and renamed into place whole: a failed renderer leaves nothing. */
#ifndef PSD_PLACERENDER_H
#define PSD_PLACERENDER_H

#include <stddef.h>

#include "place.h"

/* The defaults: the placement fixture's settings. */
#define PSD_PLACERENDER_DC_OPTIONS "-ab 3 -ad 1024 -lw 1e-4"
#define PSD_PLACERENDER_ELEC_OPTIONS "-ab 3 -ad 2048 -as 512 -aa 0.1 -lw 1e-4 -ps 1"

struct psd_placerender_count {
	int dc_rendered, dc_cached, elec_rendered, elec_cached;
};

/* For every pose, point p->dcdir (when s->o->dc_octree) and p->elecfile
 * (when s->o->elec_octree) into the cache, rendering those missing with
 * s->o->jobs renderers at once.  -1 with err naming the candidate and the
 * command that failed; nothing partial stays in the cache. */
int psd_placerender_all(struct search *s, struct psd_placerender_count *n, char *err, size_t errlen);

#endif
