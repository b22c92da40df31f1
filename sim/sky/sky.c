/* SPDX-License-Identifier: ISC */
#include "sky.h"

#include <math.h>
#include <string.h>

#include "sum.h"
#include "sun.h"

#define DEG (M_PI / 180.0)
#define SKY_DARK 1e-4          /* direct + diffuse at or below this: night */
#define SKY_TINY 1e-6          /* a sky (or colour) sum at or below this counts as none */
#define SUN_HALF_ANGLE (0.533 / 2 * DEG)

void ps_sky_opt_default(struct ps_sky_opt *o)
{
	memset(o, 0, sizeof *o);
	o->ground[0] = o->ground[1] = o->ground[2] = 0.2;
	o->sky_color[0] = 0.960;
	o->sky_color[1] = 1.004;
	o->sky_color[2] = 1.118;
	o->sun_color[0] = o->sun_color[1] = o->sun_color[2] = 1.0;
	o->output = PS_SKY_VISIBLE;
	o->nsun = 4;
}

double ps_sky_bright(const double rgb[3])
{
	return 0.265074126 * rgb[0] + 0.670114631 * rgb[1] + 0.064811243 * rgb[2];
}

void ps_sky_init(struct ps_sky *s, const struct ps_sky_in *in, const struct ps_sky_opt *o)
{
	struct ps_perez_in pin;
	double dir = in->dir, azi, g;
	int photometric = in->units == PS_WX_ILLUM;
	memset(s, 0, sizeof *s);
	s->opt = *o;
	s->sun_alt = in->sun_alt;
	azi = fmod(in->sun_azi - o->rotation * DEG, 2 * M_PI);
	s->sun_azi = azi < 0 ? azi + 2 * M_PI : azi;
	ps_sun_direction(s->sun_alt, s->sun_azi, s->sun_dir);
	if (in->dir + in->dif <= SKY_DARK) {
		s->dark = 1;
		return;
	}
	if (s->sun_alt <= -SUN_HALF_ANGLE && dir > (photometric ? 20.0 * PS_WHITE_EFFICACY : 20.0))
		s->bright_night = 1;
	/* a direct horizontal value becomes direct normal */
	if (in->units == PS_WX_DHOR_DH && s->sun_alt > SKY_TINY)
		dir /= sin(s->sun_alt);
	pin.dir = dir;
	pin.dif = in->dif;
	pin.photometric = photometric;
	pin.dew = in->dew;
	pin.doy = in->doy;
	pin.sun_alt = s->sun_alt;
	ps_perez_init(&s->model, &pin);
	if (o->output == PS_SKY_SOLAR) {
		s->dif_lum = s->model.dif_irr * PS_WHITE_EFFICACY;
		s->dir_lum = s->model.dir_irr * PS_WHITE_EFFICACY;
	} else {
		s->dif_lum = s->model.dif_lux;
		s->dir_lum = s->model.dir_lux;
	}
	ps_sun_direction(M_PI / 2 - s->model.zenith, s->sun_azi, s->model_sun);
	g = s->dif_lum + (s->sun_alt > 0 ? s->dir_lum * sin(s->sun_alt) : 0.0);
	g /= M_PI * PS_WHITE_EFFICACY;
	for (int c = 0; c < 3; c++)
		s->ground_rad[c] = g * o->ground[c];
}

int ps_sky_step(struct ps_sky *s, const struct ps_weather *w, size_t i, const struct ps_sky_opt *o,
                struct ps_err *e)
{
	struct ps_sky_in in;
	const struct ps_wx_step *st;
	if (i >= w->n)
		return ps_err_set(e, PS_EINVAL, "%s: step %zu of %zu", w->name, i, w->n);
	st = &w->step[i];
	in.dir = st->dir;
	in.dif = st->dif;
	in.units = w->units;
	in.dew = st->dew;
	in.doy = st->doy;
	in.sun_alt = st->sun.alt;
	in.sun_azi = st->sun.azi;
	ps_sky_init(s, &in, o);
	return 0;
}

int ps_sky_sun_patches(const struct ps_sky *s, const struct ps_patches *P, int idx[4], double v[4],
                       double *v1)
{
	int nsun = s->opt.sun_disc > 0 ? 1 : s->opt.nsun < 1 ? 1 : s->opt.nsun > 4 ? 4 : s->opt.nsun;
	double best[4], wt[4], wsum = 0.0, disc = 0.0, total;
	*v1 = 0.0;
	if (s->dark || s->dir_lum <= SKY_DARK || ps_sky_bright(s->opt.sun_color) <= SKY_DARK)
		return 0;
	for (int k = 0; k < nsun; k++) {
		best[k] = -1.0;
		idx[k] = 0;
	}
	/* the nsun nearest centres; on a tie the lower patch number comes first */
	for (int p = 1; p < P->n; p++) {
		const double *d = P->dir + 3 * p;
		double c = d[0] * s->sun_dir[0] + d[1] * s->sun_dir[1] + d[2] * s->sun_dir[2];
		for (int k = 0; k < nsun; k++)
			if (c > best[k]) {
				for (int m = nsun - 1; m > k; m--) {
					best[m] = best[m - 1];
					idx[m] = idx[m - 1];
				}
				best[k] = c;
				idx[k] = p;
				break;
			}
	}
	for (int k = 0; k < nsun; k++) {
		wt[k] = 1.0 / (1.002 - best[k]);
		wsum += wt[k];
	}
	if (s->opt.sun_disc > 0) {
		double r = 0.5 * s->opt.sun_disc * DEG;
		disc = M_PI * r * r;
	}
	total = s->dir_lum / PS_WHITE_EFFICACY;
	for (int k = 0; k < nsun; k++)
		v[k] = wt[k] / wsum * total / (disc > 0 ? disc : P->omega[idx[k]]);
	*v1 = total / (disc > 0 ? disc : P->omega[idx[0]]);
	return nsun;
}

