/* SPDX-License-Identifier: ISC */
#include "rescan.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "fisheye.h"
#include "integrate.h"
#include "sum.h"

#define DEG (M_PI / 180.0)

void ps_rescan_free(struct ps_rescan *p)
{
	free(p->e);
	memset(p, 0, sizeof *p);
}

/* Energy b from direction (th, ph) into the cells: shared between the two
 * nearest cell centres each way, in proportion to the distance (as linear
 * interpolation of the sensitivity between the centres would weigh it), so
 * a pixel between two centres reads neither alone; below the first ring's
 * centre or beyond the last one's, that ring alone.  th is below the last
 * ring's edge. */
static void deposit(struct ps_rescan *p, double th, double ph, double b)
{
	double ft = th / p->dtheta - 0.5, fp, at, ap, *r0;
	int i0 = (int)floor(ft), m, m1;
	at = ft - i0;
	if (i0 < 0) {
		i0 = 0;
		at = 0.0;
	}
	if (i0 + 1 >= p->ntheta)
		at = 0.0;
	/* phi - phi0 is within a few turns: no integer division */
	fp = (ph - p->phi0) * (1.0 / p->dphi) - 0.5;
	m = (int)floor(fp);
	ap = fp - m;
	while (m >= p->nphi)
		m -= p->nphi;
	while (m < 0)
		m += p->nphi;
	m1 = m + 1 == p->nphi ? 0 : m + 1;
	r0 = p->e + (size_t)i0 * (size_t)p->nphi;
	r0[m] += b * (1.0 - at) * (1.0 - ap);
	r0[m1] += b * (1.0 - at) * ap;
	if (at > 0.0) {
		r0[(size_t)p->nphi + (size_t)m] += b * at * (1.0 - ap);
		r0[(size_t)p->nphi + (size_t)m1] += b * at * ap;
	}
}

/* Pixel (x, row) of energy b split into sub x sub parts, each at its centre
 * with a share of b in proportion to the solid angle per plane area there
 * (the shares sum to b). */
static void deposit_split(struct ps_rescan *p, const struct ps_fisheye *f, int x, int row, int sub,
                          double b)
{
	double jac[64], sum = 0.0;
	for (int pass = 0; pass < 2; pass++)
		for (int a = 0, k = 0; a < sub; a++)
			for (int c = 0; c < sub; c++, k++) {
				double u = ps_fisheye_u(f, x + (c + 0.5) / sub);
				double v = ps_fisheye_v(f, f->height - row - 1 + (a + 0.5) / sub);
				double rho = sqrt(u * u + v * v), th;
				if (pass == 0) {
					double j = ps_fisheye_jacobian(f, rho);
					jac[k] = isfinite(j) ? j : 0.0;
					sum += jac[k];
					continue;
				}
				th = ps_fisheye_theta(f, rho);
				if (jac[k] > 0 && th < p->ntheta * p->dtheta)
					deposit(p, th, atan2(v, u) - M_PI / 2, b * jac[k] / sum);
			}
}

int ps_rescan_project(struct ps_rescan *p, const struct ps_weights *omega,
                      const struct ps_picture *pic, const struct ps_view *v,
                      const double coef[3], double dtheta_deg, double dphi_deg,
                      double phi0_deg, double theta_max_deg, struct ps_err *e)
{
	return ps_rescan_project_split(p, omega, pic, v, coef, dtheta_deg, dphi_deg, phi0_deg,
	                               theta_max_deg, 1, 0.0, e);
}

/* n projections of one picture, projection c with coefficients coef[c],
 * each pixel's direction found once for all: every projection the same,
 * bit for bit, as made alone */
