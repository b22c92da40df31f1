/* SPDX-License-Identifier: ISC */
#include "placeset.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dcset.h"
#include "integrate.h"
#include "picture.h"
#include "rescan.h"
#include "weights.h"

#define LINE 4096

int psd_placeset_read(struct search *s, char *err, size_t errlen)
{
	FILE *fp = fopen(s->o->cands, "r");
	char line[LINE];
	int ln = 0;
	if (!fp)
		return snprintf(err, errlen, "%s: %s", s->o->cands, strerror(errno)), -1;
	while (fgets(line, sizeof line, fp)) {
		char *p = line + strspn(line, " \t"), *q;
		struct pose *np;
		struct ps_err e;
		ln++;
		p[strcspn(p, "\r\n")] = 0;
		if (!*p || *p == '#')
			continue;
		q = p + strcspn(p, " \t");
		if (!*q || (size_t)(q - p) >= sizeof np->id) {
			fclose(fp);
			return snprintf(err, errlen, "%s:%d: expected an id and a view", s->o->cands, ln), -1;
		}
		np = realloc(s->poses, (size_t)(s->nposes + 1) * sizeof *np);
		if (!np) {
			fclose(fp);
			return snprintf(err, errlen, "out of memory"), -1;
		}
		s->poses = np;
		np = &s->poses[s->nposes];
		memset(np, 0, sizeof *np);
		ps_view_default(&np->view);   /* what a candidate's line leaves out: Radiance's defaults */
		memcpy(np->id, p, (size_t)(q - p));
		q += strspn(q, " \t");
		snprintf(np->view_text, sizeof np->view_text, "%s", q);
		{
			char where[600];
			snprintf(where, sizeof where, "%s:%d", s->o->cands, ln);
			if (ps_view_parse(&np->view, q, where, &e) != 0) {
				fclose(fp);
				return snprintf(err, errlen, "%s", e.msg), -1;
			}
		}
		s->nposes++;
	}
	fclose(fp);
	if (!s->nposes)
		return snprintf(err, errlen, "%s: no candidate", s->o->cands), -1;
	return 0;
}

/* one more pose: id and view text (parsed onto Radiance's defaults) */
static int add_pose(struct search *s, const char *id, const char *view, const char *where, char *err, size_t errlen)
{
	struct pose *np = realloc(s->poses, (size_t)(s->nposes + 1) * sizeof *np);
	struct ps_err e;
	if (!np)
		return snprintf(err, errlen, "out of memory"), -1;
	s->poses = np;
	np = &s->poses[s->nposes];
	memset(np, 0, sizeof *np);
	ps_view_default(&np->view);
	snprintf(np->id, sizeof np->id, "%s", id);
	snprintf(np->view_text, sizeof np->view_text, "%s", view);
	if (ps_view_parse(&np->view, view, where, &e) != 0)
		return snprintf(err, errlen, "%s", e.msg), -1;
	s->nposes++;
	return 0;
}

static int numbers(const char *text, double *v, int n)
{
	int k = 0;
	while (k < n) {
		char *end;
		v[k] = strtod(text, &end);
		if (end == text || !isfinite(v[k]))
			return -1;
		k++;
		text = end;
		if (k < n && *text++ != ',')
			return -1;
	}
	return *text ? -1 : 0;
}