static void add_sun(const struct ps_sky *s, const struct ps_patches *P, double *rgb)
{
	int idx[4];
	double v[4], v1;
	int n = ps_sky_sun_patches(s, P, idx, v, &v1);
	for (int k = 0; k < n; k++)
		for (int c = 0; c < 3; c++)
			rgb[3 * idx[k] + c] += v[k] * s->opt.sun_color[c];
}

double ps_sky_table_sin(double x)
{
	/* Radiance's tcos(): the nearest of 1024 cosines a quadrant, no
	 * interpolation (Radiance built without -ffast-math), sin x = cos(x - pi/2) */
	const int n = 1024;
	int i;
	x -= M_PI / 2;
	if (x < 0)
		x = -x;
	i = (int)((2.0 * n / M_PI) * x + 0.5);
	i %= 4 * n;
	switch (i / n) {
	case 0: return cos(M_PI / 2 / n * i);
	case 1: return -cos(M_PI / 2 / n * (2 * n - i));
	case 2: return -cos(M_PI / 2 / n * (i - 2 * n));
	default: return cos(M_PI / 2 / n * (4 * n - i));
	}
}

void ps_sky_vector(const struct ps_sky *s, const struct ps_patches *P, unsigned parts, double *rgb)
{
	memset(rgb, 0, (size_t)P->n * 3 * sizeof *rgb);
	if (s->dark)
		return;
	if (parts & PS_SKY_GROUND)
		for (int c = 0; c < 3; c++)
			rgb[c] = s->ground_rad[c];
	if ((parts & PS_SKY_DIFFUSE) && ps_sky_bright(s->opt.sky_color) > SKY_DARK) {
		const struct ps_perez *m = &s->model;
		const double *sun = s->model_sun;
		struct ps_sum sum;
		double total, k;
		ps_sum_init(&sum);
		/* the gradation term and the cosine weight are the same along a row */
		for (int r = 0; r < P->nrows; r++) {
			int first = P->row_first[r], n = P->row_count[r];
			double alt = P->alt[first], cz = sin(alt);
			double grad = 1.0 + m->coef[0] * exp(m->coef[1] / fmax(cz, PS_PEREZ_COS_ZETA_MIN));
			double wh = (s->opt.exact_sine ? cz : ps_sky_table_sin(alt)) * P->omega[first];
			struct ps_sum row;
			ps_sum_init(&row);
			for (int p = first; p < first + n; p++) {
				const double *d = P->dir + 3 * p;
				double cg = d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2], l;
				cg = cg > 1.0 ? 1.0 : cg < -1.0 ? -1.0 : cg;
				l = grad * (1.0 + m->coef[2] * exp(m->coef[3] * acos(cg)) + m->coef[4] * cg * cg);
				if (!(l > 0))
					l = 0.0;
				rgb[3 * p] = l;
				ps_sum_add(&row, l);
			}
			ps_sum_add(&sum, ps_sum_get(&row) * wh);
		}
		total = ps_sum_get(&sum);
		if (!(total > SKY_TINY)) {   /* no sky: make it uniform */
			for (int p = 1; p < P->n; p++)
				rgb[3 * p] = 1.0;
			total = M_PI;
		}
		k = s->dif_lum / total / PS_WHITE_EFFICACY;
		for (int p = 1; p < P->n; p++) {
			double l = rgb[3 * p] * k;
			for (int c = 0; c < 3; c++)
				rgb[3 * p + c] = l * s->opt.sky_color[c];
		}
	}
	if (parts & PS_SKY_SUN)
		add_sun(s, P, rgb);
}

/* ---- the continuous sky --------------------------------------------------- */

struct hemi_ctx {
	const struct ps_sky *s;
	ps_sky_weight_fn weight;
	void *wctx;
	int uniform;
};

/* integrand in zenith angle x and azimuth y: weight x relative luminance x sin(zenith) */
static double hemi_f(double x, double y, void *p)
{
	const struct hemi_ctx *c = p;
	double sz = sin(x), d[3] = { sz * sin(y), sz * cos(y), cos(x) }, l, w;
	w = c->weight(d, c->wctx);
	if (w == 0.0)
		return 0.0;
	l = c->uniform ? 1.0 : ps_perez_rel_dir(&c->s->model, d, c->s->model_sun);
	return w * l * sz;
}

