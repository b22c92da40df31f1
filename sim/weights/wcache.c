/* SPDX-License-Identifier: ISC */
/* Weight maps in the cache: payload
 *   u32 PS_WEIGHTS_ALGO_VERSION, i32 width, i32 height, i32 method,
 *   u64 nruns, u64 nw, f64 solid_angle, sens_sum, sens_full, coverage,
 *   nruns x (i32 row, i32 x0, i32 n, i32 share),
 *   nw x f64 weights
 * share is 0 in a full map (each run's n weights follow the last run's);
 * in a compact map (weights.h) -1 for a run with its own (n + 1) / 2
 * weights (next in order), k >= 1 for one with the weights of run k - 1,
 * an earlier run of its own with the same x0 and n.
 * in the machine's byte order (a cache is one machine's; the key holds the
 * layout's version).  The weights start 8-byte aligned in the map. */
#include "wcache.h"

#include <math.h>
#include <nettle/sha2.h>
#include <pthread.h>
#include <stdio.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "cache.h"
#include "cellmap.h"

enum { FIXED = 64, RUN = 16 };

static void hash_doubles(struct sha256_ctx *c, const double *v, size_t n)
{
	sha256_update(c, n * sizeof *v, (const uint8_t *)v);
}

static void hash_int(struct sha256_ctx *c, long long v)
{
	sha256_update(c, sizeof v, (const uint8_t *)&v);
}

void ps_wcache_key_hex(const struct ps_wcache_key *k, char hex[65])
{
	static const char digits[] = "0123456789abcdef";
	const struct ps_sensor *s = k->sensor;
	const struct ps_view *v = k->view;
	struct sha256_ctx c;
	uint8_t d[SHA256_DIGEST_SIZE];
	double view[4] = { v->vh, v->vv, v->vs, v->vl };
	sha256_init(&c);
	sha256_update(&c, 16, (const uint8_t *)"psens-weights\n\0\0");
	hash_int(&c, PS_WEIGHTS_ALGO_VERSION);
	hash_int(&c, (long long)sizeof(double));
	hash_int(&c, s->kind);
	hash_int(&c, s->ntheta);
	hash_int(&c, s->nphi);
	if (s->ntheta > 0 && s->theta)
		hash_doubles(&c, s->theta, (size_t)s->ntheta);
	if (s->nphi > 0 && s->phi)
		hash_doubles(&c, s->phi, (size_t)s->nphi);
	if (s->ntheta > 0 && s->nphi > 0 && s->val)
		hash_doubles(&c, s->val, (size_t)s->ntheta * (size_t)s->nphi);
	hash_int(&c, s->reading);
	hash_doubles(&c, &k->rotation_deg, 1);
	hash_int(&c, v->type);
	hash_doubles(&c, view, 4);
	hash_int(&c, k->width);
	hash_int(&c, k->height);
	hash_int(&c, k->method);
	sha256_digest(&c, sizeof d, d);
	for (int i = 0; i < 32; i++) {
		hex[2 * i] = digits[d[i] >> 4];
		hex[2 * i + 1] = digits[d[i] & 15];
	}
	hex[64] = '\0';
}