int psd_placeset_grid(struct search *s, char *err, size_t errlen)
{
	const char *aims = s->o->aims ? s->o->aims : "down";
	double g[7], tilt[32], az[32];
	int naim = 0, nx, ny;
	if (numbers(s->o->ceiling, g, 7) != 0 || g[2] < 1 || g[5] < 1 || g[2] > 100 || g[5] > 100 ||
	    g[2] != floor(g[2]) || g[5] != floor(g[5]))
		return snprintf(err, errlen, "--ceiling %s: expected X0,X1,NX,Y0,Y1,NY,Z (NX and NY 1 to 100)",
		                s->o->ceiling), -1;
	nx = (int)g[2];
	ny = (int)g[5];
	for (const char *a = aims; *a;) {
		size_t n = strcspn(a, ",");
		char w[64];
		snprintf(w, sizeof w, "%.*s", (int)(n < sizeof w ? n : sizeof w - 1), a);
		if (naim == 32)
			return snprintf(err, errlen, "--aims %s: at most 32 aims", aims), -1;
		if (!strcmp(w, "down")) {
			tilt[naim] = az[naim] = 0;
		} else {
			char *at = strchr(w, '@'), *end;
			if (!at)
				return snprintf(err, errlen, "--aims: '%s' is not down or TILT@AZIMUTH", w), -1;
			*at = 0;
			tilt[naim] = strtod(w, &end);
			if (end == w || *end || !(tilt[naim] >= 0 && tilt[naim] < 90))
				return snprintf(err, errlen, "--aims: tilt '%s' is not 0 to below 90 degrees", w), -1;
			az[naim] = strtod(at + 1, &end);
			if (end == at + 1 || *end || !isfinite(az[naim]))
				return snprintf(err, errlen, "--aims: azimuth '%s' is not a number", at + 1), -1;
		}
		naim++;
		a += n + (a[n] == ',');
	}
	if (!naim)
		return snprintf(err, errlen, "--aims: no aim"), -1;
	for (int j = 0; j < ny; j++)
		for (int i = 0; i < nx; i++)
			for (int k = 0; k < naim; k++) {
				double x = nx > 1 ? g[0] + (g[1] - g[0]) * i / (nx - 1) : g[0];
				double y = ny > 1 ? g[3] + (g[4] - g[3]) * j / (ny - 1) : g[3];
				double t = tilt[k] * M_PI / 180, a = az[k] * M_PI / 180;
				double hx = sin(a), hy = cos(a), d[3], u[3];
				char id[64], view[400];
				if (tilt[k] == 0) {
					/* straight down, +y up in the picture */
					d[0] = d[1] = 0, d[2] = -1;
					u[0] = 0, u[1] = 1, u[2] = 0;
				} else {
					/* tilted: +x up in the picture, +y when it tilts along x */
					d[0] = sin(t) * hx, d[1] = sin(t) * hy, d[2] = -cos(t);
					if (fabs(hy) < 1e-9)
						u[0] = 0, u[1] = 1, u[2] = 0;
					else
						u[0] = 1, u[1] = 0, u[2] = 0;
				}
				snprintf(id, sizeof id, naim > 1 ? "g%02d-%d" : "g%02d", j * nx + i, k + 1);
				snprintf(view, sizeof view, "-vta -vp %.10g %.10g %.10g -vd %.10g %.10g %.10g -vu %g %g %g "
				         "-vh 180 -vv 180", x, y, g[6], fabs(d[0]) < 1e-12 ? 0 : d[0], fabs(d[1]) < 1e-12 ? 0 : d[1],
				         d[2], u[0], u[1], u[2]);
				if (add_pose(s, id, view, "--ceiling", err, errlen) != 0)
					return -1;
			}
	return 0;
}

/* a pose's picture: the rendered one in the cache, else DIR/id/name */
static void pose_path(const struct search *s, const struct pose *p, const char *name, char *out, size_t n)
{
	if (p->dcdir[0] && !strncmp(name, "dc_", 3))
		snprintf(out, n, "%s/%s", p->dcdir, name);
	else if (p->elecfile[0] && !strncmp(name, "elec", 4))
		snprintf(out, n, "%s", p->elecfile);
	else
		snprintf(out, n, "%s/%s/%s", s->o->dir, p->id, name);
}

int psd_placeset_elec_read(const struct search *s, const struct pose *p, struct ps_picture *pic, char *err,
                           size_t errlen)
{
	char path[LINE + 128], alt[LINE + 128];
	struct ps_err e, e2;
	pose_path(s, p, "elec.hdr", path, sizeof path);
	if (ps_picture_read(pic, path, &e) == 0)
		return 0;
	pose_path(s, p, "elec_128.hdr", alt, sizeof alt);
	if (ps_picture_read(pic, alt, &e2) == 0)
		return 0;
	return snprintf(err, errlen, "candidate %s: no electric picture: %s", p->id, e.msg), -1;
}

/* The pose's pictures, in memory: npatch coefficient pictures and the
 * electric one.  Every error names the candidate. */
