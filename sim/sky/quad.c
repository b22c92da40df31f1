/* SPDX-License-Identifier: ISC */
#include "quad.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sum.h"

/* Kronrod nodes (positive half, the last is 0) and weights; the Gauss
 * 7-point rule uses the odd-numbered nodes. */
static const double xk[8] = {
	0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
	0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
	0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
	0.207784955007898467600689403773245, 0.0
};
static const double wk[8] = {
	0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
	0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
	0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
	0.204432940075298892414161999234649, 0.209482141084727828012999174891714
};
static const double wg[4] = {
	0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
	0.381830050505118944950369775488975, 0.417959183673469387755102040816327
};

struct piece {
	double a, b, value, error;
};

static void gk15(ps_quad_fn f, void *ctx, struct piece *p)
{
	double c = 0.5 * (p->a + p->b), h = 0.5 * (p->b - p->a);
	double fc = f(c, ctx), k = wk[7] * fc, g = wg[3] * fc;
	for (int i = 0; i < 7; i++) {
		double s = f(c - h * xk[i], ctx) + f(c + h * xk[i], ctx);
		k += wk[i] * s;
		if (i & 1)
			g += wg[i / 2] * s;
	}
	p->value = k * h;
	p->error = fabs((k - g) * h);
	if (!isfinite(p->error))
		p->error = INFINITY;
}

/* max-heap of pieces by error */
static void sift_up(struct piece *h, int i)
{
	while (i > 0) {
		int up = (i - 1) / 2;
		struct piece t;
		if (!(h[i].error > h[up].error))
			break;
		t = h[i];
		h[i] = h[up];
		h[up] = t;
		i = up;
	}
}

static void sift_down(struct piece *h, int n, int i)
{
	for (;;) {
		int l = 2 * i + 1, r = l + 1, m = i;
		struct piece t;
		if (l < n && h[l].error > h[m].error)
			m = l;
		if (r < n && h[r].error > h[m].error)
			m = r;
		if (m == i)
			return;
		t = h[i];
		h[i] = h[m];
		h[m] = t;
		i = m;
	}
}

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return x < y ? -1 : x > y;
}

static void totals(const struct piece *h, int n, double *value, double *error)
{
	struct ps_sum v, e;
	ps_sum_init(&v);
	ps_sum_init(&e);
	for (int i = 0; i < n; i++) {
		ps_sum_add(&v, h[i].value);
		ps_sum_add(&e, h[i].error);
	}
	*value = ps_sum_get(&v);
	*error = ps_sum_get(&e);
}

/* Integral of f over [a, b], starting from the pieces the breakpoints brk[]
 * (any order; those outside (a, b) ignored) cut; stops when error <=
 * max(abstol, reltol |value|) or after max_intervals intervals. */
static void ps_quad_1d(ps_quad_fn f, void *ctx, double a, double b, const double *brk, int nbrk,
                       double abstol, double reltol, int max_intervals, struct ps_quad *r)
{
	int cap = (max_intervals > nbrk + 1 ? max_intervals : nbrk + 1) + 1, n = 0;
	struct piece *h = malloc((size_t)cap * sizeof *h);
	double *cut = malloc(((size_t)nbrk + 2) * sizeof *cut), value, error;
	int ncut = 0;
	memset(r, 0, sizeof *r);
	if (!h || !cut || !(b > a)) {
		free(h);
		free(cut);
		r->converged = (b == a);
		r->error = (b == a) ? 0.0 : INFINITY;
		return;
	}
	cut[ncut++] = a;
	for (int i = 0; i < nbrk; i++)
		if (brk[i] > a && brk[i] < b)
			cut[ncut++] = brk[i];
	qsort(cut + 1, (size_t)ncut - 1, sizeof *cut, cmp_double);
	cut[ncut++] = b;
	for (int i = 0; i + 1 < ncut; i++) {
		if (!(cut[i + 1] > cut[i]))
			continue;
		h[n].a = cut[i];
		h[n].b = cut[i + 1];
		gk15(f, ctx, &h[n]);
		r->evals += 15;
		sift_up(h, n);
		n++;
	}
	for (;;) {
		struct piece lo, hi;
		double mid;
		totals(h, n, &value, &error);
		if (error <= fmax(abstol, reltol * fabs(value)) || n + 1 > cap - 1 || n + 1 > max_intervals)
			break;
		mid = 0.5 * (h[0].a + h[0].b);
		if (!(mid > h[0].a && mid < h[0].b))
			break;   /* the interval cannot be halved in double */
		lo.a = h[0].a;
		lo.b = mid;
		hi.a = mid;
		hi.b = h[0].b;
		gk15(f, ctx, &lo);
		gk15(f, ctx, &hi);
		r->evals += 30;
		h[0] = lo;
		sift_down(h, n, 0);
		h[n] = hi;
		sift_up(h, n);
		n++;
	}
	r->value = value;
	r->error = error;
	r->intervals = n;
	r->converged = error <= fmax(abstol, reltol * fabs(value));
	free(h);
	free(cut);
}

struct inner_ctx {
	ps_quad_fn2 f;
	void *ctx;
	double x;
	const struct ps_quad2_spec *s;
	double abstol;
	double max_err;
	long evals;
	int failed;
};

static double inner_f(double y, void *p)
{
	struct inner_ctx *c = p;
	return c->f(c->x, y, c->ctx);
}

static double outer_f(double x, void *p)
{
	struct inner_ctx *c = p;
	struct ps_quad q;
	c->x = x;
	ps_quad_1d(inner_f, c, c->s->y0, c->s->y1, c->s->yb, c->s->nyb, c->abstol,
	           0.1 * c->s->reltol, c->s->max_intervals, &q);
	c->evals += q.evals;
	if (q.error > c->max_err)
		c->max_err = q.error;
	if (!q.converged)
		c->failed = 1;
	return q.value;
}

void ps_quad_2d(ps_quad_fn2 f, void *ctx, const struct ps_quad2_spec *s, struct ps_quad *r)
{
	struct inner_ctx c = { f, ctx, 0.0, s, 0.0, 0.0, 0, 0 };
	double width = s->x1 - s->x0;
	c.abstol = width > 0 ? 0.1 * s->abstol / width : s->abstol;
	ps_quad_1d(outer_f, &c, s->x0, s->x1, s->xb, s->nxb, s->abstol, s->reltol, s->max_intervals, r);
	r->evals = c.evals;
	r->error += c.max_err * width;
	r->converged = r->converged && !c.failed;
}