static int project_n(struct ps_rescan *p, int n, const double (*coef)[3], const struct ps_weights *omega,
                     const struct ps_picture *pic, const struct ps_view *v, double dtheta_deg, double dphi_deg,
                     double phi0_deg, double theta_max_deg, int sub, double share, struct ps_err *e)
{
	struct ps_fisheye f;
	double k[3][3], kc[PS_RESCAN_MAX_COEF][3], cut[PS_RESCAN_MAX_COEF], mag[PS_RESCAN_MAX_COEF];
	if (n < 1 || n > PS_RESCAN_MAX_COEF)
		return ps_err_set(e, PS_EINVAL, "%d projections at once: 1 to %d", n, PS_RESCAN_MAX_COEF);
	for (int c = 0; c < n; c++)
		memset(&p[c], 0, sizeof p[c]);
	if (sub < 1 || sub > 8 || !(share >= 0))
		return ps_err_set(e, PS_EINVAL, "bad split: %d x %d parts above a share of %g", sub, sub,
		                  share);
	if (!(dtheta_deg > 0 && dtheta_deg <= 180) || !(dphi_deg > 0 && dphi_deg <= 360) ||
	    !(theta_max_deg > 0) || !isfinite(phi0_deg))
		return ps_err_set(e, PS_EINVAL, "bad grid: %g x %g degrees to %g", dtheta_deg, dphi_deg,
		                  theta_max_deg);
	if (pic->width != omega->width || pic->height != omega->height)
		return ps_err_set(e, PS_EINVAL, "picture is %d x %d, the solid angles are for %d x %d",
		                  pic->width, pic->height, omega->width, omega->height);
	if (theta_max_deg > 180)
		theta_max_deg = 180;
	for (int c = 0; c < n; c++) {
		struct ps_rescan *q = &p[c];
		q->dtheta = dtheta_deg * DEG;
		q->dphi = dphi_deg * DEG;
		q->phi0 = phi0_deg * DEG;
		q->ntheta = (int)ceil(theta_max_deg / dtheta_deg - 1e-9);
		q->nphi = (int)lround(360.0 / dphi_deg);
		if (fabs(q->nphi * dphi_deg - 360.0) > 1e-9 * 360.0) {
			for (int j = 0; j < c; j++)
				ps_rescan_free(&p[j]);
			return ps_err_set(e, PS_EINVAL, "%g degrees does not divide 360", dphi_deg);
		}
		q->e = calloc((size_t)q->ntheta * (size_t)q->nphi, sizeof *q->e);
		if (!q->e) {
			for (int j = 0; j <= c; j++)
				ps_rescan_free(&p[j]);
			return ps_err_set(e, PS_ENOMEM, "out of memory for %d x %d cells", q->ntheta, q->nphi);
		}
		cut[c] = HUGE_VAL;
		mag[c] = 0.0;
	}
	ps_fisheye_init(&f, v, pic->width, pic->height);
	/* stored channels -> response per unit of decoded (m + 0.5) 2^(e-136) */
	ps_integrate_pic_matrix(pic, k);
	for (int c = 0; c < n; c++)
		for (int ch = 0; ch < 3; ch++)
			kc[c][ch] = coef[c][0] * k[0][ch] + coef[c][1] * k[1][ch] + coef[c][2] * k[2][ch];
	for (int pass = sub > 1 ? 0 : 1; pass < 2; pass++) {
		/* pixel centres' plane coordinates once; rho by sqrt (hypot's
		 * care for overflow is not needed within the unit square).  Pass
		 * 0 (only when splitting) sums the pixels' |energy| for the cut. */
		double *uc = malloc(((size_t)pic->width + 1) * sizeof *uc);
		if (!uc) {
			for (int c = 0; c < n; c++)
				ps_rescan_free(&p[c]);
			return ps_err_set(e, PS_ENOMEM, "out of memory");
		}
		for (int x = 0; x < pic->width; x++)
			uc[x] = ps_fisheye_u(&f, x + 0.5);
		for (size_t ri = 0; ri < omega->nruns; ri++) {
			const struct ps_weights_run *run = &omega->runs[ri];
			const uint8_t *row = pic->pix + 4 * (size_t)run->row * (size_t)pic->width;
			double vc = ps_fisheye_v(&f, pic->height - run->row - 0.5);
			for (int i = 0; i < run->n; i++) {
				int x = run->x0 + i, it;
				const uint8_t *px = row + 4 * (size_t)x;
				double th, ph, sc, rho, w;
				if (px[3] == 0)
					continue;
				rho = sqrt(uc[x] * uc[x] + vc * vc);
				if (rho > 1.0)
					continue;
				th = ps_fisheye_theta(&f, rho);
				it = (int)(th / p[0].dtheta);
				if (it >= p[0].ntheta)
					continue;
				ph = atan2(vc, uc[x]) - M_PI / 2;
				sc = ps_picture_rgbe_scale[px[3]];
				w = ps_weights_run_at(omega, run, i);
				for (int c = 0; c < n; c++) {
					double b = ((px[0] + 0.5) * kc[c][0] + (px[1] + 0.5) * kc[c][1] + (px[2] + 0.5) * kc[c][2]) *
					           sc * w;
					if (pass == 0)
						mag[c] += fabs(b);
					else if (fabs(b) >= cut[c])
						deposit_split(&p[c], &f, x, run->row, sub, b);
					else
						deposit(&p[c], th, ph, b);
				}
			}
		}
		free(uc);
		for (int c = 0; c < n && pass == 0; c++)
			if (share * mag[c] > 0)
				cut[c] = share * mag[c];
	}
	for (int c = 0; c < n; c++) {
		struct ps_sum s;
		ps_sum_init(&s);
		for (size_t i = 0; i < (size_t)p[c].ntheta * (size_t)p[c].nphi; i++)
			ps_sum_add(&s, p[c].e[i]);
		p[c].total = ps_sum_get(&s);
	}
	return 0;
}