static int load_pictures(const struct search *s, const struct pose *p, struct ps_picture *pics,
                         struct ps_picture *elec, char *err, size_t errlen)
{
	char path[LINE + 128];
	struct ps_err e;
	int i;
	memset(pics, 0, (size_t)s->npatch * sizeof *pics);
	memset(elec, 0, sizeof *elec);
	for (i = 0; i < s->npatch; i++) {
		char name[32];
		snprintf(name, sizeof name, "dc_%03d.hdr", i);
		pose_path(s, p, name, path, sizeof path);
		if (ps_picture_read(&pics[i], path, &e) != 0) {
			snprintf(err, errlen, "candidate %s: patch %d of %d: %s", p->id, i, s->npatch, e.msg);
			goto bad;
		}
		if (pics[i].width != pics[0].width || pics[i].height != pics[0].height) {
			snprintf(err, errlen, "candidate %s: %.600s is %d x %d where dc_000.hdr is %d x %d: a mismatched set",
			         p->id, path, pics[i].width, pics[i].height, pics[0].width, pics[0].height);
			i++;
			goto bad;
		}
	}
	{
		char name[32];
		snprintf(name, sizeof name, "dc_%03d.hdr", s->npatch);
		pose_path(s, p, name, path, sizeof path);
		FILE *fp = fopen(path, "rb");
		if (fp) {
			fclose(fp);
			snprintf(err, errlen, "candidate %s: %.600s exists: more pictures than the grid's %d patches (MF %d)",
			         p->id, path, s->npatch, s->mf);
			goto bad;
		}
	}
	if (psd_placeset_elec_read(s, p, elec, err, errlen) != 0)
		goto bad;
	return 0;
bad:
	for (int k = 0; k < i && k < s->npatch; k++)
		ps_picture_free(&pics[k]);
	return -1;
}

/* cells: cell_theta degrees in polar angle; in azimuth the rotation step
 * split into whole cells of at most 10 degrees */
static double cell_phi(const struct search *s)
{
	double step = 360.0 / s->o->nrot;
	return step / ceil(step / 10.0 - 1e-9);
}

/* project one picture per colour channel and read every sensor at every
 * rotation: out[(r nsens + k) stride + c].  tab[nsens]: the sensors'
 * sensitivity on the cells, made at the first projection (tab[0].nphi 0)
 * and read by every later one (the pose's cells are the same for all its
 * pictures) */
