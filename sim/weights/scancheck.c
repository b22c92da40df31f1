/* SPDX-License-Identifier: ISC */
#include "scancheck.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "integrate.h"

/* The refinement: cells FINER times finer in azimuth (where the
 * sensitivity's sharp edges are: in polar angle it is affine within a patch
 * of its table, and the cells share a pixel between their centres), and a
 * pixel carrying at least SHARE of the picture's energy split SPLIT x SPLIT
 * (a sun disc of a few pixels on an edge sharper than a pixel) */
enum { FINER = 4, SPLIT = 8 };
#define SHARE 1e-4

static int add(int idx[PS_SCANCHECK_MAX], int m, int k)
{
	for (int i = 0; i < m; i++)
		if (idx[i] == k)
			return m;
	if (m < PS_SCANCHECK_MAX)
		idx[m++] = k;
	return m;
}

int ps_scancheck_pick(const double *out, int n, int closed, int idx[PS_SCANCHECK_MAX])
{
	int m = 0, ja = -1, jr = -1, top = 0;
	double da = -1, dr = -1;
	if (n <= 0)
		return 0;
	/* jump k: between rotation k - 1 (n - 1 for k = 0 when closed) and k;
	 * relative to the smaller of the two responses too, where a small
	 * response beside a sharp edge makes a large relative error */
	for (int k = closed ? 0 : 1; k < n && n > 1; k++) {
		double a = out[k == 0 ? n - 1 : k - 1], b = out[k], d = fabs(b - a);
		double lo = fmin(fabs(a), fabs(b)), r = lo > 0 ? d / lo : d > 0 ? HUGE_VAL : 0;
		if (d > da) {
			da = d;
			ja = k;
		}
		if (r > dr) {
			dr = r;
			jr = k;
		}
	}
	for (int k = 1; k < n; k++)
		if (out[k] > out[top])
			top = k;
	if (ja >= 0) {
		m = add(idx, m, ja);
		m = add(idx, m, ja == 0 ? n - 1 : ja - 1);
	}
	if (jr >= 0) {
		m = add(idx, m, jr);
		m = add(idx, m, jr == 0 ? n - 1 : jr - 1);
	}
	return add(idx, m, top);
}

/* The exact route at one rotation. */
static int exact_at(const struct ps_picture *pic, const struct ps_view *v, const double coef[3],
                    const struct ps_sensor *s, double rot_deg, const struct ps_wcache_dir *cache,
                    double *r, struct ps_err *e)
{
	struct ps_wcache_key key = { .sensor = s, .rotation_deg = rot_deg, .view = v,
	                             .width = pic->width, .height = pic->height, .method = PS_W_EXACT };
	struct ps_weights w;
	struct ps_response res;
	int how, rc;
	memset(&res, 0, sizeof res);
	if (ps_wcache_get(&w, &key, cache, &how, NULL, e) != 0)
		return -1;
	rc = ps_integrate(&w, pic, coef, &res, e);
	ps_weights_free(&w);
	*r = res.response;
	return rc;
}

static double rel(double got, double want)
{
	if (want != 0)
		return fabs(got - want) / fabs(want);
	return got == 0 ? 0.0 : HUGE_VAL;
}

/* The estimate of out[] against the exact values at the checked rotations. */
static double worst(const double *out, const int *idx, const double *ex, int m, int *at)
{
	double w = 0;
	*at = m > 0 ? idx[0] : 0;
	for (int i = 0; i < m; i++)
		if (rel(out[idx[i]], ex[i]) > w) {
			w = rel(out[idx[i]], ex[i]);
			*at = idx[i];
		}
	return w;
}

int ps_scancheck_scan(const struct ps_rescan *p, const struct ps_weights *omega,
                      const struct ps_picture *pic, const struct ps_view *v, const double coef[3],
                      const struct ps_sensor *s, double rot0_deg, double step_deg, int n,
                      int nthreads, const struct ps_wcache_dir *cache, double *out,
                      struct ps_scancheck *c, struct ps_err *e)
{
	int idx[PS_SCANCHECK_MAX], m, at;
	double ex[PS_SCANCHECK_MAX], est;
	c->estimate = c->first_estimate = 0;
	c->refined = 0;
	c->at_deg = rot0_deg;
	c->nchecked = 0;
	if (ps_rescan_scan_mt(p, s, rot0_deg, step_deg, n, nthreads, out, e) != 0)
		return -1;
	if (!(c->tolerance > 0) || n <= 0)
		return 0;
	for (int k = 0; k < n; k++)
		if (!isfinite(out[k]))
			return 0;   /* not a result: for the caller to name */
	m = ps_scancheck_pick(out, n, fabs(n * step_deg - 360.0) < 1e-9, idx);
	for (int i = 0; i < m; i++) {
		c->checked_deg[i] = rot0_deg + idx[i] * step_deg;
		if (exact_at(pic, v, coef, s, c->checked_deg[i], cache, &ex[i], e) != 0)
			return -1;
	}
	c->nchecked = m;
	est = worst(out, idx, ex, m, &at);
	c->estimate = c->first_estimate = est;
	c->at_deg = rot0_deg + at * step_deg;
	if (est > c->tolerance && omega) {
		/* still whole cells a step */
		struct ps_rescan f;
		double *fine = malloc((size_t)n * sizeof *fine), fest;
		int fat;
		if (!fine)
			return ps_err_set(e, PS_ENOMEM, "out of memory for %d rotations", n);
		if (ps_rescan_project_split(&f, omega, pic, v, coef, p->dtheta * 180.0 / M_PI,
		                            p->dphi * 180.0 / M_PI / FINER, p->phi0 * 180.0 / M_PI,
		                            p->ntheta * p->dtheta * 180.0 / M_PI, SPLIT, SHARE, e) != 0 ||
		    ps_rescan_scan_mt(&f, s, rot0_deg, step_deg, n, nthreads, fine, e) != 0) {
			ps_rescan_free(&f);
			free(fine);
			return -1;
		}
		ps_rescan_free(&f);
		fest = worst(fine, idx, ex, m, &fat);
		if (fest < est) {
			memcpy(out, fine, (size_t)n * sizeof *out);
			c->estimate = fest;
			c->at_deg = rot0_deg + fat * step_deg;
			c->refined = 1;
		}
		free(fine);
	}
	return 0;
}
