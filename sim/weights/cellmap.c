/* SPDX-License-Identifier: ISC */
#include "cellmap.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <stdint.h>
#include <sys/mman.h>
#include <unistd.h>

#include "fisheye.h"
#include "sum.h"

enum { MAX_THREADS = 8, CHUNK = 16 };

/* Large arrays filled once and read across rows (the moments' mirrored
 * reads stride a whole quadrant row): huge pages where the kernel offers
 * them, for fewer faults and TLB misses; a refusal only costs time. */
static void advise_huge(void *p, size_t n)
{
	long pg = sysconf(_SC_PAGESIZE);
	uintptr_t a, b;
	if (pg <= 0 || n < ((size_t)4 << 20))
		return;
	a = ((uintptr_t)p + (uintptr_t)pg - 1) & ~((uintptr_t)pg - 1);
	b = ((uintptr_t)p + n) & ~((uintptr_t)pg - 1);
	if (b > a)
		madvise((void *)a, b - a, MADV_HUGEPAGE);
}

int ps_cellmap_fits(const struct ps_sensor *s, int method)
{
	if (method != PS_W_EXACT || s->kind != PS_SENS_TABLE)
		return 0;
	for (int i = 0; i < s->ntheta; i++)
		for (int j = 1; j < s->nphi; j++)
			if (s->val[(size_t)i * (size_t)s->nphi + (size_t)j] != s->val[(size_t)i * (size_t)s->nphi])
				return s->reading == PS_READ_CELL ? PS_CELLMAP_CELL : PS_CELLMAP_LINEAR;
	return 0;
}

/* ---- the linear reading: centred moments ----------------------------------
 * Inside one patch the linear reading is bilinear in theta and phi, so about
 * a pixel's centre (theta_c, phi_c)
 *   S = S_c + S_t dt + S_p dp + S_tp dt dp,  dt = theta - theta_c, dp = phi - phi_c
 * exactly, and a pixel inside one patch weighs
 *   S_c omega + S_t M_t + S_p M_p + S_tp M_tp
 * with omega its solid angle (the cached map) and M_* the integrals of dt,
 * dp and dt dp over its solid angle.  On the angular projection (theta =
 * pi rho, density J = pi sin(pi rho) / rho) these are integrals over the
 * pixel of functions analytic except where u^2 + v^2 = 0: an n x n
 * Gauss-Legendre rule on a pixel whose nearest point lies at rho_min >= 20
 * pixel sides h from the zenith errs per coordinate by at most
 * 64 Mx / (15 (R^2 - 1) R^(2n)) with R = rho_min / h (Trefethen, ATAP,
 * theorem 19.3, on the Bernstein ellipse of half the singularity's
 * parameter, >= 2 rho_min / h): inside it one coordinate is complex, at
 * most rho_min / 4 off the pixel, so |rho| <= r = rho_max + rho_min / 2,
 * |J| <= pi sinh(pi r) / r, |dt| < 1.1, |dp| < 0.5, |dt dp| < 0.55 and
 * Mx <= |J| (1.1 G_t + 0.5 G_p + 0.55 G_tp), G_* the table's largest slopes
 * |S_t|, |S_p|, |S_tp|.  n is the smallest up to LIN_MAXN with twice that
 * bound times the pixel's area below 1e-14 of the table's largest value
 * times the area (the largest weight is that value times up to pi^2 times
 * the area: 100 times below the 1e-12 asked of a weight); pixels nearer the zenith, reaching
 * the field's edge, or with no such n take the exact edge route.  dp is
 * atan((u_c v - v_c u) / (u_c u + v_c v)) by its series (the ratio below
 * 0.04 at 20 h), dt is pi (rho^2 - rho_c^2) / (rho + rho_c): no
 * cancellation.  The moments are the view's alone: on a view not shifted
 * they are computed for the lower left quadrant and mirrored (dt the same,
 * dp changes sign under each reflection). */
enum { LIN_MAXN = 8, LIN_ZENITH = 20, LIN_JSTEPS = 64 };

struct gl {
	int n;
	double x[LIN_MAXN], w[LIN_MAXN];
};

static void gl_rule(struct gl *r, int n)
{
	r->n = n;
	for (int i = 0; i < n; i++) {
		double x = cos(M_PI * (i + 0.75) / (n + 0.5)), p = 1, dp = 0;
		for (int it = 0; it < 100; it++) {
			double p0 = 1.0, p1 = x, dx;
			for (int k = 2; k <= n; k++) {
				double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
				p0 = p1;
				p1 = p2;
			}
			p = p1;
			dp = n * (x * p1 - p0) / (x * x - 1.0);
			dx = p / dp;
			x -= dx;
			if (fabs(dx) < 1e-16)
				break;
		}
		{
			double p0 = 1.0, p1 = x;
			for (int k = 2; k <= n; k++) {
				double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
				p0 = p1;
				p1 = p2;
			}
			dp = n * (x * p1 - p0) / (x * x - 1.0);
		}
		r->x[i] = x;
		r->w[i] = 2.0 / ((1.0 - x * x) * dp * dp);
	}
}

