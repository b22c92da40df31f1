/* SPDX-License-Identifier: ISC */
#include "sensor.h"

#include "fileio.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define DEG (M_PI / 180.0)

enum { SENSOR_MAX_ROWS = 100000, SENSOR_MAX_COLS = 100000, SENSOR_MAX_FILE = 64 << 20 };

static void free_reading(struct ps_sensor *s)
{
	free(s->tb);
	free(s->pb);
	free(s->corner);
	free(s->cum);
	free(s->mcoef);
	s->tb = s->pb = s->corner = s->cum = s->mcoef = NULL;
	s->nt = s->np = 0;
}

void ps_sensor_free(struct ps_sensor *s)
{
	if (!s)
		return;
	free_reading(s);
	free(s->path);
	free(s->theta);
	free(s->phi);
	free(s->val);
	memset(s, 0, sizeof *s);
}

int ps_sensor_reading_parse(const char *name)
{
	if (strcmp(name, "linear") == 0)
		return PS_READ_LINEAR;
	if (strcmp(name, "cell") == 0)
		return PS_READ_CELL;
	return -1;
}

const char *ps_sensor_reading_name(int reading)
{
	return reading == PS_READ_CELL ? "cell" : "linear";
}

/* 1 - cos t and sin t - t cos t, without cancellation for small t */
static void h_g(double t, double *h, double *g)
{
	double sh = sin(0.5 * t);
	*h = 2.0 * sh * sh;
	*g = t < PS_SENSOR_SMALL_THETA ? ps_sensor_sin_t_cos_small(t) : sin(t) - t * cos(t);
}

/* integral_{t0}^{t} (a + b u) sin u du for s linear from s0 at t0 to s1 at t1:
 * a (h(t) - h(t0)) + b (g(t) - g(t0)), h = 1 - cos, g = sin u - u cos u */
static double lin_sin_integral(double s0, double s1, double t0, double t1, double t)
{
	double b = (t1 > t0) ? (s1 - s0) / (t1 - t0) : 0.0;
	double a = s0 - b * t0;
	double h, g, h0, g0;
	h_g(t, &h, &g);
	h_g(t0, &h0, &g0);
	return a * (h - h0) + b * (g - g0);
}

static double *corner_at(const struct ps_sensor *s, int i, int j)
{
	return s->corner + 4 * ((size_t)i * (size_t)s->np + (size_t)j);
}

static double *cum_at(const struct ps_sensor *s, int i, int j)
{
	return s->cum + 2 * ((size_t)i * (size_t)s->np + (size_t)j);
}

/* Running integrals along the left and right edge of each phi patch. */
static void build_cum(struct ps_sensor *s)
{
	for (int j = 0; j < s->np; j++) {
		double l = 0.0, r = 0.0;
		cum_at(s, 0, j)[0] = 0.0;
		cum_at(s, 0, j)[1] = 0.0;
		for (int i = 0; i < s->nt; i++) {
			const double *c = corner_at(s, i, j);
			l += lin_sin_integral(c[0], c[1], s->tb[i], s->tb[i + 1], s->tb[i + 1]);
			r += lin_sin_integral(c[2], c[3], s->tb[i], s->tb[i + 1], s->tb[i + 1]);
			cum_at(s, i + 1, j)[0] = l;
			cum_at(s, i + 1, j)[1] = r;
		}
	}
	/* Within a patch, along an edge where S = a + b t:
	 *   M(theta) = cum + integral_{t0}^{theta} (a + b t) sin t dt
	 *            = K + a (1 - cos theta) + b (sin theta - theta cos theta)
	 * with K = cum - a (1 - cos t0) - b (sin t0 - t0 cos t0): one sine and
	 * one cosine, and near the axis no cancellation (ps_sensor_m_patch). */
	for (int i = 0; i < s->nt; i++)
		for (int j = 0; j < s->np; j++) {
			const double *c = corner_at(s, i, j), *cu = cum_at(s, i, j);
			double t0 = s->tb[i], t1 = s->tb[i + 1], h0, g0;
			double *k = s->mcoef + 6 * ((size_t)i * (size_t)s->np + (size_t)j);
			h_g(t0, &h0, &g0);
			for (int side = 0; side < 2; side++) {
				double v0 = c[2 * side], v1 = c[2 * side + 1];
				double b = t1 > t0 ? (v1 - v0) / (t1 - t0) : 0.0, a = v0 - b * t0;
				k[3 * side + 0] = cu[side] - a * h0 - b * g0;
				k[3 * side + 1] = a;
				k[3 * side + 2] = b;
			}
		}
}

