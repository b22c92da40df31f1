/* SPDX-License-Identifier: ISC */
#include "weights.h"

#include <sys/mman.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "fisheye.h"
#include "sum.h"

#define DEG (M_PI / 180.0)

/* Gauss-Legendre rules on [-1, 1], computed once per build (no globals). */
enum { GL_MAXN = 24, GL_RULES = 4 };
/* The orders a piece may get: piece_rule picks one from an error bound. */
static const int gl_orders[GL_RULES] = { 3, 6, 12, 24 };

struct gl_rule {
	int n;
	double x[GL_MAXN], w[GL_MAXN];
};

/* Legendre polynomial P_n(x) and its derivative. */
static void legendre(int n, double x, double *p, double *dp)
{
	double p0 = 1.0, p1 = x;
	for (int k = 2; k <= n; k++) {
		double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
		p0 = p1;
		p1 = p2;
	}
	*p = p1;
	*dp = n * (x * p1 - p0) / (x * x - 1.0);
}

static void gl_compute(struct gl_rule *r, int n)
{
	r->n = n;
	for (int i = 0; i < n; i++) {
		double x = cos(M_PI * (i + 0.75) / (n + 0.5)), p, dp;
		for (int it = 0; it < 100; it++) {   /* Newton on P_n */
			double dx;
			legendre(n, x, &p, &dp);
			dx = p / dp;
			x -= dx;
			if (fabs(dx) < 1e-16)
				break;
		}
		legendre(n, x, &p, &dp);
		r->x[i] = x;
		r->w[i] = 2.0 / ((1.0 - x * x) * dp * dp);
	}
}

/* What an edge integral needs. */
struct edge_ctx {
	const struct ps_sensor *s;
	struct ps_fisheye f;
	double rot;              /* radians */
	double *rho_breaks;      /* sorted plane radii where the integrand has a kink or jump */
	int *rho_is_field;       /* 1 for the field's edge (hemisphere: square-root singularity) */
	double *rho2_breaks;     /* their squares (edge_fast compares squared radii) */
	double z2_min[13];       /* edge_fast: z^2 from which n points meet the bound */
	int nrho;
	int use_phi_breaks;
	int sa_n;                /* > 0: builtins' weights by the sa_n x sa_n rule over the pixel (sa_row) */
	double sa_coef[20];      /* the weight's density as a polynomial in rho^2 */
	int sa_terms;            /* its terms in use */
	double sa_r2;            /* the rule for pixels whose corners are all within rho^2 <= sa_r2 */
	struct gl_rule gl[GL_RULES];
	struct gl_rule glf[13];  /* glf[n]: n points, for edge_fast */
};

struct brk {
	double a;
	int field;
};

static void sort_brk(struct brk *b, int n)
{
	for (int i = 1; i < n; i++) {
		struct brk k = b[i];
		int j = i - 1;
		while (j >= 0 && b[j].a > k.a) {
			b[j + 1] = b[j];
			j--;
		}
		b[j + 1] = k;
	}
}

/* M along the segment's line at plane azimuth a, in patch (i, j), with phi
 * shifted into the patch's branch by phi_shift. */
static double m_at(const struct edge_ctx *c, double p, double an, double a, int i, int j,
                   double phi_shift)
{
	double ca = cos(a - an);
	double rho = ca > 0 ? p / ca : INFINITY;
	double theta = ps_fisheye_theta(&c->f, rho);
	double phi = a - M_PI / 2 - c->rot + phi_shift;
	return ps_sensor_m_in(c->s, i, j, theta, phi);
}

/* Distance from a to the nearest point of {b + k period}. */
static double dist_mod(double a, double b, double period)
{
	double d = fmod(a - b, period);
	if (d < 0)
		d += period;
	return fmin(d, period - d);
}

/* The rule for a piece of azimuth length len around am: along the line
 * the integrand's singularities are real, where cos(alpha - an) = 0 (rho
 * infinite) and, for the hemispherical projection, where rho = 1 (asin's
 * branch point, cos(alpha - an) = p).  With x the nearest one's distance
 * in half-lengths, the Bernstein parameter is r = x + sqrt(x^2 - 1); the
 * smallest rule whose bound 64 Mx / (15 (r^2 - 1) r^(2n)) (taken at r / 2,
 * Mx at most 8 times the integrand) is below 1e-19, else the largest. */
static int piece_rule(const struct edge_ctx *c, double p, double an, double am, double len)
{
	double d = dist_mod(am, an + M_PI / 2, M_PI), x, r;
	if (c->f.type == PS_VT_HEMI && p < 1.0) {
		double a = acos(p);
		d = fmin(d, fmin(dist_mod(am, an + a, 2 * M_PI), dist_mod(am, an - a, 2 * M_PI)));
	}
	x = d / (0.5 * len);
	if (x <= 1.0)
		return GL_RULES - 1;
	r = 0.5 * (x + sqrt(x * x - 1.0));
	if (r <= 1.5)
		return GL_RULES - 1;
	for (int k = 0; k < GL_RULES; k++)
		if (8.0 * 64.0 / (15.0 * (r * r - 1.0)) * pow(r, -2.0 * gl_orders[k]) <= 1e-19)
			return k;
	return GL_RULES - 1;
}

/* Integral of M d(alpha) over alpha in [a0, a1] on one smooth piece. */
static double piece(const struct edge_ctx *c, double p, double an, double a0, double a1,
                    int field0, int field1)
{
	double len = a1 - a0, am = 0.5 * (a0 + a1), sum = 0.0;
	double ca = cos(am - an), rho = ca > 0 ? p / ca : INFINITY;
	double theta = ps_fisheye_theta(&c->f, rho), phi = am - M_PI / 2 - c->rot, phin = phi;
	const struct gl_rule *g;
	int i, j;
	if (len <= 0)
		return 0.0;
	ps_sensor_locate(c->s, theta, &phin, &i, &j);
	g = &c->gl[piece_rule(c, p, an, am, len)];
	if (c->f.type == PS_VT_HEMI && rho < 1.0 && (field0 || field1)) {
		/* theta = asin(rho) has a square-root singularity at the field's edge:
		 * alpha = edge -/+ len s^2 makes the integrand smooth in s. */
		double edge = field1 ? a1 : a0, dir = field1 ? -1.0 : 1.0;
		g = &c->gl[3];
		for (int k = 0; k < g->n; k++) {
			double sq = 0.5 * (g->x[k] + 1.0);
			double a = edge + dir * len * sq * sq;
			sum += g->w[k] * 0.5 * m_at(c, p, an, a, i, j, phin - phi) * 2.0 * len * sq;
		}
		return sum;
	}
	for (int k = 0; k < g->n; k++)
		sum += g->w[k] * m_at(c, p, an, am + 0.5 * len * g->x[k], i, j, phin - phi);
	return 0.5 * len * sum;
}