int ps_rescan_project_split(struct ps_rescan *p, const struct ps_weights *omega,
                            const struct ps_picture *pic, const struct ps_view *v,
                            const double coef[3], double dtheta_deg, double dphi_deg,
                            double phi0_deg, double theta_max_deg, int sub, double share,
                            struct ps_err *e)
{
	const double (*c)[3] = (const double (*)[3])coef;
	return project_n(p, 1, c, omega, pic, v, dtheta_deg, dphi_deg, phi0_deg, theta_max_deg, sub, share, e);
}

int ps_rescan_project_many(struct ps_rescan *p, int n, const double (*coef)[3], const struct ps_weights *omega,
                           const struct ps_picture *pic, const struct ps_view *v, double dtheta_deg,
                           double dphi_deg, double phi0_deg, double theta_max_deg, struct ps_err *e)
{
	return project_n(p, n, coef, omega, pic, v, dtheta_deg, dphi_deg, phi0_deg, theta_max_deg, 1, 0.0, e);
}

/* A row's energies and where its sensitivity starts in sg[] (the rings
 * collapse onto these rows, ps_rescan_sens_init) */
struct ring {
	size_t z;       /* its np energies in ez[] */
	size_t g;       /* its 2 np values in sg[] */
};

struct scan_job {
	const struct ring *rings;
	int nrings, np;
	const double *ez, *sg;
	long qs;
	int k0, k1;
	double *out;
};

/* Four rotations at a time: their sums are four independent chains over
 * the same energies, each in its own order (cell by cell, ring by ring),
 * so each is what it would be alone while the four run side by side. */
#define SCAN_LANES 4
static void *scan_run(void *arg)
{
	const struct scan_job *j = arg;
	for (int k0 = j->k0; k0 < j->k1; k0 += SCAN_LANES) {
		int nk = j->k1 - k0 < SCAN_LANES ? j->k1 - k0 : SCAN_LANES;
		long sh[SCAN_LANES];
		struct ps_sum acc[SCAN_LANES];
		for (int l = 0; l < SCAN_LANES; l++) {
			/* rotation rot0 + k step: cell m reads sg[m - k q] (a lane
			 * past the last rotation repeats the first) */
			sh[l] = ((long)(k0 + (l < nk ? l : 0)) * j->qs) % j->np;
			ps_sum_init(&acc[l]);
		}
		for (int r = 0; r < j->nrings; r++) {
			const struct ring *g = &j->rings[r];
			const double *ez = j->ez + g->z, *sg = j->sg + g->g + (size_t)j->np;
			const double *s0 = sg - sh[0], *s1 = sg - sh[1], *s2 = sg - sh[2], *s3 = sg - sh[3];
			double a0 = 0.0, a1 = 0.0, a2 = 0.0, a3 = 0.0;
			for (int m = 0; m < j->np; m++) {
				double x = ez[m];
				a0 += x * s0[m];
				a1 += x * s1[m];
				a2 += x * s2[m];
				a3 += x * s3[m];
			}
			ps_sum_add(&acc[0], a0);
			ps_sum_add(&acc[1], a1);
			ps_sum_add(&acc[2], a2);
			ps_sum_add(&acc[3], a3);
		}
		for (int l = 0; l < nk; l++)
			j->out[k0 + l] = ps_sum_get(&acc[l]);
	}
	return NULL;
}

