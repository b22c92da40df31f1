/* SPDX-License-Identifier: ISC */
/* Batches: one weight map (one sensor, reading, rotation, view, size,
 * method) applied to many pictures, read and integrated in parallel.
 *
 *   struct ps_batch b;
 *   struct ps_batch_spec sp = { .map = { &sensor, rotation_deg, &view, width,
 *                                       height, PS_W_EXACT },
 *                              .coef = coef, .nthreads = 2 };
 *   ps_batch_init(&b, &sp, &e);                     weights built once
 *   ps_batch_run_files(&b, paths, n, results);      results[i] for paths[i]
 *   ps_batch_free(&b);
 *
 * Each result is the one-picture route's (ps_integrate with the same
 * weights) bit for bit: the threads only share the read-only weights, and
 * every picture is summed by one thread in the one order.  Results come back
 * in input order whatever the number of threads.  A picture of another size
 * or view than the batch's is an error of that picture (naming its file),
 * not of the batch; so is an unreadable one.  The sensor must outlive the
 * batch.  Threads: pthreads; at most nthreads pictures are in memory at
 * once. */
#ifndef PS_BATCH_H
#define PS_BATCH_H

#include <stddef.h>
#include <stdint.h>

#include "err.h"
#include "integrate.h"
#include "picture.h"
#include "sensor.h"
#include "view.h"
#include "wcache.h"
#include "weights.h"

#define PS_BATCH_THREADS_DEFAULT 2
#define PS_BATCH_THREADS_MAX 256

struct ps_batch {
	struct ps_weights w;           /* the batch's weights (read-only once built) */
	const struct ps_sensor *sens;
	double rotation;               /* degrees */
	int method;                    /* enum ps_wmethod */
	double coef[3];
	int nthreads;
	struct ps_wcache_store *pending;     /* the weights' cache store under way, or NULL */
};

enum ps_batch_status {
	PS_BATCH_OK = 0,
	PS_BATCH_FAILED = 1,           /* unreadable, bad view, out of memory: err says */
	PS_BATCH_MISMATCH = 2,         /* readable, but another size or view: err says */
};

struct ps_batch_result {
	int status;                    /* enum ps_batch_status */
	struct ps_response r;          /* valid when status is PS_BATCH_OK */
	int view_assumed;              /* the picture had no VIEW= (the default fisheye) */
	int width, height;             /* the picture's size (0 if unreadable) */
	struct ps_err err;             /* when status is not OK: names the file */
};

/* A batch: its weight map, the colour coefficients, the threads. */
struct ps_batch_spec {
	struct ps_wcache_key map;      /* the weight map (its sensor must outlive the batch) */
	const double *coef;            /* [3] */
	int nthreads;                  /* <= 0: PS_BATCH_THREADS_DEFAULT */
};

/* Build the weights once. */
int ps_batch_init(struct ps_batch *b, const struct ps_batch_spec *sp, struct ps_err *e);
/* The same with the weights through the cache (sim/weights/wcache.h; NULL:
 * none), stored there while the pictures are integrated
 * (ps_wcache_get_async): *how is a ps_wcache_how, provisional until
 * ps_batch_finish_store gives the final one (and warn). */
int ps_batch_init_cache_async(struct ps_batch *b, const struct ps_batch_spec *sp,
                              const struct ps_wcache_dir *cache, int *how, struct ps_err *warn,
                              struct ps_err *e);
void ps_batch_finish_store(struct ps_batch *b, int *how, struct ps_err *warn);
/* Frees the weights (waiting for a store under way first). */
void ps_batch_free(struct ps_batch *b);

/* Read and integrate n picture files; out[i] for paths[i].  Returns the
 * number of pictures whose status is not PS_BATCH_OK, or -1 (and e) when
 * the threads could not be started. */
long ps_batch_run_files(const struct ps_batch *b, const char *const *paths, size_t n,
                        struct ps_batch_result *out, struct ps_err *e);

/* The same with paths[0]'s bytes read already (first, first_len: a pipe
 * cannot be read twice); they must stay valid until it returns. */
long ps_batch_run_files_first(const struct ps_batch *b, const char *const *paths, size_t n,
                              const uint8_t *first, size_t first_len,
                              struct ps_batch_result *out, struct ps_err *e);

/* The same for pictures the caller makes: load(ctx, i, pic, e) fills pic
 * (0) or fails (-1 with e); it is called from several threads at once. The
 * picture's own VIEW= is checked as for files (none: the default fisheye);
 * name(ctx, i) names it in messages (may be NULL: "picture <i>"). */
long ps_batch_run(const struct ps_batch *b, size_t n,
                  int (*load)(void *ctx, size_t i, struct ps_picture *pic, struct ps_err *e),
                  const char *(*name)(void *ctx, size_t i), void *ctx,
                  struct ps_batch_result *out, struct ps_err *e);

#endif