/* Integral of M d(alpha) along the segment from A to B (see weights.h). */
static double edge_integral(const struct edge_ctx *c, double ax, double ay, double bx, double by)
{
	double dx = bx - ax, dy = by - ay, len2 = dx * dx + dy * dy;
	double cr = ax * dy - ay * dx, dalpha, alo, ahi, t, fx, fy, p, an;
	double ra = hypot(ax, ay), rb = hypot(bx, by), rmin, rmax;
	struct brk b[512];
	int nb = 0;
	double total = 0.0;
	/* A segment on a line through the origin sweeps no azimuth (M is 0 where
	 * it would jump): it contributes nothing. */
	if (len2 == 0.0 || fabs(cr) <= 1e-15 * len2)
		return 0.0;
	dalpha = atan2(cr, ax * bx + ay * by);
	alo = atan2(ay, ax);
	if (dalpha < 0)
		alo += dalpha;
	ahi = alo + fabs(dalpha);
	t = -(ax * dx + ay * dy) / len2;
	fx = ax + t * dx;
	fy = ay + t * dy;
	p = hypot(fx, fy);
	an = atan2(fy, fx);
	rmin = (t > 0 && t < 1) ? p : fmin(ra, rb);
	rmax = fmax(ra, rb);
	b[nb++] = (struct brk){ alo, 0 };
	/* circles: rho = p / cos(alpha - an) = rc */
	/* rho_breaks is sorted: start at the first one not below rmin */
	int lo = 0, hi = c->nrho;
	while (lo < hi) {
		int mid = (lo + hi) / 2;
		if (c->rho_breaks[mid] < rmin)
			lo = mid + 1;
		else
			hi = mid;
	}
	for (int k = lo; k < c->nrho && c->rho_breaks[k] <= rmax && nb < 500; k++) {
		double rc = c->rho_breaks[k], d;
		if (rc <= p)
			continue;
		d = acos(p / rc);
		for (int sgn = -1; sgn <= 1; sgn += 2) {
			double a = an + sgn * d;
			a += 2 * M_PI * ceil((alo - a) / (2 * M_PI));
			if (a > alo && a < ahi)
				b[nb++] = (struct brk){ a, c->rho_is_field[k] };
		}
	}
	/* rays: phi = pb[j]; start from the first one at or after alo */
	if (c->use_phi_breaks) {
		const struct ps_sensor *s = c->s;
		double off = M_PI / 2 + c->rot;   /* alpha = phi + off */
		double plo = alo - off, shift;
		int i0, j;
		ps_sensor_locate(s, 0.0, &plo, &i0, &j);
		shift = (alo - off) - plo;        /* a multiple of 2 pi */
		for (int k = 0; k < s->np + 1 && nb < 510; k++, j++) {
			double a;
			if (j >= s->np) {
				j -= s->np;
				shift += 2 * M_PI;
			}
			a = s->pb[j] + off + shift;
			if (a >= ahi)
				break;
			if (a > alo)
				b[nb++] = (struct brk){ a, 0 };
		}
	}
	sort_brk(b + 1, nb - 1);
	b[nb++] = (struct brk){ ahi, 0 };
	{
		struct ps_sum acc;
		ps_sum_init(&acc);
		for (int k = 0; k + 1 < nb; k++)
			ps_sum_add(&acc, piece(c, p, an, b[k].a, b[k + 1].a, b[k].field, b[k + 1].field));
		total = ps_sum_get(&acc);
	}
	return dalpha < 0 ? -total : total;
}


/* The fast route for an axis-parallel edge that crosses no break (no
 * sensitivity circle or ray, not the field's edge): along the line v = k
 * (horizontal) or u = k (vertical), d(alpha) = -k / rho^2 du or
 * k / rho^2 dv, so the edge integral is the integral in the plane
 * coordinate t of M(theta(rho), phi) times that factor, with M the one
 * cell's closed form: no break search, no trigonometry for the nodes'
 * azimuths.  The integrand is analytic except where rho^2 = 0 (the
 * complex points t = +-i k) and, for the hemispherical projection, where
 * rho = 1 (asin's branch point); Gauss-Legendre with n points on an
 * interval whose nearest singularity lies on the Bernstein ellipse of
 * parameter r errs by at most 64 Mx / (15 (r^2 - 1) r^(2n)) (Trefethen,
 * ATAP, theorem 19.3), Mx the integrand's bound inside the ellipse.  The
 * order is the smallest with that bound below a small fraction of the integrand's
 * size (1e-19 here), taking the ellipse of parameter r / 2 (so Mx is within a small
 * factor of the integrand on the edge; bounded by 8 times it here).
 * Returns 0 and leaves *out alone when the edge needs the general route. */
enum { FAST_MAXN = 12 };

/* Bernstein parameter of the point (x, y) for [-1, 1]: the ellipse with
 * foci -1 and 1 through it has semi-major axis a = (|z - 1| + |z + 1|) / 2
 * and parameter a + sqrt(a^2 - 1). */
static double bernstein(double x, double y)
{
	double a = 0.5 * (sqrt((x - 1) * (x - 1) + y * y) + sqrt((x + 1) * (x + 1) + y * y));
	return a + sqrt(fmax(a * a - 1.0, 0.0));
}

/* atan(x) for |x| <= 0.05 by its series to x^17: the first omitted term
 * is below 1e-22 of x, so this is atan to rounding, without libm. */
static double atan_small(double x)
{
	double x2 = x * x;
	if (x2 < 1e-6)   /* |x| < 1e-3: to x^7, the rest below 1e-24 of x */
		return x * (1 + x2 * (-1.0 / 3 + x2 * (1.0 / 5 + x2 * (-1.0 / 7))));
	return x * (1 + x2 * (-1.0 / 3 + x2 * (1.0 / 5 + x2 * (-1.0 / 7 + x2 * (1.0 / 9 +
	       x2 * (-1.0 / 11 + x2 * (1.0 / 13 + x2 * (-1.0 / 15 + x2 * (1.0 / 17)))))))));
}

/* The plane azimuth at coordinate t on the edge's line, from the one at tm:
 * atan2(k, t) - atan2(k, tm) = atan(k (tm - t) / (t tm + k^2)) for a
 * horizontal line v = k, atan2(t, k) - atan2(tm, k) = atan(k (t - tm) /
 * (t tm + k^2)) for a vertical u = k (both with the points on the same
 * side of the origin's perpendicular: t tm + k^2 > 0, which holds on an
 * edge whose poles are far, r > 1.5 below).  -2: the difference is not
 * small enough for atan_small (the caller then takes the general route). */
static int alpha_at(int vertical, double k, double tm, double am, double t, double *a)
{
	double den = t * tm + k * k, x;
	if (den <= 0)
		return -2;
	x = (vertical ? k * (t - tm) : k * (tm - t)) / den;
	if (fabs(x) > 0.05)
		return -2;
	*a = am + atan_small(x);
	return 0;
}