/* atan(x) for |x| <= 0.05 by its series: to x^7 below |x| = 1e-3, to x^11
 * below 1e-2, else to x^17 (the first omitted term below 1e-22 of x). */
static inline double atan_small(double x)
{
	double x2 = x * x;
	if (x2 < 1e-6)
		return x * (1 + x2 * (-1.0 / 3 + x2 * (1.0 / 5 + x2 * (-1.0 / 7))));
	if (x2 < 1e-4)
		return x * (1 + x2 * (-1.0 / 3 + x2 * (1.0 / 5 + x2 * (-1.0 / 7 + x2 * (1.0 / 9 +
		       x2 * (-1.0 / 11))))));
	return x * (1 + x2 * (-1.0 / 3 + x2 * (1.0 / 5 + x2 * (-1.0 / 7 + x2 * (1.0 / 9 +
	       x2 * (-1.0 / 11 + x2 * (1.0 / 13 + x2 * (-1.0 / 15 + x2 * (1.0 / 17)))))))));
}

/* sin(pi rc + d) from sc = sin(pi rc), cc = cos(pi rc) and |d| <= LIN_SERIES:
 * sin(d) to d^9 and cos(d) to d^10 (the first omitted terms below 2e-23 and
 * 3e-26 of 1 at 0.05), so one sine and cosine per pixel, not one per node;
 * for |d| <= LIN_SHORT (pixels under 1/700 of the plane's unit) sin(d) to
 * d^5 and cos(d) to d^6 (the first omitted terms below 3e-23 and 7e-27). */
#define LIN_SERIES 0.05
#define LIN_SHORT 2e-3
static inline double sin_near_short(double sc, double cc, double d)
{
	double d2 = d * d;
	double sd = d * (1 + d2 * (-1.0 / 6 + d2 * (1.0 / 120)));
	double cd = 1 + d2 * (-1.0 / 2 + d2 * (1.0 / 24 + d2 * (-1.0 / 720)));
	return sc * cd + cc * sd;
}

static inline double sin_near(double sc, double cc, double d)
{
	double d2 = d * d;
	double sd = d * (1 + d2 * (-1.0 / 6 + d2 * (1.0 / 120 + d2 * (-1.0 / 5040 + d2 * (1.0 / 362880)))));
	double cd = 1 + d2 * (-1.0 / 2 + d2 * (1.0 / 24 + d2 * (-1.0 / 720 + d2 * (1.0 / 40320 +
	            d2 * (-1.0 / 3628800)))));
	return sc * cd + cc * sd;
}

/* sin and cos of pi k / LIN_TAB, k = 0 .. LIN_TAB (a moment pixel's centre
 * lies inside the unit circle) */
#define LIN_TAB 1024

struct lin {
	double tsin[LIN_TAB + 1], tcos[LIN_TAB + 1];
	int series;          /* the nodes' sines from the centre's: 2 sin_near_short, 1 sin_near, 0 sin */
	int qw, qh;          /* the moments' columns [0, qw), bottom-based rows [0, qh) */
	int mirror;          /* 1: a quadrant, mirrored; 0: every pixel */
	double *mom;         /* qw x qh x 3: M_t, M_p, M_tp; NaN: the exact route */
	int transpose;       /* and symmetric in the diagonal: x >= j only */
	double h, kbound;    /* pixel side; the bound's constant over the tolerance */
	double du, dv;       /* a pixel's sides in the plane */
	double jbound[2 * LIN_JSTEPS + 1];   /* pi sinh(pi r) / r at r = k / LIN_JSTEPS */
	struct gl gl[LIN_MAXN + 1];
	int next;
};

/* The largest slopes of the linear reading's patches. */
static void lin_slopes(const struct ps_sensor *s, double *gt, double *gp, double *gtp)
{
	*gt = *gp = *gtp = 0.0;
	for (int i = 0; i < s->nt; i++)
		for (int j = 0; j < s->np; j++) {
			const double *c = s->corner + 4 * ((size_t)i * (size_t)s->np + (size_t)j);
			double dt = s->tb[i + 1] - s->tb[i], dp = s->pb[j + 1] - s->pb[j];
			*gt = fmax(*gt, fmax(fabs(c[1] - c[0]), fabs(c[3] - c[2])) / dt);
			*gp = fmax(*gp, fmax(fabs(c[2] - c[0]), fabs(c[3] - c[1])) / dp);
			*gtp = fmax(*gtp, fabs(c[0] - c[1] - c[2] + c[3]) / (dt * dp));
		}
}

