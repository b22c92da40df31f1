/* SPDX-License-Identifier: ISC */
#include "dcset.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "batch.h"
#include "dcpic.h"
#include "integrate.h"
#include "patches.h"
#include "picture.h"
#include "sum.h"
#include "weights.h"

static int exists(const char *path)
{
	struct stat st;
	return stat(path, &st) == 0;
}

void ps_dcset_row_free(struct ps_dcset_row *row)
{
	if (!row)
		return;
	free(row->c);
	memset(row, 0, sizeof *row);
}

/* Check a set's files without reading them: every patch present, the count
 * a subdivision's (mf > 0: that one's; 0: any).  *n gets the count, *mf_out
 * the subdivision.  Errors name the pattern and the first missing patch's
 * file, or the count and the counts that would do. */
static int ps_dcset_count(const char *pattern, int mf, int *n, int *mf_out, struct ps_err *e)
{
	char path[4096];
	int want = mf > 0 ? ps_patches_count(mf) : 0, count = 0, limit;
	if (mf < 0 || mf > PS_PATCHES_MF_MAX)
		return ps_err_set(e, PS_ERANGE, "%s: MF %d is not 1 to %d", pattern, mf, PS_PATCHES_MF_MAX);
	limit = ps_patches_count(PS_PATCHES_MF_MAX);
	/* the contiguous run from patch 0 */
	for (;;) {
		if (ps_dcpic_path(pattern, count, path, sizeof path, e) != 0)
			return -1;
		if (!exists(path) || count >= limit)
			break;
		count++;
	}
	if (want) {
		if (count < want)
			return ps_err_set(e, PS_EMISSING, "%s: patch %d of %d (MF %d) is missing: %s", pattern,
			                  count, want, mf, path);
		if (count > want)
			return ps_err_set(e, PS_EFORMAT, "%s: %d pictures or more, MF %d has %d patches (found %s)",
			                  pattern, count, mf, want,
			                  (ps_dcpic_path(pattern, want, path, sizeof path, e), path));
	} else if (count == 0) {
		return ps_err_set(e, PS_EMISSING, "%s: no pictures (patch 0 would be %s)", pattern, path);
	} else if (ps_patches_mf_for_count(count) < 0) {
		/* a gap, or a count no subdivision has */
		int next = 0;
		for (int m = 1; m <= PS_PATCHES_MF_MAX && !next; m++)
			if (ps_patches_count(m) > count)
				next = ps_patches_count(m);
		return ps_err_set(e, PS_EFORMAT, "%s: %d pictures (patches 0 to %d) match no MF (146, 578, "
		                  "2306, 5186 for MF 1, 2, 4, 6); if the set has %d, patch %d is missing: %s",
		                  pattern, count, count - 1, next, count, path);
	}
	*n = count;
	*mf_out = ps_patches_mf_for_count(count);
	return 0;
}

/* What the batch's loader needs: the set's pattern and view (its pictures
 * carry none: the view given is written into each as it is read), and
 * patch 0, read already for the size. */
struct dc_load {
	const char *pattern;
	char view[400];
	struct ps_picture first;
	int have_first;
	char (*names)[4096];
};

static int dc_load_pic(void *ctx, size_t i, struct ps_picture *pic, struct ps_err *e)
{
	struct dc_load *l = ctx;
	char *view = strdup(l->view);
	if (!view)
		return ps_err_set(e, PS_ENOMEM, "%s: out of memory", l->names[i]);
	if (i == 0 && l->have_first) {
		/* patch 0's picture goes to the one thread that asks for it */
		*pic = l->first;
		l->have_first = 0;
	} else if (ps_picture_read(pic, l->names[i], e) != 0) {
		free(view);
		return -1;
	}
	free(pic->view);
	pic->view = view;
	return 0;
}

static const char *dc_name(void *ctx, size_t i)
{
	return ((struct dc_load *)ctx)->names[i];
}

