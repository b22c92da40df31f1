/* SPDX-License-Identifier: ISC */
#include "radgeom.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fileio.h"

#define TOKEN_MAX 256
#define COMMAND_MAX 65536
#define DEG (M_PI / 180.0)

struct lex {
	const char *p, *end, *name;
	int line;
};

/* an affine map x -> m x + t */
struct xf {
	double m[3][3], t[3];
};

static int is_space(char c)
{
	return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
}

static void skip_space(struct lex *l)
{
	while (l->p < l->end && is_space(*l->p)) {
		if (*l->p == '\n')
			l->line++;
		l->p++;
	}
}

/* The next word into buf: 0, 1 at the end of the input, -1 when too long. */
static int next_word(struct lex *l, char *buf, struct ps_err *e)
{
	size_t n = 0;
	skip_space(l);
	if (l->p >= l->end)
		return 1;
	while (l->p < l->end && !is_space(*l->p)) {
		if (n + 1 >= TOKEN_MAX)
			return ps_err_set(e, PS_EFORMAT, "%s:%d: a word longer than %d bytes", l->name, l->line,
			                  TOKEN_MAX - 1);
		buf[n++] = *l->p++;
	}
	buf[n] = '\0';
	return 0;
}

static int parse_double(const char *s, double *out)
{
	char *end;
	errno = 0;
	*out = strtod(s, &end);
	return end != s && !*end && errno != ERANGE && isfinite(*out) ? 0 : -1;
}

static int parse_count(const char *s, long *out)
{
	char *end;
	errno = 0;
	*out = strtol(s, &end, 10);
	return end != s && !*end && errno != ERANGE && *out >= 0 ? 0 : -1;
}

void ps_radgeom_init(struct ps_radgeom *g)
{
	memset(g, 0, sizeof *g);
}

void ps_radgeom_free(struct ps_radgeom *g)
{
	for (size_t i = 0; i < g->npoly; i++) {
		free(g->poly[i].name);
		free(g->poly[i].material);
		free(g->poly[i].v);
	}
	free(g->poly);
	for (int i = 0; i < g->nfiles; i++)
		free(g->files[i]);
	free(g->files);
	memset(g, 0, sizeof *g);
}

/* Add a polygon (takes v); drops one without area.  0 or -1 (memory). */
static int add_poly(struct ps_radgeom *g, const char *name, const char *mat, int file, int line,
                    double *v, int nv, struct ps_err *e)
{
	struct ps_radpoly *p;
	double n[3] = { 0, 0, 0 }, len, size = 0;
	for (int i = 0; i < nv; i++) {
		const double *a = v + 3 * i, *b = v + 3 * ((i + 1) % nv);
		n[0] += (a[1] - b[1]) * (a[2] + b[2]);
		n[1] += (a[2] - b[2]) * (a[0] + b[0]);
		n[2] += (a[0] - b[0]) * (a[1] + b[1]);
		for (int k = 0; k < 3; k++)
			size = fmax(size, fabs(a[k] - v[k]));
	}
	len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
	if (!(len > 1e-12 * size * size) || !isfinite(len)) {
		g->degenerate++;
		free(v);
		return 0;
	}
	if (g->npoly == g->cap) {
		size_t cap = g->cap ? 2 * g->cap : 64;
		struct ps_radpoly *np = realloc(g->poly, cap * sizeof *np);
		if (!np) {
			free(v);
			return ps_err_set(e, PS_ENOMEM, "out of memory");
		}
		g->poly = np;
		g->cap = cap;
	}
	p = &g->poly[g->npoly];
	memset(p, 0, sizeof *p);
	p->name = strdup(name);
	p->material = strdup(mat);
	if (!p->name || !p->material) {
		free(p->name);
		free(p->material);
		free(v);
		return ps_err_set(e, PS_ENOMEM, "out of memory");
	}
	p->file = file;
	p->line = line;
	p->nv = nv;
	p->v = v;
	for (int k = 0; k < 3; k++)
		p->n[k] = n[k] / len;
	p->d = p->n[0] * v[0] + p->n[1] * v[1] + p->n[2] * v[2];
	for (int k = 0; k < 3; k++) {
		p->lo[k] = p->hi[k] = v[k];
		for (int i = 1; i < nv; i++) {
			p->lo[k] = fmin(p->lo[k], v[3 * i + k]);
			p->hi[k] = fmax(p->hi[k], v[3 * i + k]);
		}
	}
	/* project along the normal's largest component */
	{
		int drop = fabs(p->n[0]) >= fabs(p->n[1]) && fabs(p->n[0]) >= fabs(p->n[2]) ? 0
		         : fabs(p->n[1]) >= fabs(p->n[2]) ? 1 : 2;
		p->a0 = drop == 0 ? 1 : 0;
		p->a1 = drop == 2 ? 1 : 2;
	}
	g->npoly++;
	return 0;
}

