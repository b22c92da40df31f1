/* SPDX-License-Identifier: ISC */
/* Batches of pictures on one weight map: a pool of pthreads takes picture
 * indices from a shared counter; each writes only its own results. */
#include "batch.h"

#include <errno.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>

#include "fileio.h"
#include "picview.h"
#include "stream.h"
#include "wcache.h"

static int init(struct ps_batch *b, const struct ps_batch_spec *sp, const struct ps_wcache_dir *cache,
                int *how, struct ps_err *warn, int async, struct ps_err *e)
{
	memset(b, 0, sizeof *b);
	if (sp->nthreads > PS_BATCH_THREADS_MAX)
		return ps_err_set(e, PS_EINVAL, "%d threads: at most %d", sp->nthreads, PS_BATCH_THREADS_MAX);
	b->sens = sp->map.sensor;
	b->rotation = sp->map.rotation_deg;
	b->method = sp->map.method;
	memcpy(b->coef, sp->coef, sizeof b->coef);
	b->nthreads = sp->nthreads > 0 ? sp->nthreads : PS_BATCH_THREADS_DEFAULT;
	if (async)
		return ps_wcache_get_async(&b->w, &sp->map, cache, how, warn, &b->pending, e);
	return ps_wcache_get(&b->w, &sp->map, cache, how, warn, e);
}

int ps_batch_init(struct ps_batch *b, const struct ps_batch_spec *sp, struct ps_err *e)
{
	int how;
	return init(b, sp, NULL, &how, NULL, 0, e);
}

int ps_batch_init_cache_async(struct ps_batch *b, const struct ps_batch_spec *sp,
                              const struct ps_wcache_dir *cache, int *how, struct ps_err *warn,
                              struct ps_err *e)
{
	return init(b, sp, cache, how, warn, 1, e);
}

void ps_batch_finish_store(struct ps_batch *b, int *how, struct ps_err *warn)
{
	ps_wcache_store_finish(b->pending, how, warn);
	b->pending = NULL;
}

void ps_batch_free(struct ps_batch *b)
{
	ps_batch_finish_store(b, NULL, NULL);
	ps_weights_free(&b->w);
	memset(b, 0, sizeof *b);
}

struct job {
	const struct ps_batch *b;
	size_t n;
	int (*load)(void *ctx, size_t i, struct ps_picture *pic, struct ps_err *e);
	const char *(*name)(void *ctx, size_t i);
	void *ctx;
	struct ps_batch_result *out;
	const char *const *paths;   /* files: read and integrated row by row */
	int inner;                  /* threads for one picture's rows */
	const uint8_t *first;       /* paths[0]'s bytes, read already (or NULL) */
	size_t first_len;
	pthread_mutex_t mu;
	size_t next;        /* under mu */
	long failed;        /* under mu */
};

static void one(struct job *j, size_t i)
{
	const struct ps_batch *b = j->b;
	struct ps_batch_result *r = &j->out[i];
	struct ps_picture pic;
	struct ps_view view;
	char key[sizeof b->w.key], nbuf[32];
	const char *name = j->name ? j->name(j->ctx, i) : NULL;
	if (!name) {
		snprintf(nbuf, sizeof nbuf, "picture %zu", i);
		name = nbuf;
	}
	memset(r, 0, sizeof *r);
	r->status = PS_BATCH_FAILED;
	if (j->load(j->ctx, i, &pic, &r->err) != 0)
		return;
	r->width = pic.width;
	r->height = pic.height;
	if (ps_picview_fisheye(&pic, name, &view, &r->view_assumed, &r->err) != 0)
		goto out;
	if (pic.width != b->w.width || pic.height != b->w.height) {
		r->status = PS_BATCH_MISMATCH;
		ps_err_set(&r->err, PS_EINVAL, "%s: picture is %d x %d, the batch's weights are for %d x %d",
		           name, pic.width, pic.height, b->w.width, b->w.height);
		goto out;
	}
	ps_weights_key(b->sens, b->rotation, &view, pic.width, pic.height, b->method, key, sizeof key);
	if (strcmp(key, b->w.key) != 0) {
		char vs[400];
		r->status = PS_BATCH_MISMATCH;
		ps_view_format(&view, vs, sizeof vs);
		ps_err_set(&r->err, PS_EINVAL, "%s: its view (%s) is not the batch's", name, vs);
		goto out;
	}
	if (ps_integrate(&b->w, &pic, b->coef, &r->r, &r->err) != 0) {
		char msg[sizeof r->err.msg];
		memcpy(msg, r->err.msg, sizeof msg);
		ps_err_set(&r->err, r->err.code, "%.200s: %.300s", name, msg);
		goto out;
	}
	r->status = PS_BATCH_OK;
out:
	ps_picture_free(&pic);
}

/* A file: the header first (size and view), then decoding fused with the
 * integration (sim/weights/stream.h), which gives ps_integrate's numbers exactly. */