static int edge_fast(const struct edge_ctx *c, int vertical, double k, double t0, double t1,
                     double *out)
{
	const struct ps_sensor *s = c->s;
	double tm = 0.5 * (t0 + t1), hl = 0.5 * (t1 - t0), tlo, thi, rmin, rmax, r, am, phim, phin;
	double sum = 0.0, shift, rho_m;
	int i, j, n, lo, hi;
	if (k == 0.0) {   /* on a line through the origin: no azimuth swept */
		*out = 0.0;
		return 1;
	}
	if (hl <= 0)
		return 0;
	/* rho's range on the edge */
	tlo = fmin(fabs(t0), fabs(t1));
	thi = fmax(fabs(t0), fabs(t1));
	if (t0 < 0 && t1 > 0)
		tlo = 0.0;
	/* squared radii: no square root for the tests below */
	rmin = tlo * tlo + k * k;
	rmax = thi * thi + k * k;
	/* no circle in (rmin, rmax] (a circle at rmin exactly only touches) */
	lo = 0;
	hi = c->nrho;
	while (lo < hi) {
		int mid = (lo + hi) / 2;
		if (c->rho2_breaks[mid] <= rmin)
			lo = mid + 1;
		else
			hi = mid;
	}
	if (lo < c->nrho && c->rho2_breaks[lo] <= rmax)
		return 0;
	/* the order from the error bound: the poles at t = +-i k, at distance
	 * rho_m / hl half-lengths from the middle; the ellipse through them
	 * has a semi-major axis at least that, so r at least this */
	if (c->f.type != PS_VT_HEMI || rmax >= 1.0) {
		/* the poles alone: the smallest n whose threshold z^2 = (rho_m /
		 * hl)^2 reaches (z2_min, ctx_init: the same bound, no root) */
		double rm2 = tm * tm + k * k, h2 = hl * hl;
		for (n = 1; n <= FAST_MAXN; n++)
			if (rm2 >= c->z2_min[n] * h2)
				break;
		if (n > FAST_MAXN)
			return 0;
		rho_m = sqrt(rm2);
		goto order_done;
	}
	rho_m = sqrt(tm * tm + k * k);
	rmax = sqrt(rmax);
	{
		double z = rho_m / hl;
		r = z + sqrt(z * z - 1.0);
	}
	if (c->f.type == PS_VT_HEMI && rmax < 1.0) {
		/* asin's branch points at rho = 1: t = +-sqrt(1 - k^2) */
		double b = sqrt(1.0 - k * k), r2;
		r2 = bernstein((b - tm) / hl, 0.0);
		if (r2 < r)
			r = r2;
		r2 = bernstein((-b - tm) / hl, 0.0);
		if (r2 < r)
			r = r2;
	}
	r *= 0.5;
	if (r <= 1.5)
		return 0;
	{
		double bound = 8.0 * 64.0 / (15.0 * (r * r - 1.0)), q = 1.0 / (r * r);
		for (n = 1; n <= FAST_MAXN; n++) {
			bound *= q;
			if (bound <= 1e-19)
				break;
		}
		if (n > FAST_MAXN)
			return 0;
	}
order_done:
	if (s->kind != PS_SENS_TABLE) {
		/* a builtin: M depends on theta alone, one cell, no azimuth needed
		 * (the same nodes and sum as below, without the cell search) */
		const struct gl_rule *g = &c->glf[n];
		for (int q = 0; q < g->n; q++) {
			double t = tm + hl * g->x[q], r2 = t * t + k * k;
			sum += g->w[q] * ps_sensor_m_builtin(s->kind, ps_fisheye_theta(&c->f, sqrt(r2))) /
			       r2;
		}
		*out = (vertical ? k : -k) * hl * sum;
		return 1;
	}
	/* the cell: from the middle; the edge must not cross a ray, nor (a
	 * vertical edge left of the origin) atan2's cut */
	am = vertical ? atan2(tm, k) : atan2(k, tm);
	phim = am - M_PI / 2 - c->rot;
	phin = phim;
	ps_sensor_locate(s, ps_fisheye_theta(&c->f, rho_m), &phin, &i, &j);
	shift = phin - phim;
	{
		/* the azimuths at the ends (monotone along the edge): inside the cell */
		double a0, a1, p0, p1;
		if (alpha_at(vertical, k, tm, am, t0, &a0) || alpha_at(vertical, k, tm, am, t1, &a1))
			return 0;
		p0 = a0 - M_PI / 2 - c->rot + shift;
		p1 = a1 - M_PI / 2 - c->rot + shift;
		if (c->use_phi_breaks &&
		    (fmin(p0, p1) < s->pb[j] || fmax(p0, p1) > s->pb[j + 1]))
			return 0;
	}
	{
		const struct gl_rule *g = &c->glf[n];
		double sgn = vertical ? k : -k;
		int need_phi = s->kind == PS_SENS_TABLE && s->reading != PS_READ_CELL;
		if (s->kind == PS_SENS_TABLE && i < s->nt) {
			/* ps_sensor_m_in's patch formula, its coefficients fetched once */
			const double *kc = s->mcoef + 6 * ((size_t)i * (size_t)s->np + (size_t)j);
			double inv = 1.0 / (s->pb[j + 1] - s->pb[j]), p0 = s->pb[j];
			for (int q = 0; q < g->n; q++) {
				double t = tm + hl * g->x[q], r2 = t * t + k * k, rho = sqrt(r2);
				double theta = ps_fisheye_theta(&c->f, rho), st, ct, ml, m, a;
				sincos(theta, &st, &ct);
				ml = ps_sensor_m_patch(kc, theta, st, ct);
				if (need_phi) {
					double mr = ps_sensor_m_patch(kc + 3, theta, st, ct), wphi;
					if (alpha_at(vertical, k, tm, am, t, &a))
						return 0;   /* not reached: the ends bound the nodes */
					wphi = (a - M_PI / 2 - c->rot + shift - p0) * inv;
					m = (1.0 - wphi) * ml + wphi * mr;
				} else {
					m = ml;
				}
				sum += g->w[q] * m / r2;
			}
		} else {
			for (int q = 0; q < g->n; q++) {
				double t = tm + hl * g->x[q], r2 = t * t + k * k, rho = sqrt(r2), phi = phin;
				double theta = ps_fisheye_theta(&c->f, rho), a;
				if (need_phi) {
					if (alpha_at(vertical, k, tm, am, t, &a))
						return 0;   /* not reached: the ends bound the nodes */
					phi = a - M_PI / 2 - c->rot + shift;
				}
				sum += g->w[q] * ps_sensor_m_in(s, i, j, theta, phi) / r2;
			}
		}
		*out = sgn * hl * sum;
	}
	return 1;
}

/* An axis-parallel edge: the fast route when it can, else the general. */
static double edge_hv(const struct edge_ctx *c, double ax, double ay, double bx, double by)
{
	double out;
	if (ay == by) {
		if (ax < bx ? edge_fast(c, 0, ay, ax, bx, &out) : edge_fast(c, 0, ay, bx, ax, &out))
			return ax < bx ? out : -out;
	} else if (ax == bx) {
		if (ay < by ? edge_fast(c, 1, ax, ay, by, &out) : edge_fast(c, 1, ax, by, ay, &out))
			return ay < by ? out : -out;
	}
	return edge_integral(c, ax, ay, bx, by);
}

/* edge_fast's orders without roots: with the poles at z = rho_m / hl
 * half-lengths, r = (z + sqrt(z^2 - 1)) / 2 (the ellipse at half their
 * parameter) and n points are enough when r > 1.5 and
 * 8 x 64 / (15 (r^2 - 1)) r^(-2n) <= 1e-19.  Both grow with z: z2_min[n]
 * is the square of the z where they start to hold, from the r found by
 * bisection (its upper end) and z = r + 1 / (4 r), made a little larger
 * (never a smaller order than the bound asks). */
static double fast_bound(double r, int n)
{
	return 8.0 * 64.0 / (15.0 * (r * r - 1.0)) * pow(r, -2.0 * n);
}

static void order_thresholds(struct edge_ctx *c)
{
	for (int n = 1; n <= FAST_MAXN; n++) {
		double a = 1.5, b = 1e12, z;
		if (fast_bound(b, n) > 1e-19) {
			c->z2_min[n] = INFINITY;
			continue;
		}
		if (fast_bound(a, n) <= 1e-19)
			b = a;
		for (int it = 0; it < 200 && b - a > 1e-13 * b; it++) {
			double m = 0.5 * (a + b);
			if (fast_bound(m, n) <= 1e-19)
				b = m;
			else
				a = m;
		}
		b *= 1.0 + 1e-12;
		if (b <= 1.5)
			b = 1.5 * (1.0 + 1e-12);
		z = b + 1.0 / (4.0 * b);
		c->z2_min[n] = z * z * (1.0 + 1e-12);
	}
}

