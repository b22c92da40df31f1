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

int ps_rescan_project_split(struct ps_rescan *p, const struct ps_weights *omega,
                            const struct ps_picture *pic, const struct ps_view *v,
                            const double coef[3], double dtheta_deg, double dphi_deg,
                            double phi0_deg, double theta_max_deg, int sub, double share,
                            struct ps_err *e)
{
	struct ps_fisheye f;
	double k[3][3], kc[3], cut = HUGE_VAL;
	memset(p, 0, sizeof *p);
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
	p->dtheta = dtheta_deg * DEG;
	p->dphi = dphi_deg * DEG;
	p->phi0 = phi0_deg * DEG;
	p->ntheta = (int)ceil(theta_max_deg / dtheta_deg - 1e-9);
	p->nphi = (int)lround(360.0 / dphi_deg);
	if (fabs(p->nphi * dphi_deg - 360.0) > 1e-9 * 360.0)
		return ps_err_set(e, PS_EINVAL, "%g degrees does not divide 360", dphi_deg);
	p->e = calloc((size_t)p->ntheta * (size_t)p->nphi, sizeof *p->e);
	if (!p->e)
		return ps_err_set(e, PS_ENOMEM, "out of memory for %d x %d cells", p->ntheta, p->nphi);
	ps_fisheye_init(&f, v, pic->width, pic->height);
	/* stored channels -> response per unit of decoded (m + 0.5) 2^(e-136) */
	ps_integrate_pic_matrix(pic, k);
	for (int c = 0; c < 3; c++)
		kc[c] = coef[0] * k[0][c] + coef[1] * k[1][c] + coef[2] * k[2][c];
	for (int pass = sub > 1 ? 0 : 1; pass < 2; pass++) {
		/* pixel centres' plane coordinates once; rho by sqrt (hypot's
		 * care for overflow is not needed within the unit square).  Pass
		 * 0 (only when splitting) sums the pixels' |energy| for the cut. */
		double *uc = malloc(((size_t)pic->width + 1) * sizeof *uc), mag = 0.0;
		if (!uc) {
			ps_rescan_free(p);
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
				double th, ph, b, sc, rho;
				if (px[3] == 0)
					continue;
				rho = sqrt(uc[x] * uc[x] + vc * vc);
				if (rho > 1.0)
					continue;
				th = ps_fisheye_theta(&f, rho);
				it = (int)(th / p->dtheta);
				if (it >= p->ntheta)
					continue;
				ph = atan2(vc, uc[x]) - M_PI / 2;
				sc = ps_picture_rgbe_scale[px[3]];
				b = ((px[0] + 0.5) * kc[0] + (px[1] + 0.5) * kc[1] + (px[2] + 0.5) * kc[2]) * sc *
				    ps_weights_run_at(omega, run, i);
				if (pass == 0)
					mag += fabs(b);
				else if (fabs(b) >= cut)
					deposit_split(p, &f, x, run->row, sub, b);
				else
					deposit(p, th, ph, b);
			}
		}
		free(uc);
		if (pass == 0 && share * mag > 0)
			cut = share * mag;
	}
	{
		struct ps_sum s;
		ps_sum_init(&s);
		for (size_t i = 0; i < (size_t)p->ntheta * (size_t)p->nphi; i++)
			ps_sum_add(&s, p->e[i]);
		p->total = ps_sum_get(&s);
	}
	return 0;
}

/* The rings some pixel fell in, each with its occupied cells and the
 * sensitivity at its cell centres (doubled so no index wraps). */
struct ring {
	int cnt;        /* occupied cells */
	size_t z;       /* their first index in nz[], ez[] */
	size_t g;       /* its 2 np values in sg[] */
};

struct scan_job {
	const struct ring *rings;
	int nrings, np;
	const int *nz;
	const double *ez, *sg;
	long qs;
	int k0, k1;
	double *out;
};

