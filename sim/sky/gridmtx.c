/* SPDX-License-Identifier: ISC */
#include "gridmtx.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fileio.h"
#include "integrate.h"
#include "year.h"

#define MAX_FILE ((size_t)1 << 31)

void ps_gridmtx_free(struct ps_gridmtx *m)
{
	free(m->c);
	memset(m, 0, sizeof *m);
}

void ps_gridmtx_row(const struct ps_gridmtx *m, int i, struct ps_dcset_row *row)
{
	memset(row, 0, sizeof *row);
	row->mf = m->mf;
	row->n = m->npatch;
	row->c = m->c + 3 * (size_t)i * (size_t)m->npatch;
	row->coverage = 1.0;
}

/* The subdivision whose patch count is n (144 MF^2 + 2), or 0. */
static int mf_of(int n)
{
	for (int mf = 1; mf <= 64; mf++)
		if (144 * mf * mf + 2 == n)
			return mf;
	return 0;
}

/* A positive integer after "KEY=" (white space allowed). */
static int header_int(const char *v, int *out)
{
	char *end;
	long x;
	errno = 0;
	x = strtol(v, &end, 10);
	while (*end == ' ' || *end == '\t' || *end == '\r')
		end++;
	if (errno || end == v || *end || x <= 0 || x > 100000000)
		return -1;
	*out = (int)x;
	return 0;
}

static int little_endian(void)
{
	const uint16_t one = 1;
	return *(const uint8_t *)&one == 1;
}

static void swap_bytes(unsigned char *p, size_t n)
{
	for (size_t i = 0; i < n / 2; i++) {
		unsigned char t = p[i];
		p[i] = p[n - 1 - i];
		p[n - 1 - i] = t;
	}
}

/* One value: finite, not negative; where: "name:line" or "name: byte N". */
static int check_value(double v, const char *where, struct ps_err *e)
{
	if (isnan(v) || isinf(v))
		return ps_err_set(e, PS_EFORMAT, "%s: %s is not a coefficient", where, isnan(v) ? "NaN" : "infinity");
	if (v < 0)
		return ps_err_set(e, PS_EFORMAT, "%s: negative coefficient %g", where, v);
	return 0;
}

struct header {
	int nrows, ncols, ncomp, format, swap;
	int line;          /* lines the header took, the empty one included */
	size_t end;        /* byte after the empty line */
};

static int parse_header(const unsigned char *d, size_t len, const char *name, struct header *h,
                        struct ps_err *e)
{
	size_t at = 0;
	int line = 0, order = 0;
	memset(h, 0, sizeof *h);
	for (;;) {
		char buf[256];
		size_t s = at, n;
		const char *v;
		if (at >= len)
			return ps_err_set(e, PS_EFORMAT, "%s:%d: the header has no end (an empty line)", name, line + 1);
		while (at < len && d[at] != '\n')
			at++;
		n = at - s;
		if (at < len)
			at++;
		line++;
		if (n > 0 && d[s + n - 1] == '\r')
			n--;
		if (line == 1) {
			if (n < 10 || memcmp(d + s, "#?RADIANCE", 10) != 0)
				return ps_err_set(e, PS_EFORMAT,
				                  "%s:1: not a Radiance matrix (no #?RADIANCE; rfluxmtx and rmtxop write one)",
				                  name);
			continue;
		}
		if (n == 0)
			break;
		if (n >= sizeof buf)
			continue;   /* a long command line: no field of ours */
		memcpy(buf, d + s, n);
		buf[n] = 0;
		if (!strncmp(buf, "NROWS=", 6) || !strncmp(buf, "NCOLS=", 6) || !strncmp(buf, "NCOMP=", 6)) {
			int *dst = !strncmp(buf, "NROWS", 5) ? &h->nrows : !strncmp(buf, "NCOLS", 5) ? &h->ncols : &h->ncomp;
			if (header_int(buf + 6, dst) != 0)
				return ps_err_set(e, PS_EFORMAT, "%s:%d: bad %.5s: '%s'", name, line, buf, buf + 6);
		} else if (!strncmp(buf, "FORMAT=", 7)) {
			v = buf + 7;
			if (!strcmp(v, "ascii"))
				h->format = 'a';
			else if (!strcmp(v, "float"))
				h->format = 'f';
			else if (!strcmp(v, "double"))
				h->format = 'd';
			else
				return ps_err_set(e, PS_EUNSUPPORTED,
				                  "%s:%d: FORMAT=%s: only ascii, float and double matrices are read", name,
				                  line, v);
		} else if (!strncmp(buf, "BYTEORDER=", 10)) {
			v = buf + 10;
			if (!strcmp(v, "LittleEndian"))
				order = 'l';
			else if (!strcmp(v, "BigEndian"))
				order = 'b';
			else
				return ps_err_set(e, PS_EFORMAT, "%s:%d: bad BYTEORDER=%s", name, line, v);
		}
	}
	h->line = line;
	h->end = at;
	if (!h->nrows || !h->ncols)
		return ps_err_set(e, PS_EFORMAT, "%s:%d: the header gives no %s (rfluxmtx -I+ writes NROWS and NCOLS)",
		                  name, line, !h->nrows ? "NROWS" : "NCOLS");
	if (!h->ncomp)
		h->ncomp = 3;
	if (h->ncomp != 3 && h->ncomp != 1)
		return ps_err_set(e, PS_EUNSUPPORTED, "%s:%d: NCOMP=%d: only 1 or 3 components are read", name, line,
		                  h->ncomp);
	if (!h->format)
		return ps_err_set(e, PS_EFORMAT, "%s:%d: the header gives no FORMAT", name, line);
	if (!mf_of(h->ncols))
		return ps_err_set(e, PS_EFORMAT,
		                  "%s:%d: NCOLS=%d is no sky subdivision's patch count (146, 578, 2306, ...: "
		                  "one column per patch, the ground first)",
		                  name, line, h->ncols);
	h->swap = order && (order == 'l') != little_endian();
	return 0;
}