static int alloc_reading(struct ps_sensor *s, int nt, int np, struct ps_err *e)
{
	free_reading(s);
	s->nt = nt;
	s->np = np;
	s->tb = calloc((size_t)nt + 1, sizeof *s->tb);
	s->pb = calloc((size_t)np + 1, sizeof *s->pb);
	s->corner = calloc((size_t)nt * (size_t)np * 4, sizeof *s->corner);
	s->cum = calloc(((size_t)nt + 1) * (size_t)np * 2, sizeof *s->cum);
	s->mcoef = calloc((size_t)nt * (size_t)np * 6, sizeof *s->mcoef);
	if (!s->tb || !s->pb || !s->corner || !s->cum || !s->mcoef) {
		free_reading(s);
		return ps_err_set(e, PS_ENOMEM, "%s: out of memory", s->path ? s->path : "sensor");
	}
	return 0;
}

int ps_sensor_set_reading(struct ps_sensor *s, int reading, struct ps_err *e)
{
	int nt = s->ntheta, nph = s->nphi;
	if (s->kind != PS_SENS_TABLE) {
		s->reading = reading;
		return 0;
	}
	if (reading == PS_READ_LINEAR) {
		/* patches between table rows and between azimuth columns (wrapping) */
		if (alloc_reading(s, nt - 1, nph, e) != 0)
			return -1;
		for (int i = 0; i < nt; i++)
			s->tb[i] = s->theta[i] * DEG;
		for (int j = 0; j < nph; j++)
			s->pb[j] = s->phi[j] * DEG;
		s->pb[nph] = s->pb[0] + 2 * M_PI;
		for (int i = 0; i + 1 < nt; i++)
			for (int j = 0; j < nph; j++) {
				double *c = corner_at(s, i, j);
				int jr = (j + 1) % nph;
				c[0] = s->val[(size_t)i * nph + j];
				c[1] = s->val[(size_t)(i + 1) * nph + j];
				c[2] = s->val[(size_t)i * nph + jr];
				c[3] = s->val[(size_t)(i + 1) * nph + jr];
			}
		s->theta_end = s->tb[nt - 1];
	} else {
		/* rsensor's cells: between midpoints; the last ends half a step on */
		double end = 1.5 * s->theta[nt - 1] - 0.5 * s->theta[nt - 2];
		if (alloc_reading(s, nt, nph, e) != 0)
			return -1;
		s->tb[0] = 0.0;
		for (int i = 1; i < nt; i++)
			s->tb[i] = 0.5 * (s->theta[i - 1] + s->theta[i]) * DEG;
		s->tb[nt] = (end > 180.0 ? 180.0 : end) * DEG;
		for (int j = 0; j < nph; j++) {
			double next = (j + 1 < nph) ? s->phi[j + 1] : s->phi[0] + 360.0;
			s->pb[j + 1] = 0.5 * (s->phi[j] + next) * DEG;
		}
		s->pb[0] = s->pb[nph] - 2 * M_PI;
		for (int i = 0; i < nt; i++)
			for (int j = 0; j < nph; j++) {
				double *c = corner_at(s, i, j);
				c[0] = c[1] = c[2] = c[3] = s->val[(size_t)i * nph + j];
			}
		s->theta_end = s->tb[nt];
	}
	s->reading = reading;
	build_cum(s);
	if (!isfinite(ps_sensor_integral(s)))
		return ps_err_set(e, PS_ERANGE,
		                  "%s: the sensitivity's integral over the sphere is not finite (values up "
		                  "to %g): scale the table down",
		                  s->path ? s->path : "sensor", s->max_value);
	return 0;
}