/* The centred moments of pixel x on bottom-based row j; -1: the exact route. */
static int lin_moments(const struct lin *L, const struct ps_fisheye *f, int x, int j, double m[3])
{
	double u0 = f->u0 + x * L->du, u1 = f->u0 + (x + 1) * L->du;
	double v0 = f->v0 + j * L->dv, v1 = f->v0 + (j + 1) * L->dv;
	double du = u0 > 0 ? u0 : u1 < 0 ? -u1 : 0.0, dv = v0 > 0 ? v0 : v1 < 0 ? -v1 : 0.0;
	double rmin = sqrt(du * du + dv * dv), umax = fmax(fabs(u0), fabs(u1)), vmax = fmax(fabs(v0), fabs(v1));
	double R, b, um, uh, vm, vh, uc, vc, rc2, rc, mt = 0, mp = 0, mtp = 0, sc = 0, cc = 0;
	const struct gl *g;
	int n;
	if (umax * umax + vmax * vmax >= 1.0 || !(rmin >= LIN_ZENITH * L->h))
		return -1;
	R = rmin / L->h;
	{
		/* |J| on the ellipse: at most pi sinh(pi r) / r (growing with r),
		 * r bounding |rho| there, taken at the next 64th up */
		double r = sqrt(umax * umax + vmax * vmax) + 0.5 * rmin;
		b = L->kbound * L->jbound[(int)ceil(r * LIN_JSTEPS)];
	}
	{
		/* the bound b / ((R^2 - 1) R^(2n)) <= 1, without a division */
		double R2 = R * R, t = (R2 - 1.0) * R2;
		for (n = 2; n <= LIN_MAXN; n++) {
			t *= R2;
			if (b <= t)
				break;
		}
	}
	if (n > LIN_MAXN)
		return -1;
	g = &L->gl[n];
	um = 0.5 * (u0 + u1);
	uh = 0.5 * (u1 - u0);
	vm = 0.5 * (v0 + v1);
	vh = 0.5 * (v1 - v0);
	uc = um;
	vc = vm;
	rc2 = uc * uc + vc * vc;
	rc = sqrt(rc2);
	if (L->series) {
		/* from the table's nearest point: |d| <= pi / (2 LIN_TAB) < LIN_SHORT */
		int k = (int)(rc * LIN_TAB + 0.5);
		double d = M_PI * (rc - (double)k / LIN_TAB), d2 = d * d;
		double sd = d * (1 + d2 * (-1.0 / 6 + d2 * (1.0 / 120)));
		double cd = 1 + d2 * (-1.0 / 2 + d2 * (1.0 / 24 + d2 * (-1.0 / 720)));
		sc = L->tsin[k] * cd + L->tcos[k] * sd;
		cc = L->tcos[k] * cd - L->tsin[k] * sd;
	}
	for (int bq = 0; bq < n; bq++) {
		double v = vm + vh * g->x[bq], st = 0, sp = 0, stp = 0;
		for (int a = 0; a < n; a++) {
			double u = um + uh * g->x[a], r2 = u * u + v * v, r = sqrt(r2);
			double q = 1.0 / (r * (r + rc));   /* one division for 1/r and 1/(r + rc) */
			double dt = M_PI * (r2 - rc2) * (q * r);
			double J = (L->series == 2 ? sin_near_short(sc, cc, dt)
			            : L->series ? sin_near(sc, cc, dt) : sin(M_PI * r)) * (M_PI * (q * (r + rc))) *
			           g->w[a];
			double dp = atan_small((uc * v - vc * u) / (uc * u + vc * v));
			st += J * dt;
			sp += J * dp;
			stp += J * dt * dp;
		}
		mt += g->w[bq] * st;
		mp += g->w[bq] * sp;
		mtp += g->w[bq] * stp;
	}
	m[0] = mt * uh * vh;
	m[1] = mp * uh * vh;
	m[2] = mtp * uh * vh;
	return 0;
}

static void lin_free(struct lin *L)
{
	if (L)
		free(L->mom);
	free(L);
}

struct lin_job {
	struct lin *L;
	const struct ps_fisheye *f;
};

