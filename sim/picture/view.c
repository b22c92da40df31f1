/* SPDX-License-Identifier: ISC */
#include "view.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void ps_view_default(struct ps_view *v)
{
	memset(v, 0, sizeof *v);
	v->type = PS_VT_PERSP;
	v->vd[1] = 1.0;
	v->vu[2] = 1.0;
	v->vh = 45.0;
	v->vv = 45.0;
}

void ps_view_default_fisheye(struct ps_view *v)
{
	ps_view_default(v);
	v->type = PS_VT_ANGULAR;
	v->vd[0] = 0.0;
	v->vd[1] = 0.0;
	v->vd[2] = -1.0;
	v->vu[1] = 1.0;
	v->vu[2] = 0.0;
	v->vh = 180.0;
	v->vv = 180.0;
}

/* Next whitespace-separated word of *s into buf; 0 at the end. */
static int next_word(const char **s, char *buf, size_t len)
{
	const char *p = *s;
	size_t n;
	while (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r')
		p++;
	if (!*p)
		return 0;
	n = strcspn(p, " \t\n\r");
	if (n >= len)
		n = len - 1;
	memcpy(buf, p, n);
	buf[n] = '\0';
	p += strcspn(p, " \t\n\r");
	*s = p;
	return 1;
}

static int read_numbers(const char **s, double *out, int n, const char *opt, const char *where,
                        struct ps_err *e)
{
	char w[128];
	for (int i = 0; i < n; i++) {
		char *end;
		if (!next_word(s, w, sizeof w))
			return ps_err_set(e, PS_EFORMAT, "%s: %s needs %d number%s", where, opt, n,
			                  n > 1 ? "s" : "");
		errno = 0;
		out[i] = strtod(w, &end);
		if (end == w || *end || errno == ERANGE || !isfinite(out[i]))
			return ps_err_set(e, PS_EFORMAT, "%s: %s: '%s' is not a number", where, opt, w);
	}
	return 0;
}

int ps_view_parse(struct ps_view *v, const char *text, const char *where, struct ps_err *e)
{
	const char *s = text;
	char w[128];
	struct ps_view nv = *v;   /* all or nothing */
	while (next_word(&s, w, sizeof w)) {
		if (w[0] != '-' || w[1] != 'v')
			continue;
		switch (w[2]) {
		case 't':
			if (!w[3] || w[4] || !strchr("vlahcsr", w[3]))
				return ps_err_set(e, PS_EFORMAT, "%s: unknown view type '%s'", where, w);
			nv.type = w[3];
			break;
		case 'p':
		case 'd':
		case 'u':
			if (w[3])
				goto unknown;
			if (read_numbers(&s, w[2] == 'p' ? nv.vp : w[2] == 'd' ? nv.vd : nv.vu, 3, w,
			                 where, e) != 0)
				return -1;
			break;
		case 'h':
		case 'v':
		case 's':
		case 'l':
		case 'o':
		case 'a': {
			double *dst = w[2] == 'h' ? &nv.vh : w[2] == 'v' ? &nv.vv : w[2] == 's' ? &nv.vs
			            : w[2] == 'l' ? &nv.vl : w[2] == 'o' ? &nv.vo : &nv.va;
			if (w[3])
				goto unknown;
			if (read_numbers(&s, dst, 1, w, where, e) != 0)
				return -1;
			break;
		}
		default:
		unknown:
			/* -vf (view file) and anything else: ignored, as the issue asks */
			break;
		}
	}
	*v = nv;
	return 0;
}

int ps_view_check_fisheye(const struct ps_view *v, const char *where, struct ps_err *e)
{
	double dd = v->vd[0] * v->vd[0] + v->vd[1] * v->vd[1] + v->vd[2] * v->vd[2];
	double uu = v->vu[0] * v->vu[0] + v->vu[1] * v->vu[1] + v->vu[2] * v->vu[2];
	double cx = v->vd[1] * v->vu[2] - v->vd[2] * v->vu[1];
	double cy = v->vd[2] * v->vu[0] - v->vd[0] * v->vu[2];
	double cz = v->vd[0] * v->vu[1] - v->vd[1] * v->vu[0];
	if (v->type != PS_VT_ANGULAR && v->type != PS_VT_HEMI)
		return ps_err_set(e, PS_EUNSUPPORTED,
		                  "%s: view type -vt%c is not a fisheye (psens needs -vta or -vth)", where,
		                  v->type);
	if (dd <= 0.0)
		return ps_err_set(e, PS_ERANGE, "%s: -vd is a zero vector", where);
	if (uu <= 0.0 || cx * cx + cy * cy + cz * cz <= 1e-12 * dd * uu)
		return ps_err_set(e, PS_ERANGE, "%s: -vu is zero or parallel to -vd", where);
	if (!(v->vh > 0.0) || !(v->vv > 0.0) ||
	    v->vh > (v->type == PS_VT_ANGULAR ? 360.0 : 180.0) ||
	    v->vv > (v->type == PS_VT_ANGULAR ? 360.0 : 180.0))
		return ps_err_set(e, PS_ERANGE, "%s: -vh %g -vv %g outside what -vt%c allows (0 to %d)",
		                  where, v->vh, v->vv, v->type, v->type == PS_VT_ANGULAR ? 360 : 180);
	if (!isfinite(v->vs) || !isfinite(v->vl) || fabs(v->vs) > 10 || fabs(v->vl) > 10)
		return ps_err_set(e, PS_ERANGE, "%s: -vs %g -vl %g out of range", where, v->vs, v->vl);
	return 0;
}

void ps_view_format(const struct ps_view *v, char *buf, size_t len)
{
	snprintf(buf, len, "-vt%c -vp %.17g %.17g %.17g -vd %.17g %.17g %.17g -vu %.17g %.17g %.17g "
	         "-vh %.17g -vv %.17g -vo %.17g -va %.17g -vs %.17g -vl %.17g",
	         v->type, v->vp[0], v->vp[1], v->vp[2], v->vd[0], v->vd[1], v->vd[2], v->vu[0], v->vu[1],
	         v->vu[2], v->vh, v->vv, v->vo, v->va, v->vs, v->vl);
}