int ps_sensor_builtin(struct ps_sensor *s, int kind, struct ps_err *e)
{
	memset(s, 0, sizeof *s);
	s->kind = kind;
	s->path = strdup(kind == PS_SENS_COSINE ? "builtin:cosine" : "builtin:uniform");
	s->theta_end = kind == PS_SENS_COSINE ? M_PI / 2 : M_PI;
	s->max_value = 1.0;
	s->total = 1.0;
	s->nt = 1;
	s->np = 1;
	s->tb = malloc(2 * sizeof *s->tb);
	s->pb = malloc(2 * sizeof *s->pb);
	if (!s->path || !s->tb || !s->pb) {
		ps_sensor_free(s);
		return ps_err_set(e, PS_ENOMEM, "out of memory");
	}
	s->tb[0] = 0.0;
	s->tb[1] = s->theta_end;
	s->pb[0] = 0.0;
	s->pb[1] = 2 * M_PI;
	return 0;
}

/* ---- reading files ---------------------------------------------------------- */

struct lines {
	const char *p, *end;
	int lineno;
};

/* Next line into a malloc'd string (NULL at the end). */
static char *next_line(struct lines *l)
{
	const char *nl;
	char *out;
	size_t n;
	if (l->p >= l->end)
		return NULL;
	nl = memchr(l->p, '\n', (size_t)(l->end - l->p));
	n = nl ? (size_t)(nl - l->p) : (size_t)(l->end - l->p);
	out = malloc(n + 1);
	if (!out)
		return NULL;
	memcpy(out, l->p, n);
	out[n] = '\0';
	if (n && out[n - 1] == '\r')
		out[n - 1] = '\0';
	l->p += n + (nl ? 1 : 0);
	l->lineno++;
	return out;
}

static int blank(const char *s)
{
	return s[strspn(s, " \t")] == '\0';
}

/* Parse numbers from a line into a growing array. */
static int line_numbers(const char *line, double **v, int *n, int *cap, const char *name,
                        int lineno, struct ps_err *e)
{
	const char *p = line;
	for (;;) {
		char *end;
		double x;
		p += strspn(p, " \t");
		if (!*p)
			return 0;
		errno = 0;
		x = strtod(p, &end);
		if (end == p || (*end && *end != ' ' && *end != '\t'))
			return ps_err_set(e, PS_EFORMAT, "%s:%d: '%.*s' is not a number", name, lineno,
			                  (int)strcspn(p, " \t"), p);
		if (errno == ERANGE || !isfinite(x))
			return ps_err_set(e, PS_ERANGE, "%s:%d: '%.*s' is not a finite number", name, lineno,
			                  (int)strcspn(p, " \t"), p);
		if (*n == *cap) {
			int ncap = *cap ? *cap * 2 : 64;
			double *nv;
			if (ncap > SENSOR_MAX_COLS + 1)
				return ps_err_set(e, PS_ERANGE, "%s:%d: more than %d values on a line", name,
				                  lineno, SENSOR_MAX_COLS);
			nv = realloc(*v, (size_t)ncap * sizeof *nv);
			if (!nv)
				return ps_err_set(e, PS_ENOMEM, "%s:%d: out of memory", name, lineno);
			*v = nv;
			*cap = ncap;
		}
		(*v)[(*n)++] = x;
		p = end;
	}
}

/* The field a table states on its "Elevation" line: the word "field", an
 * optional ':' or '=', and a polar angle in degrees ("Elevation field 90").
 * The line is free text that rsensor skips, so the statement keeps the
 * file readable by rsensor.  1 and *field when stated, 0 when not,
 * -1 when the angle is out of range. */