static int parse_ascii(const struct header *h, const unsigned char *d, size_t len, const char *name,
                       double *v, size_t want, struct ps_err *e)
{
	size_t at = h->end, got = 0;
	long line = h->line + 1;
	while (at < len) {
		char num[64];
		size_t s, n;
		double x;
		char *end;
		if (d[at] == '\n') {
			line++;
			at++;
			continue;
		}
		if (d[at] == ' ' || d[at] == '\t' || d[at] == '\r') {
			at++;
			continue;
		}
		s = at;
		while (at < len && d[at] != ' ' && d[at] != '\t' && d[at] != '\r' && d[at] != '\n')
			at++;
		n = at - s;
		if (got == want)
			return ps_err_set(e, PS_EFORMAT, "%s:%ld: more values than NROWS x NCOLS x NCOMP = %zu", name, line,
			                  want);
		if (n >= sizeof num)
			return ps_err_set(e, PS_EFORMAT, "%s:%ld: not a number", name, line);
		memcpy(num, d + s, n);
		num[n] = 0;
		errno = 0;
		x = strtod(num, &end);
		if (end == num || *end)
			return ps_err_set(e, PS_EFORMAT, "%s:%ld: not a number: '%s'", name, line, num);
		if (!(x >= 0) || isinf(x)) {
			char where[300];
			snprintf(where, sizeof where, "%s:%ld", name, line);
			return check_value(x, where, e);
		}
		v[got++] = x;
	}
	if (got < want)
		return ps_err_set(e, PS_EFORMAT, "%s:%ld: %zu values where NROWS x NCOLS x NCOMP = %d x %d x %d = %zu", name,
		                  line, got, h->nrows, h->ncols, h->ncomp, want);
	return 0;
}

static int parse_binary(const struct header *h, const unsigned char *d, size_t len, const char *name,
                        double *v, size_t want, struct ps_err *e)
{
	size_t size = h->format == 'd' ? 8 : 4, have = len - h->end;
	if (have != want * size)
		return ps_err_set(e, PS_EFORMAT, "%s: byte %zu: %zu bytes of data where NROWS x NCOLS x NCOMP = %zu %s "
		                  "values take %zu", name, h->end, have, want, h->format == 'd' ? "double" : "float",
		                  want * size);
	for (size_t i = 0; i < want; i++) {
		unsigned char b[8];
		memcpy(b, d + h->end + i * size, size);
		if (h->swap)
			swap_bytes(b, size);
		if (size == 8)
			memcpy(&v[i], b, 8);
		else {
			float f;
			memcpy(&f, b, 4);
			v[i] = f;
		}
		if (!(v[i] >= 0) || isinf(v[i])) {
			char where[300];
			snprintf(where, sizeof where, "%s: byte %zu", name, h->end + i * size);
			return check_value(v[i], where, e);
		}
	}
	return 0;
}

