/* SPDX-License-Identifier: ISC */
#include "integrate.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rowsum.h"
#include "sum.h"

/* White is 0.3333, 0.3333 exactly as Radiance's color.h has it (not 1/3): only
 * then is the Y row psens's default 0.265074126 0.670114631 0.064811243. */
const double ps_integrate_std_primaries[8] = { 0.640, 0.330, 0.290, 0.600, 0.150, 0.060, 0.3333, 0.3333 };

void ps_integrate_mat3_invert(const double a[3][3], double out[3][3])
{
	double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
	             a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
	             a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
	out[0][0] = (a[1][1] * a[2][2] - a[1][2] * a[2][1]) / det;
	out[0][1] = (a[0][2] * a[2][1] - a[0][1] * a[2][2]) / det;
	out[0][2] = (a[0][1] * a[1][2] - a[0][2] * a[1][1]) / det;
	out[1][0] = (a[1][2] * a[2][0] - a[1][0] * a[2][2]) / det;
	out[1][1] = (a[0][0] * a[2][2] - a[0][2] * a[2][0]) / det;
	out[1][2] = (a[0][2] * a[1][0] - a[0][0] * a[1][2]) / det;
	out[2][0] = (a[1][0] * a[2][1] - a[1][1] * a[2][0]) / det;
	out[2][1] = (a[0][1] * a[2][0] - a[0][0] * a[2][1]) / det;
	out[2][2] = (a[0][0] * a[1][1] - a[0][1] * a[1][0]) / det;
}

void ps_integrate_rgb_to_xyz(const double prim[8], double m[3][3])
{
	/* columns: XYZ of each primary scaled so that R + G + B = white (Y = 1) */
	double p[3][3], inv[3][3], wx = prim[6] / prim[7], wz = (1 - prim[6] - prim[7]) / prim[7];
	double sc[3];
	for (int k = 0; k < 3; k++) {
		double x = prim[2 * k], y = prim[2 * k + 1];
		p[0][k] = x / y;
		p[1][k] = 1.0;
		p[2][k] = (1 - x - y) / y;
	}
	ps_integrate_mat3_invert((const double(*)[3])p, inv);
	for (int k = 0; k < 3; k++)
		sc[k] = inv[k][0] * wx + inv[k][1] * 1.0 + inv[k][2] * wz;
	for (int i = 0; i < 3; i++)
		for (int k = 0; k < 3; k++)
			m[i][k] = p[i][k] * sc[k];
}

/* The Sharp cone-response matrix (Finlayson and Suesstrunk), the one
 * Radiance's von Kries white balance works in (vkmat of its colour code). */
static const double sharp_cones[3][3] = { { 1.2694, -0.0988, -0.1706 },
                                          { -0.8364, 1.8006, 0.0357 },
                                          { 0.0297, -0.0315, 1.0018 } };

/* m = a b */
static void mat3_mul(const double a[3][3], const double b[3][3], double m[3][3])
{
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++)
			m[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
}

/* The von Kries transform in the Sharp cones taking XYZ seen under white
 * (x1, y1) to XYZ seen under white (x2, y2): S^-1 diag(S w2 / S w1) S, w the
 * whites' XYZ with Y = 1.  The exact inverse of S is used, so white maps to
 * white exactly (Radiance's colour code tables a 4-digit inverse: its
 * D65-to-neutral matrix differs from this one by at most 8.3e-5, and takes
 * the D65 white to Y = 0.99994; psens(1) states it, test_colour_formats
 * measures it). */
static void white_balance(double x1, double y1, double x2, double y2, double m[3][3])
{
	double w1[3] = { x1 / y1, 1.0, (1 - x1 - y1) / y1 }, w2[3] = { x2 / y2, 1.0, (1 - x2 - y2) / y2 };
	double inv[3][3], d[3][3] = { { 0 } }, t[3][3];
	for (int i = 0; i < 3; i++) {
		double c1 = sharp_cones[i][0] * w1[0] + sharp_cones[i][1] * w1[1] + sharp_cones[i][2] * w1[2];
		double c2 = sharp_cones[i][0] * w2[0] + sharp_cones[i][1] * w2[1] + sharp_cones[i][2] * w2[2];
		d[i][i] = c2 / c1;
	}
	ps_integrate_mat3_invert(sharp_cones, inv);
	mat3_mul((const double(*)[3])d, sharp_cones, t);
	mat3_mul((const double(*)[3])inv, (const double(*)[3])t, m);
}

