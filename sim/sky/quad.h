/* SPDX-License-Identifier: ISC */
/* Adaptive quadrature: Gauss-Kronrod 7-15 on each interval, the interval
 * with the largest error estimate halved until the estimates sum below the
 * tolerance.  The error stated is the sum over intervals of |K15 - G7|,
 * which bounds the true error of K15 by a wide margin on smooth pieces (put
 * kinks and jumps at breakpoints).  Sums are compensated (sum.h). */
#ifndef PS_QUAD_H
#define PS_QUAD_H

typedef double (*ps_quad_fn)(double x, void *ctx);
typedef double (*ps_quad_fn2)(double x, double y, void *ctx);

struct ps_quad {
	double value;        /* the integral */
	double error;        /* estimated absolute error */
	long evals;          /* integrand evaluations */
	int intervals;       /* (outer) intervals at the end */
	int converged;       /* 1: error within the tolerance */
};

/* Integral of f(x, y) over [x0, x1] x [y0, y1] as nested 1-D quadratures
 * (inner over y).  The inner tolerance is a tenth of the outer one spread
 * over the outer range; the error stated is the outer estimate plus the
 * largest inner estimate times (x1 - x0). */
struct ps_quad2_spec {
	double x0, x1;
	const double *xb;
	int nxb;
	double y0, y1;
	const double *yb;
	int nyb;
	double abstol, reltol;
	int max_intervals;   /* per 1-D quadrature */
};
void ps_quad_2d(ps_quad_fn2 f, void *ctx, const struct ps_quad2_spec *s, struct ps_quad *r);

#endif