int ps_gridmtx_parse(struct ps_gridmtx *m, const unsigned char *data, size_t len, const char *name,
                     struct ps_err *e)
{
	struct header h;
	size_t want;
	double *v;
	memset(m, 0, sizeof *m);
	if (parse_header(data, len, name, &h, e) != 0)
		return -1;
	want = (size_t)h.nrows * (size_t)h.ncols * (size_t)h.ncomp;
	/* no more values than the file could hold (the counts are the file's word) */
	if (want > len)
		return ps_err_set(e, PS_EFORMAT, "%s:%d: NROWS x NCOLS x NCOMP = %zu values cannot fit in %zu bytes",
		                  name, h.line, want, len);
	v = malloc(want * sizeof *v);
	m->c = malloc(3 * (size_t)h.nrows * (size_t)h.ncols * sizeof *m->c);
	if (!v || !m->c) {
		free(v);
		ps_gridmtx_free(m);
		return ps_err_set(e, PS_ENOMEM, "%s: out of memory for %zu values", name, want);
	}
	if ((h.format == 'a' ? parse_ascii(&h, data, len, name, v, want, e)
	                     : parse_binary(&h, data, len, name, v, want, e)) != 0) {
		free(v);
		ps_gridmtx_free(m);
		return -1;
	}
	for (size_t i = 0; i < (size_t)h.nrows * (size_t)h.ncols; i++)
		for (int k = 0; k < 3; k++)
			m->c[3 * i + (size_t)k] = v[h.ncomp == 3 ? 3 * i + (size_t)k : i];
	free(v);
	m->npoints = h.nrows;
	m->npatch = h.ncols;
	m->mf = mf_of(h.ncols);
	return 0;
}

int ps_gridmtx_read(struct ps_gridmtx *m, const char *path, struct ps_err *e)
{
	struct ps_fileio_map f;
	int rc;
	memset(m, 0, sizeof *m);
	if (ps_fileio_map(path, MAX_FILE, &f, e) != 0)
		return -1;
	rc = ps_gridmtx_parse(m, f.data, f.len, path, e);
	ps_fileio_unmap(&f);
	return rc;
}

int ps_gridmtx_elec_parse(const char *text, size_t len, const char *name, int npoints, double *lux,
                          struct ps_err *e)
{
	static const double vl[3] = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B };
	size_t at = 0;
	int line = 0, got = 0, in_header = len >= 10 && !memcmp(text, "#?RADIANCE", 10);
	while (at < len) {
		char buf[512], *p, *end;
		size_t s = at, n;
		double rgb[3];
		while (at < len && text[at] != '\n')
			at++;
		n = at - s;
		if (at < len)
			at++;
		line++;
		if (n >= sizeof buf)
			return ps_err_set(e, PS_EFORMAT, "%s:%d: line too long for R G B", name, line);
		memcpy(buf, text + s, n);
		buf[n] = 0;
		p = buf + strspn(buf, " \t\r");
		if (in_header) {
			if (!*p)
				in_header = 0;
			continue;
		}
		if (!*p || *p == '#')
			continue;
		for (int k = 0; k < 3; k++) {
			rgb[k] = strtod(p, &end);
			if (end == p)
				return ps_err_set(e, PS_EFORMAT, "%s:%d: expected R G B irradiance (rtrace -I+), got '%s'",
				                  name, line, buf);
			if (!isfinite(rgb[k]) || rgb[k] < 0)
				return ps_err_set(e, PS_EFORMAT, "%s:%d: %s irradiance", name, line,
				                  isfinite(rgb[k]) ? "negative" : "not a finite");
			p = end;
		}
		p += strspn(p, " \t\r");
		if (*p)
			return ps_err_set(e, PS_EFORMAT, "%s:%d: more than R G B on the line", name, line);
		if (got == npoints)
			return ps_err_set(e, PS_EFORMAT, "%s:%d: more points than the grid's %d", name, line, npoints);
		lux[got++] = PS_YEAR_LUX_PER_WM2 * (vl[0] * rgb[0] + vl[1] * rgb[1] + vl[2] * rgb[2]);
	}
	if (got != npoints)
		return ps_err_set(e, PS_EFORMAT, "%s:%d: %d points where the grid has %d", name, line, got, npoints);
	return 0;
}

int ps_gridmtx_elec_read(const char *path, int npoints, double *lux, struct ps_err *e)
{
	struct ps_fileio_map f;
	int rc;
	if (ps_fileio_map(path, (size_t)1 << 28, &f, e) != 0)
		return -1;
	rc = ps_gridmtx_elec_parse((const char *)f.data, f.len, path, npoints, lux, e);
	ps_fileio_unmap(&f);
	return rc;
}