static void *lin_run(void *arg)
{
	struct lin_job *lj = arg;
	struct lin *L = lj->L;
	for (;;) {
		int j0 = __atomic_fetch_add(&L->next, CHUNK, __ATOMIC_RELAXED);
		if (j0 >= L->qh)
			break;
		for (int j = j0; j < j0 + CHUNK && j < L->qh; j++)
			for (int x = L->transpose ? j : 0; x < L->qw; x++) {
				double *m = L->mom + 3 * ((size_t)j * (size_t)L->qw + (size_t)x);
				if (lin_moments(L, lj->f, x, j, m) != 0)
					m[0] = m[1] = m[2] = NAN;
			}
	}
	return NULL;
}

/* The moments of pixel x on bottom-based row j (a pointer into L->mom) and
 * the sign of its dp (-1 when mirrored an odd number of times). */
static const double *lin_at(const struct lin *L, int width, int height, int x, int j, double *sign)
{
	double sg = 1.0;
	if (L->mirror) {
		if (x >= L->qw) {
			x = width - 1 - x;
			sg = -sg;
		}
		if (j >= L->qh) {
			j = height - 1 - j;
			sg = -sg;
		}
		if (L->transpose && x < j) {   /* u and v swapped: phi - phi_c changes sign */
			int t = x;
			x = j;
			j = t;
			sg = -sg;
		}
	}
	*sign = sg;
	return L->mom + 3 * ((size_t)j * (size_t)L->qw + (size_t)x);
}

struct job {
	const struct ps_sensor *s;
	struct ps_fisheye f;
	double rot;                      /* radians */
	const struct ps_weights *omega;
	const int *orun;                 /* top-based row -> omega's run, -1: none */
	struct ps_weights *w;
	const struct ps_weights_exact *ex;
	const double *radius;            /* plane radii of the circles (cells, table end, field) */
	int nradius;
	const double *ray_c, *ray_s;     /* the rays' directions in the plane */
	double tmax;                     /* beyond the picture's farthest corner from the zenith */
	double du, dv;                   /* a pixel's sides in the plane */
	int nray;
	struct ps_sum *rowsum;           /* per run */
	const struct lin *lin;           /* the linear reading's moments; NULL: the cell reading */
	size_t nexact;                   /* pixels that took the edge route */
	int next;
	int oom;
};

/* Mark the pixels of [x0, x1] (a run) whose closed u range meets [ua, ub]
 * (a millionth of a pixel wider on each side: a curve through a pixel
 * corner or along a pixel edge marks the pixels on both sides, whatever
 * the rounding of a, b). */
static void mark_u(const struct job *jb, unsigned char *mark, int x0, int x1, double ua, double ub)
{
	double du = jb->f.su / jb->f.width, a, b;
	int xa, xb;
	if (!(ua <= ub))
		return;
	a = (fmax(ua, -1e9) - jb->f.u0) / du;
	b = (fmin(ub, 1e9) - jb->f.u0) / du;
	xa = (int)floor(fmax(a, -2.0) - 1e-6);
	xb = (int)floor(fmin(b, (double)jb->f.width + 2.0) + 1e-6);
	if (xa < x0)
		xa = x0;
	if (xb > x1)
		xb = x1;
	for (int x = xa; x <= xb; x++)
		mark[x] = 1;
}

/* Mark the pixels of the run on row band [vb, vt] that a circle or a ray
 * may touch. */
static void mark_row(const struct job *jb, unsigned char *mark, int x0, int x1, double vb, double vt)
{
	double vmin = vb <= 0 && vt >= 0 ? 0.0 : fmin(fabs(vb), fabs(vt));
	double vmax = fmax(fabs(vb), fabs(vt));
	memset(mark + x0, 0, (size_t)(x1 - x0 + 1));
	for (int k = 0; k < jb->nradius; k++) {
		/* the circle meets the band where |u| = sqrt(R^2 - v^2), v in it */
		double r2 = jb->radius[k] * jb->radius[k], a, b;
		if (r2 < vmin * vmin)
			continue;
		a = sqrt(fmax(r2 - vmax * vmax, 0.0));
		b = sqrt(r2 - vmin * vmin);
		mark_u(jb, mark, x0, x1, a, b);
		mark_u(jb, mark, x0, x1, -b, -a);
	}
	for (int k = 0; k < jb->nray; k++) {
		/* the ray (t c, t s), t >= 0, inside the band */
		double c = jb->ray_c[k], s = jb->ray_s[k], t0, t1;
		if (s == 0.0) {
			if (vb <= 0 && vt >= 0)
				mark_u(jb, mark, x0, x1, c > 0 ? 0.0 : -1e9, c > 0 ? 1e9 : 0.0);
			continue;
		}
		t0 = (s > 0 ? vb : vt) / s;
		t1 = (s > 0 ? vt : vb) / s;
		/* within the picture: a ray along a picture axis has s of
		 * rounding's size, t0 and t1 far beyond it */
		t0 = fmax(t0, 0.0);
		t1 = fmin(t1, jb->tmax);
		if (t1 < t0)
			continue;
		mark_u(jb, mark, x0, x1, fmin(c * t0, c * t1), fmax(c * t0, c * t1));
	}
	if (vb <= 0 && vt >= 0)
		mark_u(jb, mark, x0, x1, 0.0, 0.0);   /* the zenith */
}

