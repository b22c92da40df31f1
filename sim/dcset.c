#include "dcset.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

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

void ps_dcrow_free(struct ps_dcrow *row)
{
	if (!row)
		return;
	free(row->c);
	memset(row, 0, sizeof *row);
}

int ps_dcset_count(const char *pattern, int mf, int *n, int *mf_out, struct ps_err *e)
{
	char path[4096];
	int want = mf > 0 ? ps_patches_count(mf) : 0, count = 0, limit;
	if (mf < 0 || mf > PS_PATCHES_MF_MAX)
		return ps_errf(e, PS_ERANGE, "%s: MF %d is not 1 to %d", pattern, mf, PS_PATCHES_MF_MAX);
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
			return ps_errf(e, PS_EMISSING, "%s: patch %d of %d (MF %d) is missing: %s", pattern,
			               count, want, mf, path);
		if (count > want)
			return ps_errf(e, PS_EFORMAT, "%s: %d pictures or more, MF %d has %d patches (found %s)",
			               pattern, count, mf, want,
			               (ps_dcpic_path(pattern, want, path, sizeof path, e), path));
	} else if (count == 0) {
		return ps_errf(e, PS_EMISSING, "%s: no pictures (patch 0 would be %s)", pattern, path);
	} else if (ps_patches_mf_for_count(count) < 0) {
		/* a gap, or a count no subdivision has */
		int next = 0;
		for (int m = 1; m <= PS_PATCHES_MF_MAX && !next; m++)
			if (ps_patches_count(m) > count)
				next = ps_patches_count(m);
		return ps_errf(e, PS_EFORMAT, "%s: %d pictures (patches 0 to %d) match no MF (146, 578, "
		               "2306, 5186 for MF 1, 2, 4, 6); if the set has %d, patch %d is missing: %s",
		               pattern, count, count - 1, next, count, path);
	}
	*n = count;
	*mf_out = ps_patches_mf_for_count(count);
	return 0;
}

int ps_dcset_row(const char *pattern, const struct ps_view *v, int mf, const struct ps_sensor *s,
                 double rotation, struct ps_dcrow *row, struct ps_err *e)
{
	static const double none[3] = { 1, 1, 1 };
	struct ps_weights w;
	int n, m, have_w = 0, rc = 0;
	char path[4096], first[4096];
	memset(row, 0, sizeof *row);
	memset(&w, 0, sizeof w);
	if (ps_view_check_fisheye(v, pattern, e) != 0 || ps_dcset_count(pattern, mf, &n, &m, e) != 0)
		return -1;
	row->c = calloc((size_t)n * 3, sizeof *row->c);
	if (!row->c)
		return ps_errf(e, PS_ENOMEM, "%s: out of memory for %d coefficients", pattern, n);
	row->n = n;
	row->mf = m;
	for (int p = 0; p < n && rc == 0; p++) {
		struct ps_picture pic;
		struct ps_response r;
		ps_dcpic_path(pattern, p, path, sizeof path, e);
		if (ps_pic_read(&pic, path, e) != 0) {
			rc = -1;
			break;
		}
		if (p == 0) {
			snprintf(first, sizeof first, "%s", path);
			rc = ps_weights_build(&w, s, rotation, v, pic.width, pic.height, PS_W_EXACT, e);
			have_w = rc == 0;
			row->width = pic.width;
			row->height = pic.height;
			row->coverage = have_w ? w.coverage : 0;
		} else if (pic.width != row->width || pic.height != row->height) {
			rc = ps_errf(e, PS_EFORMAT, "%s: patch %d is %d x %d, patch 0 (%s) is %d x %d: one "
			             "set, one size", path, p, pic.width, pic.height, first, row->width,
			             row->height);
		}
		if (rc == 0 && (rc = ps_integrate(&w, &pic, none, &r, e)) == 0)
			memcpy(row->c + 3 * p, r.rgb, 3 * sizeof *row->c);
		else if (rc != 0 && e->msg[0] && !strstr(e->msg, path)) {
			char msg[sizeof e->msg];
			snprintf(msg, sizeof msg, "%s", e->msg);
			ps_errf(e, e->code, "%s (patch %d): %s", path, p, msg);
		}
		ps_pic_free(&pic);
	}
	if (have_w)
		ps_weights_free(&w);
	if (rc != 0)
		ps_dcrow_free(row);
	return rc;
}

double ps_dcrow_apply(const struct ps_dcrow *row, const double coef[3], const double *sky)
{
	struct ps_sum s;
	ps_sum_init(&s);
	for (int p = 0; p < row->n; p++)
		for (int c = 0; c < 3; c++)
			ps_sum_add(&s, coef[c] * row->c[3 * p + c] * sky[3 * p + c]);
	return ps_sum_get(&s);
}

double ps_dcrow_apply_list(const struct ps_dcrow *row, const double coef[3], const double *sky,
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
