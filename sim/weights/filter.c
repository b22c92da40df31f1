/* SPDX-License-Identifier: ISC */
#include "filter.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cie.h"
#include "fileio.h"
#include "integrate.h"
#include "sum.h"

enum { FILTER_MAX_POINTS = 1000000 };

void ps_filter_free(struct ps_filter *f)
{
	if (!f)
		return;
	free(f->path);
	free(f->nm);
	free(f->value);
	memset(f, 0, sizeof *f);
}

int ps_filter_parse(struct ps_filter *f, const char *text, size_t len, const char *name,
                    int percent, struct ps_err *e)
{
	const char *p = text, *end = text + len;
	int lineno = 0, cap = 0;
	double vmax = 0.0;
	memset(f, 0, sizeof *f);
	f->path = strdup(name);
	if (!f->path)
		return ps_err_set(e, PS_ENOMEM, "out of memory");
	if (memchr(text, '\0', len)) {
		ps_err_set(e, PS_EFORMAT, "%s: byte %zu: NUL byte in a text file", name,
		           (size_t)((const char *)memchr(text, '\0', len) - text));
		goto fail;
	}
	while (p < end) {
		const char *nl = memchr(p, '\n', (size_t)(end - p));
		size_t n = nl ? (size_t)(nl - p) : (size_t)(end - p);
		char line[512], *q, *r2;
		double wl, v;
		lineno++;
		if (n >= sizeof line) {
			ps_err_set(e, PS_EFORMAT, "%s:%d: line longer than %zu bytes", name, lineno, sizeof line - 1);
			goto fail;
		}
		memcpy(line, p, n);
		line[n] = '\0';
		p += n + (nl ? 1 : 0);
		if ((q = strchr(line, '#')))
			*q = '\0';
		q = line + strspn(line, " \t\r,");
		if (!*q)
			continue;
		errno = 0;
		wl = strtod(q, &r2);
		if (r2 == q || !isfinite(wl)) {
			ps_err_set(e, PS_EFORMAT, "%s:%d: '%.*s' is not a wavelength", name, lineno,
			           (int)strcspn(q, " \t,"), q);
			goto fail;
		}
		q = r2 + strspn(r2, " \t,;");
		v = strtod(q, &r2);
		if (r2 == q || !isfinite(v)) {
			ps_err_set(e, PS_EFORMAT, "%s:%d: '%.*s' is not a number (expected wavelength and value)",
			           name, lineno, (int)strcspn(q, " \t,"), *q ? q : "(nothing)");
			goto fail;
		}
		if (r2[strspn(r2, " \t\r,")] != '\0') {
			ps_err_set(e, PS_EFORMAT, "%s:%d: more than two numbers on a line", name, lineno);
			goto fail;
		}
		if (v < 0) {
			ps_err_set(e, PS_ERANGE, "%s:%d: negative transmittance %g", name, lineno, v);
			goto fail;
		}
		if (wl <= 0) {
			ps_err_set(e, PS_ERANGE, "%s:%d: wavelength %g nm is not positive", name, lineno, wl);
			goto fail;
		}
		if (f->n > 0 && wl == f->nm[f->n - 1]) {
			ps_err_set(e, PS_EFORMAT, "%s:%d: wavelength %g nm appears twice", name, lineno, wl);
			goto fail;
		}
		if (f->n > 0 && wl < f->nm[f->n - 1]) {
			ps_err_set(e, PS_EFORMAT, "%s:%d: wavelength %g nm comes after %g nm: sort the file", name,
			           lineno, wl, f->nm[f->n - 1]);
			goto fail;
		}
		if (f->n == cap) {
			int ncap = cap ? 2 * cap : 256;
			double *a, *b;
			if (ncap > FILTER_MAX_POINTS) {
				ps_err_set(e, PS_ERANGE, "%s:%d: more than %d points", name, lineno, FILTER_MAX_POINTS);
				goto fail;
			}
			a = realloc(f->nm, (size_t)ncap * sizeof *a);
			if (a)
				f->nm = a;
			b = realloc(f->value, (size_t)ncap * sizeof *b);
			if (b)
				f->value = b;
			if (!a || !b) {
				ps_err_set(e, PS_ENOMEM, "%s:%d: out of memory", name, lineno);
				goto fail;
			}
			cap = ncap;
		}
		f->nm[f->n] = wl;
		f->value[f->n++] = v;
		if (v > vmax)
			vmax = v;
	}
	if (f->n < 2) {
		ps_err_set(e, PS_EFORMAT, "%s:%d: a filter needs at least two points (has %d)", name, lineno, f->n);
		goto fail;
	}
	if (f->nm[f->n - 1] <= 380.0 || f->nm[0] >= 780.0) {
		ps_err_set(e, PS_ERANGE, "%s: %g to %g nm does not overlap 380-780 nm", name, f->nm[0],
		           f->nm[f->n - 1]);
		goto fail;
	}
	if (vmax <= 0) {
		ps_err_set(e, PS_ERANGE, "%s: every value is zero", name);
		goto fail;
	}
	/* A transmittance in fractions stays below 1, but a relative spectral
	 * response may pass it a little (x-bar peaks at 1.06): only a maximum
	 * above 2 reads as percent, unless the caller says. */
	f->percent = percent == PS_FILTER_PERCENT_AUTO ? vmax > 2.0 : percent;
	if (f->percent)
		for (int i = 0; i < f->n; i++)
			f->value[i] /= 100.0;
	return 0;
fail:
	ps_filter_free(f);
	return -1;
}