void ps_integrate_own_rgb_to_xyz(const double prim[8], double m[3][3])
{
	double own[3][3], wb[3][3];
	ps_integrate_rgb_to_xyz(prim, own);
	white_balance(prim[6], prim[7], ps_integrate_std_primaries[6], ps_integrate_std_primaries[7], wb);
	mat3_mul((const double(*)[3])wb, (const double(*)[3])own, m);
}

void ps_integrate_pic_matrix(const struct ps_picture *pic, double k[3][3])
{
	double to_xyz[3][3], from_xyz[3][3], m[3][3];
	ps_integrate_rgb_to_xyz(ps_integrate_std_primaries, to_xyz);
	ps_integrate_mat3_invert((const double(*)[3])to_xyz, from_xyz);
	if (pic->format == PS_PIC_XYZE) {
		/* XYZE holds luminance-based values (Y in cd/m2 once EXPOSURE is
		 * divided out): Radiance's ra_xyze writes EXPOSURE=1/179 on the
		 * unchanged XYZ of a radiance picture.  Back to radiance: / 179. */
		for (int i = 0; i < 3; i++)
			for (int c = 0; c < 3; c++)
				m[i][c] = from_xyz[i][c] / PS_WHTEFFICACY;
	} else if (pic->has_primaries) {
		/* RGB in the picture's own primaries -> XYZ balanced to the
		 * standard white -> standard RGB */
		double own[3][3];
		ps_integrate_own_rgb_to_xyz(pic->primaries, own);
		for (int i = 0; i < 3; i++)
			for (int c = 0; c < 3; c++)
				m[i][c] = from_xyz[i][0] * own[0][c] + from_xyz[i][1] * own[1][c] +
				          from_xyz[i][2] * own[2][c];
	} else {
		for (int i = 0; i < 3; i++)
			for (int c = 0; c < 3; c++)
				m[i][c] = i == c;
	}
	/* EXPOSURE and COLORCORR act on the stored channels, before any change
	 * of colour space (Radiance divides them out of the pixel as read) */
	for (int i = 0; i < 3; i++)
		for (int c = 0; c < 3; c++)
			k[i][c] = m[i][c] / pic->exposure[c];
}

/* A figure for a message: the number, or "infinite" / "not a number" (the
 * C library's "inf" and "-nan" are no figure to a reader). */
static const char *figure(double v, char buf[32])
{
	if (isnan(v))
		return "not a number";
	if (isinf(v))
		return v > 0 ? "infinite" : "minus infinite";
	snprintf(buf, 32, "%g", v);
	return buf;
}

int ps_integrate_check_finite(const struct ps_response *r, const double coef[3], double sens_sum,
                              struct ps_err *e)
{
	char b[6][32];
	if (isfinite(r->response) && isfinite(r->rgb[0]) && isfinite(r->rgb[1]) && isfinite(r->rgb[2]))
		return 0;
	if (!isfinite(coef[0]) || !isfinite(coef[1]) || !isfinite(coef[2]))
		return ps_err_set(e, PS_ERANGE, "the response is not finite: the colour coefficients "
		                  "(%s %s %s) are not", figure(coef[0], b[0]), figure(coef[1], b[1]),
		                  figure(coef[2], b[2]));
	if (!isfinite(sens_sum))
		return ps_err_set(e, PS_ERANGE, "the response is not finite: the sensor's weights sum "
		                  "to %s (its sensitivities are too large)", figure(sens_sum, b[0]));
	if (!isfinite(r->rgb[0]) || !isfinite(r->rgb[1]) || !isfinite(r->rgb[2]))
		return ps_err_set(e, PS_ERANGE, "the response is not finite: the picture's weighted "
		                  "radiance (R %s G %s B %s) overflows with weights summing to %g",
		                  figure(r->rgb[0], b[0]), figure(r->rgb[1], b[1]), figure(r->rgb[2], b[2]),
		                  sens_sum);
	return ps_err_set(e, PS_ERANGE, "the response is %s: the colour coefficients (%g %g %g) "
	                  "times the picture's weighted radiance (R %g G %g B %g) overflow",
	                  isnan(r->response) ? "not a number" : "infinite", coef[0], coef[1], coef[2],
	                  r->rgb[0], r->rgb[1], r->rgb[2]);
}