int ps_rescan_scan(const struct ps_rescan *p, const struct ps_sensor *s, double rot0_deg,
                   double step_deg, int n, double *out, struct ps_err *e)
{
	return ps_rescan_scan_mt(p, s, rot0_deg, step_deg, n, 1, out, e);
}

int ps_rescan_scan_mt(const struct ps_rescan *p, const struct ps_sensor *s, double rot0_deg,
                      double step_deg, int n, int nthreads, double *out, struct ps_err *e)
{
	struct ps_rescan_sens t;
	int rc;
	if (n <= 0)
		return 0;
	if (ps_rescan_sens_init(&t, p, s, rot0_deg, e) != 0)
		return -1;
	rc = ps_rescan_scan_sens(p, &t, step_deg, n, nthreads, out, e);
	ps_rescan_sens_free(&t);
	return rc;
}

void ps_rescan_sens_free(struct ps_rescan_sens *t)
{
	free(t->row);
	free(t->wa);
	free(t->wb);
	free(t->used);
	free(t->sg);
	memset(t, 0, sizeof *t);
}

/* The rings collapse onto a few rows: within one patch of the table the
 * sensitivity is affine in theta at every azimuth (bilinear reading, or
 * constant for rsensor's), so S(theta_r, phi) = (1 - a) S(theta_A, phi) +
 * a S(theta_B, phi) with theta_A, theta_B two polar angles inside the
 * patch and a = (theta_r - theta_A) / (theta_B - theta_A); ring r's
 * energies go to the patch's two rows with weights 1 - a and a.  A
 * builtin is the same at every azimuth: one row of S(theta_r) e_r against
 * a sensitivity of 1.  The sums are those of the rings, in another order:
 * 2 nt rows instead of hundreds of rings.  None of it depends on the
 * picture: the rings' rows and weights and the rows' sensitivity at the
 * cell centres are made once here for every projection on these cells. */
int ps_rescan_sens_init(struct ps_rescan_sens *t, const struct ps_rescan *p, const struct ps_sensor *s,
                        double rot0_deg, struct ps_err *e)
{
	double r0 = (rot0_deg * DEG - p->phi0) / p->dphi;
	long r0s = lround(r0);
	int np = p->nphi, table = s->kind == PS_SENS_TABLE, nrow = table ? 2 * s->nt : 1;
	memset(t, 0, sizeof *t);
	if (fabs(r0 - r0s) > 1e-9)
		return ps_err_set(e, PS_EINVAL, "rotations %g + k x a step degrees are not whole cells of %g",
		                  rot0_deg, p->dphi / DEG);
	t->ntheta = p->ntheta;
	t->nphi = np;
	t->dtheta = p->dtheta;
	t->dphi = p->dphi;
	t->phi0 = p->phi0;
	t->rot0 = rot0_deg;
	t->nrow = nrow;
	t->row = malloc(((size_t)p->ntheta + 1) * sizeof *t->row);
	t->wa = malloc(((size_t)p->ntheta + 1) * sizeof *t->wa);
	t->wb = malloc(((size_t)p->ntheta + 1) * sizeof *t->wb);
	t->used = calloc((size_t)nrow + 1, sizeof *t->used);
	t->sg = malloc(((size_t)nrow * 2 * (size_t)np + 1) * sizeof *t->sg);
	if (!t->row || !t->wa || !t->wb || !t->used || !t->sg) {
		ps_rescan_sens_free(t);
		return ps_err_set(e, PS_ENOMEM, "out of memory for %d x %d cells", p->ntheta, np);
	}
	for (int it = 0; it < p->ntheta; it++) {
		double th = (it + 0.5) * p->dtheta, ph = 0.0;
		int i = 0, j;
		if (table) {
			double ta, tb;
			ps_sensor_locate(s, th, &ph, &i, &j);
			if (i >= s->nt) {
				t->row[it] = -1;   /* beyond the table: no sensitivity */
				continue;
			}
			ta = s->tb[i] + 0.25 * (s->tb[i + 1] - s->tb[i]);
			tb = s->tb[i] + 0.75 * (s->tb[i + 1] - s->tb[i]);
			t->wb[it] = (th - ta) / (tb - ta);
			t->wa[it] = 1.0 - t->wb[it];
			t->row[it] = 2 * i;
			t->used[2 * i] = t->used[2 * i + 1] = 1;
		} else {
			t->wa[it] = ps_sensor_value(s, th, 0.0);
			t->wb[it] = 0.0;
			t->row[it] = 0;
			t->used[0] = 1;
		}
	}
	/* the used rows' sensitivity at the cell centres, the sensor at
	 * rotation rot0: cell m's direction phi0 + (m + 0.5) dphi reads S at
	 * that minus the rotation (doubled so no index wraps) */
	for (int r = 0; r < nrow; r++) {
		double *g = t->sg + (size_t)t->nused * 2 * (size_t)np;
		if (!t->used[r])
			continue;
		for (int m = 0; m < np; m++) {
			double ph = (m + 0.5) * p->dphi - (double)r0s * p->dphi, th;
			int i = r / 2;
			if (!table)
				g[m] = g[m + np] = 1.0;
			else {
				th = s->tb[i] + (r % 2 ? 0.75 : 0.25) * (s->tb[i + 1] - s->tb[i]);
				g[m] = g[m + np] = ps_sensor_value(s, th, ph);
			}
		}
		t->nused++;
	}
	return 0;
}

