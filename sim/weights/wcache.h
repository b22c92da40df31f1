/* SPDX-License-Identifier: ISC */
/* Weight maps kept in the cache directory psscene uses (sim/cache.c's
 * binary entries): a map is found again by its content - the sensor's
 * table (not its file name), the reading, the rotation, the view's type,
 * -vh -vv -vs -vl, the size, the method and the version of the weights'
 * algorithm - memory-mapped and checksummed.  An entry that fails its
 * checks is removed and the map rebuilt; a cache that cannot be written
 * only costs time. */
#ifndef PS_WCACHE_H
#define PS_WCACHE_H

#include "err.h"
#include "sensor.h"
#include "view.h"
#include "weights.h"

/* Bump when ps_weights_build's numbers change: older entries are then never
 * found again (and age out). */
#define PS_WEIGHTS_ALGO_VERSION 8   /* 2: symmetric maps mirrored; 3: and transposed;
                                      * 4: compact symmetric maps; 5: M without
                                      * cancellation near the axis; 6: the uniform
                                      * sensor's angular map by a rule over each pixel;
                                      * 7: and the cosine's; 8: an azimuthal
                                      * table's linear reading from moments */

/* What a weight map is of: everything its numbers depend on, so the content
 * its cache entry is found by. */
struct ps_wcache_key {
	const struct ps_sensor *sensor;
	double rotation_deg;
	const struct ps_view *view;
	int width, height;             /* the picture's size */
	int method;                    /* enum ps_wmethod */
};

/* The cache directory (path NULL: no cache) and its bound (max_bytes 0:
 * unbounded). */
struct ps_wcache_dir {
	const char *path;
	size_t max_bytes;
};

/* The content key (64 hex digits). */
void ps_wcache_key_hex(const struct ps_wcache_key *k, char hex[65]);

enum ps_wcache_how {
	PS_WC_BUILT = 0,       /* no cache given: built */
	PS_WC_HIT = 1,         /* read from the cache */
	PS_WC_STORED = 2,      /* built and stored */
	PS_WC_UNWRITABLE = 3,  /* built; the cache could not be written (warn says why) */
	PS_WC_REBUILT = 4,     /* an entry failed its checks (warn says which): rebuilt, stored */
};

/* ps_weights_build of the map k through the cache (NULL, or a NULL path:
 * no cache).  *how says what happened; warn (may be NULL) gets the message
 * for PS_WC_UNWRITABLE and PS_WC_REBUILT.  Errors are ps_weights_build's. */
int ps_wcache_get(struct ps_weights *w, const struct ps_wcache_key *k, const struct ps_wcache_dir *cache,
                  int *how, struct ps_err *warn, struct ps_err *e);

/* The same, with a map built for the cache stored by a thread while the
 * caller goes on (the store costs a checksum and a write of the map: off
 * the critical path, the integration runs meanwhile; the entry is written
 * and renamed as by ps_wcache_get, so it stays whole or absent).  When a
 * store is under way *pending is set (else NULL) and *how says
 * PS_WC_STORED or PS_WC_REBUILT provisionally; ps_wcache_store_finish
 * waits for it and gives the final *how and warn.  Call it before w is
 * freed. */
struct ps_wcache_store;
int ps_wcache_get_async(struct ps_weights *w, const struct ps_wcache_key *k,
                        const struct ps_wcache_dir *cache, int *how, struct ps_err *warn,
                        struct ps_wcache_store **pending, struct ps_err *e);
void ps_wcache_store_finish(struct ps_wcache_store *p, int *how, struct ps_err *warn);

/* Parse a cache payload into w (runs copied, weights left in place:
 * data must outlive w, or be owned by it through w->map).  -1 with e when
 * the payload is not a consistent map of width x height (never trusted). */
int ps_wcache_from_payload(struct ps_weights *w, const void *data, size_t len, int width,
                           int height, int method, const char *name, struct ps_err *e);

#endif