int ps_filter_read(struct ps_filter *f, const char *path, int percent, struct ps_err *e)
{
	uint8_t *buf;
	size_t len;
	int rc;
	memset(f, 0, sizeof *f);
	if (ps_fileio_read(path, (size_t)64 << 20, &buf, &len, e) != 0)
		return -1;
	rc = ps_filter_parse(f, (const char *)buf, len, path, percent, e);
	free(buf);
	return rc;
}

double ps_filter_at(const struct ps_filter *f, double nm)
{
	int lo = 0, hi = f->n - 1;
	if (nm < f->nm[0] || nm > f->nm[f->n - 1])
		return 0.0;
	while (hi - lo > 1) {
		int mid = (lo + hi) / 2;
		if (f->nm[mid] <= nm)
			lo = mid;
		else
			hi = mid;
	}
	if (f->nm[hi] == f->nm[lo])
		return f->value[lo];
	return f->value[lo] + (nm - f->nm[lo]) / (f->nm[hi] - f->nm[lo]) * (f->value[hi] - f->value[lo]);
}

/* Integral over the 1-nm grid [a, b] of the product of two functions
 * sampled there (trapezoid weights: 1/2 at the ends). */
typedef double (*spec_fn)(const void *ctx, double nm);

static double grid_integral(double a, double b, spec_fn f, const void *fc, spec_fn g, const void *gc)
{
	struct ps_sum s;
	ps_sum_init(&s);
	for (double nm = a; nm <= b + 1e-9; nm += 1.0) {
		double w = (nm == a || nm > b - 0.5) ? 0.5 : 1.0;
		ps_sum_add(&s, w * f(fc, nm) * (g ? g(gc, nm) : 1.0));
	}
	return ps_sum_get(&s);
}

static double at_spectrum(const void *ctx, double nm)
{
	return ps_cie_spectrum_at(ctx, nm);
}

static double at_filter(const void *ctx, double nm)
{
	return ps_filter_at(ctx, nm);
}

struct proj {
	double c[3];
};

static double at_projection(const void *ctx, double nm)
{
	const struct proj *p = ctx;
	return p->c[0] * ps_cie_spectrum_at(ps_cie_cmf(0), nm) + p->c[1] * ps_cie_spectrum_at(ps_cie_cmf(1), nm) +
	       p->c[2] * ps_cie_spectrum_at(ps_cie_cmf(2), nm);
}