int ps_wcache_from_payload(struct ps_weights *w, const void *data, size_t len, int width,
                           int height, int method, const char *name, struct ps_err *e)
{
	const uint8_t *p = data;
	uint32_t version;
	int32_t hw, hh, hm;
	uint64_t nruns, nw, sum = 0;
	double f[4];
	memset(w, 0, sizeof *w);
	if (len < FIXED)
		return ps_err_set(e, PS_EFORMAT, "%s: %zu bytes, shorter than a weight map's header", name,
		                  len);
	memcpy(&version, p, 4);
	memcpy(&hw, p + 4, 4);
	memcpy(&hh, p + 8, 4);
	memcpy(&hm, p + 12, 4);
	memcpy(&nruns, p + 16, 8);
	memcpy(&nw, p + 24, 8);
	memcpy(f, p + 32, sizeof f);
	if (version != PS_WEIGHTS_ALGO_VERSION || hw != width || hh != height || hm != method)
		return ps_err_set(e, PS_EFORMAT, "%s: a map of another version, size or method", name);
	/* every run is a piece of one row: no more runs than rows, no more
	 * weights than pixels; then the length must be exact */
	if (nruns > (uint64_t)height || nw > (uint64_t)width * (uint64_t)height ||
	    len != FIXED + nruns * RUN + nw * sizeof(double))
		return ps_err_set(e, PS_EFORMAT, "%s: %llu runs and %llu weights do not fit %zu bytes",
		                  name, (unsigned long long)nruns, (unsigned long long)nw, len);
	for (int i = 0; i < 4; i++)
		if (!isfinite(f[i]))
			return ps_err_set(e, PS_EFORMAT, "%s: a total is not finite", name);
	w->runs = malloc((nruns ? nruns : 1) * sizeof *w->runs);
	if (!w->runs)
		return ps_err_set(e, PS_ENOMEM, "%s: out of memory", name);
	for (uint64_t i = 0; i < nruns; i++) {
		int32_t r[4];
		memcpy(r, p + FIXED + i * RUN, sizeof r);
		if (i == 0)
			w->mirror = r[3] != 0;
		if (r[0] < 0 || r[0] >= height || r[1] < 0 || r[2] <= 0 || r[2] > width - r[1] ||
		    (r[3] != 0) != w->mirror || r[3] < -1 || (r[3] > 0 && (uint64_t)r[3] > i)) {
			free(w->runs);
			w->runs = NULL;
			return ps_err_set(e, PS_EFORMAT, "%s: run %llu (row %d, x %d, %d pixels, share %d) is "
			                  "outside %d x %d", name, (unsigned long long)i, r[0], r[1], r[2], r[3],
			                  width, height);
		}
		if (r[3] > 0) {
			/* the weights of an earlier run of its own, of the same pixels */
			const struct ps_weights_run *o = &w->runs[r[3] - 1];
			int32_t k;
			memcpy(&k, p + FIXED + (uint64_t)(r[3] - 1) * RUN + 12, 4);
			if (k != -1 || o->x0 != r[1] || o->n != r[2]) {
				free(w->runs);
				w->runs = NULL;
				return ps_err_set(e, PS_EFORMAT, "%s: run %llu shares the weights of run %d, "
				                  "not one of its own of %d pixels from x %d", name,
				                  (unsigned long long)i, r[3] - 1, r[2], r[1]);
			}
			w->runs[i] = (struct ps_weights_run){ r[0], r[1], r[2], o->off };
		} else {
			w->runs[i] = (struct ps_weights_run){ r[0], r[1], r[2], (size_t)sum };
			sum += (uint64_t)(w->mirror ? (r[2] + 1) / 2 : r[2]);
		}
		w->npix += (size_t)r[2];
	}
	if (sum != nw) {
		free(w->runs);
		w->runs = NULL;
		return ps_err_set(e, PS_EFORMAT, "%s: the runs hold %llu pixels, the map %llu weights", name,
		                  (unsigned long long)sum, (unsigned long long)nw);
	}
	w->width = width;
	w->height = height;
	w->method = method;
	w->nruns = (size_t)nruns;
	w->nw = (size_t)nw;
	w->w = (double *)(uintptr_t)(p + FIXED + nruns * RUN);
	w->solid_angle = f[0];
	w->sens_sum = f[1];
	w->sens_full = f[2];
	w->coverage = f[3];
	return 0;
}

/* The payload's header and runs into fixed (FIXED bytes) and runs
 * (nruns x RUN bytes). */
