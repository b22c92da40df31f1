/* SPDX-License-Identifier: ISC */
#include "regions.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fisheye.h"

#define DEG (M_PI / 180.0)

int ps_regions_group_parse(const char *name)
{
	if (strcmp(name, "auto") == 0)
		return PS_GROUP_AUTO;
	if (strcmp(name, "name") == 0)
		return PS_GROUP_NAME;
	if (strcmp(name, "material") == 0)
		return PS_GROUP_MATERIAL;
	return -1;
}

/* the identifier without genbox's ".1540" */
static size_t base_len(const char *s)
{
	size_t n = strlen(s), k = n;
	while (k > 0 && isdigit((unsigned char)s[k - 1]))
		k--;
	if (k > 0 && k < n && s[k - 1] == '.')
		return k - 1;
	return n;
}

/* the first word of the base (up to '_'), 0 when there is none */
static size_t word_len(const char *s, size_t base)
{
	const char *u = memchr(s, '_', base);
	return u && u > s ? (size_t)(u - s) : 0;
}

static int find_label(char **labels, int n, const char *s, size_t len)
{
	for (int i = 0; i < n; i++)
		if (strlen(labels[i]) == len && memcmp(labels[i], s, len) == 0)
			return i;
	return -1;
}

int ps_regions_groups(const struct ps_radgeom *g, int group, char ***labels, int *nlabels,
                      int **of_poly, struct ps_err *e)
{
	char **lab = calloc(g->npoly + 1, sizeof *lab);
	int *of = calloc(g->npoly + 1, sizeof *of), n = 0;
	if (!lab || !of)
		goto nomem;
	for (size_t i = 0; i < g->npoly; i++) {
		const char *s = group == PS_GROUP_MATERIAL ? g->poly[i].material : g->poly[i].name;
		size_t len = group == PS_GROUP_MATERIAL ? strlen(s) : base_len(s);
		if (group == PS_GROUP_AUTO) {
			size_t w = word_len(s, len);
			/* shared: another surface with another base has the same first word */
			for (size_t j = 0; w && j < g->npoly; j++) {
				const char *o = g->poly[j].name;
				size_t ob = base_len(o);
				if (word_len(o, ob) == w && memcmp(o, s, w) == 0 &&
				    (ob != len || memcmp(o, s, len) != 0)) {
					len = w;
					break;
				}
			}
		}
		of[i] = find_label(lab, n, s, len);
		if (of[i] < 0) {
			if (!(lab[n] = strndup(s, len)))
				goto nomem;
			of[i] = n++;
		}
	}
	*labels = lab;
	*nlabels = n;
	*of_poly = of;
	return 0;
nomem:
	for (int i = 0; lab && i < n; i++)
		free(lab[i]);
	free(lab);
	free(of);
	return ps_err_set(e, PS_ENOMEM, "out of memory");
}

static void cross(const double a[3], const double b[3], double c[3])
{
	c[0] = a[1] * b[2] - a[2] * b[1];
	c[1] = a[2] * b[0] - a[0] * b[2];
	c[2] = a[0] * b[1] - a[1] * b[0];
}

static void unit(double a[3])
{
	double l = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
	for (int k = 0; k < 3; k++)
		a[k] /= l;
}

/* The world direction of plane point (u, v) of a fisheye view (unit length);
 * -1 outside the field. */
static int ps_regions_ray(const struct ps_view *v, int type, double u, double w, double dir[3])
{
	double d[3] = { v->vd[0], v->vd[1], v->vd[2] }, h[3], up[3], rho = hypot(u, w), th, s;
	struct ps_fisheye f;
	if (rho > 1.0)
		return -1;
	f.type = type;
	f.theta_field = type == PS_VT_HEMI ? M_PI / 2 : M_PI;
	th = ps_fisheye_theta(&f, rho);
	unit(d);
	cross(d, v->vu, h);
	unit(h);
	cross(h, d, up);
	unit(up);
	s = rho > 0 ? sin(th) / rho : 0.0;
	for (int k = 0; k < 3; k++)
		dir[k] = cos(th) * d[k] + s * (u * h[k] + w * up[k]);
	return 0;
}