struct scaled_diff {
	const struct ps_filter *f;
	double k;
};

static double at_abs_diff(const void *ctx, double nm)
{
	const struct scaled_diff *d = ctx;
	return fabs(d->k * ps_filter_at(d->f, nm) - ps_cie_spectrum_at(ps_cie_v(), nm));
}

struct resid {
	const struct ps_filter *f;
	const struct proj *p;
};

static double at_resid(const void *ctx, double nm)
{
	const struct resid *r = ctx;
	double d = ps_filter_at(r->f, nm) - at_projection(r->p, nm);
	return d * d;
}

/* Solve the symmetric 3 x 3 system a x = b by Gaussian elimination with
 * partial pivoting; also its condition number in the 1-norm. */
static int solve3(double a[3][3], double b[3], double x[3], double *cond)
{
	double m[3][4], inv[3][3], n1 = 0, ninv = 0;
	for (int i = 0; i < 3; i++) {
		double row = 0;
		for (int j = 0; j < 3; j++)
			row += fabs(a[j][i]);
		if (row > n1)
			n1 = row;
	}
	for (int col = 0; col < 4; col++) {
		for (int i = 0; i < 3; i++) {
			for (int j = 0; j < 3; j++)
				m[i][j] = a[i][j];
			m[i][3] = col < 3 ? (i == col) : b[i];
		}
		for (int k = 0; k < 3; k++) {
			int piv = k;
			for (int i = k + 1; i < 3; i++)
				if (fabs(m[i][k]) > fabs(m[piv][k]))
					piv = i;
			if (m[piv][k] == 0.0)
				return -1;
			for (int j = 0; j < 4; j++) {
				double t = m[k][j];
				m[k][j] = m[piv][j];
				m[piv][j] = t;
			}
			for (int i = k + 1; i < 3; i++) {
				double f = m[i][k] / m[k][k];
				for (int j = k; j < 4; j++)
					m[i][j] -= f * m[k][j];
			}
		}
		for (int k = 2; k >= 0; k--) {
			double s = m[k][3];
			for (int j = k + 1; j < 3; j++)
				s -= m[k][j] * (col < 3 ? inv[j][col] : x[j]);
			if (col < 3)
				inv[k][col] = s / m[k][k];
			else
				x[k] = s / m[k][k];
		}
	}
	for (int j = 0; j < 3; j++) {
		double colsum = 0;
		for (int i = 0; i < 3; i++)
			colsum += fabs(inv[i][j]);
		if (colsum > ninv)
			ninv = colsum;
	}
	*cond = n1 * ninv;
	return 0;
}