static void xf_identity(struct xf *x)
{
	memset(x, 0, sizeof *x);
	for (int i = 0; i < 3; i++)
		x->m[i][i] = 1.0;
}

/* x = a after x (a applied last) */
static void xf_then(struct xf *x, const struct xf *a)
{
	struct xf r;
	for (int i = 0; i < 3; i++) {
		for (int j = 0; j < 3; j++)
			r.m[i][j] = a->m[i][0] * x->m[0][j] + a->m[i][1] * x->m[1][j] + a->m[i][2] * x->m[2][j];
		r.t[i] = a->m[i][0] * x->t[0] + a->m[i][1] * x->t[1] + a->m[i][2] * x->t[2] + a->t[i];
	}
	*x = r;
}

static void xf_apply(const struct xf *x, const double in[3], double out[3])
{
	for (int i = 0; i < 3; i++)
		out[i] = x->m[i][0] * in[0] + x->m[i][1] * in[1] + x->m[i][2] * in[2] + x->t[i];
}

/* Split a command's text into words (in place); returns the count. */
static int split_words(char *s, char **w, int max)
{
	int n = 0;
	while (*s) {
		while (*s && is_space(*s))
			s++;
		if (!*s)
			break;
		if (n == max)
			return max + 1;
		w[n++] = s;
		while (*s && !is_space(*s))
			s++;
		if (*s)
			*s++ = '\0';
	}
	return n;
}

/* One xform stage's options onto x (and the material). */
static int xform_stage(char **w, int n, struct xf *x, const char **mat, const char *where,
                       struct ps_err *e)
{
	for (int i = 1; i < n; i++) {
		const char *o = w[i];
		struct xf a;
		xf_identity(&a);
		if (strcmp(o, "-t") == 0) {
			if (i + 3 >= n)
				return ps_err_set(e, PS_EFORMAT, "%s: xform -t needs 3 numbers", where);
			for (int k = 0; k < 3; k++)
				if (parse_double(w[i + 1 + k], &a.t[k]) != 0)
					return ps_err_set(e, PS_EFORMAT, "%s: xform -t: '%s' is not a number", where,
					                  w[i + 1 + k]);
			i += 3;
		} else if (strcmp(o, "-rx") == 0 || strcmp(o, "-ry") == 0 || strcmp(o, "-rz") == 0) {
			double deg, c, s;
			int ax = o[2] - 'x', p = (ax + 1) % 3, q = (ax + 2) % 3;
			if (i + 1 >= n || parse_double(w[i + 1], &deg) != 0)
				return ps_err_set(e, PS_EFORMAT, "%s: xform %s needs an angle in degrees", where, o);
			/* right-handed about the axis: p towards q */
			c = cos(deg * DEG);
			s = sin(deg * DEG);
			a.m[p][p] = c;
			a.m[p][q] = -s;
			a.m[q][p] = s;
			a.m[q][q] = c;
			i++;
		} else if (strcmp(o, "-s") == 0) {
			double s;
			if (i + 1 >= n || parse_double(w[i + 1], &s) != 0 || s == 0)
				return ps_err_set(e, PS_EFORMAT, "%s: xform -s needs a non-zero scale", where);
			for (int k = 0; k < 3; k++)
				a.m[k][k] = s;
			i++;
		} else if (strcmp(o, "-mx") == 0 || strcmp(o, "-my") == 0 || strcmp(o, "-mz") == 0) {
			a.m[o[2] - 'x'][o[2] - 'x'] = -1.0;
		} else if (strcmp(o, "-m") == 0) {
			if (i + 1 >= n)
				return ps_err_set(e, PS_EFORMAT, "%s: xform -m needs a material", where);
			*mat = w[++i];
			continue;
		} else {
			return ps_err_set(e, PS_EUNSUPPORTED, "%s: xform option '%s' is not handled (only -t, "
			                  "-rx, -ry, -rz, -s, -mx, -my, -mz and -m)", where, o);
		}
		xf_then(x, &a);
	}
	return 0;
}