static void one_file(struct job *j, size_t i)
{
	const struct ps_batch *b = j->b;
	struct ps_batch_result *r = &j->out[i];
	const char *name = j->paths[i];
	struct ps_fileio_map m;
	struct ps_picture head;
	struct ps_view view;
	char key[sizeof b->w.key];
	size_t off;
	memset(r, 0, sizeof *r);
	r->status = PS_BATCH_FAILED;
	/* 4 GiB: more than the largest picture accepted could need */
	if (i == 0 && j->first) {   /* given: a pipe cannot be read twice */
		memset(&m, 0, sizeof m);
		m.data = j->first;
		m.len = j->first_len;
	} else if (ps_fileio_map(name, (size_t)4 << 30, &m, &r->err) != 0) {
		return;
	}
	if (ps_picture_head_mem(&head, m.data, m.len, name, &off, &r->err) != 0) {
		ps_fileio_unmap(&m);
		return;
	}
	r->width = head.width;
	r->height = head.height;
	if (ps_picview_fisheye(&head, name, &view, &r->view_assumed, &r->err) != 0)
		goto out;
	if (head.width != b->w.width || head.height != b->w.height) {
		r->status = PS_BATCH_MISMATCH;
		ps_err_set(&r->err, PS_EINVAL, "%s: picture is %d x %d, the batch's weights are for %d x %d",
		           name, head.width, head.height, b->w.width, b->w.height);
		goto out;
	}
	ps_weights_key(b->sens, b->rotation, &view, head.width, head.height, b->method, key,
	               sizeof key);
	if (strcmp(key, b->w.key) != 0) {
		char vs[400];
		r->status = PS_BATCH_MISMATCH;
		ps_view_format(&view, vs, sizeof vs);
		ps_err_set(&r->err, PS_EINVAL, "%s: its view (%s) is not the batch's", name, vs);
		goto out;
	}
	if (ps_stream_integrate(&b->w, &head, m.data, m.len, off, name, b->coef, j->inner, &r->r,
	                        &r->err) != 0)
		goto out;
	r->status = PS_BATCH_OK;
out:
	ps_picture_free(&head);
	ps_fileio_unmap(&m);
}

static void *worker(void *arg)
{
	struct job *j = arg;
	for (;;) {
		size_t i;
		pthread_mutex_lock(&j->mu);
		i = j->next < j->n ? j->next++ : j->n;
		pthread_mutex_unlock(&j->mu);
		if (i >= j->n)
			break;
		if (j->paths)
			one_file(j, i);
		else
			one(j, i);
		if (j->out[i].status != PS_BATCH_OK) {
			pthread_mutex_lock(&j->mu);
			j->failed++;
			pthread_mutex_unlock(&j->mu);
		}
	}
	return NULL;
}

static long run(const struct ps_batch *b, size_t n,
                int (*load)(void *ctx, size_t i, struct ps_picture *pic, struct ps_err *e),
                const char *(*name)(void *ctx, size_t i), void *ctx, const char *const *paths,
                const uint8_t *first, size_t first_len, struct ps_batch_result *out,
                struct ps_err *e)
{
	struct job j = { .b = b, .n = n, .load = load, .name = name, .ctx = ctx, .out = out,
	                 .paths = paths, .inner = 1, .first = first, .first_len = first_len };
	pthread_t th[PS_BATCH_THREADS_MAX];
	int nt = b->nthreads > 0 ? b->nthreads : PS_BATCH_THREADS_DEFAULT, started = 0, rc;
	if (nt > PS_BATCH_THREADS_MAX)
		nt = PS_BATCH_THREADS_MAX;
	if ((size_t)nt > n) {   /* fewer pictures than threads: the rest share their rows */
		j.inner = n ? nt / (int)n : 1;
		nt = (int)n;
	}
	if ((rc = pthread_mutex_init(&j.mu, NULL)) != 0) {
		errno = rc;
		return ps_err_sys(e, "batch: mutex");
	}
	/* the calling thread is one of the workers; a thread that cannot be
	 * started only leaves more pictures to the others */
	for (; started < nt - 1; started++)
		if ((rc = pthread_create(&th[started], NULL, worker, &j)) != 0)
			break;
	worker(&j);
	for (int t = 0; t < started; t++)
		pthread_join(th[t], NULL);
	pthread_mutex_destroy(&j.mu);
	return j.failed;
}

long ps_batch_run(const struct ps_batch *b, size_t n,
                  int (*load)(void *ctx, size_t i, struct ps_picture *pic, struct ps_err *e),
                  const char *(*name)(void *ctx, size_t i), void *ctx,
                  struct ps_batch_result *out, struct ps_err *e)
{
	return run(b, n, load, name, ctx, NULL, NULL, 0, out, e);
}

long ps_batch_run_files(const struct ps_batch *b, const char *const *paths, size_t n,
                        struct ps_batch_result *out, struct ps_err *e)
{
	return run(b, n, NULL, NULL, NULL, paths, NULL, 0, out, e);
}

long ps_batch_run_files_first(const struct ps_batch *b, const char *const *paths, size_t n,
                              const uint8_t *first, size_t first_len,
                              struct ps_batch_result *out, struct ps_err *e)
{
	return run(b, n, NULL, NULL, NULL, paths, first, first_len, out, e);
}