/* The cell value at the centre of pixel x on bottom-based row j. */
static double cell_value(const struct job *jb, int x, int j)
{
	const struct ps_sensor *s = jb->s;
	double uc = ps_fisheye_u(&jb->f, x + 0.5), vc = ps_fisheye_v(&jb->f, j + 0.5);
	double theta = ps_fisheye_theta(&jb->f, hypot(uc, vc));
	double phi = atan2(vc, uc) - M_PI / 2 - jb->rot;
	int i, k;
	ps_sensor_locate(s, theta, &phi, &i, &k);
	return i >= s->nt ? 0.0 : s->val[(size_t)i * (size_t)s->nphi + (size_t)k];
}

/* The linear reading's patch of a stretch: its corners, breakpoints, and
 * the turn from the plane azimuth to the sensor's phi in it. */
struct patch {
	const double *c;
	double t0, p0, p1, dt, dp, idt, idp, off;
	double c0, dT, dP, dTP, stp;   /* c[0] and the differences of the corners */
	double ua, va, pa;   /* the last pixel centre whose phi came from atan2, and that phi */
	int anchored;
};

static void lin_patch(const struct job *jb, int x, int j, struct patch *P)
{
	const struct ps_sensor *s = jb->s;
	double uc = ps_fisheye_u(&jb->f, x + 0.5), vc = ps_fisheye_v(&jb->f, j + 0.5);
	double raw = atan2(vc, uc) - M_PI / 2 - jb->rot, ph = raw;
	int i, k;
	ps_sensor_locate(s, M_PI * sqrt(uc * uc + vc * vc), &ph, &i, &k);
	if (i >= s->nt)
		i = s->nt - 1;   /* beyond the table's end: S = 0 (lin_weight) */
	P->c = s->corner + 4 * ((size_t)i * (size_t)s->np + (size_t)k);
	P->t0 = s->tb[i];
	P->dt = s->tb[i + 1] - s->tb[i];
	P->p0 = s->pb[k];
	P->p1 = s->pb[k + 1];
	P->dp = s->pb[k + 1] - s->pb[k];
	P->idt = 1.0 / P->dt;
	P->idp = 1.0 / P->dp;
	P->c0 = P->c[0];
	P->dT = P->c[1] - P->c[0];
	P->dP = P->c[2] - P->c[0];
	P->dTP = P->c[0] - P->c[1] - P->c[2] + P->c[3];
	P->stp = P->dTP * (P->idt * P->idp);
	P->off = ph - raw;
	P->anchored = 0;
}

/* A linear-reading pixel inside patch P (x on bottom-based row j):
 * S_c omega + S_t M_t + S_p M_p + S_tp M_tp (the moments m, dp's sign sg). */
static double lin_weight(const struct job *jb, struct patch *P, int x, int j, double omega,
                         const double *m, double sg)
{
	/* the centre by the pixel's step: no division at every pixel */
	double uc = jb->f.u0 + (x + 0.5) * jb->du, vc = jb->f.v0 + (j + 0.5) * jb->dv;
	double th = M_PI * sqrt(uc * uc + vc * vc), ph, t, w, sc, st, sp, stp;
	if (th >= jb->s->theta_end)
		return 0.0;
	{
		/* phi from the anchor's by atan's series while the turn is small
		 * (|ratio| <= 0.01: atan_small to x^11), else afresh from atan2 */
		double den = P->ua * uc + P->va * vc, num = P->ua * vc - P->va * uc;
		if (P->anchored && den > 0 && fabs(num) <= 0.01 * den) {
			ph = P->pa + atan_small(num / den);
		} else {
			ph = atan2(vc, uc) - M_PI / 2 - jb->rot + P->off;
			P->ua = uc;
			P->va = vc;
			P->pa = ph;
			P->anchored = 1;
		}
	}
	if (ph < P->p0 - 1e-9 || ph > P->p1 + 1e-9) {
		/* atan2's cut inside the stretch: phi reduced afresh */
		int i, k;
		ph = atan2(vc, uc) - M_PI / 2 - jb->rot;
		ps_sensor_locate(jb->s, th, &ph, &i, &k);
		P->anchored = 0;
	}
	t = (th - P->t0) * P->idt;
	w = (ph - P->p0) * P->idp;
	/* the patch c0 + t dT + w dP + t w dTP in its fractions t, w */
	sp = P->dP + t * P->dTP;
	sc = P->c0 + t * P->dT + w * sp;
	st = (P->dT + w * P->dTP) * P->idt;
	sp *= P->idp;
	stp = P->stp;
	return sc * omega + st * m[0] + sg * (sp * m[1] + stp * m[2]);
}