/* Rearrange v so that its k largest values come first (quickselect, O(n)). */
static void select_largest(double *v, size_t n, size_t k)
{
	size_t lo = 0, hi = n;
	while (hi - lo > 1) {
		double pivot = v[lo + (hi - lo) / 2];
		size_t i = lo, j = hi - 1;
		while (i <= j) {
			while (v[i] > pivot)
				i++;
			while (v[j] < pivot)
				j--;
			if (i <= j) {
				double t = v[i];
				v[i] = v[j];
				v[j] = t;
				i++;
				if (j == 0)
					break;
				j--;
			}
		}
		if (k <= j + 1 && j + 1 > lo)
			hi = j + 1;
		else if (k >= i)
			lo = i;
		else
			return;
	}
}

double ps_integrate_top1_share(double *contrib, size_t n, double response)
{
	size_t top = n / 100 ? n / 100 : 1;
	struct ps_sum s;
	select_largest(contrib, n, top);
	ps_sum_init(&s);
	for (size_t i = 0; i < top; i++)
		ps_sum_add(&s, contrib[i]);
	return ps_sum_get(&s) / response;
}

int ps_integrate(const struct ps_weights *w, const struct ps_picture *pic, const double coef[3],
                 struct ps_response *r, struct ps_err *e)
{
	struct ps_sum tot, ch[3];
	double k[3][3];   /* radiance channel c of the stored pixel -> weighted RGB */
	double kc[3];     /* stored channels -> response */
	double best = -1.0, *contrib = NULL;
	size_t ncontrib = 0;
	memset(r, 0, sizeof *r);
	if (pic->width != w->width || pic->height != w->height)
		return ps_err_set(e, PS_EINVAL, "picture is %d x %d, the weights are for %d x %d", pic->width,
		                  pic->height, w->width, w->height);
	ps_integrate_pic_matrix(pic, k);
	ps_integrate_coef_k(coef, k, kc);
	/* Each run is summed with compensation in four lanes (rowsum.h) and
	 * the runs are added with compensation: a 1e9 sun next to 1e-2 walls
	 * keeps the walls to 1e-12 (test_weights). */
	ps_sum_init(&tot);
	for (int c = 0; c < 3; c++)
		ps_sum_init(&ch[c]);
	for (size_t ri = 0; ri < w->nruns; ri++) {
		const struct ps_weights_run *run = &w->runs[ri];
		const uint8_t *px = pic->pix + 4 * ((size_t)run->row * (size_t)pic->width + (size_t)run->x0);
		struct ps_rowsum row;
		double rc[3];
		ps_rowsum(px, w, run, kc, &row);
		ncontrib += row.n;
		if (row.n && row.best > best) {   /* a lit pixel: best_i >= 0 */
			best = row.best;
			r->brightest_x = run->x0 + row.best_i;
			r->brightest_row = run->row;
		}
		ps_sum_merge(&tot, &row.sum);
		ps_integrate_row_rgb(k, row.raw, rc);
		for (int c = 0; c < 3; c++)
			ps_sum_add(&ch[c], rc[c]);
	}
	r->response = ps_sum_get(&tot);
	for (int c = 0; c < 3; c++)
		r->rgb[c] = ps_sum_get(&ch[c]);
	r->solid_angle = w->solid_angle;
	r->npixels = ncontrib;
	r->top1_share = NAN;
	if (ps_integrate_check_finite(r, coef, w->sens_sum, e) != 0)
		return -1;
	if (r->response > 0 && ncontrib > 0)
		r->brightest_share = best / r->response;
	/* the brightest 1 % only matters when one pixel already stands out:
	 * only then a second pass collects every contribution */
	if (r->response > 0 && ncontrib > 0 && r->brightest_share > 0.001) {
		size_t n = 0;
		contrib = malloc(ncontrib * sizeof *contrib);
		if (!contrib)
			return ps_err_set(e, PS_ENOMEM, "out of memory");
		for (size_t ri = 0; ri < w->nruns; ri++) {
			const struct ps_weights_run *run = &w->runs[ri];
			const uint8_t *px = pic->pix + 4 * ((size_t)run->row * (size_t)pic->width + (size_t)run->x0);
			for (int i = 0; i < run->n && n < ncontrib; i++, px += 4) {
				double raws[3] = { 0, 0, 0 };
				if (px[3] == 0)
					continue;
				contrib[n++] = ps_integrate_pixel_response(px, ps_weights_run_at(w, run, i), kc, raws);
			}
		}
		r->top1_share = ps_integrate_top1_share(contrib, n, r->response);
	}
	free(contrib);
	return 0;
}
