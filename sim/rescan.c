#include "rescan.h"

#include <math.h>
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

int ps_rescan_project(struct ps_rescan *p, const struct ps_weights *omega,
                      const struct ps_picture *pic, const struct ps_view *v,
                      const double coef[3], double dtheta_deg, double dphi_deg,
                      double phi0_deg, double theta_max_deg, struct ps_err *e)
{
	struct ps_fisheye f;
	double k[3][3], kc[3];
	memset(p, 0, sizeof *p);
	if (!(dtheta_deg > 0 && dtheta_deg <= 180) || !(dphi_deg > 0 && dphi_deg <= 360) ||
	    !(theta_max_deg > 0) || !isfinite(phi0_deg))
		return ps_errf(e, PS_EINVAL, "bad grid: %g x %g degrees to %g", dtheta_deg, dphi_deg,
		               theta_max_deg);
	if (pic->width != omega->width || pic->height != omega->height)
		return ps_errf(e, PS_EINVAL, "picture is %d x %d, the solid angles are for %d x %d",
		               pic->width, pic->height, omega->width, omega->height);
	if (theta_max_deg > 180)
		theta_max_deg = 180;
	p->dtheta = dtheta_deg * DEG;
	p->dphi = dphi_deg * DEG;
	p->phi0 = phi0_deg * DEG;
	p->ntheta = (int)ceil(theta_max_deg / dtheta_deg - 1e-9);
	p->nphi = (int)lround(360.0 / dphi_deg);
	if (fabs(p->nphi * dphi_deg - 360.0) > 1e-9 * 360.0)
		return ps_errf(e, PS_EINVAL, "%g degrees does not divide 360", dphi_deg);
	p->e = calloc((size_t)p->ntheta * (size_t)p->nphi, sizeof *p->e);
	if (!p->e)
		return ps_errf(e, PS_ENOMEM, "out of memory for %d x %d cells", p->ntheta, p->nphi);
	ps_fisheye_init(&f, v, pic->width, pic->height);
	/* stored channels -> response per unit of decoded (m + 0.5) 2^(e-136) */
	ps_pic_rgb_matrix(pic, k);
	for (int c = 0; c < 3; c++)
		kc[c] = coef[0] * k[0][c] + coef[1] * k[1][c] + coef[2] * k[2][c];
	for (size_t ri = 0; ri < omega->nruns; ri++) {
		const struct ps_wrun *run = &omega->runs[ri];
		for (int i = 0; i < run->n; i++) {
			int x = run->x0 + i, it, m;
			const uint8_t *px = pic->pix + 4 * ((size_t)run->row * (size_t)pic->width + (size_t)x);
			double th, ph, b, sc;
			if (px[3] == 0 || ps_fisheye_pixel_dir(&f, x, run->row, &th, &ph) != 0)
				continue;
			sc = ps_rgbe_scale[px[3]];
			b = ((px[0] + 0.5) * kc[0] + (px[1] + 0.5) * kc[1] + (px[2] + 0.5) * kc[2]) * sc *
			    omega->w[run->off + (size_t)i];
			it = (int)(th / p->dtheta);
			if (it >= p->ntheta)
				continue;
			m = (int)floor((ph - p->phi0) / p->dphi);
			m %= p->nphi;
			if (m < 0)
				m += p->nphi;
			p->e[(size_t)it * (size_t)p->nphi + (size_t)m] += b;
		}
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

int ps_rescan_scan(const struct ps_rescan *p, const struct ps_sensor *s, double rot0_deg,
                   double step_deg, int n, double *out, struct ps_err *e)
{
	double q = step_deg * DEG / p->dphi, r0 = (rot0_deg * DEG - p->phi0) / p->dphi;
	long qs = lround(q), r0s = lround(r0);
	double *sg;
	int np = p->nphi;
	if (n <= 0)
		return 0;
	if (fabs(q - qs) > 1e-9 || fabs(r0 - r0s) > 1e-9)
		return ps_errf(e, PS_EINVAL, "rotations %g + k %g degrees are not whole cells of %g",
		               rot0_deg, step_deg, p->dphi / DEG);
	sg = malloc((size_t)np * 2 * sizeof *sg);
	if (!sg) {
		free(sg);
		return ps_errf(e, PS_ENOMEM, "out of memory");
	}
	{
		struct ps_sum *acc = malloc((size_t)n * sizeof *acc);
		if (!acc) {
			free(sg);
			return ps_errf(e, PS_ENOMEM, "out of memory");
		}
		for (int k = 0; k < n; k++)
			ps_sum_init(&acc[k]);
		int *nz = malloc((size_t)np * sizeof *nz);
		double *ez = malloc((size_t)np * sizeof *ez);
		if (!nz || !ez) {
			free(nz);
			free(ez);
			free(acc);
			free(sg);
			return ps_errf(e, PS_ENOMEM, "out of memory");
		}
		for (int it = 0; it < p->ntheta; it++) {
			const double *er = p->e + (size_t)it * (size_t)np;
			double th = (it + 0.5) * p->dtheta;
			int cnt = 0;
			/* only the cells some pixel fell in (near the pole, few) */
			for (int m = 0; m < np; m++)
				if (er[m] != 0.0) {
					nz[cnt] = m;
					ez[cnt++] = er[m];
				}
			if (!cnt)
				continue;
			/* sensitivity at the cell centres of this ring, the sensor at
			 * rotation rot0: cell m's direction phi0 + (m + 0.5) dphi reads
			 * S at that minus the rotation; doubled so no index wraps */
			for (int m = 0; m < np; m++) {
				double ph = p->phi0 + (m + 0.5) * p->dphi - (double)r0s * p->dphi - p->phi0;
				sg[m] = sg[m + np] = ps_sensor_value(s, th, ph);
			}
			for (int k = 0; k < n; k++) {
				/* rotation rot0 + k step: cell m reads sg[m - k q] */
				long sh = ((long)k * qs) % np;
				const double *sk = sg + np - sh;
				double sum = 0.0;
				if (cnt == np)
					for (int m = 0; m < np; m++)
						sum += ez[m] * sk[m];
				else
					for (int c = 0; c < cnt; c++)
						sum += ez[c] * sk[nz[c]];
				ps_sum_add(&acc[k], sum);
			}
		}
		free(nz);
		free(ez);
		for (int k = 0; k < n; k++)
			out[k] = ps_sum_get(&acc[k]);
		free(acc);
	}
	free(sg);
	return 0;
}
