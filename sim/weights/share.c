/* SPDX-License-Identifier: ISC */
#include "share.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lum.h"
#include "sum.h"

int ps_share_compute(struct ps_share *s, const struct ps_weights *w, const struct ps_picture *pic,
                     const double coef[3], struct ps_err *e)
{
	struct ps_lum l;
	struct ps_sum tot;
	size_t npix = (size_t)pic->width * (size_t)pic->height;
	memset(s, 0, sizeof *s);
	if (pic->width != w->width || pic->height != w->height)
		return ps_err_set(e, PS_EINVAL, "picture is %d x %d, the weights are for %d x %d", pic->width,
		                  pic->height, w->width, w->height);
	s->share = calloc(npix ? npix : 1, sizeof *s->share);
	if (!s->share)
		return ps_err_set(e, PS_ENOMEM, "out of memory");
	s->width = pic->width;
	s->height = pic->height;
	ps_lum_init(&l, pic);
	ps_sum_init(&tot);
	for (size_t k = 0; k < w->nruns; k++) {
		const struct ps_weights_run *r = &w->runs[k];
		for (int i = 0; i < r->n; i++) {
			double rgb[3], b;
			ps_lum_rgb(&l, pic, r->x0 + i, r->row, rgb);
			b = ps_weights_run_at(w, r, i) * (coef[0] * rgb[0] + coef[1] * rgb[1] + coef[2] * rgb[2]);
			s->share[(size_t)r->row * (size_t)pic->width + (size_t)(r->x0 + i)] = b;
			ps_sum_add(&tot, b);
		}
	}
	s->response = ps_sum_get(&tot);
	if (!isfinite(s->response)) {
		ps_share_free(s);
		return ps_err_set(e, PS_ERANGE, "the response is %s: the colour coefficients (%g %g %g) "
		                  "times the picture's radiance overflow, or the sensor's weights do",
		                  isnan(s->response) ? "not a number" : "infinite", coef[0], coef[1], coef[2]);
	}
	if (s->response == 0) {
		ps_share_free(s);
		return ps_err_set(e, PS_ERANGE, "the response is 0: no share to give");
	}
	for (size_t p = 0; p < npix; p++)
		s->share[p] /= s->response;
	return 0;
}

void ps_share_free(struct ps_share *s)
{
	free(s->share);
	memset(s, 0, sizeof *s);
}

static int by_share(const void *a, const void *b)
{
	const struct ps_region_share *x = a, *y = b;
	if (x->share != y->share)
		return x->share < y->share ? 1 : -1;
	return x->label - y->label;
}

int ps_share_regions(const struct ps_share *s, const struct ps_regions *r,
                     const struct ps_weights *omega, const struct ps_picture *pic,
                     struct ps_region_share **out, struct ps_err *e)
{
	struct ps_sum *sh, *om, *lo;
	struct ps_region_share *res;
	double *dense;
	struct ps_lum l;
	size_t npix = (size_t)s->width * (size_t)s->height;
	int n = r->nlabels;
	if (r->width != s->width || r->height != s->height || omega->width != s->width ||
	    omega->height != s->height)
		return ps_err_set(e, PS_EINVAL, "regions, shares and solid angles are of different sizes");
	sh = calloc((size_t)n + 1, sizeof *sh);
	om = calloc((size_t)n + 1, sizeof *om);
	lo = calloc((size_t)n + 1, sizeof *lo);
	res = calloc((size_t)n + 1, sizeof *res);
	dense = calloc(npix ? npix : 1, sizeof *dense);
	if (!sh || !om || !lo || !res || !dense) {
		free(sh);
		free(om);
		free(lo);
		free(res);
		free(dense);
		return ps_err_set(e, PS_ENOMEM, "out of memory");
	}
	for (size_t k = 0; k < omega->nruns; k++)
		for (int i = 0; i < omega->runs[k].n; i++)
			dense[(size_t)omega->runs[k].row * (size_t)s->width + (size_t)(omega->runs[k].x0 + i)] =
			        ps_weights_run_at(omega, &omega->runs[k], i);
	ps_lum_init(&l, pic);
	for (int i = 0; i < n; i++) {
		ps_sum_init(&sh[i]);
		ps_sum_init(&om[i]);
		ps_sum_init(&lo[i]);
	}
	for (size_t p = 0; p < npix; p++) {
		double lum = 0;
		if (dense[p] > 0) {
			double rgb[3];
			ps_lum_rgb(&l, pic, (int)(p % (size_t)s->width), (int)(p / (size_t)s->width), rgb);
			lum = PS_LUM_EFFICACY * ps_lum_y(&l, rgb);
		}
		for (size_t k = r->off[p]; k < r->off[p + 1]; k++) {
			const struct ps_region_part *pt = &r->part[k];
			ps_sum_add(&sh[pt->label], s->share[p] * pt->frac);
			ps_sum_add(&om[pt->label], dense[p] * pt->frac);
			ps_sum_add(&lo[pt->label], dense[p] * pt->frac * lum);
		}
	}
	for (int i = 0; i < n; i++) {
		res[i].label = i;
		res[i].share = ps_sum_get(&sh[i]);
		res[i].solid_angle = ps_sum_get(&om[i]);
		res[i].luminance = res[i].solid_angle > 0 ? ps_sum_get(&lo[i]) / res[i].solid_angle : 0;
	}
	qsort(res, (size_t)n, sizeof *res, by_share);
	free(sh);
	free(om);
	free(lo);
	free(dense);
	*out = res;
	return 0;
}