static int elevation_field(const char *line, double *field, const char *name, int lineno,
                           struct ps_err *e)
{
	for (const char *p = strstr(line, "field"); p; p = strstr(p + 5, "field")) {
		const char *q = p + 5;
		char *end;
		double x;
		if (p > line && (isalnum((unsigned char)p[-1]) || p[-1] == '_'))
			continue;
		q += strspn(q, " \t");
		if (*q == ':' || *q == '=')
			q++;
		q += strspn(q, " \t");
		if (!isdigit((unsigned char)*q) && *q != '.' && *q != '+' && *q != '-')
			continue;   /* "field" as a word of the title */
		x = strtod(q, &end);
		if (end == q || isalnum((unsigned char)*end) || *end == '.')
			continue;
		if (!(x > 0.0 && x <= 180.0))   /* the text as written: 1e999 is no "inf" */
			return ps_err_set(e, PS_ERANGE,
			                  "%s:%d: the field %.*s is not a polar angle above 0 and at most 180",
			                  name, lineno, (int)(end - q), q);
		*field = x;
		return 1;
	}
	return 0;
}

/* "the row for 90 degrees is missing", or a range with the count at the
 * step of the last two rows when the gap is a whole number of them. */
static void missing_rows(char *out, size_t n, double last, double step, double field)
{
	double k = step > 0.0 ? (field - last) / step : 0.0;
	if (k > 0.5 && fabs(k - floor(k + 0.5)) < 1e-6 && k < 1e7) {
		long rows = (long)floor(k + 0.5);
		if (rows == 1)
			snprintf(out, n, "the row for %g degrees is missing", field);
		else
			snprintf(out, n, "the rows for %g to %g degrees are missing (%ld rows at the "
			         "table's %g-degree step)", last + step, field, rows, step);
		return;
	}
	snprintf(out, n, "the rows above %g up to %g degrees are missing", last, field);
}

/* A table must reach the field it states.  One that states none is taken
 * only when it cannot be a cut copy: it reaches the hemisphere (90 degrees
 * or more) or its last row is zero at every azimuth; otherwise a truncated
 * file (a cosine table cut after 4 degrees reads 400 times too low) cannot
 * be told from a narrow sensor, and the reader asks for the statement. */
static int check_field(const struct ps_sensor *s, const char *name, int stated, double field,
                       int field_line, int last_line, struct ps_err *e)
{
	int n = s->ntheta;
	double last = s->theta[n - 1];
	const double *row = s->val + (size_t)(n - 1) * (size_t)s->nphi;
	if (stated) {
		char what[160];
		if (last >= field)
			return 0;
		missing_rows(what, sizeof what, last, last - s->theta[n - 2], field);
		return ps_err_set(e, PS_EFORMAT,
		                  "%s:%d: the table ends at polar angle %g but line %d states a field of "
		                  "%g: %s (a cut copy?)",
		                  name, last_line, last, field_line, field, what);
	}
	if (last >= 90.0)
		return 0;
	for (int j = 0; j < s->nphi; j++)
		if (row[j] != 0.0)
			return ps_err_set(e, PS_EFORMAT,
			                  "%s:%d: the table ends at polar angle %g with a non-zero response "
			                  "(%g at azimuth %g) and states no field, so a cut copy cannot be "
			                  "told from a sensor that sees to %g: restore the missing rows, or, "
			                  "if the table is whole, state its field on a first line "
			                  "'Elevation field %g'",
			                  name, last_line, last, row[j], s->phi[j], last, last);
	return 0;
}