/* !genbox MAT NAME X Y Z [-i] | xform ... */
static int command(struct ps_radgeom *g, char *text, int file, const char *name, int line,
                   struct ps_err *e)
{
	char where[320], *stage[64], *w[64], *save = NULL, *s;
	int nstage = 0, n;
	double size[3];
	const char *mat, *box;
	struct xf x;
	snprintf(where, sizeof where, "%.255s:%d", name, line);
	for (s = strtok_r(text, "|", &save); s; s = strtok_r(NULL, "|", &save)) {
		if (nstage == 64)
			return ps_err_set(e, PS_EFORMAT, "%s: more than 64 commands in one pipe", where);
		stage[nstage++] = s;
	}
	if (nstage == 0)
		return ps_err_set(e, PS_EFORMAT, "%s: an empty command", where);
	n = split_words(stage[0], w, 64);
	if (n == 0)
		return ps_err_set(e, PS_EFORMAT, "%s: an empty command", where);
	if (n > 64)
		return ps_err_set(e, PS_EFORMAT, "%s: too many words in a command", where);
	if (strcmp(w[0], "genbox") != 0)
		return ps_err_set(e, PS_EUNSUPPORTED, "%s: command '%.64s' is not handled (only !genbox, "
		                  "piped to xform)", where, w[0]);
	if (n < 6 || n > 7 || (n == 7 && strcmp(w[6], "-i") != 0))
		return ps_err_set(e, PS_EUNSUPPORTED, "%s: genbox takes MATERIAL NAME X Y Z [-i] here "
		                  "(-r and -b are not handled)", where);
	for (int k = 0; k < 3; k++)
		if (parse_double(w[3 + k], &size[k]) != 0)
			return ps_err_set(e, PS_EFORMAT, "%s: genbox: '%s' is not a number", where, w[3 + k]);
	mat = w[1];
	box = w[2];
	xf_identity(&x);
	for (int k = 1; k < nstage; k++) {
		char *xw[64];
		int xn = split_words(stage[k], xw, 64);
		if (xn == 0 || strcmp(xw[0], "xform") != 0)
			return ps_err_set(e, PS_EUNSUPPORTED, "%s: genbox piped to '%.64s': only xform is "
			                  "handled", where, xn ? xw[0] : "");
		if (xn > 64)
			return ps_err_set(e, PS_EFORMAT, "%s: too many xform options", where);
		if (xform_stage(xw, xn, &x, &mat, where, e) != 0)
			return -1;
	}
	{
		/* genbox's faces: corner bits x = 1, y = 2, z = 4 */
		static const int face[6][4] = { { 1, 5, 4, 0 }, { 4, 6, 2, 0 }, { 2, 3, 1, 0 },
		                                { 3, 2, 6, 7 }, { 5, 1, 3, 7 }, { 6, 4, 5, 7 } };
		for (int f = 0; f < 6; f++) {
			char fname[TOKEN_MAX + 8];
			double *v = malloc(12 * sizeof *v);
			if (!v)
				return ps_err_set(e, PS_ENOMEM, "out of memory");
			for (int i = 0; i < 4; i++) {
				int c = face[f][i];
				double p[3] = { c & 1 ? size[0] : 0, c & 2 ? size[1] : 0, c & 4 ? size[2] : 0 };
				xf_apply(&x, p, v + 3 * i);
			}
			snprintf(fname, sizeof fname, "%s.%d%d%d%d", box, face[f][0], face[f][1], face[f][2],
			         face[f][3]);
			if (add_poly(g, fname, mat, file, line, v, 4, e) != 0)
				return -1;
		}
	}
	return 0;
}

