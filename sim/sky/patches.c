/* SPDX-License-Identifier: ISC */
#include "patches.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* patches per Tregenza band, horizon to the top */
static const int band_count[7] = { 30, 30, 24, 24, 18, 12, 6 };

int ps_patches_count(int mf)
{
	return 144 * mf * mf + 2;
}

int ps_patches_mf_for_count(int n)
{
	for (int mf = 1; mf <= PS_PATCHES_MF_MAX; mf++)
		if (ps_patches_count(mf) == n)
			return mf;
	return -1;
}

void ps_patches_free(struct ps_patches *p)
{
	if (!p)
		return;
	free(p->row_count);
	free(p->row_first);
	free(p->alt);
	free(p->azi);
	free(p->omega);
	free(p->dir);
	free(p->row);
	memset(p, 0, sizeof *p);
}

int ps_patches_init(struct ps_patches *p, int mf, struct ps_err *e)
{
	int k = 1;
	memset(p, 0, sizeof *p);
	if (mf < 1 || mf > PS_PATCHES_MF_MAX)
		return ps_err_set(e, PS_EINVAL, "sky subdivision %d is not 1 to %d", mf, PS_PATCHES_MF_MAX);
	p->mf = mf;
	p->n = ps_patches_count(mf);
	p->nrows = 7 * mf + 1;
	p->alpha = (M_PI / 2) / (7 * mf + 0.5);
	p->row_count = malloc((size_t)p->nrows * sizeof *p->row_count);
	p->row_first = malloc((size_t)p->nrows * sizeof *p->row_first);
	p->alt = malloc((size_t)p->n * sizeof *p->alt);
	p->azi = malloc((size_t)p->n * sizeof *p->azi);
	p->omega = malloc((size_t)p->n * sizeof *p->omega);
	p->dir = malloc((size_t)p->n * 3 * sizeof *p->dir);
	p->row = malloc((size_t)p->n * sizeof *p->row);
	if (!p->row_count || !p->row_first || !p->alt || !p->azi || !p->omega || !p->dir || !p->row) {
		ps_patches_free(p);
		return ps_err_set(e, PS_ENOMEM, "out of memory for %d sky patches", ps_patches_count(mf));
	}
	p->alt[0] = -M_PI / 2;
	p->azi[0] = 0.0;
	p->omega[0] = 2 * M_PI;
	p->row[0] = -1;
	for (int r = 0; r < p->nrows; r++) {
		int cap = r == p->nrows - 1, n = cap ? 1 : band_count[r / mf] * mf;
		double a0 = r * p->alpha, a1 = cap ? M_PI / 2 : (r + 1) * p->alpha;
		/* solid angle of the band, shared equally */
		double om = 2 * M_PI * (sin(a1) - sin(a0)) / n;
		p->row_count[r] = n;
		p->row_first[r] = k;
		for (int j = 0; j < n; j++, k++) {
			p->alt[k] = cap ? M_PI / 2 : (r + 0.5) * p->alpha;
			p->azi[k] = 2 * M_PI * j / n;
			p->omega[k] = om;
			p->row[k] = r;
		}
	}
	for (int i = 0; i < p->n; i++) {
		double c = cos(p->alt[i]);
		p->dir[3 * i + 0] = c * sin(p->azi[i]);
		p->dir[3 * i + 1] = c * cos(p->azi[i]);
		p->dir[3 * i + 2] = sin(p->alt[i]);
	}
	/* the cap and the ground are exact directions */
	p->dir[3 * (p->n - 1) + 0] = p->dir[3 * (p->n - 1) + 1] = 0.0;
	p->dir[3 * (p->n - 1) + 2] = 1.0;
	p->dir[0] = p->dir[1] = 0.0;
	p->dir[2] = -1.0;
	return 0;
}

int ps_patches_find(const struct ps_patches *p, const double d[3])
{
	double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), s, alt, azi, inc;
	int r, j, n;
	if (!(len > 0) || !(d[2] > 0))
		return 0;
	s = d[2] / len;
	alt = asin(s > 1.0 ? 1.0 : s);
	r = (int)floor(alt / p->alpha);
	if (r >= p->nrows - 1)
		return p->n - 1;
	n = p->row_count[r];
	azi = atan2(d[0], d[1]);
	if (azi < 0)
		azi += 2 * M_PI;
	inc = 2 * M_PI / n;
	j = (int)floor((azi + 0.5 * inc) / inc);
	if (j >= n || j < 0)
		j = 0;
	return p->row_first[r] + j;
}

void ps_patches_bounds(const struct ps_patches *p, int i, double b[4])
{
	int r = p->row[i];
	if (i <= 0 || i >= p->n) {
		b[0] = -M_PI / 2;
		b[1] = 0.0;
		b[2] = 0.0;
		b[3] = 2 * M_PI;
		return;
	}
	if (r == p->nrows - 1) {
		b[0] = r * p->alpha;
		b[1] = M_PI / 2;
		b[2] = 0.0;
		b[3] = 2 * M_PI;
		return;
	}
	b[0] = r * p->alpha;
	b[1] = (r + 1) * p->alpha;
	b[2] = p->azi[i] - M_PI / p->row_count[r];
	b[3] = p->azi[i] + M_PI / p->row_count[r];
}