int ps_sensor_parse(struct ps_sensor *s, const char *text, size_t len, const char *name,
                    struct ps_err *e)
{
	struct lines l = { text, text + len, 0 };
	char *line = NULL;
	double *row = NULL;
	int nrow = 0, caprow = 0, rows_cap = 0, header_line = 0;
	int stated = 0, field_line = 0, last_line = 0;
	double field = 0.0;
	memset(s, 0, sizeof *s);
	s->kind = PS_SENS_TABLE;
	s->path = strdup(name);
	if (!s->path)
		return ps_err_set(e, PS_ENOMEM, "out of memory");
	if (memchr(text, '\0', len))
		goto nul;
	/* header: optional "Elevation ..." then "degrees phi..." */
	while ((line = next_line(&l)) && blank(line))
		free(line);
	if (line && strncmp(line, "Elevation", 9) == 0) {
		field_line = l.lineno;
		stated = elevation_field(line + 9, &field, name, l.lineno, e);
		if (stated < 0)
			goto fail;
		free(line);
		while ((line = next_line(&l)) && blank(line))
			free(line);
	}
	if (!line) {
		ps_err_set(e, PS_EFORMAT, "%s:%d: empty sensitivity table", name, l.lineno);
		goto fail;
	}
	header_line = l.lineno;
	{
		const char *p = line + strspn(line, " \t");
		if (strncmp(p, "degrees", 7) != 0 || (p[7] && p[7] != ' ' && p[7] != '\t')) {
			ps_err_set(e, PS_EFORMAT, "%s:%d: first line must be 'degrees' and the azimuths", name,
			           l.lineno);
			goto fail;
		}
		if (line_numbers(p + 7, &s->phi, &s->nphi, &caprow, name, l.lineno, e) != 0)
			goto fail;
	}
	free(line);
	line = NULL;
	if (s->nphi == 0) {
		ps_err_set(e, PS_EFORMAT, "%s:%d: no azimuths after 'degrees'", name, header_line);
		goto fail;
	}
	if (s->phi[0] != 0.0) {
		ps_err_set(e, PS_ERANGE, "%s:%d: azimuths must start at 0 (not %g)", name, header_line, s->phi[0]);
		goto fail;
	}
	for (int j = 1; j < s->nphi; j++)
		if (!(s->phi[j] > s->phi[j - 1])) {
			ps_err_set(e, PS_ERANGE, "%s:%d: azimuth %g does not increase (after %g)", name,
			           header_line, s->phi[j], s->phi[j - 1]);
			goto fail;
		}
	if (s->phi[s->nphi - 1] < 270.0 || s->phi[s->nphi - 1] >= 360.0) {
		ps_err_set(e, PS_ERANGE, "%s:%d: azimuths must reach at least 270 and stay below 360 (last is %g)",
		           name, header_line, s->phi[s->nphi - 1]);
		goto fail;
	}
	caprow = 0;
	while ((line = next_line(&l))) {
		if (blank(line)) {
			free(line);
			continue;
		}
		nrow = 0;
		if (line_numbers(line, &row, &nrow, &caprow, name, l.lineno, e) != 0)
			goto fail;
		if (nrow != s->nphi + 1) {
			ps_err_set(e, PS_EFORMAT, "%s:%d: row has %d values, expected a polar angle and %d",
			           name, l.lineno, nrow, s->nphi);
			goto fail;
		}
		if (s->ntheta == 0 ? row[0] != 0.0 : !(row[0] > s->theta[s->ntheta - 1])) {
			ps_err_set(e, PS_ERANGE, "%s:%d: polar angle %g %s", name, l.lineno, row[0],
			           s->ntheta == 0 ? "must be 0 in the first row" : "does not increase");
			goto fail;
		}
		if (row[0] > 180.0) {
			ps_err_set(e, PS_ERANGE, "%s:%d: polar angle %g is beyond 180", name, l.lineno, row[0]);
			goto fail;
		}
		if (stated && row[0] > field) {
			ps_err_set(e, PS_ERANGE, "%s:%d: polar angle %g is beyond the field of %g stated on line %d",
			           name, l.lineno, row[0], field, field_line);
			goto fail;
		}
		last_line = l.lineno;
		for (int j = 1; j < nrow; j++)
			if (row[j] < 0.0) {
				ps_err_set(e, PS_ERANGE, "%s:%d: negative sensitivity %g (azimuth %g)", name,
				           l.lineno, row[j], s->phi[j - 1]);
				goto fail;
			}
		if (s->ntheta == rows_cap) {
			int ncap = rows_cap ? rows_cap * 2 : 64;
			double *nt = realloc(s->theta, (size_t)ncap * sizeof *nt);
			double *nv;
			if (!nt)
				goto oom;
			s->theta = nt;
			if (ncap > SENSOR_MAX_ROWS || (size_t)ncap * (size_t)s->nphi > (size_t)SENSOR_MAX_FILE) {
				ps_err_set(e, PS_ERANGE, "%s:%d: table too large", name, l.lineno);
				goto fail;
			}
			nv = realloc(s->val, (size_t)ncap * (size_t)s->nphi * sizeof *nv);
			if (!nv)
				goto oom;
			s->val = nv;
			rows_cap = ncap;
		}
		s->theta[s->ntheta] = row[0];
		for (int j = 0; j < s->nphi; j++) {
			double v = row[j + 1];
			s->val[(size_t)s->ntheta * s->nphi + j] = v;
			s->total += v;
			if (v > s->max_value)
				s->max_value = v;
		}
		s->ntheta++;
		free(line);
		line = NULL;
	}
	free(row);
	row = NULL;
	if (s->ntheta < 2) {
		ps_err_set(e, PS_EFORMAT, "%s:%d: the table needs at least two polar angle rows (has %d)",
		           name, l.lineno, s->ntheta);
		goto fail;
	}
	if (s->max_value <= 0.0) {
		ps_err_set(e, PS_ERANGE, "%s: every sensitivity is zero", name);
		goto fail;
	}
	if (check_field(s, name, stated, field, field_line, last_line, e) != 0)
		goto fail;
	if (!isfinite(s->total)) {
		ps_err_set(e, PS_ERANGE,
		           "%s: the sensitivities (up to %g) add up past the largest number: the total "
		           "sensitivity would not be finite; scale the table down",
		           name, s->max_value);
		goto fail;
	}
	return ps_sensor_set_reading(s, PS_READ_LINEAR, e) == 0 ? 0 : (ps_sensor_free(s), -1);
nul:
	ps_err_set(e, PS_EFORMAT, "%s: byte %zu: NUL byte in a text file", name,
	           (size_t)((const char *)memchr(text, '\0', len) - text));
	goto fail;
oom:
	ps_err_set(e, PS_ENOMEM, "%s:%d: out of memory", name, l.lineno);
fail:
	free(line);
	free(row);
	ps_sensor_free(s);
	return -1;
}