int ps_rescan_scan_sens(const struct ps_rescan *p, const struct ps_rescan_sens *t, double step_deg, int n,
                        int nthreads, double *out, struct ps_err *e)
{
	enum { MAX_THREADS = 16 };
	double q = step_deg * DEG / p->dphi;
	long qs = lround(q);
	int np = p->nphi, nrow = t->nrow, nt = nthreads < 1 ? 1 : nthreads > MAX_THREADS ? MAX_THREADS : nthreads;
	struct ring *rings;
	double *re;
	struct scan_job jobs[MAX_THREADS];
	pthread_t tid[MAX_THREADS];
	int started[MAX_THREADS] = { 0 }, nrings = 0;
	if (n <= 0)
		return 0;
	if (t->ntheta != p->ntheta || t->nphi != np || t->dtheta != p->dtheta || t->dphi != p->dphi ||
	    t->phi0 != p->phi0)
		return ps_err_set(e, PS_EINVAL, "the sensitivity is for %d x %d cells, the projection has %d x %d",
		                  t->ntheta, t->nphi, p->ntheta, np);
	if (fabs(q - qs) > 1e-9)
		return ps_err_set(e, PS_EINVAL, "rotations %g + k %g degrees are not whole cells of %g",
		                  t->rot0, step_deg, p->dphi / DEG);
	/* the rings' energies onto their rows (in the rings' order) */
	re = calloc((size_t)nrow * (size_t)np + 1, sizeof *re);
	rings = malloc(((size_t)nrow + 1) * sizeof *rings);
	if (!re || !rings) {
		free(re);
		free(rings);
		return ps_err_set(e, PS_ENOMEM, "out of memory for %d x %d cells", p->ntheta, np);
	}
	for (int it = 0; it < p->ntheta; it++) {
		const double *er = p->e + (size_t)it * (size_t)np;
		double wa = t->wa[it], wb = t->wb[it];
		int row = t->row[it];
		double *ra = re + (size_t)(row < 0 ? 0 : row) * (size_t)np;
		if (row < 0)
			continue;
		if (t->nrow > 1)
			for (int m = 0; m < np; m++) {
				ra[m] += wa * er[m];
				ra[(size_t)np + (size_t)m] += wb * er[m];
			}
		else
			for (int m = 0; m < np; m++)
				ra[m] += wa * er[m];
	}
	for (int r = 0; r < nrow; r++)
		if (t->used[r]) {
			rings[nrings] = (struct ring){ (size_t)r * (size_t)np, (size_t)nrings * 2 * (size_t)np };
			nrings++;
		}
	/* the rotations shared among the threads: each one's sum is the same
	 * whoever computes it */
	if (nt > n)
		nt = n;
	for (int k = 0; k < nt; k++)
		jobs[k] = (struct scan_job){ rings, nrings, np, re, t->sg, qs, (int)((long)n * k / nt),
		                             (int)((long)n * (k + 1) / nt), out };
	for (int k = 1; k < nt; k++)
		started[k] = pthread_create(&tid[k], NULL, scan_run, &jobs[k]) == 0;
	scan_run(&jobs[0]);
	for (int k = 1; k < nt; k++) {
		if (started[k])
			pthread_join(tid[k], NULL);
		else
			scan_run(&jobs[k]);
	}
	free(rings);
	free(re);
	return 0;
}
