/* SPDX-License-Identifier: ISC */
#include "stream.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "rowsum.h"
#include "sum.h"

enum { MAX_THREADS = 16 };
#define RELEASE_MIN ((size_t)64 << 20)   /* maps from 64 MiB up are released after a picture */

/* What one run (one row) gives; merged in run order afterwards. */
struct acc {
	struct ps_sum row;
	double rc[3];
	double best;
	int bx;
	size_t n;
};

/* One weight map's part of a job (several maps share one decoding). */
struct one {
	const struct ps_weights *w;
	int *row_run;         /* row -> run index, -1: none */
	struct acc *acc;      /* per run */
	double *contrib;      /* second pass (NULL: not for this map): every contribution */
	size_t *coff;         /* second pass: each run's first contribution */
};

struct job {
	struct one *m;
	int nm;
	const struct ps_picture *head;
	const uint8_t *data;
	size_t len;
	const char *name;
	double k[3][3];
	double kc[3];         /* coef^T k */
	uintptr_t page;       /* the page size */
	const uint8_t *want;  /* row has weights in some map */
};

/* Weights mapped from the cache leave this process's resident set once
 * the picture has been read (they stay in the page cache), so a large map
 * held between pictures or periods is not resident.  Once a map, never a
 * row at a time: each madvise(MADV_DONTNEED) on a shared map is a TLB
 * shoot-down on every core, and one a row (4000 at 4000 x 4000) was most of
 * a warm run's system time.  Maps under RELEASE_MIN stay resident, and so
 * does a map just built in its new entry's mapping: resident already, and
 * read again by the entry's checksum (dropping its pages took a cold run
 * from 0.22 to 0.27 s). */
static void release(const struct ps_weights *w, uintptr_t page)
{
	uintptr_t a, b;
	/* small maps stay: a batch would fault them in again for every picture */
	if (!w->map || w->built_in_map || w->maplen < RELEASE_MIN || w->nruns == 0)
		return;
	a = (uintptr_t)w->map & ~(page - 1);
	b = ((uintptr_t)w->map + w->maplen + page - 1) & ~(page - 1);
	madvise((void *)a, b - a, MADV_DONTNEED);
}

static void row_sum_one(const struct job *j, const struct one *o, int ri, const uint8_t *px_row)
{
	const struct ps_weights_run *run = &o->w->runs[ri];
	struct acc *a = &o->acc[ri];
	struct ps_rowsum rs;
	ps_rowsum(px_row + 4 * (size_t)run->x0, o->w, run, j->kc, &rs);
	a->row = rs.sum;
	a->n = rs.n;
	a->best = rs.best;
	a->bx = run->x0 + rs.best_i;   /* read only when n > 0 (totals), then best_i >= 0 */
	ps_integrate_row_rgb(j->k, rs.raw, a->rc);
}

static int row_sum(void *ctx, int y, const uint8_t *px_row)
{
	const struct job *j = ctx;
	for (int k = 0; k < j->nm; k++)
		if (j->m[k].row_run[y] >= 0)
			row_sum_one(j, &j->m[k], j->m[k].row_run[y], px_row);
	return 0;
}

/* The same pixels again, keeping each contribution (ps_integrate's second
 * pass, in its order). */
static int row_contrib(void *ctx, int y, const uint8_t *px_row)
{
	const struct job *j = ctx;
	for (int k = 0; k < j->nm; k++) {
		const struct one *o = &j->m[k];
		int ri = o->row_run[y];
		const struct ps_weights_run *run;
		const uint8_t *px;
		double *out;
		if (ri < 0 || !o->contrib)
			continue;
		run = &o->w->runs[ri];
		px = px_row + 4 * (size_t)run->x0;
		out = o->contrib + o->coff[ri];
		for (int i = 0; i < run->n; i++, px += 4) {
			double raws[3] = { 0, 0, 0 };
			if (px[3] == 0)
				continue;
			*out++ = ps_integrate_pixel_response(px, ps_weights_run_at(o->w, run, i), j->kc, raws);
		}
	}
	return 0;
}

struct band {
	struct job *j;
	int (*fn)(void *, int, const uint8_t *);
	int y0, y1;
	size_t off;
	struct ps_err e;
	int rc;
};

static void *band_run(void *arg)
{
	struct band *b = arg;
	b->rc = ps_picture_scan_rows(b->j->head, b->j->data, b->j->len, b->j->name, b->off, b->y0, b->y1,
	                             b->j->want, b->fn, b->j, &b->e);
	return NULL;
}