static int encode(const struct ps_weights *w, uint8_t *fixed, uint8_t *runs, struct ps_err *e)
{
	uint32_t version = PS_WEIGHTS_ALGO_VERSION;
	int32_t hw = w->width, hh = w->height, hm = w->method;
	uint64_t nruns = w->nruns, nw = w->nw;
	double f[4] = { w->solid_angle, w->sens_sum, w->sens_full, w->coverage };
	memset(fixed, 0, FIXED);
	memcpy(fixed, &version, 4);
	memcpy(fixed + 4, &hw, 4);
	memcpy(fixed + 8, &hh, 4);
	memcpy(fixed + 12, &hm, 4);
	memcpy(fixed + 16, &nruns, 8);
	memcpy(fixed + 24, &nw, 8);
	memcpy(fixed + 32, f, sizeof f);
	{
		size_t next = 0, nown = 0;
		for (size_t i = 0; i < w->nruns; i++) {
			int32_t r[4] = { w->runs[i].row, w->runs[i].x0, w->runs[i].n, 0 };
			if (w->mirror && w->runs[i].off == next) {
				r[3] = -1;
				next += (size_t)ps_weights_run_stored(w, &w->runs[i]);
				nown++;
			} else if (w->mirror) {
				/* the earlier run of its own it shares: those come first,
				 * in the order of their weights (ps_weights_build_ex); any
				 * other order is searched in full */
				size_t a = 0, b = nown, k = i;
				while (a < b) {
					size_t m = (a + b) / 2;
					if (w->runs[m].off < w->runs[i].off)
						a = m + 1;
					else
						b = m;
				}
				if (a < i && w->runs[a].off == w->runs[i].off && w->runs[a].n == w->runs[i].n)
					k = a;
				for (size_t q = 0; q < i && k == i; q++)
					if (w->runs[q].off == w->runs[i].off && w->runs[q].n == w->runs[i].n)
						k = q;
				if (k == i)
					return ps_err_set(e, PS_EINVAL, "run %zu shares no earlier run's weights", i);
				r[3] = (int32_t)(k + 1);
			}
			memcpy(runs + i * RUN, r, sizeof r);
		}
	}
	return 0;
}

static int store(const struct ps_weights *w, const char *dir, const char *hex, size_t max_bytes,
                 struct ps_err *e)
{
	uint8_t fixed[FIXED];
	uint8_t *runs = malloc((w->nruns ? w->nruns : 1) * RUN);
	const void *ptr[3];
	size_t len[3];
	int rc;
	if (!runs)
		return ps_err_set(e, PS_ENOMEM, "out of memory");
	if (encode(w, fixed, runs, e) != 0) {
		free(runs);
		return -1;
	}
	ptr[0] = fixed;
	len[0] = FIXED;
	ptr[1] = runs;
	len[1] = w->nruns * RUN;
	ptr[2] = w->w;
	len[2] = w->nw * sizeof(double);
	rc = ps_cache_blob_put(dir, hex, 3, ptr, len, max_bytes, e);
	free(runs);
	return rc;
}

struct ps_wcache_store {
	pthread_t tid;
	const struct ps_weights *w;
	struct ps_cache_blob_out out;   /* placed: the entry to commit */
	int placed;
	char *dir;
	char hex[65];
	size_t max_bytes;
	int rebuilt, rc;
	struct ps_err warn;   /* the rebuild's reason, then the store's error */
};

static void *store_run(void *arg)
{
	struct ps_wcache_store *p = arg;
	struct ps_err ce;
	p->rc = p->placed ? ps_cache_blob_commit(&p->out, p->dir, p->max_bytes, &ce)
	                  : store(p->w, p->dir, p->hex, p->max_bytes, &ce);
	if (p->rc != 0)
		p->warn = ce;
	return NULL;
}

void ps_wcache_store_finish(struct ps_wcache_store *p, int *how, struct ps_err *warn)
{
	if (!p)
		return;
	pthread_join(p->tid, NULL);
	if (how)
		*how = p->rc != 0 ? PS_WC_UNWRITABLE : p->rebuilt ? PS_WC_REBUILT : PS_WC_STORED;
	if (warn && (p->rc != 0 || p->rebuilt))
		*warn = p->warn;
	free(p->dir);
	free(p);
}