/* The builtins on the angular projection (theta = pi rho): a pixel's
 * weight is the integral over it of S(theta) times the solid angle's
 * density pi sin(pi rho) / rho, for the uniform sensor
 *   J = pi sin(pi rho) / rho = pi^2 sum_k (-pi^2 rho^2)^k / (2k + 1)!
 * and inside 90 degrees (rho <= 1/2) for the cosine
 *   J = (pi / 2) sin(2 pi rho) / rho = pi^2 sum_k (-4 pi^2 rho^2)^k / (2k + 1)!,
 * entire functions of u and v (no singularity at the zenith: that is the
 * edge route's), so the n x n Gauss-Legendre rule over a pixel inside that
 * disc converges as fast as n grows.  Its error (Trefethen, ATAP, theorem
 * 19.3, per coordinate, with the Bernstein ellipse of parameter 1 / h, h the
 * pixel's side in plane units: semi-axes below h / 4 x (1 / h) = 1/4, so in
 * it |rho| <= 1.77 for the uniform sensor's disc, |J| <= pi^2 e^(pi 1.77) <
 * 259 pi^2, and |rho| <= 1.07 for the cosine's, |J| <= pi^2 e^(2 pi 1.07) <
 * 787 pi^2) is below 2 x 2.13 x 787 h^(2n + 2) < 3400 h^(2n + 2) of the
 * largest weight pi^2 h^2; n is the smallest with 4000 h^(2n + 2) <= 1e-17
 * (2 at 4000 x 4000 on a 180-degree field, 3 at 1000 x 1000, 4 at
 * 256 x 256), none when no n up to 8 meets it.  No four edge integrals
 * cancel: the weight is exact to its rounding.  Pixels reaching past the
 * disc (the field's edge, the cosine's 90 degrees) keep the edge route. */
static void solid_angle_rule(struct edge_ctx *c)
{
	double h = fmax(c->f.su / c->f.width, c->f.sv / c->f.height), t = M_PI * M_PI, q;
	c->sa_n = 0;
	if ((c->s->kind != PS_SENS_UNIFORM && c->s->kind != PS_SENS_COSINE) ||
	    c->f.type != PS_VT_ANGULAR || !(h < 0.01))
		return;
	for (int n = 2; n <= 8 && !c->sa_n; n++)
		if (4000.0 * pow(h, 2.0 * n + 2.0) <= 1e-17)
			c->sa_n = n;
	c->sa_r2 = c->s->kind == PS_SENS_UNIFORM ? 1.0 : 0.25;
	q = c->s->kind == PS_SENS_UNIFORM ? M_PI * M_PI : 4.0 * M_PI * M_PI;
	/* pi^2 (-q)^k / (2k + 1)!, up to the first term below 1e-20 of pi^2
	 * at the picture's largest rho^2 inside the disc (the rest,
	 * alternating and falling, is smaller still; q rho^2 <= pi^2: that
	 * is k = 15 at most) */
	{
		double u1 = c->f.u0 + c->f.su, v1 = c->f.v0 + c->f.sv;
		double zmax = fmin(c->sa_r2, fmax(c->f.u0 * c->f.u0, u1 * u1) + fmax(c->f.v0 * c->f.v0, v1 * v1));
		double term = 1.0;
		c->sa_terms = 18;
		for (int k = 0; k < 18; k++) {
			c->sa_coef[k] = t;
			t *= -q / ((2.0 * k + 2.0) * (2.0 * k + 3.0));
			term *= q * zmax / ((2.0 * k + 2.0) * (2.0 * k + 3.0));
			if (term < 1e-20) {
				c->sa_terms = k + 2;   /* coefficients 0 .. k + 1 */
				c->sa_coef[k + 1] = t;
				break;
			}
		}
	}
}

/* The solid angles of pixels xs..xe between lines vb and vt by the
 * sa_n-point rule (inside the field: solid_angle_rule) into out[x - lo];
 * four pixels' nodes at a time, their polynomials side by side (the
 * evaluations are independent: the sums wait on no one). */
static void sa_row(const struct edge_ctx *c, const double *u, int xs, int xe, int lo, double vb,
                   double vt, double *out)
{
	enum { B = 4 };
	const struct gl_rule *g = &c->glf[c->sa_n];
	int n = g->n, nn = n * n, nt = c->sa_terms;
	double vm = 0.5 * (vb + vt), vh = 0.5 * (vt - vb), v2[8];
	for (int b = 0; b < n; b++) {
		double vq = vm + vh * g->x[b];
		v2[b] = vq * vq;
	}
	for (int x0 = xs; x0 <= xe; x0 += B) {
		double z[B * 64 + 8], p[B * 64 + 8];
		int m = xe - x0 + 1 < B ? xe - x0 + 1 : B, nz = m * nn;
		for (int i = 0; i < m; i++) {
			double um = 0.5 * (u[x0 + i] + u[x0 + i + 1]), uh = 0.5 * (u[x0 + i + 1] - u[x0 + i]);
			for (int a = 0; a < n; a++) {
				double uq = um + uh * g->x[a], u2 = uq * uq;
				for (int b = 0; b < n; b++)
					z[i * nn + b * n + a] = u2 + v2[b];
			}
		}
		for (int q = nz; q % 8; q++)
			z[q] = 0.0;   /* padding: eight values a pass, in registers */
		for (int q0 = 0; q0 < nz; q0 += 8) {
			double z0 = z[q0], z1 = z[q0 + 1], z2 = z[q0 + 2], z3 = z[q0 + 3];
			double z4 = z[q0 + 4], z5 = z[q0 + 5], z6 = z[q0 + 6], z7 = z[q0 + 7];
			double ck = c->sa_coef[nt - 1];
			double p0 = ck, p1 = ck, p2 = ck, p3 = ck, p4 = ck, p5 = ck, p6 = ck, p7 = ck;
			for (int k = nt - 2; k >= 0; k--) {
				ck = c->sa_coef[k];
				p0 = p0 * z0 + ck;
				p1 = p1 * z1 + ck;
				p2 = p2 * z2 + ck;
				p3 = p3 * z3 + ck;
				p4 = p4 * z4 + ck;
				p5 = p5 * z5 + ck;
				p6 = p6 * z6 + ck;
				p7 = p7 * z7 + ck;
			}
			p[q0] = p0;
			p[q0 + 1] = p1;
			p[q0 + 2] = p2;
			p[q0 + 3] = p3;
			p[q0 + 4] = p4;
			p[q0 + 5] = p5;
			p[q0 + 6] = p6;
			p[q0 + 7] = p7;
		}
		for (int i = 0; i < m; i++) {
			double sum = 0.0, uh = 0.5 * (u[x0 + i + 1] - u[x0 + i]);
			for (int b = 0; b < n; b++) {
				double row = 0.0;
				for (int a = 0; a < n; a++)
					row += g->w[a] * p[i * nn + b * n + a];
				sum += g->w[b] * row;
			}
			out[x0 + i - lo] = sum * uh * vh;
		}
	}
}

static int ctx_init(struct edge_ctx *c, const struct ps_sensor *s, double rot_deg,
                    const struct ps_view *v, int width, int height, struct ps_err *e)
{
	memset(c, 0, sizeof *c);
	c->s = s;
	c->rot = rot_deg * DEG;
	ps_fisheye_init(&c->f, v, width, height);
	for (int k = 0; k < GL_RULES; k++)
		gl_compute(&c->gl[k], gl_orders[k]);
	for (int k = 1; k <= 12; k++)
		gl_compute(&c->glf[k], k);
	c->rho_breaks = malloc(((size_t)s->nt + 2) * sizeof *c->rho_breaks);
	c->rho2_breaks = malloc(((size_t)s->nt + 2) * sizeof *c->rho2_breaks);
	c->rho_is_field = malloc(((size_t)s->nt + 2) * sizeof *c->rho_is_field);
	if (!c->rho_breaks || !c->rho_is_field || !c->rho2_breaks) {
		free(c->rho_breaks);
		free(c->rho2_breaks);
		free(c->rho_is_field);
		return ps_err_set(e, PS_ENOMEM, "out of memory");
	}
	for (int i = 1; i <= s->nt; i++)
		if (s->tb[i] < c->f.theta_field) {
			c->rho_breaks[c->nrho] = ps_fisheye_rho(&c->f, s->tb[i]);
			c->rho_is_field[c->nrho++] = 0;
		}
	c->rho_breaks[c->nrho] = 1.0;
	c->rho_is_field[c->nrho++] = 1;
	if (s->kind == PS_SENS_COSINE && c->f.type == PS_VT_ANGULAR) {
		/* the cosine's end at 90 degrees is a kink */
		c->rho_breaks[c->nrho - 1] = 0.5;
		c->rho_is_field[c->nrho - 1] = 0;
		c->rho_breaks[c->nrho] = 1.0;
		c->rho_is_field[c->nrho++] = 1;
	}
	for (int i = 0; i < c->nrho; i++)
		c->rho2_breaks[i] = c->rho_breaks[i] * c->rho_breaks[i];
	order_thresholds(c);
	c->use_phi_breaks = s->kind == PS_SENS_TABLE;
	solid_angle_rule(c);
	return 0;
}