static int scan_picture(const struct search *s, const struct ps_weights *om, const struct ps_picture *pic,
                        const struct ps_view *v, struct ps_rescan_sens *tab, double *out, size_t stride,
                        char *err, size_t errlen)
{
	static const double unit[3][3] = { { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
	struct ps_err e;
	struct ps_rescan pr[3];
	double *tmp = malloc((size_t)s->o->nrot * sizeof *tmp);
	int rc = 0;
	if (!tmp)
		return snprintf(err, errlen, "out of memory"), -1;
	/* the three channels projected together (each pixel's direction once) */
	if (ps_rescan_project_many(pr, 3, unit, om, pic, v, s->cell_theta, cell_phi(s), 0, s->theta_max, &e) != 0) {
		free(tmp);
		return snprintf(err, errlen, "%s", e.msg), -1;
	}
	for (int k = 0, first = tab[0].nphi == 0; k < s->o->nsens && first && !rc; k++)
		if (ps_rescan_sens_init(&tab[k], &pr[0], &s->sens[k], 0, &e) != 0) {
			for (int j = 0; j < k; j++)
				ps_rescan_sens_free(&tab[j]);
			rc = -1;
		}
	for (int c = 0; c < 3 && !rc; c++)
		for (int k = 0; k < s->o->nsens && !rc; k++) {
			if (ps_rescan_scan_sens(&pr[c], &tab[k], 360.0 / s->o->nrot, s->o->nrot, 1, tmp, &e) != 0) {
				rc = -1;
				break;
			}
			for (int r = 0; r < s->o->nrot; r++)
				out[((size_t)r * (size_t)s->o->nsens + (size_t)k) * stride + (size_t)c] = tmp[r];
		}
	for (int c = 0; c < 3; c++)
		ps_rescan_free(&pr[c]);
	free(tmp);
	if (rc)
		snprintf(err, errlen, "%s", e.msg);
	return rc;
}

int psd_placeset_project(struct search *s, struct pose *p, char *err, size_t errlen)
{
	struct ps_picture *pics = calloc((size_t)s->npatch, sizeof *pics), elec;
	struct ps_sensor uni;
	struct ps_weights om, ome;
	struct ps_rescan_sens *tab = calloc((size_t)s->o->nsens, sizeof *tab);
	struct ps_err e;
	int rc = -1;
	size_t nrs = (size_t)s->o->nrot * (size_t)s->o->nsens;
	if (!pics || !tab) {
		free(pics);
		free(tab);
		return snprintf(err, errlen, "out of memory"), -1;
	}
	if (load_pictures(s, p, pics, &elec, err, errlen) != 0) {
		free(pics);
		free(tab);
		return -1;
	}
	p->row = calloc(nrs * (size_t)s->npatch * 3, sizeof *p->row);
	p->elec = calloc(nrs, sizeof *p->elec);
	memset(&om, 0, sizeof om);
	memset(&ome, 0, sizeof ome);
	if (!p->row || !p->elec || ps_sensor_builtin(&uni, PS_SENS_UNIFORM, &e) != 0) {
		snprintf(err, errlen, "out of memory");
		goto out;
	}
	if (ps_weights_build(&om, &uni, 0, &p->view, pics[0].width, pics[0].height, PS_W_EXACT, &e) != 0 ||
	    ps_weights_build(&ome, &uni, 0, &p->view, elec.width, elec.height, PS_W_EXACT, &e) != 0) {
		snprintf(err, errlen, "candidate %s: %s", p->id, e.msg);
		ps_sensor_free(&uni);
		goto out;
	}
	ps_sensor_free(&uni);
	for (int i = 0; i < s->npatch; i++) {
		/* row[((r nsens + k) npatch + i) 3 + c] */
		double *tmp = malloc(nrs * 3 * sizeof *tmp);
		if (!tmp) {
			snprintf(err, errlen, "out of memory");
			goto out;
		}
		if (scan_picture(s, &om, &pics[i], &p->view, tab, tmp, 3, err, errlen) != 0) {
			free(tmp);
			goto out;
		}
		for (size_t rk = 0; rk < nrs; rk++)
			for (int c = 0; c < 3; c++)
				p->row[(rk * (size_t)s->npatch + (size_t)i) * 3 + (size_t)c] = tmp[rk * 3 + (size_t)c];
		free(tmp);
	}
	{
		/* the electric picture per channel, weighed by each sensor's colour weights */
		double *tmp = malloc(nrs * 3 * sizeof *tmp);
		if (!tmp) {
			snprintf(err, errlen, "out of memory");
			goto out;
		}
		if (scan_picture(s, &ome, &elec, &p->view, tab, tmp, 3, err, errlen) != 0) {
			free(tmp);
			goto out;
		}
		for (size_t rk = 0; rk < nrs; rk++) {
			const double *w = s->o->coef[rk % (size_t)s->o->nsens];
			p->elec[rk] = w[0] * tmp[rk * 3] + w[1] * tmp[rk * 3 + 1] + w[2] * tmp[rk * 3 + 2];
		}
		free(tmp);
	}
	rc = 0;
out:
	for (int k = 0; k < s->o->nsens; k++)
		ps_rescan_sens_free(&tab[k]);
	free(tab);
	ps_weights_free(&om);
	ps_weights_free(&ome);
	for (int i = 0; i < s->npatch; i++)
		ps_picture_free(&pics[i]);
	ps_picture_free(&elec);
	free(pics);
	return rc;
}

/* The exact route for one pose, sensor and rotation: the coefficient row
 * (npatch x 3, ps_dcset_row) and the electric response. */
int psd_placeset_exact(const struct search *s, const struct pose *p, int k, double rot, double *row, double *elec,
                     char *err, size_t errlen)
{
	char pattern[LINE + 128];
	struct ps_dcset_row dr;
	struct ps_picture ep;
	struct ps_weights we;
	struct ps_response r;
	struct ps_err e;
	pose_path(s, p, "dc_%03d.hdr", pattern, sizeof pattern);
	if (ps_dcset_row(pattern, &p->view, s->mf, &s->sens[k], rot, &dr, &e) != 0)
		return snprintf(err, errlen, "candidate %s: %s", p->id, e.msg), -1;
	memcpy(row, dr.c, (size_t)dr.n * 3 * sizeof *row);
	ps_dcset_row_free(&dr);
	if (psd_placeset_elec_read(s, p, &ep, err, errlen) != 0)
		return -1;
	if (ps_weights_build(&we, &s->sens[k], rot, &p->view, ep.width, ep.height, PS_W_EXACT, &e) != 0) {
		ps_picture_free(&ep);
		return snprintf(err, errlen, "candidate %s: %s", p->id, e.msg), -1;
	}
	if (ps_integrate(&we, &ep, s->o->coef[k], &r, &e) != 0) {
		ps_weights_free(&we);
		ps_picture_free(&ep);
		return snprintf(err, errlen, "candidate %s: %s", p->id, e.msg), -1;
	}
	*elec = r.response;
	ps_weights_free(&we);
	ps_picture_free(&ep);
	return 0;
}