static int get(struct ps_weights *w, const struct ps_wcache_key *k, const struct ps_wcache_dir *cache,
               int *how, struct ps_err *warn, struct ps_wcache_store **pending, struct ps_err *e);

int ps_wcache_get(struct ps_weights *w, const struct ps_wcache_key *k, const struct ps_wcache_dir *cache,
                  int *how, struct ps_err *warn, struct ps_err *e)
{
	return get(w, k, cache, how, warn, NULL, e);
}

int ps_wcache_get_async(struct ps_weights *w, const struct ps_wcache_key *k,
                        const struct ps_wcache_dir *cache, int *how, struct ps_err *warn,
                        struct ps_wcache_store **pending, struct ps_err *e)
{
	*pending = NULL;
	return get(w, k, cache, how, warn, pending, e);
}

struct place {
	const char *dir;
	const char *hex;
	struct ps_cache_blob_out out;
	int placed;   /* out holds the map's entry, not committed yet */
};

/* The weights straight into a new cache entry's mapping, after the room
 * for the payload's header and runs; NULL (the route's own memory, stored
 * afterwards) when the entry cannot be made. */
static double *place_in_entry(void *arg, struct ps_weights *w)
{
	struct place *pl = arg;
	struct ps_err ce;
	size_t head = FIXED + w->nruns * RUN;
	if (ps_cache_blob_create(pl->dir, pl->hex, head + w->nw * sizeof(double), &pl->out, &ce) != 0)
		return NULL;
	pl->placed = 1;
	w->map = pl->out.map;
	w->maplen = pl->out.maplen;
	w->built_in_map = 1;
	return (double *)(void *)((uint8_t *)pl->out.payload + head);
}

/* A linear-reading table that changes with azimuth on the angular
 * projection: from the solid-angle map by sim/weights/cellmap.c (the solid
 * angles built here, not stored: on an empty cache building them costs
 * less than storing them); with pl, the map is built in its new entry's
 * mapping (pl->placed), else stored afterwards as any other.  On the
 * hemispherical projection that route has no moments: the edge route's
 * map. */
static int build(struct ps_weights *w, const struct ps_wcache_key *k, struct place *pl,
                 struct ps_err *e)
{
	if (ps_cellmap_fits(k->sensor, k->method) == PS_CELLMAP_LINEAR && k->view->type == PS_VT_ANGULAR) {
		struct ps_sensor uni;
		struct ps_weights omega;
		int rc;
		if (ps_sensor_builtin(&uni, PS_SENS_UNIFORM, e) != 0)
			return -1;
		rc = ps_weights_build_ex(&omega, &uni, 0.0, k->view, k->width, k->height, PS_W_EXACT,
		                         PS_WB_COMPACT, e);
		ps_sensor_free(&uni);
		if (rc != 0)
			return -1;
		rc = ps_cellmap_build_placed(w, k->sensor, k->rotation_deg, k->view, k->width, k->height,
		                             &omega, pl ? place_in_entry : NULL, pl, e);
		ps_weights_free(&omega);
		if (pl && pl->placed) {
			/* the payload's header and runs before the weights */
			struct ps_err ce;
			if (rc != 0 || encode(w, pl->out.payload, (uint8_t *)pl->out.payload + FIXED, &ce) != 0) {
				ps_cache_blob_abort(&pl->out);
				pl->placed = 0;
			}
		}
		return rc;
	}
	return ps_weights_build_ex(w, k->sensor, k->rotation_deg, k->view, k->width, k->height, k->method,
	                           PS_WB_COMPACT, e);
}

/* A cell-reading table that changes with azimuth: its map from the uniform
 * sensor's (sim/weights/cellmap.h), which the cache keeps; the map itself
 * is not stored (building it from the solid angles costs less than storing
 * and reading its full size).  *how is the solid-angle map's: PS_WC_HIT
 * when it came from the cache. */