/* A thread's rows, CHUNK runs (consecutive rows, bottom up) at a time.
 * The exact pixels share their edges: a vertical one with the marked
 * neighbour on its left, the bottom one with the marked pixel below when
 * the row below was done here just before. */
struct rowbuf {
	unsigned char *mark[2];
	double *htop[2];
	int x0[2], x1[2];
};

static void *fill_run(void *arg)
{
	struct job *jb = arg;
	struct ps_weights *w = jb->w;
	size_t wd = (size_t)jb->f.width + 1, nexact = 0;
	struct rowbuf b;
	b.mark[0] = malloc(2 * wd);
	b.htop[0] = malloc(2 * wd * sizeof(double));
	if (!b.mark[0] || !b.htop[0]) {
		free(b.mark[0]);
		free(b.htop[0]);
		__atomic_store_n(&jb->oom, 1, __ATOMIC_RELAXED);
		return NULL;
	}
	b.mark[1] = b.mark[0] + wd;
	b.htop[1] = b.htop[0] + wd;
	for (;;) {
		size_t r0 = (size_t)__atomic_fetch_add(&jb->next, CHUNK, __ATOMIC_RELAXED);
		int prev_j = -2;   /* the bottom-based row done last here (its marks in b.*[1 - cur]) */
		int cur = 0;
		if (r0 >= w->nruns)
			break;
		for (size_t ri = r0; ri < r0 + CHUNK && ri < w->nruns; ri++) {
			const struct ps_weights_run *run = &w->runs[ri];
			int j = w->height - 1 - run->row, x0 = run->x0, x1 = run->x0 + run->n - 1;
			int oi = jb->orun[run->row], below = prev_j == j - 1, prev_x = -2;
			const struct ps_weights_run *orun = oi >= 0 ? &jb->omega->runs[oi] : NULL;
			unsigned char *mark = b.mark[cur], *mark_b = b.mark[1 - cur];
			double *ht = b.htop[cur], *hb_prev = b.htop[1 - cur];
			double *out = w->w + run->off, vright = 0.0;
			struct ps_sum rs;   /* local: the stores to out cannot alias it */
			mark_row(jb, mark, x0, x1, ps_fisheye_v(&jb->f, j), ps_fisheye_v(&jb->f, j + 1));
			ps_sum_init(&rs);
			for (int x = x0; x <= x1;) {
				double wt;
				if (!orun || x < orun->x0 || x >= orun->x0 + orun->n ||
				    (!jb->lin && jb->s->reading != PS_READ_CELL))
					mark[x] = 1;   /* no solid angle to scale, no moments: the edge route */
				if (!mark[x] && jb->lin) {
					/* the linear reading: a stretch of unmarked pixels, all in
					 * the first one's patch, from the moments */
					int xe = x, oe = orun->x0 + orun->n, q;
					double lane[4] = { 0, 0, 0, 0 };
					struct patch P;
					while (xe < x1 && xe + 1 < oe && !mark[xe + 1])
						xe++;
					lin_patch(jb, x, j, &P);
					for (q = x; q <= xe; q++) {
						double mm[3], sg = 1.0, wq;
						const double *m = mm;
						if (jb->lin->mirror)
							m = lin_at(jb->lin, w->width, w->height, q, j, &sg);
						else if (lin_moments(jb->lin, &jb->f, q, j, mm) != 0)
							mm[0] = NAN;
						if (isnan(m[0])) {
							mark[q] = 1;   /* near the zenith or the field's edge */
							break;
						}
						wq = lin_weight(jb, &P, q, j, ps_weights_run_at(jb->omega, orun, q - orun->x0), m, sg);
						out[q - x0] = wq;
						lane[(q - x) & 3] += wq;
					}
					ps_sum_add(&rs, (lane[0] + lane[1]) + (lane[2] + lane[3]));
					x = q;
				} else if (mark[x]) {
					double hb, vl;
					hb = below && x >= b.x0[1 - cur] && x <= b.x1[1 - cur] && mark_b[x]
					         ? hb_prev[x]
					         : ps_weights_exact_hedge(jb->ex, x, j);
					ht[x] = ps_weights_exact_hedge(jb->ex, x, j + 1);
					vl = prev_x == x - 1 ? vright : ps_weights_exact_vedge(jb->ex, x, j);
					vright = ps_weights_exact_vedge(jb->ex, x + 1, j);
					prev_x = x;
					wt = ps_weights_exact_pixel(hb, vright, ht[x], vl);
					nexact++;
					out[x - x0] = wt;
					ps_sum_add(&rs, wt);
					x++;
				} else {
					/* a stretch of unmarked pixels: neighbours that share an
					 * edge inside one cell, so all in the first one's cell */
					int xe = x, o0 = orun->x0, oe = orun->x0 + orun->n;
					double sens = cell_value(jb, x, j), lane[4] = { 0, 0, 0, 0 };
					while (xe < x1 && xe + 1 < oe && !mark[xe + 1])
						xe++;
					/* four lanes of plain sums (one sign, at most a row's
					 * pixels: each within 1e-13), then one compensated add */
					for (int q = x; q <= xe; q++) {
						double wq = sens * ps_weights_run_at(jb->omega, orun, q - o0);
						out[q - x0] = wq;
						lane[(q - x) & 3] += wq;
					}
					ps_sum_add(&rs, (lane[0] + lane[1]) + (lane[2] + lane[3]));
					x = xe + 1;
				}
			}
			jb->rowsum[ri] = rs;
			b.x0[cur] = x0;
			b.x1[cur] = x1;
			prev_j = j;
			cur = 1 - cur;
		}
	}
	free(b.mark[0]);
	free(b.htop[0]);
	__atomic_fetch_add(&jb->nexact, nexact, __ATOMIC_RELAXED);
	return NULL;
}