static void ctx_free(struct edge_ctx *c)
{
	free(c->rho_breaks);
	free(c->rho2_breaks);
	free(c->rho_is_field);
}

double ps_weights_rect_solid_angle(int type, double u0, double v0, double u1, double v1)
{
	struct ps_sensor s;
	struct ps_view v;
	struct edge_ctx c;
	double sa;
	ps_view_default_fisheye(&v);
	v.type = type;
	if (ps_sensor_builtin(&s, PS_SENS_UNIFORM, NULL) != 0)
		return NAN;
	if (ctx_init(&c, &s, 0.0, &v, 1, 1, NULL) != 0) {
		ps_sensor_free(&s);
		return NAN;
	}
	sa = edge_integral(&c, u0, v0, u1, v0) + edge_integral(&c, u1, v0, u1, v1) +
	     edge_integral(&c, u1, v1, u0, v1) + edge_integral(&c, u0, v1, u0, v0);
	ctx_free(&c);
	ps_sensor_free(&s);
	return sa;
}

void ps_weights_key(const struct ps_sensor *s, double rotation_deg, const struct ps_view *v,
                    int width, int height, int method, char *buf, size_t len)
{
	snprintf(buf, len, "%s|%s|%.17g|%c|%.17g|%.17g|%.17g|%.17g|%dx%d|%s", s->path,
	         ps_sensor_reading_name(s->reading), rotation_deg, v->type, v->vh, v->vv, v->vs, v->vl,
	         width, height, method == PS_W_CENTRE ? "centre" : "exact");
}

void ps_weights_free(struct ps_weights *w)
{
	if (!w)
		return;
	free(w->runs);
	if (w->map)
		munmap(w->map, w->maplen);
	else
		free(w->w);
	memset(w, 0, sizeof *w);
}

static int push_run(struct ps_weights *w, size_t *cap, int row, int x0, int n, size_t off)
{
	if (w->nruns == *cap) {
		size_t ncap = *cap ? *cap * 2 : 256;
		struct ps_weights_run *nr = realloc(w->runs, ncap * sizeof *nr);
		if (!nr)
			return -1;
		w->runs = nr;
		*cap = ncap;
	}
	w->runs[w->nruns++] = (struct ps_weights_run){ row, x0, n, off };
	return 0;
}

/* x range [lo, hi] of pixels on bottom-based row j whose squares come
 * within plane radius R of the origin; lo > hi when none. */
static void row_range(const struct ps_fisheye *f, int j, double R, int *lo, int *hi)
{
	double v0 = ps_fisheye_v(f, j), v1 = ps_fisheye_v(f, j + 1);
	double dy = (v0 <= 0 && v1 >= 0) ? 0.0 : fmin(fabs(v0), fabs(v1)), hw, du = f->su / f->width;
	*lo = 1;
	*hi = 0;
	if (dy > R)
		return;
	hw = sqrt(R * R - dy * dy);
	/* pixel x spans [u(x), u(x+1)]: keep those meeting [-hw, hw] */
	*lo = (int)floor((-hw - f->u0) / du) - 1;
	*hi = (int)ceil((hw - f->u0) / du) + 1;
	if (*lo < 0)
		*lo = 0;
	if (*hi > f->width - 1)
		*hi = f->width - 1;
}

/* A band of rows computed by one thread; the runs and their offsets are laid
 * out before, so threads write disjoint parts of w->w and the map is the same
 * whatever the number of threads. */
struct band {
	const struct edge_ctx *c;
	const struct ps_sensor *s;
	int method;
	const double *u;
	const int *lo, *hi;
	const size_t *off;    /* offset of row j's first weight */
	int j0, j1;           /* bottom-based rows [j0, j1) */
	double *w;
	int oom;
	int mirror_x;         /* the map is symmetric in x: the right half copies the left */
	int transpose;        /* and in the diagonal: pixels left of it are copied after */
	int compact;          /* only the left half is stored (a compact map) */
	int *next;            /* non-NULL: rows [j0, j1) are taken CHUNK at a time from *next */
};

/* Rows a band takes at a time when the bands share the rows: a chunk's
 * first bottom line is computed again (the same numbers), 1/CHUNK more
 * horizontal edges for an even load whatever the rows cost. */
enum { CHUNK = 16 };

/* The exact weight of pixel x between lines vb and vt, alone (its four
 * edges computed here, none shared): for the few pixels a mirror misses. */
static double pixel_alone(const struct edge_ctx *c, const double *u, int x, double vb, double vt)
{
	struct ps_sum ps;
	double wt;
	ps_sum_init(&ps);
	ps_sum_add(&ps, edge_hv(c, u[x], vb, u[x + 1], vb));
	ps_sum_add(&ps, edge_hv(c, u[x + 1], vb, u[x + 1], vt));
	ps_sum_add(&ps, -edge_hv(c, u[x], vt, u[x + 1], vt));
	ps_sum_add(&ps, -edge_hv(c, u[x], vb, u[x], vt));
	wt = ps_sum_get(&ps);
	return wt < 0 && wt > -1e-15 ? 0.0 : wt;
}

/* Symmetry: a sensor the same at every azimuth (the builtins, or a table
 * whose rows are constant) on a view not shifted (-vs 0 -vl 0) gives a map
 * symmetric in x and in y: pixel (x, j) and (W-1-x, j) and (x, H-1-j) have
 * the same footprint up to reflection, so the same exact weight. */
static int sensor_symmetric(const struct ps_sensor *s)
{
	if (s->kind != PS_SENS_TABLE)
		return 1;
	for (int i = 0; i < s->ntheta; i++)
		for (int j = 1; j < s->nphi; j++)
			if (s->val[(size_t)i * (size_t)s->nphi + (size_t)j] != s->val[(size_t)i * (size_t)s->nphi])
				return 0;
	return 1;
}