static int refused_surface(const char *type)
{
	static const char *const t[] = { "sphere", "bubble", "cone", "cup", "cylinder", "tube",
	                                 "ring", "instance", "mesh" };
	for (size_t i = 0; i < sizeof t / sizeof t[0]; i++)
		if (strcmp(type, t[i]) == 0)
			return 1;
	return 0;
}

int ps_radgeom_parse(struct ps_radgeom *g, const char *text, size_t len, const char *name,
                     struct ps_err *e)
{
	struct lex l = { text, text + len, name, 1 };
	char mod[TOKEN_MAX], type[TOKEN_MAX], id[TOKEN_MAX], w[TOKEN_MAX];
	int file;
	{
		char **nf = realloc(g->files, (size_t)(g->nfiles + 1) * sizeof *nf);
		if (!nf)
			return ps_err_set(e, PS_ENOMEM, "out of memory");
		g->files = nf;
		if (!(g->files[g->nfiles] = strdup(name)))
			return ps_err_set(e, PS_ENOMEM, "out of memory");
		file = g->nfiles++;
	}
	for (;;) {
		int line, rc;
		long cnt[3];
		double *v = NULL;
		skip_space(&l);
		if (l.p >= l.end)
			return 0;
		line = l.line;
		if (*l.p == '#') {
			while (l.p < l.end && *l.p != '\n')
				l.p++;
			continue;
		}
		if (*l.p == '!') {
			/* to the end of the line; a backslash before the newline continues it */
			char *buf = malloc(COMMAND_MAX);
			size_t n = 0;
			if (!buf)
				return ps_err_set(e, PS_ENOMEM, "out of memory");
			l.p++;
			while (l.p < l.end && *l.p != '\n') {
				if (*l.p == '\\' && l.p + 1 < l.end && l.p[1] == '\n') {
					l.p += 2;
					l.line++;
					buf[n++] = ' ';
				} else {
					buf[n++] = *l.p == '\0' ? ' ' : *l.p;
					l.p++;
				}
				if (n + 1 >= COMMAND_MAX) {
					free(buf);
					return ps_err_set(e, PS_EFORMAT, "%s:%d: a command longer than %d bytes", name,
					                  line, COMMAND_MAX - 1);
				}
			}
			buf[n] = '\0';
			rc = command(g, buf, file, name, line, e);
			free(buf);
			if (rc != 0)
				return -1;
			continue;
		}
		if (next_word(&l, mod, e) < 0)
			return -1;
		if ((rc = next_word(&l, type, e)) != 0 || (rc = next_word(&l, id, e)) != 0) {
			if (rc < 0)
				return -1;
			return ps_err_set(e, PS_EFORMAT, "%s:%d: the input ends inside a primitive (after '%s')",
			                  name, line, mod);
		}
		if (strcmp(type, "alias") == 0) {
			/* MOD alias ID ORIGINAL: no argument counts */
			if ((rc = next_word(&l, w, e)) != 0)
				return rc < 0 ? -1 : ps_err_set(e, PS_EFORMAT, "%s:%d: alias '%s' has no original",
				                                name, line, id);
			g->skipped++;
			continue;
		}
		if (refused_surface(type))
			return ps_err_set(e, PS_EUNSUPPORTED, "%s:%d: %s '%s' is not handled (the labeller reads "
			                  "polygon primitives and !genbox | xform)", name, line, type, id);
		for (int k = 0; k < 3; k++) {
			if ((rc = next_word(&l, w, e)) != 0) {
				free(v);
				return rc < 0 ? -1 : ps_err_set(e, PS_EFORMAT, "%s:%d: %s '%s' ends before its "
				                                "argument counts", name, line, type, id);
			}
			/* every argument takes two bytes at least: no count beyond the input */
			if (parse_count(w, &cnt[k]) != 0 || cnt[k] > (l.end - l.p + 1) / 2) {
				free(v);
				return ps_err_set(e, PS_EFORMAT, "%s:%d: %s '%s': '%s' is not an argument count "
				                  "this input can hold", name, l.line, type, id, w);
			}
			if (k == 2 && strcmp(type, "polygon") == 0) {
				if (cnt[0] != 0 || cnt[1] != 0 || cnt[2] < 9 || cnt[2] % 3 != 0)
					return ps_err_set(e, PS_EFORMAT, "%s:%d: polygon '%s' needs 0 strings, 0 integers "
					                  "and 3 x 3 or more reals (has %ld, %ld, %ld)", name, line, id,
					                  cnt[0], cnt[1], cnt[2]);
				v = malloc((size_t)cnt[2] * sizeof *v);
				if (!v)
					return ps_err_set(e, PS_ENOMEM, "out of memory");
			}
			for (long i = 0; i < cnt[k]; i++) {
				if ((rc = next_word(&l, w, e)) != 0) {
					free(v);
					return rc < 0 ? -1 : ps_err_set(e, PS_EFORMAT, "%s:%d: %s '%s' ends before its "
					                                "%ld arguments", name, line, type, id, cnt[k]);
				}
				if (v && k == 2 && parse_double(w, &v[i]) != 0) {
					free(v);
					return ps_err_set(e, PS_EFORMAT, "%s:%d: polygon '%s': '%s' is not a number",
					                  name, l.line, id, w);
				}
			}
		}
		if (v) {
			if (add_poly(g, id, mod, file, line, v, (int)(cnt[2] / 3), e) != 0)
				return -1;
		} else {
			g->skipped++;
		}
	}
}