/* Scan every row with fn, in nt bands of about equal weighted pixels. */
static int scan(struct job *j, int (*fn)(void *, int, const uint8_t *), int nt,
                const size_t *starts, size_t off, struct ps_err *e)
{
	struct band bands[MAX_THREADS];
	pthread_t tid[MAX_THREADS];
	int started[MAX_THREADS] = { 0 }, h = j->head->height, y = 0, rc = 0;
	size_t total = 0, done = 0;
	for (int k = 0; k < j->nm; k++)
		total += j->m[k].w->npix;
	if (nt <= 1 || !starts) {
		struct band b = { j, fn, 0, h, off, { 0 }, 0 };
		band_run(&b);
		if (b.rc)
			*e = b.e;
		return b.rc;
	}
	for (int t = 0; t < nt; t++) {
		size_t want = total * (size_t)(t + 1) / (size_t)nt;
		bands[t] = (struct band){ j, fn, y, y, starts[y < h ? y : h - 1], { 0 }, 0 };
		while (y < h && (t == nt - 1 || done < want)) {
			for (int k = 0; k < j->nm; k++)
				if (j->m[k].row_run[y] >= 0)
					done += (size_t)j->m[k].w->runs[j->m[k].row_run[y]].n;
			y++;
		}
		bands[t].y1 = y;
	}
	for (int t = 1; t < nt; t++)
		started[t] = bands[t].y1 > bands[t].y0 &&
		             pthread_create(&tid[t], NULL, band_run, &bands[t]) == 0;
	if (bands[0].y1 > bands[0].y0)
		band_run(&bands[0]);
	for (int t = 1; t < nt; t++) {
		if (started[t])
			pthread_join(tid[t], NULL);
		else if (bands[t].y1 > bands[t].y0)
			band_run(&bands[t]);
	}
	for (int t = 0; t < nt; t++)
		if (bands[t].rc && !rc) {   /* the first band's error: the earliest byte */
			rc = bands[t].rc;
			*e = bands[t].e;
		}
	return rc;
}

/* Map k's totals from its runs' accumulators (in run order, as
 * ps_integrate merges its rows). */
static void totals(const struct one *o, struct ps_response *r, size_t *ncontrib, double *best)
{
	struct ps_sum tot, ch[3];
	const struct ps_weights *w = o->w;
	ps_sum_init(&tot);
	for (int c = 0; c < 3; c++)
		ps_sum_init(&ch[c]);
	*best = -1.0;
	*ncontrib = 0;
	for (size_t ri = 0; ri < w->nruns; ri++) {
		struct acc *a = &o->acc[ri];
		ps_sum_merge(&tot, &a->row);
		for (int c = 0; c < 3; c++)
			ps_sum_add(&ch[c], a->rc[c]);
		if (a->n && a->best > *best) {
			*best = a->best;
			r->brightest_x = a->bx;
			r->brightest_row = w->runs[ri].row;
		}
		*ncontrib += a->n;
	}
	r->response = ps_sum_get(&tot);
	for (int c = 0; c < 3; c++)
		r->rgb[c] = ps_sum_get(&ch[c]);
	r->solid_angle = w->solid_angle;
	r->npixels = *ncontrib;
	r->top1_share = NAN;
	if (r->response > 0 && *ncontrib > 0)
		r->brightest_share = *best / r->response;
}

int ps_stream_integrate(const struct ps_weights *w, const struct ps_picture *head,
                        const uint8_t *data, size_t len, size_t off, const char *name,
                        const double coef[3], int nthreads, struct ps_response *r,
                        struct ps_err *e)
{
	return ps_stream_integrate_multi(&w, 1, head, data, len, off, name, coef, nthreads, r, e);
}