int ps_cellmap_build(struct ps_weights *w, const struct ps_sensor *s, double rotation_deg,
                     const struct ps_view *v, int width, int height,
                     const struct ps_weights *omega, struct ps_err *e)
{
	return ps_cellmap_build_placed(w, s, rotation_deg, v, width, height, omega, NULL, NULL, e);
}

int ps_cellmap_build_placed(struct ps_weights *w, const struct ps_sensor *s, double rotation_deg,
                            const struct ps_view *v, int width, int height,
                            const struct ps_weights *omega, ps_cellmap_place_fn *place, void *ctx,
                            struct ps_err *e)
{
	struct job jb;
	struct ps_weights_exact *ex = NULL;
	double *radius = NULL, *ray = NULL;
	int *orun = NULL, nthreads = 1, started = 0;
	struct lin *lin = NULL;
	pthread_t tid[MAX_THREADS];
	struct ps_sum total;
	if (!ps_cellmap_fits(s, PS_W_EXACT))
		return ps_err_set(e, PS_EINVAL, "%s: not a table that changes with azimuth",
		                  s->path ? s->path : "sensor");
	if (omega->width != width || omega->height != height || omega->method != PS_W_EXACT)
		return ps_err_set(e, PS_EINVAL, "solid-angle map of %d x %d for %d x %d weights",
		                  omega->width, omega->height, width, height);
	if (ps_weights_layout(w, s, rotation_deg, v, width, height, e) != 0)
		return -1;
	if (place) {
		/* the layout's own block is not touched yet: freeing it costs nothing */
		double *p;
		w->map = NULL;
		p = place(ctx, w);
		if (p) {
			free(w->w);
			w->w = p;
		}
	}
	memset(&jb, 0, sizeof jb);
	jb.s = s;
	jb.rot = rotation_deg * M_PI / 180.0;
	jb.omega = omega;
	jb.w = w;
	ps_fisheye_init(&jb.f, v, width, height);
	jb.du = jb.f.su / width;
	jb.dv = jb.f.sv / height;
	radius = malloc(((size_t)s->nt + 2) * sizeof *radius);
	ray = malloc(2 * ((size_t)s->np + 1) * sizeof *ray);
	orun = malloc((size_t)height * sizeof *orun);
	if (!radius || !ray || !orun)
		goto oom;
	for (int i = 0; i <= s->nt; i++)
		if (s->tb[i] > 0 && s->tb[i] < jb.f.theta_field)
			radius[jb.nradius++] = ps_fisheye_rho(&jb.f, s->tb[i]);
	radius[jb.nradius++] = 1.0;   /* the field's edge */
	for (int k = 0; k < s->np; k++) {
		double a = s->pb[k] + M_PI / 2 + jb.rot;
		ray[k] = cos(a);
		ray[s->np + 1 + k] = sin(a);
	}
	jb.tmax = 2.0 * (hypot(fmax(fabs(jb.f.u0), fabs(jb.f.u0 + jb.f.su)),
	                       fmax(fabs(jb.f.v0), fabs(jb.f.v0 + jb.f.sv))) + 1.0);
	jb.radius = radius;
	jb.ray_c = ray;
	jb.ray_s = ray + s->np + 1;
	jb.nray = s->np;
	for (int y = 0; y < height; y++)
		orun[y] = -1;
	for (size_t k = 0; k < omega->nruns; k++)
		if (omega->runs[k].row >= 0 && omega->runs[k].row < height)
			orun[omega->runs[k].row] = (int)k;
	jb.orun = orun;
	jb.rowsum = malloc((w->nruns ? w->nruns : 1) * sizeof *jb.rowsum);
	if (!jb.rowsum)
		goto oom;
	if (ps_weights_exact_open(&ex, s, rotation_deg, v, width, height, e) != 0)
		goto fail;
	jb.ex = ex;
	if (w->nw > 8192) {
		long n = sysconf(_SC_NPROCESSORS_ONLN);
		nthreads = n < 1 ? 1 : n > MAX_THREADS ? MAX_THREADS : (int)n;
	}
	if (s->reading == PS_READ_LINEAR && jb.f.type == PS_VT_ANGULAR && s->max_value > 0) {
		double gt, gp, gtp;
		lin = calloc(1, sizeof *lin);
		if (!lin)
			goto oom;
		lin_slopes(s, &gt, &gp, &gtp);
		lin->h = fmax(jb.f.su / width, jb.f.sv / height);
		lin->du = jb.du;
		lin->dv = jb.dv;
		/* a node lies at most h / sqrt(2) from its pixel's centre */
		lin->series = M_PI * lin->h * M_SQRT1_2 <= LIN_SHORT    ? 2
		              : M_PI * lin->h * M_SQRT1_2 <= LIN_SERIES ? 1
		                                                        : 0;
		for (int k = 0; k <= LIN_TAB; k++) {
			lin->tsin[k] = sin(M_PI * k / LIN_TAB);
			lin->tcos[k] = cos(M_PI * k / LIN_TAB);
		}
		lin->kbound = 2.0 * 64.0 / 15.0 * (1.1 * gt + 0.5 * gp + 0.55 * gtp) / (1e-14 * s->max_value);
		for (int n = 2; n <= LIN_MAXN; n++)
			gl_rule(&lin->gl[n], n);
		lin->jbound[0] = M_PI * M_PI;
		for (int k = 1; k <= 2 * LIN_JSTEPS; k++) {
			double r = (double)k / LIN_JSTEPS;
			lin->jbound[k] = M_PI * sinh(M_PI * r) / r;
		}
		lin->mirror = v->vs == 0.0 && v->vl == 0.0;
		if (lin->mirror) {
			struct lin_job lj = { lin, &jb.f };
			lin->qw = (width + 1) / 2;
			lin->qh = (height + 1) / 2;
			lin->transpose = width == height && jb.f.su == jb.f.sv;
			lin->mom = malloc((size_t)lin->qw * (size_t)lin->qh * 3 * sizeof *lin->mom);
			if (!lin->mom)
				goto oom;
			advise_huge(lin->mom, (size_t)lin->qw * (size_t)lin->qh * 3 * sizeof *lin->mom);
			for (int t = 1; t < nthreads; t++)
				if (pthread_create(&tid[t], NULL, lin_run, &lj) == 0)
					started |= 1 << t;
			lin_run(&lj);
			for (int t = 1; t < nthreads; t++)
				if (started & (1 << t))
					pthread_join(tid[t], NULL);
			started = 0;
		}
		jb.lin = lin;
	}
	for (int t = 1; t < nthreads; t++)
		if (pthread_create(&tid[t], NULL, fill_run, &jb) == 0)
			started |= 1 << t;
	fill_run(&jb);
	for (int t = 1; t < nthreads; t++)
		if (started & (1 << t))
			pthread_join(tid[t], NULL);
	if (jb.oom)
		goto oom;
	ps_sum_init(&total);
	for (size_t ri = 0; ri < w->nruns; ri++)
		ps_sum_merge(&total, &jb.rowsum[ri]);
	w->sens_sum = ps_sum_get(&total);
	w->coverage = w->sens_full > 0 ? w->sens_sum / w->sens_full : 0.0;
	ps_weights_exact_close(ex);
	lin_free(lin);
	free(jb.rowsum);
	free(radius);
	free(ray);
	free(orun);
	return 0;
oom:
	ps_err_set(e, PS_ENOMEM, "out of memory building %d x %d weights", width, height);
fail:
	ps_weights_exact_close(ex);
	lin_free(lin);
	free(jb.rowsum);
	free(radius);
	free(ray);
	free(orun);
	ps_weights_free(w);
	return -1;
}