/* a labelling rule: the label of a direction's sample */
struct classify {
	const struct ps_radgeom *g;
	const int *of_poly;
	int nothing;          /* label for a miss (-1 until needed) */
	const struct ps_view *v;
	int *nlabels;
	char ***labels;
	int sectors;
};

static int add_label(char ***labels, int *n, const char *name)
{
	char **nl = realloc(*labels, (size_t)(*n + 1) * sizeof *nl);
	if (!nl)
		return -1;
	*labels = nl;
	if (!(nl[*n] = strdup(name)))
		return -1;
	return (*n)++;
}

static int classify(struct classify *c, int type, double u, double w)
{
	double dir[3];
	if (ps_regions_ray(c->v, type, u, w, dir) != 0)
		return -2;
	if (c->sectors) {
		struct ps_fisheye f;
		double rho = hypot(u, w), th, phi;
		int band, quad;
		f.type = type;
		f.theta_field = type == PS_VT_HEMI ? M_PI / 2 : M_PI;
		th = ps_fisheye_theta(&f, rho) / DEG;
		phi = atan2(w, u) / DEG - 90.0;   /* sensor azimuth: 0 up, growing to the left */
		phi = fmod(phi + 45.0 + 720.0, 360.0);
		band = th < 30 ? 0 : th < 60 ? 1 : th < 90 ? 2 : 3;
		quad = (int)(phi / 90.0) & 3;
		return 4 * band + quad;
	}
	{
		long hit = ps_radgeom_trace(c->g, c->v->vp, dir, NULL);
		if (hit >= 0)
			return c->of_poly[hit];
		if (c->nothing < 0)
			c->nothing = add_label(c->labels, c->nlabels, "(nothing)");
		return c->nothing < 0 ? -3 : c->nothing;
	}
}

static int label_view(struct ps_regions *r, struct classify *c, const struct ps_view *v, int width,
                      int height, int sub, struct ps_err *e)
{
	struct ps_fisheye f;
	size_t npix = (size_t)width * (size_t)height, cap;
	int *lab = malloc((size_t)sub * (size_t)sub * sizeof *lab);
	double *wt = malloc((size_t)sub * (size_t)sub * sizeof *wt);
	if (v->type != PS_VT_ANGULAR && v->type != PS_VT_HEMI) {
		free(lab);
		free(wt);
		return ps_err_set(e, PS_EUNSUPPORTED, "view type -vt%c is not a fisheye (-vta or -vth)",
		                  v->type);
	}
	ps_fisheye_init(&f, v, width, height);
	r->width = width;
	r->height = height;
	r->sub = sub;
	r->major = malloc(npix * sizeof *r->major);
	r->off = malloc((npix + 1) * sizeof *r->off);
	cap = npix + 64;
	r->part = malloc(cap * sizeof *r->part);
	if (!lab || !wt || !r->major || !r->off || !r->part)
		goto nomem;
	r->npart = 0;
	for (int row = 0; row < height; row++)
		for (int x = 0; x < width; x++) {
			size_t p = (size_t)row * (size_t)width + (size_t)x;
			int n = 0;
			double tot = 0, best = 0;
			r->off[p] = r->npart;
			r->major[p] = -1;
			for (int j = 0; j < sub; j++)
				for (int i = 0; i < sub; i++) {
					double u = ps_fisheye_u(&f, x + (i + 0.5) / sub);
					double w = ps_fisheye_v(&f, height - row - 1 + (j + 0.5) / sub);
					double jac = ps_fisheye_jacobian(&f, hypot(u, w));
					int l, k;
					if (!(jac > 0) || !isfinite(jac))
						continue;
					l = classify(c, v->type, u, w);
					if (l == -2)
						continue;
					if (l < 0)
						goto nomem;
					for (k = 0; k < n && lab[k] != l; k++)
						;
					if (k == n) {
						lab[n] = l;
						wt[n++] = 0;
					}
					wt[k] += jac;
					tot += jac;
				}
			if (n == 0) {
				/* no sample fell in the field: a sliver at its edge.  Its
				 * point nearest the centre (just inside) stands for it, so
				 * that every pixel with solid angle has a label */
				double u0 = ps_fisheye_u(&f, x), u1 = ps_fisheye_u(&f, x + 1);
				double w0 = ps_fisheye_v(&f, height - row - 1), w1 = ps_fisheye_v(&f, height - row);
				double u = u0 > 0 ? u0 : u1 < 0 ? u1 : 0, w = w0 > 0 ? w0 : w1 < 0 ? w1 : 0;
				double rho = hypot(u, w);
				if (rho < 1.0) {
					int l;
					if (rho > 1 - 1e-9) {
						u *= (1 - 1e-9) / rho;
						w *= (1 - 1e-9) / rho;
					}
					l = classify(c, v->type, u, w);
					if (l == -2)
						goto next;
					if (l < 0)
						goto nomem;
					lab[n] = l;
					wt[n++] = 1;
					tot = 1;
				}
			}
		next:
			for (int k = 0; k < n; k++) {
				if (r->npart == cap) {
					struct ps_region_part *np;
					cap *= 2;
					np = realloc(r->part, cap * sizeof *np);
					if (!np)
						goto nomem;
					r->part = np;
				}
				r->part[r->npart].label = lab[k];
				r->part[r->npart++].frac = wt[k] / tot;
				if (wt[k] > best) {
					best = wt[k];
					r->major[p] = lab[k];
				}
			}
		}
	r->off[npix] = r->npart;
	free(lab);
	free(wt);
	return 0;
nomem:
	free(lab);
	free(wt);
	return ps_err_set(e, PS_ENOMEM, "out of memory labelling %d x %d pixels", width, height);
}