static void *band_run(void *arg)
{
	struct band *b = arg;
	const struct edge_ctx *c = b->c;
	int width = c->f.width, prev = -2;   /* the last row done here; -2: none */
	int clo = 1, chi = 0;                /* the x range its top edges were computed for */
	double *hline[2], *vrow;
	hline[0] = malloc(((size_t)width + 1) * sizeof(double));
	hline[1] = malloc(((size_t)width + 1) * sizeof(double));
	vrow = malloc(((size_t)width + 1) * sizeof *vrow);
	if (!hline[0] || !hline[1] || !vrow) {
		b->oom = 1;
		goto out;
	}
	/* lines j (bottom) and j+1 (top) bound row j */
	for (int jlo = b->j0, jhi = b->j1; jlo < b->j1; jlo = jhi) {
		if (b->next) {
			jlo = __atomic_fetch_add(b->next, CHUNK, __ATOMIC_RELAXED);
			if (jlo >= b->j1)
				break;
			jhi = jlo + CHUNK < b->j1 ? jlo + CHUNK : b->j1;
			prev = -2;
		}
		for (int j = jlo; j < jhi; j++) {
			double vb = ps_fisheye_v(&c->f, j), vt = ps_fisheye_v(&c->f, j + 1);
			double *hb = hline[j & 1], *ht = hline[(j + 1) & 1], *out = b->w + b->off[j];
			const double *u = b->u;
			int lo = b->lo[j], hi = b->hi[j];
			if (lo > hi)
				continue;
			/* with mirroring, the edges of pixels up to the middle one only; with
			 * transposing, from the diagonal on */
			int xe = b->mirror_x && (width - 1) / 2 < hi ? (width - 1) / 2 : hi;
			int xs = b->transpose && j > lo ? (j <= xe ? j : xe + 1) : lo;
			/* pixels [xa, xb] inside the rule's disc (solid_angle_rule): by
			 * the rule, the rest by their edges; the disc's pixels are one
			 * stretch (the farthest corner's radius falls, then grows) */
			int xa = 1, xb = 0;
			if (b->method == PS_W_EXACT && c->sa_n > 0) {
				double vv = fmax(vb * vb, vt * vt);
				for (xa = xs; xa <= xe && vv + fmax(u[xa] * u[xa], u[xa + 1] * u[xa + 1]) > c->sa_r2; xa++)
					;
				for (xb = xe; xb >= xa && vv + fmax(u[xb] * u[xb], u[xb + 1] * u[xb + 1]) > c->sa_r2; xb--)
					;
				if (xa <= xb)
					sa_row(c, u, xa, xb, lo, vb, vt, out);
			}
			if (b->method == PS_W_EXACT) {
				/* bottom line: reuse what the row below computed, where it did */
				for (int x = xs; x <= xe; x++)
					if ((x < xa || x > xb) && (prev != j - 1 || x < clo || x > chi))
						hb[x] = edge_hv(c, u[x], vb, u[x + 1], vb);
				for (int x = xs; x <= xe; x++)
					if (x < xa || x > xb)
						ht[x] = edge_hv(c, u[x], vt, u[x + 1], vt);
				for (int x = xs; x <= xe + 1; x++)
					if (x <= xa || x > xb)
						vrow[x] = edge_hv(c, u[x], vb, u[x], vt);
			}
			clo = xs;
			chi = xe;
			prev = xa <= xb ? -2 : j;   /* the top line is whole only without the rule */
			for (int x = xs; x <= xe; x++) {
				double wt;
				if (x >= xa && x <= xb)
					continue;
				if (b->method == PS_W_EXACT) {
					/* counter-clockwise: bottom, right, top (reversed), left (reversed) */
					struct ps_sum ps;
					ps_sum_init(&ps);
					ps_sum_add(&ps, hb[x]);
					ps_sum_add(&ps, vrow[x + 1]);
					ps_sum_add(&ps, -ht[x]);
					ps_sum_add(&ps, -vrow[x]);
					wt = ps_sum_get(&ps);
					if (wt < 0 && wt > -1e-15)
						wt = 0.0;   /* rounding on a pixel the sensor barely sees */
				} else {
					double uc = 0.5 * (u[x] + u[x + 1]), vc = 0.5 * (vb + vt);
					double rho = hypot(uc, vc), th = ps_fisheye_theta(&c->f, rho);
					wt = rho > 1.0 ? 0.0
					     : ps_sensor_value(b->s, th, atan2(vc, uc) - M_PI / 2 - c->rot) *
					           ps_fisheye_jacobian(&c->f, rho) * (u[x + 1] - u[x]) * (vt - vb);
				}
				out[x - lo] = wt;
			}
			/* the right half: the left half mirrored (after the transposes,
			 * when there are some: ps_weights_build) */
			for (int x = xe + 1; x <= hi && b->method == PS_W_EXACT && !b->transpose && !b->compact;
			     x++) {
				int xm = width - 1 - x;   /* the mirror pixel, left of the middle */
				out[x - lo] = xm >= lo ? out[xm - lo] : pixel_alone(c, u, x, vb, vt);
			}
			/* the centre-point method has no shared edges: the rest directly */
			for (int x = xe + 1; x <= hi && b->method != PS_W_EXACT; x++) {
				double uc = 0.5 * (u[x] + u[x + 1]), vc = 0.5 * (vb + vt);
				double rho = hypot(uc, vc), th = ps_fisheye_theta(&c->f, rho);
				out[x - lo] = rho > 1.0 ? 0.0
				              : ps_sensor_value(b->s, th, atan2(vc, uc) - M_PI / 2 - c->rot) *
				                    ps_fisheye_jacobian(&c->f, rho) * (u[x + 1] - u[x]) * (vt - vb);
			}
		}
	}
out:
	free(hline[0]);
	free(hline[1]);
	free(vrow);
	return NULL;
}

/* A compact map's second phase, rows shared among the threads CHUNK at a
 * time: left of the diagonal each row copies the transposed pixels (pixel
 * (x, j) is (j, x), computed in the first phase; a row's reads are one
 * double from each earlier row, and a chunk's rows read neighbouring ones,
 * so the lines stay in the cache), then sums its stored weights, each
 * times its mirrors (2 in x except the middle column). */
struct fill {
	const struct edge_ctx *c;
	const double *u;
	const int *lo, *hi;
	const size_t *off;
	double *w;
	int jtop, transpose, *next;
	struct ps_sum *rowsum;   /* per row of [0, jtop) */
};

static void *fill_run(void *arg)
{
	struct fill *f = arg;
	const struct edge_ctx *c = f->c;
	int width = c->f.width, xmid = (width - 1) / 2;
	for (;;) {
		int j0 = __atomic_fetch_add(f->next, CHUNK, __ATOMIC_RELAXED);
		if (j0 >= f->jtop)
			break;
		for (int j = j0; j < j0 + CHUNK && j < f->jtop; j++) {
			double vb = ps_fisheye_v(&c->f, j), vt = ps_fisheye_v(&c->f, j + 1);
			int xe = f->hi[j] < xmid ? f->hi[j] : xmid;
			double *row = f->w + f->off[j];
			ps_sum_init(&f->rowsum[j]);
			if (f->lo[j] > f->hi[j])
				continue;
			for (int x = f->lo[j]; f->transpose && x <= xe && x < j; x++) {
				int xe_x = f->hi[x] < xmid ? f->hi[x] : xmid;   /* row x's computed end */
				row[x - f->lo[j]] = f->lo[x] <= f->hi[x] && j >= f->lo[x] && j <= xe_x
				                        ? f->w[f->off[x] + (size_t)(j - f->lo[x])]
				                        : pixel_alone(c, f->u, x, vb, vt);
			}
			for (int x = f->lo[j]; x <= xe; x++)
				ps_sum_add(&f->rowsum[j],
				           (x != width - 1 - x ? 2.0 : 1.0) * row[x - f->lo[j]]);
		}
	}
	return NULL;
}

int ps_weights_build(struct ps_weights *w, const struct ps_sensor *s, double rotation_deg,
                     const struct ps_view *v, int width, int height, int method,
                     struct ps_err *e)
{
	return ps_weights_build_ex(w, s, rotation_deg, v, width, height, method, 0, e);
}

/* The rows' work in a band: pixels whose edges the row computes. */
static size_t row_work(int j, int lo, int hi, int width, int mirror_x, int transpose)
{
	int xe, xs;
	if (lo > hi)
		return 0;
	xe = mirror_x && (width - 1) / 2 < hi ? (width - 1) / 2 : hi;
	xs = transpose && j > lo ? (j <= xe ? j : xe + 1) : lo;
	return xe >= xs ? (size_t)(xe - xs + 1) : 0;
}