static double cos_weight(const double d[3], void *ctx)
{
	(void)ctx;
	return d[2];
}

static void hemi_integrate(const struct ps_sky *s, ps_sky_weight_fn weight, void *wctx, int uniform,
                           const double *zb, int nzb, const double *ab, int nab, double reltol,
                           struct ps_quad *r)
{
	struct hemi_ctx c = { s, weight, wctx, uniform };
	double xb[64], yb[64];
	int nx = 0, ny = 0;
	struct ps_quad2_spec q;
	xb[nx++] = s->model.zenith;
	xb[nx++] = acos(PS_PEREZ_COS_ZETA_MIN);
	for (int i = 0; i < nzb && nx < 64; i++)
		xb[nx++] = zb[i];
	yb[ny++] = s->sun_azi;
	for (int i = 0; i < nab && ny < 64; i++) {
		double a = fmod(ab[i], 2 * M_PI);
		yb[ny++] = a < 0 ? a + 2 * M_PI : a;
	}
	q.x0 = 0.0;
	q.x1 = M_PI / 2;
	q.xb = xb;
	q.nxb = nx;
	q.y0 = 0.0;
	q.y1 = 2 * M_PI;
	q.yb = yb;
	q.nyb = ny;
	q.abstol = 0.0;
	q.reltol = reltol;
	q.max_intervals = 4000;
	ps_quad_2d(hemi_f, &c, &q, r);
}

int ps_sky_normalise(struct ps_sky *s, double reltol, struct ps_err *e)
{
	struct ps_quad r;
	if (s->dark) {
		s->norm = M_PI;
		s->norm_err = 0.0;
		return 0;
	}
	hemi_integrate(s, cos_weight, NULL, 0, NULL, 0, NULL, 0, reltol, &r);
	s->norm = r.value;
	s->norm_err = r.error;
	if (!(r.value > SKY_TINY)) {   /* no sky: uniform, as the patches */
		s->norm = -M_PI;
		s->norm_err = 0.0;
		return 0;
	}
	if (!r.converged)
		return ps_err_set(e, PS_ERANGE, "sky normalisation did not reach %g (error %g of %g)", reltol,
		                  r.error, r.value);
	return 0;
}

/* s->norm < 0 marks a uniform sky of integral -norm */
static double diffuse_scale(const struct ps_sky *s)
{
	return s->dif_lum / (fabs(s->norm) * PS_WHITE_EFFICACY);
}

void ps_sky_radiance(const struct ps_sky *s, const double d[3], unsigned parts, double rgb[3])
{
	rgb[0] = rgb[1] = rgb[2] = 0.0;
	if (s->dark)
		return;
	if (d[2] > 0) {
		double l;
		if (!(parts & PS_SKY_DIFFUSE) || ps_sky_bright(s->opt.sky_color) <= SKY_DARK ||
		    s->norm == 0.0)
			return;
		l = (s->norm < 0 ? 1.0 : ps_perez_rel_dir(&s->model, d, s->model_sun)) * diffuse_scale(s);
		for (int c = 0; c < 3; c++)
			rgb[c] = l * s->opt.sky_color[c];
	} else if (parts & PS_SKY_GROUND) {
		for (int c = 0; c < 3; c++)
			rgb[c] = s->ground_rad[c];
	}
}

void ps_sky_sun(const struct ps_sky *s, double dir[3], double rgb[3])
{
	double v = 0.0;
	memcpy(dir, s->sun_dir, 3 * sizeof *dir);
	if (!s->dark && s->dir_lum > SKY_DARK && ps_sky_bright(s->opt.sun_color) > SKY_DARK)
		v = s->dir_lum / PS_WHITE_EFFICACY;
	for (int c = 0; c < 3; c++)
		rgb[c] = v * s->opt.sun_color[c];
}

int ps_sky_integrate(const struct ps_sky *s, const double coef[3], ps_sky_weight_fn weight,
                     void *ctx, const double *zb, int nzb, const double *ab, int nab,
                     double reltol, struct ps_quad *r, struct ps_err *e)
{
	double k;
	memset(r, 0, sizeof *r);
	if (s->dark) {
		r->converged = 1;
		return 0;
	}
	if (s->norm == 0.0)
		return ps_err_set(e, PS_EINVAL, "the continuous sky is not normalised (ps_sky_normalise)");
	k = (coef[0] * s->opt.sky_color[0] + coef[1] * s->opt.sky_color[1] +
	     coef[2] * s->opt.sky_color[2]) * diffuse_scale(s);
	if (ps_sky_bright(s->opt.sky_color) <= SKY_DARK)
		k = 0.0;
	hemi_integrate(s, weight, ctx, s->norm < 0, zb, nzb, ab, nab, reltol, r);
	r->value *= k;
	r->error *= fabs(k);
	if (!r->converged)
		return ps_err_set(e, PS_ERANGE, "sky integral did not reach %g (error %g of %g)", reltol,
		                  r->error, r->value);
	return 0;
}
