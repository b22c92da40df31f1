/* SPDX-License-Identifier: ISC */
#include "stream.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "sum.h"

enum { MAX_THREADS = 16 };
#define RELEASE_MIN ((size_t)64 << 20)   /* maps from 64 MiB up are released row by row */

/* What one run (one row) gives; merged in run order afterwards. */
struct acc {
	struct ps_sum row;
	double rc[3];
	double best;
	int bx;
	size_t n;
};

struct job {
	const struct ps_weights *w;
	const struct ps_picture *head;
	const uint8_t *data;
	size_t len;
	const char *name;
	double k[3][3];
	double kc[3];         /* coef^T k */
	uintptr_t page;       /* the page size */
	const double *coef;
	const int *row_run;   /* row -> run index, -1: none */
	const uint8_t *want;  /* row has weights */
	struct acc *acc;      /* per run */
	double *contrib;      /* second pass: every contribution, in run order */
	const size_t *coff;   /* second pass: each run's first contribution */
};

/* Weights mapped from the cache are read once a row: the pages a row has
 * used leave this process's resident set (they stay in the page cache, and
 * a neighbouring row that shares a page faults it back), so a large map is
 * never resident whole.  Maps under RELEASE_MIN stay resident. */
static void release(const struct ps_weights *w, const struct ps_wrun *run, uintptr_t page)
{
	uintptr_t a, b;
	/* small maps stay: a batch would fault them in again for every picture */
	if (!w->map || w->maplen < RELEASE_MIN || run->n <= 0)
		return;
	a = (uintptr_t)(w->w + run->off) & ~(page - 1);
	b = ((uintptr_t)(w->w + run->off + (size_t)ps_wrun_stored(w, run)) + page - 1) & ~(page - 1);
	madvise((void *)a, b - a, MADV_DONTNEED);
}

static int row_sum(void *ctx, int y, const uint8_t *px_row)
{
	struct job *j = ctx;
	int ri = j->row_run[y];
	const struct ps_wrun *run = &j->w->runs[ri];
	const uint8_t *px = px_row + 4 * (size_t)run->x0;
	const double *wt = j->w->w + run->off;
	struct acc *a = &j->acc[ri];
	double raws[3] = { 0, 0, 0 }, best = -1.0, kc[3] = { j->kc[0], j->kc[1], j->kc[2] };
	/* the row's sum, count and brightest in locals: px (bytes) may alias
	 * anything, so through a they would go to memory at every pixel */
	struct ps_sum row;
	size_t n = 0;
	int bx = 0, len = run->n;
	/* a compact map's run is a palindrome: its right half reads the left
	 * backwards (mirror, 0 for a full map) */
	int half = j->w->mirror ? (len + 1) / 2 : len;
	ps_sum_init(&row);
	for (int i = 0; i < len; i++, px += 4) {
		double b;
		if (px[3] == 0)
			continue;
		b = ps_pixel_response(px, i < half ? wt[i] : wt[len - 1 - i], kc, raws);
		ps_sum_add(&row, b);
		n++;
		if (b > best) {
			best = b;
			bx = run->x0 + i;
		}
	}
	a->row = row;
	a->n = n;
	a->best = best;
	a->bx = bx;
	ps_row_rgb(j->k, raws, a->rc);
	release(j->w, run, j->page);
	return 0;
}

/* The same pixels again, keeping each contribution (ps_integrate's second
 * pass, in its order). */