int ps_weights_build_ex(struct ps_weights *w, const struct ps_sensor *s, double rotation_deg,
                        const struct ps_view *v, int width, int height, int method, int flags,
                        struct ps_err *e)
{
	enum { MAX_THREADS = 8 };
	struct edge_ctx c;
	struct band bands[MAX_THREADS];
	pthread_t tid[MAX_THREADS];
	double R, *u = NULL;
	int *lo = NULL, *hi = NULL, nthreads = 1, started = 0, oom = 0, sym, jtop, transp, compact;
	int *runof = NULL, next_row = 0;
	size_t *off = NULL, *work = NULL, cap_runs = 0;
	struct ps_sum total;
	memset(w, 0, sizeof *w);
	if (width <= 0 || height <= 0)
		return ps_err_set(e, PS_EINVAL, "bad picture size %d x %d", width, height);
	if (!isfinite(rotation_deg))
		return ps_err_set(e, PS_EINVAL, "rotation %g is not a finite angle", rotation_deg);
	if (ps_view_check_fisheye(v, "view", e) != 0)
		return -1;
	w->width = width;
	w->height = height;
	w->method = method;
	ps_weights_key(s, rotation_deg, v, width, height, method, w->key, sizeof w->key);
	if (ctx_init(&c, s, rotation_deg, v, width, height, e) != 0)
		return -1;
	/* plane radius beyond which the sensor sees nothing */
	R = ps_fisheye_rho(&c.f, fmin(ps_sensor_extent(s), c.f.theta_field));
	if (ps_sensor_extent(s) >= c.f.theta_field)
		R = 1.0;
	R *= 1.0 + 1e-12;
	lo = malloc((size_t)height * sizeof *lo);
	hi = malloc((size_t)height * sizeof *hi);
	off = malloc((size_t)height * sizeof *off);
	work = malloc(((size_t)height + 1) * sizeof *work);
	runof = malloc((size_t)height * sizeof *runof);
	u = malloc(((size_t)width + 1) * sizeof *u);
	if (!lo || !hi || !off || !u || !work || !runof)
		goto oom;
	for (int x = 0; x <= width; x++)
		u[x] = ps_fisheye_u(&c.f, x);
	/* a symmetric map: the bands do the bottom half, its left half mirrored
	 * to the right; the top half is the bottom's mirror (below) */
	sym = method == PS_W_EXACT && v->vs == 0.0 && v->vl == 0.0 && sensor_symmetric(s);
	jtop = sym ? (height + 1) / 2 : height;
	/* square, with the same field across and up: symmetric in the diagonal */
	transp = sym && width == height && v->vh == v->vv;
	compact = sym && (flags & PS_WB_COMPACT);
	for (int j = 0; j < height; j++)
		row_range(&c.f, j, R, &lo[j], &hi[j]);
	if (compact) {
		/* the ranges made symmetric in x and y (a pixel more is a weight
		 * of 0 or one the sensor barely sees, computed as any other) */
		for (int j = 0; j < jtop; j++) {
			int jj = height - 1 - j, l = width;
			if (lo[j] <= hi[j])
				l = lo[j] < width - 1 - hi[j] ? lo[j] : width - 1 - hi[j];
			if (lo[jj] <= hi[jj]) {
				if (lo[jj] < l)
					l = lo[jj];
				if (width - 1 - hi[jj] < l)
					l = width - 1 - hi[jj];
			}
			if (l == width)
				continue;   /* both empty */
			lo[j] = lo[jj] = l;
			hi[j] = hi[jj] = width - 1 - l;
		}
	}
	/* the layout: one run per row the sensor sees, bottom row first; a
	 * compact map stores the left half of the bottom half's rows */
	for (int j = 0; j < height; j++) {
		size_t n;
		off[j] = w->nw;
		runof[j] = -1;
		if (lo[j] > hi[j])
			continue;
		n = (size_t)(hi[j] - lo[j] + 1);
		if (compact && j >= jtop) {
			if (push_run(w, &cap_runs, height - 1 - j, lo[j], (int)n, off[height - 1 - j]) != 0)
				goto oom;
			continue;
		}
		runof[j] = (int)w->nruns;
		if (push_run(w, &cap_runs, height - 1 - j, lo[j], (int)n, w->nw) != 0)
			goto oom;
		w->nw += compact ? (n + 1) / 2 : n;
	}
	w->mirror = compact;
	for (size_t i = 0; i < w->nruns; i++)
		w->npix += (size_t)w->runs[i].n;
	w->w = malloc((w->nw ? w->nw : 1) * sizeof *w->w);
	if (!w->w)
		goto oom;
	/* bands of about equal work (the pixels whose edges each row computes),
	 * one per core when there is enough of it */
	work[0] = 0;
	for (int j = 0; j < jtop; j++)
		work[j + 1] = work[j] + row_work(j, lo[j], hi[j], width, sym, transp);
	if (work[jtop] > 8192) {
		long n = sysconf(_SC_NPROCESSORS_ONLN);
		nthreads = n < 1 ? 1 : n > MAX_THREADS ? MAX_THREADS : (int)n;
	}
	/* the threads take CHUNK rows at a time from a shared counter: the
	 * rows' costs vary (more nodes near the centre, breaks) */
	for (int t = 0; t < nthreads; t++)
		bands[t] = (struct band){ &c, s, method, u, lo, hi, off, 0, jtop, w->w, 0, sym, transp,
		                          compact, nthreads > 1 ? &next_row : NULL };
	for (int t = 1; t < nthreads; t++)
		if (pthread_create(&tid[t], NULL, band_run, &bands[t]) != 0)
			bands[t].oom = -1;   /* run it here instead */
		else
			started |= 1 << t;
	band_run(&bands[0]);
	for (int t = 1; t < nthreads; t++) {
		if (started & (1 << t))
			pthread_join(tid[t], NULL);
		else
			band_run(&bands[t]);
		oom |= bands[t].oom > 0;
	}
	if (oom || bands[0].oom)
		goto oom;
	if (compact) {
		/* the transposes and the rows' sums, on every core */
		struct fill f = { &c, u, lo, hi, off, w->w, jtop, transp, &next_row, NULL };
		pthread_t ft[MAX_THREADS];
		int fstarted = 0;
		f.rowsum = malloc(((size_t)jtop + 1) * sizeof *f.rowsum);
		if (!f.rowsum)
			goto oom;
		next_row = 0;
		for (int t = 1; t < nthreads; t++)
			if (pthread_create(&ft[t], NULL, fill_run, &f) == 0)
				fstarted |= 1 << t;
		fill_run(&f);
		for (int t = 1; t < nthreads; t++)
			if (fstarted & (1 << t))
				pthread_join(ft[t], NULL);
		/* rows in order: each stands for its mirror row too (times 2,
		 * exact), except the middle one */
		ps_sum_init(&total);
		for (int j = 0; j < jtop; j++) {
			double fr = height - 1 - j != j ? 2.0 : 1.0;
			ps_sum_add(&total, fr * f.rowsum[j].s);
			ps_sum_add(&total, fr * f.rowsum[j].c);
		}
		free(f.rowsum);
	} else if (transp) {
		int xmid = (width - 1) / 2;
		/* left of the diagonal: pixel (x, j) is pixel (j, x) transposed */
		for (int j = 0; j < jtop; j++) {
			double vb = ps_fisheye_v(&c.f, j), vt = ps_fisheye_v(&c.f, j + 1);
			int xe = hi[j] < xmid ? hi[j] : xmid;
			for (int x = lo[j]; x <= xe && x < j; x++) {
				int xe_x = hi[x] < xmid ? hi[x] : xmid;   /* row x's computed end */
				w->w[off[j] + (size_t)(x - lo[j])] =
				    lo[x] <= hi[x] && j >= lo[x] && j <= xe_x
				        ? w->w[off[x] + (size_t)(j - lo[x])]
				        : pixel_alone(&c, u, x, vb, vt);
			}
		}
		/* then the right half of those rows, mirrored */
		for (int j = 0; j < jtop && !compact; j++) {
			double vb = ps_fisheye_v(&c.f, j), vt = ps_fisheye_v(&c.f, j + 1);
			for (int x = xmid + 1; x <= hi[j]; x++) {
				int xm = width - 1 - x;
				w->w[off[j] + (size_t)(x - lo[j])] =
				    xm >= lo[j] ? w->w[off[j] + (size_t)(xm - lo[j])]
				                : pixel_alone(&c, u, x, vb, vt);
			}
		}
	}
	for (int j = jtop; j < height && !compact; j++) {
		int jj = height - 1 - j;   /* the mirror row, computed above */
		double vb = ps_fisheye_v(&c.f, j), vt = ps_fisheye_v(&c.f, j + 1);
		for (int x = lo[j]; x <= hi[j]; x++)
			w->w[off[j] + (size_t)(x - lo[j])] =
			    x >= lo[jj] && x <= hi[jj] ? w->w[off[jj] + (size_t)(x - lo[jj])]
			                               : pixel_alone(&c, u, x, vb, vt);
	}
	if (!compact) {
		ps_sum_init(&total);
		for (size_t i = 0; i < w->nw; i++)
			ps_sum_add(&total, w->w[i]);
	}
	w->sens_sum = ps_sum_get(&total);
	w->sens_full = ps_sensor_integral(s);
	w->coverage = w->sens_full > 0 ? w->sens_sum / w->sens_full : 0.0;
	if (method == PS_W_EXACT) {
		w->solid_angle = ps_weights_rect_solid_angle(c.f.type, u[0], ps_fisheye_v(&c.f, 0),
		                                             u[width], ps_fisheye_v(&c.f, height));
	} else {
		struct ps_sum sa;
		ps_sum_init(&sa);
		for (int j = 0; j < height; j++)
			for (int x = 0; x < width; x++) {
				double uc = 0.5 * (u[x] + u[x + 1]);
				double vc = ps_fisheye_v(&c.f, j + 0.5);
				ps_sum_add(&sa, ps_fisheye_jacobian(&c.f, hypot(uc, vc)) * (u[x + 1] - u[x]) *
				                    (c.f.sv / height));
			}
		w->solid_angle = ps_sum_get(&sa);
	}
	free(lo);
	free(hi);
	free(off);
	free(work);
	free(runof);
	free(u);
	ctx_free(&c);
	return 0;
oom:
	free(lo);
	free(hi);
	free(off);
	free(work);
	free(runof);
	free(u);
	ctx_free(&c);
	ps_weights_free(w);
	return ps_err_set(e, PS_ENOMEM, "out of memory building %d x %d weights", width, height);
}