int ps_filter_analyse(const struct ps_filter *f, const char *calibration,
                      struct ps_filter_report *r, struct ps_err *e)
{
	const struct ps_spectrum *cmf[3] = { ps_cie_cmf(0), ps_cie_cmf(1), ps_cie_cmf(2) };
	const struct ps_spectrum *v = ps_cie_v(), *cal = ps_cie_illuminant(calibration);
	const struct ps_spectrum *illa = ps_cie_illuminant("A");
	double a[3][3], b[3], m[3][3], g0 = cmf[0]->start, g1 = cmf[0]->start + cmf[0]->step * (cmf[0]->n - 1);
	struct proj pr;
	double cal_s, cal_v, cal_p;
	memset(r, 0, sizeof *r);
	if (!cal)
		return ps_err_set(e, PS_EINVAL, "no CIE illuminant '%s' (A, D65, FL2, FL7, FL11, FL12, HP1-HP5, "
		                  "LED-B3, LED-B4)", calibration);
	r->calibration = calibration;
	r->lo = f->nm[0];
	r->hi = f->nm[f->n - 1];
	r->outside = r->lo > 380.0 || r->hi < 780.0;
	/* normal equations on the CMF grid */
	for (int i = 0; i < 3; i++) {
		for (int j = 0; j < 3; j++)
			a[i][j] = grid_integral(g0, g1, at_spectrum, cmf[i], at_spectrum, cmf[j]);
		b[i] = grid_integral(g0, g1, at_spectrum, cmf[i], at_filter, f);
	}
	if (solve3(a, b, r->xyz, &r->condition) != 0)
		return ps_err_set(e, PS_ERANGE, "the colour-matching functions are singular");
	ps_integrate_rgb_to_xyz(ps_integrate_std_primaries, m);
	for (int k = 0; k < 3; k++)
		r->rgb[k] = m[0][k] * r->xyz[0] + m[1][k] * r->xyz[1] + m[2][k] * r->xyz[2];
	memcpy(pr.c, r->xyz, sizeof pr.c);
	{
		struct resid rs = { f, &pr };
		double num = grid_integral(g0, g1, at_resid, &rs, NULL, NULL);
		double den = grid_integral(g0, g1, at_filter, f, at_filter, f);
		r->residual = den > 0 ? sqrt(num / den) : 0.0;
	}
	/* f1': the response scaled to read V(lambda) correctly under A */
	{
		double k = grid_integral(380, 780, at_spectrum, illa, at_spectrum, v) /
		           grid_integral(380, 780, at_spectrum, illa, at_filter, f);
		struct scaled_diff d = { f, k };
		r->f1p = grid_integral(380, 780, at_abs_diff, &d, NULL, NULL) /
		         grid_integral(380, 780, at_spectrum, v, NULL, NULL);
	}
	/* reading error under each illuminant, relative to the calibration one */
	cal_s = grid_integral(g0, g1, at_spectrum, cal, at_filter, f);
	cal_v = grid_integral(g0, g1, at_spectrum, cal, at_spectrum, v);
	cal_p = grid_integral(g0, g1, at_spectrum, cal, at_projection, &pr);
	for (int i = 0; ps_cie_illuminant_names[i] && r->nillum < 16; i++) {
		const struct ps_spectrum *il = ps_cie_illuminant(ps_cie_illuminant_names[i]);
		double s_, v_, p_;
		if (!il)
			continue;
		s_ = grid_integral(g0, g1, at_spectrum, il, at_filter, f);
		v_ = grid_integral(g0, g1, at_spectrum, il, at_spectrum, v);
		p_ = grid_integral(g0, g1, at_spectrum, il, at_projection, &pr);
		r->illum[r->nillum].name = ps_cie_illuminant_names[i];
		r->illum[r->nillum].spectral = (s_ / v_) / (cal_s / cal_v) - 1.0;
		r->illum[r->nillum].rgb = (p_ / v_) / (cal_p / cal_v) - 1.0;
		r->nillum++;
	}
	{
		/* a result that is not finite is an error, never a figure */
		int ok = isfinite(r->rgb[0]) && isfinite(r->rgb[1]) && isfinite(r->rgb[2]) &&
		         isfinite(r->residual) && isfinite(r->f1p);
		double top = 0;
		for (int i = 0; i < r->nillum; i++)
			ok = ok && isfinite(r->illum[i].spectral) && isfinite(r->illum[i].rgb);
		for (int i = 0; i < f->n; i++)
			top = fmax(top, fabs(f->value[i]));
		if (!ok)
			return ps_err_set(e, PS_ERANGE, "%s: the filter's figures are not finite: its "
			                  "transmittances (up to %g) overflow the integrals, or it is zero "
			                  "where the eye sees; give transmittances from 0 to 1 (or percent)",
			                  f->path ? f->path : "filter", top);
	}
	return 0;
}

int ps_filter_rgb(const char *path, double rgb[3], struct ps_err *e)
{
	struct ps_filter f;
	struct ps_filter_report r;
	if (ps_filter_read(&f, path, PS_FILTER_PERCENT_AUTO, e) != 0)
		return -1;
	if (ps_filter_analyse(&f, "A", &r, e) != 0) {
		ps_filter_free(&f);
		return -1;
	}
	memcpy(rgb, r.rgb, sizeof r.rgb);
	ps_filter_free(&f);
	return 0;
}