static int get_cellmap(struct ps_weights *w, const struct ps_wcache_key *k,
                       const struct ps_wcache_dir *cache, int *how, struct ps_err *warn,
                       struct ps_err *e)
{
	struct ps_sensor uni;
	struct ps_weights omega;
	struct ps_wcache_store *pending = NULL;
	struct ps_wcache_key ok;
	int rc;
	if (ps_sensor_builtin(&uni, PS_SENS_UNIFORM, e) != 0)
		return -1;
	ok = (struct ps_wcache_key){ &uni, 0.0, k->view, k->width, k->height, PS_W_EXACT };
	if (get(&omega, &ok, cache, how, warn, &pending, e) != 0) {
		ps_sensor_free(&uni);
		return -1;
	}
	/* a new solid-angle map is stored while the cells are filled */
	rc = ps_cellmap_build(w, k->sensor, k->rotation_deg, k->view, k->width, k->height, &omega, e);
	ps_wcache_store_finish(pending, how, warn);
	ps_weights_free(&omega);
	ps_sensor_free(&uni);
	return rc;
}

static int get(struct ps_weights *w, const struct ps_wcache_key *k, const struct ps_wcache_dir *cache,
               int *how, struct ps_err *warn, struct ps_wcache_store **pending, struct ps_err *e)
{
	const char *dir = cache ? cache->path : NULL;
	size_t max_bytes = cache ? cache->max_bytes : 0;
	char hex[65];
	struct ps_cache_blob b;
	struct ps_err ce;
	struct place pl;
	int got, rebuilt = 0;
	*how = PS_WC_BUILT;
	if (ps_cellmap_fits(k->sensor, k->method) == PS_CELLMAP_CELL)
		return get_cellmap(w, k, cache, how, warn, e);
	if (!dir)
		return build(w, k, NULL, e);
	ps_wcache_key_hex(k, hex);
	got = ps_cache_blob_get(dir, hex, &b, &ce);
	if (got == 1) {
		char name[4200];
		snprintf(name, sizeof name, "%s/blobs/%.2s/%s", dir, hex, hex + 2);
		if (ps_wcache_from_payload(w, b.data, b.len, k->width, k->height, k->method, name, &ce) == 0) {
			w->map = b.map;
			w->maplen = b.maplen;
			ps_weights_key(k->sensor, k->rotation_deg, k->view, k->width, k->height, k->method, w->key,
			               sizeof w->key);
			*how = PS_WC_HIT;
			return 0;
		}
		/* checksummed yet inconsistent: not trusted, rebuilt over it */
		ps_cache_blob_release(&b);
		got = -1;
	}
	if (got < 0) {
		rebuilt = 1;
		if (warn)
			*warn = ce;
	}
	pl.dir = dir;
	pl.hex = hex;
	pl.placed = 0;
	if (build(w, k, &pl, e) != 0)
		return -1;
	if (pending) {
		/* stored by a thread; a thread that cannot start: stored here */
		struct ps_wcache_store *p = calloc(1, sizeof *p);
		if (p && (p->dir = strdup(dir)) != NULL) {
			p->w = w;
			p->out = pl.out;
			p->placed = pl.placed;
			memcpy(p->hex, hex, sizeof p->hex);
			p->max_bytes = max_bytes;
			p->rebuilt = rebuilt;
			if (rebuilt && warn)
				p->warn = *warn;
			if (pthread_create(&p->tid, NULL, store_run, p) == 0) {
				*pending = p;
				*how = rebuilt ? PS_WC_REBUILT : PS_WC_STORED;
				return 0;
			}
			free(p->dir);
		}
		free(p);
	}
	if (pl.placed ? ps_cache_blob_commit(&pl.out, dir, max_bytes, &ce) != 0
	              : store(w, dir, hex, max_bytes, &ce) != 0) {
		*how = PS_WC_UNWRITABLE;
		if (warn)
			*warn = ce;
		return 0;
	}
	*how = rebuilt ? PS_WC_REBUILT : PS_WC_STORED;
	return 0;
}