static int row_contrib(void *ctx, int y, const uint8_t *px_row)
{
	struct job *j = ctx;
	int ri = j->row_run[y];
	const struct ps_wrun *run = &j->w->runs[ri];
	const uint8_t *px = px_row + 4 * (size_t)run->x0;
	double *out = j->contrib + j->coff[ri];
	for (int i = 0; i < run->n; i++, px += 4) {
		double raws[3] = { 0, 0, 0 };
		if (px[3] == 0)
			continue;
		*out++ = ps_pixel_response(px, ps_wrun_at(j->w, run, i), j->kc, raws);
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
	b->rc = ps_pic_scan_rows(b->j->head, b->j->data, b->j->len, b->j->name, b->off, b->y0, b->y1,
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
	size_t total = j->w->npix, done = 0;
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
			if (j->row_run[y] >= 0)
				done += (size_t)j->w->runs[j->row_run[y]].n;
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

int ps_integrate_mem(const struct ps_weights *w, const struct ps_picture *head,
                     const uint8_t *data, size_t len, size_t off, const char *name,
                     const double coef[3], int nthreads, struct ps_response *r,
                     struct ps_err *e)
{
	struct job j;
	int *row_run = NULL, rc = -1, nt = nthreads < 1 ? 1 : nthreads > MAX_THREADS ? MAX_THREADS
	                                                                             : nthreads;
	uint8_t *want = NULL;
	size_t *starts = NULL, *coff = NULL, ncontrib = 0;
	struct ps_sum tot, ch[3];
	double best = -1.0;
	memset(r, 0, sizeof *r);
	if (head->width != w->width || head->height != w->height)
		return ps_errf(e, PS_EINVAL, "picture is %d x %d, the weights are for %d x %d",
		               head->width, head->height, w->width, w->height);
	if (!ps_pic_is_standard(head)) {   /* rows are not scanlines: decode it whole */
		struct ps_picture pic;
		if (ps_pic_read_mem(&pic, data, len, name, e) != 0)
			return -1;
		rc = ps_integrate(w, &pic, coef, r, e);
		ps_pic_free(&pic);
		return rc;
	}
	memset(&j, 0, sizeof j);
	j.w = w;
	j.head = head;
	j.data = data;
	j.len = len;
	j.name = name;
	j.coef = coef;
	ps_pic_rgb_matrix(head, j.k);
	ps_coef_k(coef, j.k, j.kc);
	{
		long ps = sysconf(_SC_PAGESIZE);
		j.page = ps > 0 ? (uintptr_t)ps : 4096;
	}
	row_run = malloc((size_t)head->height * sizeof *row_run);
	want = calloc((size_t)head->height, 1);
	j.acc = malloc((w->nruns ? w->nruns : 1) * sizeof *j.acc);
	if (nt > 1)
		starts = malloc((size_t)head->height * sizeof *starts);
	if (!row_run || !want || !j.acc || (nt > 1 && !starts)) {
		ps_errf(e, PS_ENOMEM, "%s: out of memory", name);
		goto out;
	}
	for (int y = 0; y < head->height; y++)
		row_run[y] = -1;
	for (size_t ri = 0; ri < w->nruns; ri++) {
		if (row_run[w->runs[ri].row] >= 0) {   /* one run a row is what the maps are */
			ps_errf(e, PS_EINVAL, "%s: two weight runs on row %d", name, w->runs[ri].row);
			goto out;
		}
		row_run[w->runs[ri].row] = (int)ri;
		want[w->runs[ri].row] = 1;
		memset(&j.acc[ri], 0, sizeof j.acc[ri]);
		ps_sum_init(&j.acc[ri].row);
	}
	j.row_run = row_run;
	j.want = want;
	/* one pass for the scanline starts, then the bands in parallel */
	if (nt > 1 && ps_pic_scanline_starts(head, data, len, name, off, starts, e) != 0)
		goto out;
	if (scan(&j, row_sum, nt, starts, off, e) != 0)
		goto out;
	ps_sum_init(&tot);
	for (int c = 0; c < 3; c++)
		ps_sum_init(&ch[c]);
	for (size_t ri = 0; ri < w->nruns; ri++) {
		struct acc *a = &j.acc[ri];
		ps_sum_merge(&tot, &a->row);
		for (int c = 0; c < 3; c++)
			ps_sum_add(&ch[c], a->rc[c]);
		if (a->n && a->best > best) {
			best = a->best;
			r->brightest_x = a->bx;
			r->brightest_row = w->runs[ri].row;
		}
		ncontrib += a->n;
	}
	r->response = ps_sum_get(&tot);
	for (int c = 0; c < 3; c++)
		r->rgb[c] = ps_sum_get(&ch[c]);
	r->solid_angle = w->solid_angle;
	r->npixels = ncontrib;
	r->top1_share = NAN;
	if (r->response > 0 && ncontrib > 0)
		r->brightest_share = best / r->response;
	if (r->response > 0 && ncontrib > 0 && r->brightest_share > 0.001) {
		size_t at = 0;
		coff = malloc((w->nruns ? w->nruns : 1) * sizeof *coff);
		j.contrib = malloc(ncontrib * sizeof *j.contrib);
		if (!coff || !j.contrib) {
			ps_errf(e, PS_ENOMEM, "%s: out of memory", name);
			goto out;
		}
		for (size_t ri = 0; ri < w->nruns; ri++) {
			coff[ri] = at;
			at += j.acc[ri].n;
		}
		j.coff = coff;
		if (scan(&j, row_contrib, nt, starts, off, e) != 0)
			goto out;
		r->top1_share = ps_top1_share(j.contrib, ncontrib, r->response);
	}
	rc = 0;
out:
	free(row_run);
	free(want);
	free(j.acc);
	free(starts);
	free(coff);
	free(j.contrib);
	return rc;
}