int ps_sensor_read(struct ps_sensor *s, const char *path, struct ps_err *e)
{
	uint8_t *buf;
	size_t len;
	int rc;
	memset(s, 0, sizeof *s);
	if (ps_fileio_read(path, SENSOR_MAX_FILE, &buf, &len, e) != 0)
		return -1;
	rc = ps_sensor_parse(s, (const char *)buf, len, path, e);
	free(buf);
	return rc;
}

int ps_sensor_open(struct ps_sensor *s, const char *name, struct ps_err *e)
{
	if (strcmp(name, "builtin:cosine") == 0)
		return ps_sensor_builtin(s, PS_SENS_COSINE, e);
	if (strcmp(name, "builtin:uniform") == 0)
		return ps_sensor_builtin(s, PS_SENS_UNIFORM, e);
	if (strncmp(name, "builtin:", 8) == 0)
		return ps_err_set(e, PS_EINVAL, "%s: no such builtin sensor (builtin:cosine or builtin:uniform)",
		                  name);
	return ps_sensor_read(s, name, e);
}

/* ---- evaluation --------------------------------------------------------------- */

static int upper_index(const double *b, int n, double x)
{
	/* largest k in [0, n-1] with b[k] <= x (b sorted, n+1 entries) */
	int lo = 0, hi = n - 1;
	while (lo < hi) {
		int mid = (lo + hi + 1) / 2;
		if (b[mid] <= x)
			lo = mid;
		else
			hi = mid - 1;
	}
	return lo;
}