static int check_args(int width, int height, int sub, struct ps_err *e)
{
	if (width < 1 || height < 1 || width > 16384 || height > 16384)
		return ps_err_set(e, PS_ERANGE, "%d x %d pixels: 1 to 16384 a side", width, height);
	if (sub < 1 || sub > 16)
		return ps_err_set(e, PS_ERANGE, "%d samples a side per pixel: 1 to 16", sub);
	return 0;
}

int ps_regions_geometry(struct ps_regions *r, const struct ps_radgeom *g, int group,
                        const struct ps_view *v, int width, int height, int sub, struct ps_err *e)
{
	struct classify c;
	int *of = NULL;
	memset(r, 0, sizeof *r);
	if (check_args(width, height, sub, e) != 0)
		return -1;
	if (ps_regions_groups(g, group, &r->label, &r->nlabels, &of, e) != 0)
		return -1;
	memset(&c, 0, sizeof c);
	c.g = g;
	c.of_poly = of;
	c.nothing = -1;
	c.v = v;
	c.labels = &r->label;
	c.nlabels = &r->nlabels;
	if (label_view(r, &c, v, width, height, sub, e) != 0) {
		free(of);
		ps_regions_free(r);
		return -1;
	}
	free(of);
	return 0;
}

int ps_regions_sectors(struct ps_regions *r, const struct ps_view *v, int width, int height,
                       int sub, struct ps_err *e)
{
	static const char *const band[4] = { "0-30", "30-60", "60-90", "beyond 90" };
	static const char *const quad[4] = { "up", "left", "down", "right" };
	struct classify c;
	memset(r, 0, sizeof *r);
	if (check_args(width, height, sub, e) != 0)
		return -1;
	r->sectors = 1;
	for (int b = 0; b < 4; b++)
		for (int q = 0; q < 4; q++) {
			char name[64];
			snprintf(name, sizeof name, "%s\xc2\xb0 %s", band[b], quad[q]);
			if (add_label(&r->label, &r->nlabels, name) < 0) {
				ps_regions_free(r);
				return ps_err_set(e, PS_ENOMEM, "out of memory");
			}
		}
	memset(&c, 0, sizeof c);
	c.v = v;
	c.sectors = 1;
	c.nothing = -1;
	if (label_view(r, &c, v, width, height, sub, e) != 0) {
		ps_regions_free(r);
		return -1;
	}
	return 0;
}

void ps_regions_free(struct ps_regions *r)
{
	for (int i = 0; i < r->nlabels; i++)
		free(r->label[i]);
	free(r->label);
	free(r->major);
	free(r->off);
	free(r->part);
	memset(r, 0, sizeof *r);
}