int ps_radgeom_read(struct ps_radgeom *g, const char *path, struct ps_err *e)
{
	uint8_t *text;
	size_t len;
	int rc;
	if (ps_fileio_read(path, (size_t)256 << 20, &text, &len, e) != 0)
		return -1;
	rc = ps_radgeom_parse(g, (const char *)text, len, path, e);
	free(text);
	return rc;
}

/* Crossing test in the projection (half-open rule: a point on an edge shared
 * by two coplanar polygons is inside exactly one). */
static int inside(const struct ps_radpoly *p, const double x[3])
{
	double px = x[p->a0], py = x[p->a1];
	int in = 0;
	for (int i = 0, j = p->nv - 1; i < p->nv; j = i++) {
		double xi = p->v[3 * i + p->a0], yi = p->v[3 * i + p->a1];
		double xj = p->v[3 * j + p->a0], yj = p->v[3 * j + p->a1];
		if ((yi > py) != (yj > py) && px < (xj - xi) * (py - yi) / (yj - yi) + xi)
			in = !in;
	}
	return in;
}

long ps_radgeom_trace(const struct ps_radgeom *g, const double org[3], const double dir[3],
                      double *t)
{
	long best = -1;
	double tbest = INFINITY;
	for (size_t i = 0; i < g->npoly; i++) {
		const struct ps_radpoly *p = &g->poly[i];
		double den = p->n[0] * dir[0] + p->n[1] * dir[1] + p->n[2] * dir[2], tt, x[3];
		int k;
		if (den == 0)
			continue;
		tt = (p->d - (p->n[0] * org[0] + p->n[1] * org[1] + p->n[2] * org[2])) / den;
		if (!(tt > 1e-12) || tt >= tbest)
			continue;
		for (k = 0; k < 3; k++) {
			double slack = 1e-9 * (1 + fabs(p->hi[k]) + fabs(p->lo[k]));
			x[k] = org[k] + tt * dir[k];
			if (x[k] < p->lo[k] - slack || x[k] > p->hi[k] + slack)
				break;
		}
		if (k < 3 || !inside(p, x))
			continue;
		best = (long)i;
		tbest = tt;
	}
	if (t)
		*t = tbest;
	return best;
}