int ps_stream_integrate_multi(const struct ps_weights *const *ws, int nmaps,
                              const struct ps_picture *head, const uint8_t *data, size_t len,
                              size_t off, const char *name, const double coef[3], int nthreads,
                              struct ps_response *rs, struct ps_err *e)
{
	struct job j;
	int rc = -1, second = 0, nt = nthreads < 1 ? 1 : nthreads > MAX_THREADS ? MAX_THREADS
	                                                                        : nthreads;
	uint8_t *want = NULL;
	size_t *starts = NULL;
	size_t *ncontrib = NULL;
	double *best = NULL;
	for (int k = 0; k < nmaps; k++) {
		memset(&rs[k], 0, sizeof rs[k]);
		if (head->width != ws[k]->width || head->height != ws[k]->height)
			return ps_err_set(e, PS_EINVAL, "picture is %d x %d, the weights are for %d x %d",
			                  head->width, head->height, ws[k]->width, ws[k]->height);
	}
	if (!ps_picture_is_standard(head)) {   /* rows are not scanlines: decode it whole */
		struct ps_picture pic;
		if (ps_picture_read_mem(&pic, data, len, name, e) != 0)
			return -1;
		rc = 0;
		for (int k = 0; k < nmaps && rc == 0; k++)
			rc = ps_integrate(ws[k], &pic, coef, &rs[k], e);
		ps_picture_free(&pic);
		return rc;
	}
	memset(&j, 0, sizeof j);
	j.head = head;
	j.data = data;
	j.len = len;
	j.name = name;
	j.nm = nmaps;
	ps_integrate_pic_matrix(head, j.k);
	ps_integrate_coef_k(coef, j.k, j.kc);
	{
		long ps = sysconf(_SC_PAGESIZE);
		j.page = ps > 0 ? (uintptr_t)ps : 4096;
	}
	j.m = calloc((size_t)nmaps + 1, sizeof *j.m);
	want = calloc((size_t)head->height, 1);
	ncontrib = calloc((size_t)nmaps + 1, sizeof *ncontrib);
	best = calloc((size_t)nmaps + 1, sizeof *best);
	if (nt > 1)
		starts = malloc((size_t)head->height * sizeof *starts);
	if (!j.m || !want || !ncontrib || !best || (nt > 1 && !starts)) {
		ps_err_set(e, PS_ENOMEM, "%s: out of memory", name);
		goto out;
	}
	for (int k = 0; k < nmaps; k++) {
		struct one *o = &j.m[k];
		const struct ps_weights *w = ws[k];
		o->w = w;
		o->row_run = malloc((size_t)head->height * sizeof *o->row_run);
		o->acc = malloc((w->nruns ? w->nruns : 1) * sizeof *o->acc);
		if (!o->row_run || !o->acc) {
			ps_err_set(e, PS_ENOMEM, "%s: out of memory", name);
			goto out;
		}
		for (int y = 0; y < head->height; y++)
			o->row_run[y] = -1;
		for (size_t ri = 0; ri < w->nruns; ri++) {
			if (o->row_run[w->runs[ri].row] >= 0) {   /* one run a row is what the maps are */
				ps_err_set(e, PS_EINVAL, "%s: two weight runs on row %d", name, w->runs[ri].row);
				goto out;
			}
			o->row_run[w->runs[ri].row] = (int)ri;
			want[w->runs[ri].row] = 1;
			memset(&o->acc[ri], 0, sizeof o->acc[ri]);
			ps_sum_init(&o->acc[ri].row);
		}
	}
	j.want = want;
	/* one pass for the scanline starts, then the bands in parallel */
	if (nt > 1 && ps_picture_scanline_starts(head, data, len, name, off, starts, e) != 0)
		goto out;
	if (scan(&j, row_sum, nt, starts, off, e) != 0)
		goto out;
	/* the brightest 1 % only matters when one pixel already stands out:
	 * only then a second pass collects every contribution */
	for (int k = 0; k < nmaps; k++) {
		struct one *o = &j.m[k];
		struct ps_response *r = &rs[k];
		totals(o, r, &ncontrib[k], &best[k]);
		if (ps_integrate_check_finite(r, coef, o->w->sens_sum, e) != 0) {
			char why[sizeof e->msg];
			snprintf(why, sizeof why, "%s", e->msg);
			ps_err_set(e, PS_ERANGE, "%s: %s", name, why);
			goto out;
		}
		if (r->response > 0 && ncontrib[k] > 0 && r->brightest_share > 0.001) {
			size_t at = 0;
			o->coff = malloc((o->w->nruns ? o->w->nruns : 1) * sizeof *o->coff);
			o->contrib = malloc(ncontrib[k] * sizeof *o->contrib);
			if (!o->coff || !o->contrib) {
				ps_err_set(e, PS_ENOMEM, "%s: out of memory", name);
				goto out;
			}
			for (size_t ri = 0; ri < o->w->nruns; ri++) {
				o->coff[ri] = at;
				at += o->acc[ri].n;
			}
			second = 1;
		}
	}
	if (second) {
		if (scan(&j, row_contrib, nt, starts, off, e) != 0)
			goto out;
		for (int k = 0; k < nmaps; k++)
			if (j.m[k].contrib)
				rs[k].top1_share = ps_integrate_top1_share(j.m[k].contrib, ncontrib[k], rs[k].response);
	}
	rc = 0;
out:
	for (int k = 0; k < nmaps; k++)
		release(ws[k], j.page);
	for (int k = 0; j.m && k < nmaps; k++) {
		free(j.m[k].row_run);
		free(j.m[k].acc);
		free(j.m[k].contrib);
		free(j.m[k].coff);
	}
	free(j.m);
	free(want);
	free(starts);
	free(ncontrib);
	free(best);
	return rc;
}