/* ---- pieces for routes that take the exact weights of some pixels only ---- */

struct ps_weights_exact {
	struct edge_ctx c;
	double *u;
};

int ps_weights_exact_open(struct ps_weights_exact **out, const struct ps_sensor *s,
                          double rotation_deg, const struct ps_view *v, int width, int height,
                          struct ps_err *e)
{
	struct ps_weights_exact *x = calloc(1, sizeof *x);
	*out = NULL;
	if (!x)
		return ps_err_set(e, PS_ENOMEM, "out of memory");
	if (ctx_init(&x->c, s, rotation_deg, v, width, height, e) != 0) {
		free(x);
		return -1;
	}
	x->u = malloc(((size_t)width + 1) * sizeof *x->u);
	if (!x->u) {
		ctx_free(&x->c);
		free(x);
		return ps_err_set(e, PS_ENOMEM, "out of memory");
	}
	for (int k = 0; k <= width; k++)
		x->u[k] = ps_fisheye_u(&x->c.f, k);
	*out = x;
	return 0;
}

double ps_weights_exact_hedge(const struct ps_weights_exact *x, int px, int line)
{
	double v = ps_fisheye_v(&x->c.f, line);
	return edge_hv(&x->c, x->u[px], v, x->u[px + 1], v);
}

double ps_weights_exact_vedge(const struct ps_weights_exact *x, int col, int jb)
{
	return edge_hv(&x->c, x->u[col], ps_fisheye_v(&x->c.f, jb), x->u[col], ps_fisheye_v(&x->c.f, jb + 1));
}

double ps_weights_exact_pixel(double bottom, double right, double top, double left)
{
	struct ps_sum ps;
	double wt;
	ps_sum_init(&ps);
	ps_sum_add(&ps, bottom);
	ps_sum_add(&ps, right);
	ps_sum_add(&ps, -top);
	ps_sum_add(&ps, -left);
	wt = ps_sum_get(&ps);
	return wt < 0 && wt > -1e-15 ? 0.0 : wt;
}

void ps_weights_exact_close(struct ps_weights_exact *x)
{
	if (!x)
		return;
	ctx_free(&x->c);
	free(x->u);
	free(x);
}

int ps_weights_layout(struct ps_weights *w, const struct ps_sensor *s, double rotation_deg,
                      const struct ps_view *v, int width, int height, struct ps_err *e)
{
	struct ps_fisheye f;
	size_t cap = 0;
	double R;
	memset(w, 0, sizeof *w);
	if (width <= 0 || height <= 0)
		return ps_err_set(e, PS_EINVAL, "bad picture size %d x %d", width, height);
	if (!isfinite(rotation_deg))
		return ps_err_set(e, PS_EINVAL, "rotation %g is not a finite angle", rotation_deg);
	if (ps_view_check_fisheye(v, "view", e) != 0)
		return -1;
	w->width = width;
	w->height = height;
	w->method = PS_W_EXACT;
	ps_weights_key(s, rotation_deg, v, width, height, PS_W_EXACT, w->key, sizeof w->key);
	ps_fisheye_init(&f, v, width, height);
	/* as ps_weights_build_ex's full map */
	R = ps_fisheye_rho(&f, fmin(ps_sensor_extent(s), f.theta_field));
	if (ps_sensor_extent(s) >= f.theta_field)
		R = 1.0;
	R *= 1.0 + 1e-12;
	for (int j = 0; j < height; j++) {
		int lo, hi;
		row_range(&f, j, R, &lo, &hi);
		if (lo > hi)
			continue;
		if (push_run(w, &cap, height - 1 - j, lo, hi - lo + 1, w->nw) != 0)
			goto oom;
		w->nw += (size_t)(hi - lo + 1);
	}
	w->npix = w->nw;
	{
		/* a large map in huge pages where the system lends them on request:
		 * the first touch of 100 MB costs 50 faults instead of 25000 */
		size_t bytes = (w->nw ? w->nw : 1) * sizeof *w->w, huge = (size_t)2 << 20;
		void *p = NULL;
		if (bytes >= 4 * huge) {
			if (posix_memalign(&p, huge, bytes) != 0)
				p = NULL;
#ifdef MADV_HUGEPAGE
			else
				madvise(p, bytes & ~(huge - 1), MADV_HUGEPAGE);
#endif
		} else {
			p = malloc(bytes);
		}
		w->w = p;
	}
	if (!w->w)
		goto oom;
	w->sens_full = ps_sensor_integral(s);
	w->solid_angle = ps_weights_rect_solid_angle(f.type, ps_fisheye_u(&f, 0), ps_fisheye_v(&f, 0),
	                                             ps_fisheye_u(&f, width), ps_fisheye_v(&f, height));
	return 0;
oom:
	ps_weights_free(w);
	return ps_err_set(e, PS_ENOMEM, "out of memory laying out %d x %d weights", width, height);
}