int ps_dcset_row(const char *pattern, const struct ps_view *v, int mf, const struct ps_sensor *s,
                 double rotation, struct ps_dcset_row *row, struct ps_err *e)
{
	static const double none[3] = { 1, 1, 1 };
	struct dc_load l;
	struct ps_batch b;
	struct ps_batch_result *res = NULL;
	int n = 0, m = 0, rc = 0;
	memset(row, 0, sizeof *row);
	memset(&l, 0, sizeof l);
	if (ps_view_check_fisheye(v, pattern, e) != 0 || ps_dcset_count(pattern, mf, &n, &m, e) != 0)
		return -1;
	row->c = calloc((size_t)n * 3, sizeof *row->c);
	l.names = calloc((size_t)n, sizeof *l.names);
	res = calloc((size_t)n, sizeof *res);
	if (!row->c || !l.names || !res) {
		free(l.names);
		free(res);
		ps_dcset_row_free(row);
		return ps_err_set(e, PS_ENOMEM, "%s: out of memory for %d pictures", pattern, n);
	}
	row->n = n;
	row->mf = m;
	l.pattern = pattern;
	ps_view_format(v, l.view, sizeof l.view);
	for (int p = 0; p < n; p++)
		ps_dcpic_path(pattern, p, l.names[p], sizeof l.names[p], e);
	if (ps_picture_read(&l.first, l.names[0], e) != 0) {
		rc = -1;
		goto out;
	}
	l.have_first = 1;
	row->width = l.first.width;
	row->height = l.first.height;
	/* the weights once, the pictures read and integrated in parallel */
	struct ps_batch_spec sp = {
		.map = { .sensor = s, .rotation_deg = rotation, .view = v, .width = row->width,
		         .height = row->height, .method = PS_W_EXACT },
		.coef = none,
		.nthreads = 0,
	};
	if (ps_batch_init(&b, &sp, e) != 0) {
		rc = -1;
		goto out;
	}
	row->coverage = b.w.coverage;
	if (ps_batch_run(&b, (size_t)n, dc_load_pic, dc_name, &l, res, e) < 0)
		rc = -1;
	for (int p = 0; p < n && rc == 0; p++) {
		const struct ps_batch_result *r = &res[p];
		if (r->status == PS_BATCH_OK) {
			memcpy(row->c + 3 * p, r->r.rgb, 3 * sizeof *row->c);
		} else if (r->width > 0 && (r->width != row->width || r->height != row->height)) {
			rc = ps_err_set(e, PS_EFORMAT, "%s: patch %d is %d x %d, patch 0 (%s) is %d x %d: "
			                "one set, one size", l.names[p], p, r->width, r->height, l.names[0],
			                row->width, row->height);
		} else if (!strstr(r->err.msg, l.names[p])) {
			rc = ps_err_set(e, r->err.code, "%s (patch %d): %s", l.names[p], p, r->err.msg);
		} else {
			rc = ps_err_set(e, r->err.code, "%s (patch %d)", r->err.msg, p);
		}
	}
	ps_batch_free(&b);
out:
	if (l.have_first)
		ps_picture_free(&l.first);
	free(l.names);
	free(res);
	if (rc != 0)
		ps_dcset_row_free(row);
	return rc;
}

double ps_dcset_row_apply(const struct ps_dcset_row *row, const double coef[3], const double *sky)
{
	struct ps_sum s;
	ps_sum_init(&s);
	for (int p = 0; p < row->n; p++)
		for (int c = 0; c < 3; c++)
			ps_sum_add(&s, coef[c] * row->c[3 * p + c] * sky[3 * p + c]);
	return ps_sum_get(&s);
}

double ps_dcset_row_apply_list(const struct ps_dcset_row *row, const double coef[3], const double *sky,
                               const int *list, int nlist)
{
	struct ps_sum s;
	ps_sum_init(&s);
	for (int i = 0; i < nlist; i++) {
		int p = list[i];
		for (int c = 0; c < 3; c++)
			ps_sum_add(&s, coef[c] * row->c[3 * p + c] * sky[3 * p + c]);
	}
	return ps_sum_get(&s);
}