void ps_sensor_locate(const struct ps_sensor *s, double theta, double *phi, int *i, int *j)
{
	double p = fmod(*phi - s->pb[0], 2 * M_PI);
	if (p < 0)
		p += 2 * M_PI;
	p += s->pb[0];
	if (p >= s->pb[s->np])
		p = s->pb[0];
	*phi = p;
	*j = upper_index(s->pb, s->np, p);
	*i = theta >= s->theta_end ? s->nt : upper_index(s->tb, s->nt, theta);
}

double ps_sensor_m_in(const struct ps_sensor *s, int i, int j, double theta, double phi)
{
	double w, ml, mr;
	const double *cu;
	switch (s->kind) {
	case PS_SENS_COSINE:
	case PS_SENS_UNIFORM:
		return ps_sensor_m_builtin(s->kind, theta);
	default:
		break;
	}
	w = (phi - s->pb[j]) / (s->pb[j + 1] - s->pb[j]);
	cu = cum_at(s, i, j);
	if (i >= s->nt)
		return (1.0 - w) * cu[0] + w * cu[1];
	{
		const double *k = s->mcoef + 6 * ((size_t)i * (size_t)s->np + (size_t)j);
		double ct = cos(theta), st = sin(theta);
		ml = ps_sensor_m_patch(k, theta, st, ct);
		if (s->reading == PS_READ_CELL)
			return ml;
		mr = ps_sensor_m_patch(k + 3, theta, st, ct);
	}
	return (1.0 - w) * ml + w * mr;
}

double ps_sensor_m(const struct ps_sensor *s, double theta, double phi)
{
	int i, j;
	ps_sensor_locate(s, theta, &phi, &i, &j);
	return ps_sensor_m_in(s, i, j, theta, phi);
}

double ps_sensor_value(const struct ps_sensor *s, double theta, double phi)
{
	int i, j;
	double w, u;
	const double *c;
	switch (s->kind) {
	case PS_SENS_COSINE:
		return theta < M_PI / 2 ? cos(theta) : 0.0;
	case PS_SENS_UNIFORM:
		return 1.0;
	default:
		break;
	}
	ps_sensor_locate(s, theta, &phi, &i, &j);
	if (i >= s->nt)
		return 0.0;
	c = corner_at(s, i, j);
	u = (theta - s->tb[i]) / (s->tb[i + 1] - s->tb[i]);
	w = (phi - s->pb[j]) / (s->pb[j + 1] - s->pb[j]);
	return (1 - w) * ((1 - u) * c[0] + u * c[1]) + w * ((1 - u) * c[2] + u * c[3]);
}

double ps_sensor_integral(const struct ps_sensor *s)
{
	double sum = 0.0, comp = 0.0;
	if (s->kind == PS_SENS_COSINE)
		return M_PI;
	if (s->kind == PS_SENS_UNIFORM)
		return 4 * M_PI;
	for (int j = 0; j < s->np; j++) {
		const double *cu = cum_at(s, s->nt, j);
		double term = (s->pb[j + 1] - s->pb[j]) *
		              (s->reading == PS_READ_CELL ? cu[0] : 0.5 * (cu[0] + cu[1]));
		double t = sum + term;   /* Neumaier */
		comp += fabs(sum) >= fabs(term) ? (sum - t) + term : (term - t) + sum;
		sum = t;
	}
	return sum + comp;
}

double ps_sensor_extent(const struct ps_sensor *s)
{
	if (s->kind != PS_SENS_TABLE)
		return s->theta_end;
	for (int i = s->nt - 1; i >= 0; i--) {
		const double *c = corner_at(s, i, 0);
		for (int j = 0; j < s->np; j++) {
			c = corner_at(s, i, j);
			if (c[0] > 0 || c[1] > 0 || c[2] > 0 || c[3] > 0)
				return s->tb[i + 1];
		}
	}
	return 0.0;
}