static void *scan_run(void *arg)
{
	const struct scan_job *j = arg;
	for (int k = j->k0; k < j->k1; k++) {
		/* rotation rot0 + k step: cell m reads sg[m - k q] */
		long sh = ((long)k * j->qs) % j->np;
		struct ps_sum acc;
		ps_sum_init(&acc);
		for (int r = 0; r < j->nrings; r++) {
			const struct ring *g = &j->rings[r];
			const double *sk = j->sg + g->g + (size_t)(j->np - sh), *ez = j->ez + g->z;
			const int *nz = j->nz + g->z;
			double sum = 0.0;
			if (g->cnt == j->np)
				for (int m = 0; m < j->np; m++)
					sum += ez[m] * sk[m];
			else
				for (int c = 0; c < g->cnt; c++)
					sum += ez[c] * sk[nz[c]];
			ps_sum_add(&acc, sum);
		}
		j->out[k] = ps_sum_get(&acc);
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
	enum { MAX_THREADS = 16 };
	double q = step_deg * DEG / p->dphi, r0 = (rot0_deg * DEG - p->phi0) / p->dphi;
	long qs = lround(q), r0s = lround(r0);
	int np = p->nphi, nrings = 0, nt = nthreads < 1 ? 1 : nthreads > MAX_THREADS ? MAX_THREADS
	                                                                            : nthreads;
	size_t ncells = (size_t)p->ntheta * (size_t)np, z = 0;
	struct ring *rings;
	int *nz;
	double *ez, *sg;
	struct scan_job jobs[MAX_THREADS];
	pthread_t tid[MAX_THREADS];
	int started[MAX_THREADS] = { 0 };
	if (n <= 0)
		return 0;
	if (fabs(q - qs) > 1e-9 || fabs(r0 - r0s) > 1e-9)
		return ps_err_set(e, PS_EINVAL, "rotations %g + k %g degrees are not whole cells of %g",
		                  rot0_deg, step_deg, p->dphi / DEG);
	/* The rings collapse onto a few rows: within one patch of the table the
	 * sensitivity is affine in theta at every azimuth (bilinear reading, or
	 * constant for rsensor's), so S(theta_r, phi) = (1 - a) S(theta_A, phi) +
	 * a S(theta_B, phi) with theta_A, theta_B two polar angles inside the
	 * patch and a = (theta_r - theta_A) / (theta_B - theta_A); ring r's
	 * energies go to the patch's two rows with weights 1 - a and a.  A
	 * builtin is the same at every azimuth: one row of S(theta_r) e_r
	 * against a sensitivity of 1.  The sums are those of the rings, in
	 * another order: 2 nt rows instead of hundreds of rings. */
	{
		int table = s->kind == PS_SENS_TABLE, nrow = table ? 2 * s->nt : 1;
		double *re = calloc((size_t)nrow * (size_t)np + 1, sizeof *re);
		int *used = calloc((size_t)nrow + 1, sizeof *used);
		rings = malloc(((size_t)nrow + 1) * sizeof *rings);
		/* a row's np cells for every row used: up to two rows a polar
		 * cell, so more than the cells when the table's steps are finer */
		size_t nrowcells = (size_t)nrow * (size_t)np;
		nz = malloc((nrowcells + 1) * sizeof *nz);
		ez = malloc((nrowcells + 1) * sizeof *ez);
		sg = malloc(((size_t)nrow * 2 * (size_t)np + 1) * sizeof *sg);
		if (!re || !used || !rings || !nz || !ez || !sg) {
			free(re);
			free(used);
			free(rings);
			free(nz);
			free(ez);
			free(sg);
			return ps_err_set(e, PS_ENOMEM, "out of memory for %zu cells", ncells);
		}
		for (int it = 0; it < p->ntheta; it++) {
			const double *er = p->e + (size_t)it * (size_t)np;
			double th = (it + 0.5) * p->dtheta, ph = 0.0, wa, wb;
			int i = 0, j, row;
			if (table) {
				double ta, tb;
				ps_sensor_locate(s, th, &ph, &i, &j);
				if (i >= s->nt)
					continue;   /* beyond the table: no sensitivity */
				ta = s->tb[i] + 0.25 * (s->tb[i + 1] - s->tb[i]);
				tb = s->tb[i] + 0.75 * (s->tb[i + 1] - s->tb[i]);
				wb = (th - ta) / (tb - ta);
				wa = 1.0 - wb;
				row = 2 * i;
			} else {
				wa = ps_sensor_value(s, th, 0.0);
				wb = 0.0;
				row = 0;
			}
			for (int m = 0; m < np; m++) {
				re[(size_t)row * (size_t)np + (size_t)m] += wa * er[m];
				if (table)
					re[(size_t)(row + 1) * (size_t)np + (size_t)m] += wb * er[m];
			}
			used[row] = 1;
			if (table)
				used[row + 1] = 1;
		}
		for (int r = 0; r < nrow; r++) {
			double *g;
			size_t z0 = z;
			if (!used[r])
				continue;
			for (int m = 0; m < np; m++) {
				nz[z] = m;
				ez[z++] = re[(size_t)r * (size_t)np + (size_t)m];
			}
			/* the row's sensitivity at the cell centres, the sensor at
			 * rotation rot0: cell m's direction phi0 + (m + 0.5) dphi reads
			 * S at that minus the rotation */
			g = sg + (size_t)nrings * 2 * (size_t)np;
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
			rings[nrings] = (struct ring){ np, z0, (size_t)nrings * 2 * (size_t)np };
			nrings++;
		}
		free(re);
		free(used);
	}
	/* the rotations shared among the threads: each one's sum is the same
	 * whoever computes it */
	if (nt > n)
		nt = n;
	for (int t = 0; t < nt; t++)
		jobs[t] = (struct scan_job){ rings, nrings, np, nz, ez, sg, qs,
		                             (int)((long)n * t / nt), (int)((long)n * (t + 1) / nt), out };
	for (int t = 1; t < nt; t++)
		started[t] = pthread_create(&tid[t], NULL, scan_run, &jobs[t]) == 0;
	scan_run(&jobs[0]);
	for (int t = 1; t < nt; t++) {
		if (started[t])
			pthread_join(tid[t], NULL);
		else
			scan_run(&jobs[t]);
	}
	free(rings);
	free(nz);
	free(ez);
	free(sg);
	return 0;
}
