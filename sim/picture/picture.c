/* SPDX-License-Identifier: ISC */
/* Radiance picture reading and writing.
 *
 * The whole file is read into memory and decoded in one pass into 4-byte
 * RGBE pixels in standard orientation.  Every read from the input goes through
 * struct cursor, which knows how many bytes are left, so a truncated or
 * hostile file can only produce an error naming its byte offset. */
#include "picture.h"

#include "fileio.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

enum {
	HEADER_MAX = 1 << 20,       /* a header longer than 1 MiB is not a picture */
	PIC_MAX_PIXELS = 1 << 28,   /* 1 GiB of RGBE */
	PIC_MAX_RATIO = 256,        /* pixels per remaining input byte we believe */
	RLE_MIN_LEN = 8,            /* new-style run-length scanlines: 8..0x7fff */
	RLE_MAX_LEN = 0x7fff,
	RLE_MIN_RUN = 4,            /* shorter runs are written as literals */
	ORIENT_XDECR = 1,           /* Radiance's resolution-string flags */
	ORIENT_YDECR = 2,
	ORIENT_YMAJOR = 4,
	ORIENT_STANDARD = ORIENT_YMAJOR | ORIENT_YDECR,
};

/* 2^(e-136): a stored mantissa m reads as (m + 0.5) * ps_picture_rgbe_scale[e];
 * e = 0 is black.  Hexadecimal literals make every entry exact. */
const double ps_picture_rgbe_scale[256] = {
	0.0, 0x1p-135, 0x1p-134, 0x1p-133, 0x1p-132, 0x1p-131, 0x1p-130, 0x1p-129,
	0x1p-128, 0x1p-127, 0x1p-126, 0x1p-125, 0x1p-124, 0x1p-123, 0x1p-122, 0x1p-121,
	0x1p-120, 0x1p-119, 0x1p-118, 0x1p-117, 0x1p-116, 0x1p-115, 0x1p-114, 0x1p-113,
	0x1p-112, 0x1p-111, 0x1p-110, 0x1p-109, 0x1p-108, 0x1p-107, 0x1p-106, 0x1p-105,
	0x1p-104, 0x1p-103, 0x1p-102, 0x1p-101, 0x1p-100, 0x1p-99, 0x1p-98, 0x1p-97,
	0x1p-96, 0x1p-95, 0x1p-94, 0x1p-93, 0x1p-92, 0x1p-91, 0x1p-90, 0x1p-89,
	0x1p-88, 0x1p-87, 0x1p-86, 0x1p-85, 0x1p-84, 0x1p-83, 0x1p-82, 0x1p-81,
	0x1p-80, 0x1p-79, 0x1p-78, 0x1p-77, 0x1p-76, 0x1p-75, 0x1p-74, 0x1p-73,
	0x1p-72, 0x1p-71, 0x1p-70, 0x1p-69, 0x1p-68, 0x1p-67, 0x1p-66, 0x1p-65,
	0x1p-64, 0x1p-63, 0x1p-62, 0x1p-61, 0x1p-60, 0x1p-59, 0x1p-58, 0x1p-57,
	0x1p-56, 0x1p-55, 0x1p-54, 0x1p-53, 0x1p-52, 0x1p-51, 0x1p-50, 0x1p-49,
	0x1p-48, 0x1p-47, 0x1p-46, 0x1p-45, 0x1p-44, 0x1p-43, 0x1p-42, 0x1p-41,
	0x1p-40, 0x1p-39, 0x1p-38, 0x1p-37, 0x1p-36, 0x1p-35, 0x1p-34, 0x1p-33,
	0x1p-32, 0x1p-31, 0x1p-30, 0x1p-29, 0x1p-28, 0x1p-27, 0x1p-26, 0x1p-25,
	0x1p-24, 0x1p-23, 0x1p-22, 0x1p-21, 0x1p-20, 0x1p-19, 0x1p-18, 0x1p-17,
	0x1p-16, 0x1p-15, 0x1p-14, 0x1p-13, 0x1p-12, 0x1p-11, 0x1p-10, 0x1p-9,
	0x1p-8, 0x1p-7, 0x1p-6, 0x1p-5, 0x1p-4, 0x1p-3, 0x1p-2, 0x1p-1,
	0x1p0, 0x1p1, 0x1p2, 0x1p3, 0x1p4, 0x1p5, 0x1p6, 0x1p7,
	0x1p8, 0x1p9, 0x1p10, 0x1p11, 0x1p12, 0x1p13, 0x1p14, 0x1p15,
	0x1p16, 0x1p17, 0x1p18, 0x1p19, 0x1p20, 0x1p21, 0x1p22, 0x1p23,
	0x1p24, 0x1p25, 0x1p26, 0x1p27, 0x1p28, 0x1p29, 0x1p30, 0x1p31,
	0x1p32, 0x1p33, 0x1p34, 0x1p35, 0x1p36, 0x1p37, 0x1p38, 0x1p39,
	0x1p40, 0x1p41, 0x1p42, 0x1p43, 0x1p44, 0x1p45, 0x1p46, 0x1p47,
	0x1p48, 0x1p49, 0x1p50, 0x1p51, 0x1p52, 0x1p53, 0x1p54, 0x1p55,
	0x1p56, 0x1p57, 0x1p58, 0x1p59, 0x1p60, 0x1p61, 0x1p62, 0x1p63,
	0x1p64, 0x1p65, 0x1p66, 0x1p67, 0x1p68, 0x1p69, 0x1p70, 0x1p71,
	0x1p72, 0x1p73, 0x1p74, 0x1p75, 0x1p76, 0x1p77, 0x1p78, 0x1p79,
	0x1p80, 0x1p81, 0x1p82, 0x1p83, 0x1p84, 0x1p85, 0x1p86, 0x1p87,
	0x1p88, 0x1p89, 0x1p90, 0x1p91, 0x1p92, 0x1p93, 0x1p94, 0x1p95,
	0x1p96, 0x1p97, 0x1p98, 0x1p99, 0x1p100, 0x1p101, 0x1p102, 0x1p103,
	0x1p104, 0x1p105, 0x1p106, 0x1p107, 0x1p108, 0x1p109, 0x1p110, 0x1p111,
	0x1p112, 0x1p113, 0x1p114, 0x1p115, 0x1p116, 0x1p117, 0x1p118, 0x1p119,
};

void ps_picture_rgbe_decode(const uint8_t in[4], double rgb[3])
{
	double f = ps_picture_rgbe_scale[in[3]];
	if (in[3] == 0) {
		rgb[0] = rgb[1] = rgb[2] = 0.0;
		return;
	}
	rgb[0] = (in[0] + 0.5) * f;
	rgb[1] = (in[1] + 0.5) * f;
	rgb[2] = (in[2] + 0.5) * f;
}

void ps_picture_rgbe_encode(const double rgb[3], uint8_t out[4])
{
	double c[3], d;
	int e;
	for (int i = 0; i < 3; i++)
		c[i] = (isfinite(rgb[i]) && rgb[i] > 0.0) ? rgb[i] : (isinf(rgb[i]) && rgb[i] > 0 ? 1e300 : 0.0);
	d = c[0] > c[1] ? c[0] : c[1];
	if (c[2] > d)
		d = c[2];
	if (d <= 1e-32) {
		out[0] = out[1] = out[2] = out[3] = 0;
		return;
	}
	d = frexp(d, &e) * 256.0 / d;
	if (e > 127) {          /* beyond RGBE's range: the largest colour it holds */
		out[0] = out[1] = out[2] = 255;
		out[3] = 255;
		return;
	}
	for (int i = 0; i < 3; i++) {
		double m = c[i] * d;
		out[i] = (uint8_t)(m >= 255.0 ? 255 : m);
	}
	out[3] = (uint8_t)(e + 128);
}

void ps_picture_get(const struct ps_picture *pic, int x, int y, double out[3])
{
	const uint8_t *p = pic->pix + ((size_t)y * (size_t)pic->width + (size_t)x) * 4;
	ps_picture_rgbe_decode(p, out);
	out[0] /= pic->exposure[0];
	out[1] /= pic->exposure[1];
	out[2] /= pic->exposure[2];
}

void ps_picture_free(struct ps_picture *pic)
{
	if (!pic)
		return;
	free(pic->pix);
	free(pic->view);
	free(pic->header);
	memset(pic, 0, sizeof *pic);
}

/* ---- reading -------------------------------------------------------------- */

struct cursor {
	const uint8_t *data;
	size_t len;
	size_t pos;
	const char *name;
	struct ps_err *e;
};

/* A growing string: appending costs the bytes appended, never the length so
 * far, so a header of many small lines stays linear. */
struct strbuf {
	char *p;
	size_t n, cap;
};

static int sb_append(struct strbuf *b, const char *s, size_t n)
{
	if (b->n + n + 1 > b->cap) {
		size_t cap = b->cap ? b->cap : 64;
		char *p;
		while (cap < b->n + n + 1)
			cap *= 2;
		p = realloc(b->p, cap);
		if (!p)
			return -1;
		b->p = p;
		b->cap = cap;
	}
	memcpy(b->p + b->n, s, n);
	b->n += n;
	b->p[b->n] = '\0';
	return 0;
}

static int truncated(struct cursor *c, const char *what, long scanline)
{
	if (scanline >= 0)
		return ps_err_set(c->e, PS_EFORMAT, "%s: byte %zu: file ends inside %s of scanline %ld",
		                  c->name, c->pos, what, scanline);
	return ps_err_set(c->e, PS_EFORMAT, "%s: byte %zu: file ends inside %s", c->name, c->pos, what);
}

/* Parse n doubles from s; 0 if all were there, finite, and nothing follows. */
static int parse_numbers(const char *s, double *v, int n)
{
	char *end;
	for (int i = 0; i < n; i++) {
		errno = 0;
		v[i] = strtod(s, &end);
		if (end == s || errno == ERANGE || !isfinite(v[i]))
			return -1;
		s = end;
	}
	while (*s == ' ' || *s == '\t')
		s++;
	return *s == '\0' ? 0 : -1;
}

/* Radiance takes view options from VIEW= lines and from the command lines of
 * the programs that set a view (rpict -vta ...), in header order. */
static int is_view_program(const char *line)
{
	static const char *const progs[] = { "rpict", "rview", "rvu", "rpiece", "pinterp", NULL };
	const char *end = line + strcspn(line, " \t");
	const char *base = line;
	for (const char *p = line; p < end; p++)
		if (*p == '/')
			base = p + 1;
	for (int i = 0; progs[i]; i++) {
		size_t n = strlen(progs[i]);
		if ((size_t)(end - base) == n && strncmp(base, progs[i], n) == 0)
			return 1;
	}
	return 0;
}

/* One header line (NUL-terminated, newline and any '\r' removed). */
static int header_line(struct ps_picture *pic, struct cursor *c, const char *line, int lineno,
                       struct strbuf *view)
{
	double v[8];
	if (strncmp(line, "FORMAT=", 7) == 0) {
		const char *f = line + 7;
		size_t n;
		while (*f == ' ' || *f == '\t')
			f++;
		n = strcspn(f, " \t");
		if (n == 15 && strncmp(f, "32-bit_rle_rgbe", 15) == 0)
			pic->format = PS_PIC_RGBE;
		else if (n == 15 && strncmp(f, "32-bit_rle_xyze", 15) == 0)
			pic->format = PS_PIC_XYZE;
		else
			return ps_err_set(c->e, PS_EUNSUPPORTED, "%s: header line %d: unsupported %.200s",
			                  c->name, lineno, line);
	} else if (strncmp(line, "EXPOSURE=", 9) == 0) {
		if (parse_numbers(line + 9, v, 1) != 0 || v[0] <= 0.0)
			return ps_err_set(c->e, PS_EFORMAT, "%s: header line %d: bad EXPOSURE (%.200s)",
			                  c->name, lineno, line + 9);
		for (int i = 0; i < 3; i++)
			pic->exposure[i] *= v[0];
	} else if (strncmp(line, "COLORCORR=", 10) == 0) {
		if (parse_numbers(line + 10, v, 3) != 0 || v[0] <= 0 || v[1] <= 0 || v[2] <= 0)
			return ps_err_set(c->e, PS_EFORMAT, "%s: header line %d: bad COLORCORR (%.200s)",
			                  c->name, lineno, line + 10);
		for (int i = 0; i < 3; i++)
			pic->exposure[i] *= v[i];
	} else if (strncmp(line, "PIXASPECT=", 10) == 0) {
		if (parse_numbers(line + 10, v, 1) != 0 || v[0] <= 0.0)
			return ps_err_set(c->e, PS_EFORMAT, "%s: header line %d: bad PIXASPECT (%.200s)",
			                  c->name, lineno, line + 10);
		pic->pixaspect *= v[0];
	} else if (strncmp(line, "PRIMARIES=", 10) == 0) {
		if (parse_numbers(line + 10, v, 8) != 0)
			return ps_err_set(c->e, PS_EFORMAT,
			                  "%s: header line %d: PRIMARIES needs 8 numbers (%.200s)",
			                  c->name, lineno, line + 10);
		memcpy(pic->primaries, v, sizeof pic->primaries);
		pic->has_primaries = 1;
	} else if (strncmp(line, "VIEW=", 5) == 0 || is_view_program(line)) {
		const char *opts = strncmp(line, "VIEW=", 5) == 0 ? line + 5 : line + strcspn(line, " \t");
		while (*opts == ' ' || *opts == '\t')
			opts++;
		if ((view->n && sb_append(view, " ", 1) != 0) || sb_append(view, opts, strlen(opts)) != 0)
			return ps_err_set(c->e, PS_ENOMEM, "%s: out of memory", c->name);
	}
	/* anything else (SOFTWARE=, CAPDATE=, program lines) is kept in pic->header */
	return 0;
}

/* The header: "#?" magic, lines up to an empty one.  Line numbers in messages
 * are 1-based lines of the file. */
static int read_header(struct ps_picture *pic, struct cursor *c)
{
	struct strbuf line = { 0 }, view = { 0 };
	int lineno = 0, rc = -1;
	size_t end;
	if (c->len < 2 || c->data[0] != '#' || c->data[1] != '?')
		return ps_err_set(c->e, PS_EFORMAT, "%s: byte 0: not a Radiance picture (no '#?' magic)",
		                  c->name);
	for (;;) {
		size_t avail = c->len - c->pos, n;
		const uint8_t *start = c->data + c->pos, *nl;
		/* look for the newline no further than the header may reach */
		if (avail > HEADER_MAX - c->pos)
			avail = HEADER_MAX - c->pos;
		nl = memchr(start, '\n', avail);
		lineno++;
		if (!nl) {
			if (c->len > HEADER_MAX)
				ps_err_set(c->e, PS_EFORMAT, "%s: header line %d: header longer than %d bytes",
				           c->name, lineno, HEADER_MAX);
			else
				truncated(c, "the header (no empty line ends it)", -1);
			goto out;
		}
		n = (size_t)(nl - start);
		if (memchr(start, '\0', n)) {
			ps_err_set(c->e, PS_EFORMAT, "%s: header line %d (byte %zu): NUL byte in header",
			           c->name, lineno, c->pos + (size_t)((const uint8_t *)memchr(start, '\0', n) - start));
			goto out;
		}
		c->pos += n + 1;
		if (n > 0 && start[n - 1] == '\r')
			n--;
		if (n == 0)
			break;
		line.n = 0;
		if (sb_append(&line, (const char *)start, n) != 0) {
			ps_err_set(c->e, PS_ENOMEM, "%s: out of memory", c->name);
			goto out;
		}
		if (header_line(pic, c, line.p, lineno, &view) != 0)
			goto out;
	}
	/* Radiance assumes 32-bit_rle_rgbe when FORMAT= is absent (format is 0). */
	end = c->pos;   /* the header text kept: everything before the empty line */
	while (end > 0 && (c->data[end - 1] == '\n' || c->data[end - 1] == '\r'))
		end--;
	pic->header = malloc(end + 2);
	if (!pic->header) {
		ps_err_set(c->e, PS_ENOMEM, "%s: out of memory", c->name);
		goto out;
	}
	memcpy(pic->header, c->data, end);
	pic->header[end] = '\n';
	pic->header[end + 1] = '\0';
	pic->view = view.p;
	view.p = NULL;
	rc = 0;
out:
	free(line.p);
	free(view.p);
	return rc;
}

/* One "-Y" / "+X" axis and its count in a resolution line. */
static int parse_axis(const char **s, char *sign, char *axis, long *count)
{
	const char *p = *s;
	long v = 0;
	while (*p == ' ' || *p == '\t')
		p++;
	if ((p[0] != '-' && p[0] != '+') || (p[1] != 'X' && p[1] != 'Y'))
		return -1;
	*sign = p[0];
	*axis = p[1];
	p += 2;
	if (*p != ' ' && *p != '\t')
		return -1;
	while (*p == ' ' || *p == '\t')
		p++;
	if (*p < '0' || *p > '9')
		return -1;
	for (; *p >= '0' && *p <= '9'; p++) {
		if (v > (long)INT_MAX / 10)
			return -2;   /* too large for any picture */
		v = v * 10 + (*p - '0');
	}
	*count = v;
	*s = p;
	return 0;
}

/* "-Y 256 +X 512\n" and its seven siblings: the first axis is the slow one
 * (scanlines), the second the fast one (pixels within a scanline). */
static int read_resolution(struct cursor *c, int *orient, long *slow, long *fast)
{
	char buf[80];
	const uint8_t *nl;
	const char *s = buf;
	size_t n;
	char s1, a1, s2, a2;
	long n1 = 0, n2 = 0;
	int r1, r2 = -1;
	if (c->pos >= c->len)
		return truncated(c, "the resolution line", -1);
	nl = memchr(c->data + c->pos, '\n', c->len - c->pos);
	n = nl ? (size_t)(nl - (c->data + c->pos)) : c->len - c->pos;
	if (n >= sizeof buf)
		n = sizeof buf - 1;
	memcpy(buf, c->data + c->pos, n);
	buf[n] = '\0';
	if (memchr(buf, '\0', n))
		return ps_err_set(c->e, PS_EFORMAT, "%s: byte %zu: bad resolution line (NUL byte)",
		                  c->name, c->pos);
	if (!nl)
		return ps_err_set(c->e, PS_EFORMAT, "%s: byte %zu: no resolution line after the header%s%.40s%s",
		                  c->name, c->pos, n ? " ('" : "", buf, n ? "')" : "");
	r1 = parse_axis(&s, &s1, &a1, &n1);
	if (r1 == 0)
		r2 = parse_axis(&s, &s2, &a2, &n2);
	if (r1 == 0 && r2 == 0) {
		while (*s == ' ' || *s == '\t' || *s == '\r')
			s++;
	}
	if (r1 != -2 && (r1 == -1 || r2 == -1 || *s != '\0' || a1 == a2))
		return ps_err_set(c->e, PS_EFORMAT, "%s: byte %zu: bad resolution line '%.60s'",
		                  c->name, c->pos, buf);
	if (r1 == -2 || r2 == -2 || n1 <= 0 || n2 <= 0)
		return ps_err_set(c->e, PS_ERANGE, "%s: byte %zu: bad picture size in '%.60s'",
		                  c->name, c->pos, buf);
	c->pos += (size_t)(nl - (c->data + c->pos)) + 1;
	*orient = 0;
	if (a1 == 'Y')
		*orient |= ORIENT_YMAJOR;
	if ((a1 == 'X' ? s1 : s2) == '-')
		*orient |= ORIENT_XDECR;
	if ((a1 == 'Y' ? s1 : s2) == '-')
		*orient |= ORIENT_YDECR;
	*slow = n1;
	*fast = n2;
	return 0;
}

/* Old-style scanline: flat pixels, with 1 1 1 n repeating the previous pixel
 * n << shift times (shift grows by 8 for each consecutive repeat). */
static int read_old_scanline(struct cursor *c, uint8_t *sl, long len, long scanline)
{
	int shift = 0;
	long j = 0;
	while (j < len) {
		const uint8_t *p;
		if (c->len - c->pos < 4)
			return truncated(c, "a pixel", scanline);
		p = c->data + c->pos;
		if (p[0] == 1 && p[1] == 1 && p[2] == 1) {
			unsigned long count;
			if (j == 0)
				return ps_err_set(c->e, PS_EFORMAT,
				                  "%s: byte %zu: scanline %ld starts with a repeat of no pixel",
				                  c->name, c->pos, scanline);
			if (shift > 24)
				return ps_err_set(c->e, PS_EFORMAT,
				                  "%s: byte %zu: repeat count overflows in scanline %ld",
				                  c->name, c->pos, scanline);
			count = (unsigned long)p[3] << shift;
			if (count > (unsigned long)(len - j))
				return ps_err_set(c->e, PS_EFORMAT,
				                  "%s: byte %zu: repeat of %lu pixels overruns scanline %ld (%ld left)",
				                  c->name, c->pos, count, scanline, len - j);
			if (sl)
				for (unsigned long k = 0; k < count; k++)
					memcpy(sl + 4 * (j + (long)k), sl + 4 * (j - 1), 4);
			j += (long)count;
			shift += 8;
		} else {
			if (sl)
				memcpy(sl + 4 * j, p, 4);
			j++;
			shift = 0;
		}
		c->pos += 4;
	}
	return 0;
}

/* One scanline of len pixels into sl (len * 4 bytes), in whichever encoding
 * the file used for it; sl NULL only checks it and moves past it. */
static int read_scanline(struct cursor *c, uint8_t *sl, long len, long scanline)
{
	const uint8_t *p;
	if (len < RLE_MIN_LEN || len > RLE_MAX_LEN)
		return read_old_scanline(c, sl, len, scanline);
	if (c->len - c->pos < 4)
		return truncated(c, "the start", scanline);
	p = c->data + c->pos;
	if (p[0] != 2 || p[1] != 2 || (p[2] & 0x80))
		return read_old_scanline(c, sl, len, scanline);
	if (((long)p[2] << 8 | p[3]) != len)
		return ps_err_set(c->e, PS_EFORMAT,
		                  "%s: byte %zu: scanline %ld says %ld pixels, the picture has %ld",
		                  c->name, c->pos, scanline, (long)p[2] << 8 | p[3], len);
	c->pos += 4;
	for (int comp = 0; comp < 4; comp++) {
		uint8_t *o = sl ? sl + comp : NULL;
		long j = 0;
		while (j < len) {
			unsigned code;
			if (c->pos >= c->len)
				return truncated(c, "run-length data", scanline);
			code = c->data[c->pos];
			if (code > 128) {
				uint8_t v;
				code &= 127;
				if ((long)code > len - j)
					return ps_err_set(c->e, PS_EFORMAT,
					                  "%s: byte %zu: run of %u overruns scanline %ld",
					                  c->name, c->pos, code, scanline);
				if (c->len - c->pos < 2)
					return truncated(c, "a run", scanline);
				v = c->data[c->pos + 1];
				if (o)
					for (unsigned k = 0; k < code; k++)
						o[4 * (j + (long)k)] = v;
				j += code;
				c->pos += 2;
			} else {
				const uint8_t *q = c->data + c->pos + 1;
				if (code == 0)
					return ps_err_set(c->e, PS_EFORMAT,
					                  "%s: byte %zu: zero-length run in scanline %ld",
					                  c->name, c->pos, scanline);
				if ((long)code > len - j)
					return ps_err_set(c->e, PS_EFORMAT,
					                  "%s: byte %zu: literal of %u overruns scanline %ld",
					                  c->name, c->pos, code, scanline);
				if (c->len - c->pos - 1 < code)
					return truncated(c, "literal data", scanline);
				if (o)
					for (unsigned k = 0; k < code; k++)
						o[4 * (j + (long)k)] = q[k];
				j += code;
				c->pos += 1 + code;
			}
		}
	}
	return 0;
}

/* Where pixel p of scanline s lands in standard orientation (row 0 = top). */
static size_t standard_index(const struct ps_picture *pic, int orient, long slow, long fast,
                             long s, long p)
{
	long xc, yc;   /* coordinates increasing along +X and +Y */
	if (orient & ORIENT_YMAJOR) {
		yc = (orient & ORIENT_YDECR) ? slow - 1 - s : s;
		xc = (orient & ORIENT_XDECR) ? fast - 1 - p : p;
	} else {
		xc = (orient & ORIENT_XDECR) ? slow - 1 - s : s;
		yc = (orient & ORIENT_YDECR) ? fast - 1 - p : p;
	}
	return (size_t)(pic->height - 1 - yc) * (size_t)pic->width + (size_t)xc;
}

/* Refuse sizes no file of this length can hold before allocating.  The
 * densest encoding Radiance writes is a new-style scanline of 127-pixel
 * runs, under 16 pixels a byte; PIC_MAX_RATIO leaves room for old-style
 * repeats while keeping a hostile file from asking for more than a few
 * hundred times its own size. */
static int check_size(struct cursor *c, long slow, long fast)
{
	size_t npix = (size_t)slow * (size_t)fast, left = c->len - c->pos;
	if (npix > PIC_MAX_PIXELS || npix / PIC_MAX_RATIO > left)
		return ps_err_set(c->e, PS_ERANGE, "%s: byte %zu: %ld x %ld pixels cannot be in the %zu "
		                  "bytes left", c->name, c->pos, slow, fast, left);
	return 0;
}

int ps_picture_read_mem(struct ps_picture *pic, const uint8_t *data, size_t len, const char *name,
                        struct ps_err *e)
{
	struct cursor c = { data, len, 0, name ? name : "(picture)", e };
	long slow = 0, fast = 0;
	int orient = 0;
	size_t npix;
	uint8_t *sl = NULL;
	memset(pic, 0, sizeof *pic);
	pic->exposure[0] = pic->exposure[1] = pic->exposure[2] = 1.0;
	pic->pixaspect = 1.0;
	if (!data && len)
		return ps_err_set(e, PS_EINVAL, "%s: no data", c.name);
	if (read_header(pic, &c) != 0 || read_resolution(&c, &orient, &slow, &fast) != 0)
		goto fail;
	if (check_size(&c, slow, fast) != 0)
		goto fail;
	npix = (size_t)slow * (size_t)fast;
	pic->orientation = orient;
	if (orient & ORIENT_YMAJOR) {
		pic->height = (int)slow;
		pic->width = (int)fast;
	} else {
		pic->width = (int)slow;
		pic->height = (int)fast;
	}
	pic->pix = malloc(npix * 4);
	if (orient != ORIENT_STANDARD)
		sl = malloc((size_t)fast * 4);
	if (!pic->pix || (orient != ORIENT_STANDARD && !sl)) {
		ps_err_set(e, PS_ENOMEM, "%s: out of memory for %ld x %ld pixels", c.name, slow, fast);
		goto fail;
	}
	for (long s = 0; s < slow; s++) {
		if (orient == ORIENT_STANDARD) {   /* scanline s is row s: decode in place */
			if (read_scanline(&c, pic->pix + (size_t)s * (size_t)fast * 4, fast, s) != 0)
				goto fail;
			continue;
		}
		if (read_scanline(&c, sl, fast, s) != 0)
			goto fail;
		for (long p = 0; p < fast; p++)
			memcpy(pic->pix + 4 * standard_index(pic, orient, slow, fast, s, p), sl + 4 * p, 4);
	}
	/* Bytes after the last scanline are ignored, as Radiance does. */
	free(sl);
	return 0;
fail:
	free(sl);
	ps_picture_free(pic);
	return -1;
}

int ps_picture_read(struct ps_picture *pic, const char *path, struct ps_err *e)
{
	uint8_t *buf;
	size_t len;
	int rc;
	memset(pic, 0, sizeof *pic);
	/* 4 GiB: more than the largest picture we accept could need */
	if (ps_fileio_read(path, (size_t)4 << 30, &buf, &len, e) != 0)
		return -1;
	rc = ps_picture_read_mem(pic, buf, len, path, e);
	free(buf);
	return rc;
}

/* ---- row by row ------------------------------------------------------------ */

int ps_picture_head_mem(struct ps_picture *pic, const uint8_t *data, size_t len, const char *name,
                        size_t *data_off, struct ps_err *e)
{
	struct cursor c = { data, len, 0, name ? name : "(picture)", e };
	long slow = 0, fast = 0;
	int orient = 0;
	memset(pic, 0, sizeof *pic);
	pic->exposure[0] = pic->exposure[1] = pic->exposure[2] = 1.0;
	pic->pixaspect = 1.0;
	if (!data && len)
		return ps_err_set(e, PS_EINVAL, "%s: no data", c.name);
	if (read_header(pic, &c) != 0 || read_resolution(&c, &orient, &slow, &fast) != 0 ||
	    check_size(&c, slow, fast) != 0) {
		ps_picture_free(pic);
		return -1;
	}
	pic->orientation = orient;
	if (orient & ORIENT_YMAJOR) {
		pic->height = (int)slow;
		pic->width = (int)fast;
	} else {
		pic->width = (int)slow;
		pic->height = (int)fast;
	}
	*data_off = c.pos;
	return 0;
}

int ps_picture_is_standard(const struct ps_picture *pic)
{
	return pic->orientation == ORIENT_STANDARD;
}

int ps_picture_scanline_starts(const struct ps_picture *pic, const uint8_t *data, size_t len,
                               const char *name, size_t off, size_t *starts, struct ps_err *e)
{
	struct cursor c = { data, len, off, name ? name : "(picture)", e };
	if (pic->orientation != ORIENT_STANDARD)
		return ps_err_set(e, PS_EUNSUPPORTED, "%s: scanlines are not rows (orientation)", c.name);
	for (long s = 0; s < pic->height; s++) {
		starts[s] = c.pos;
		if (read_scanline(&c, NULL, pic->width, s) != 0)
			return -1;
	}
	return 0;
}

int ps_picture_scan_rows(const struct ps_picture *pic, const uint8_t *data, size_t len,
                         const char *name, size_t off, int y0, int y1, const uint8_t *want,
                         int (*row)(void *ctx, int y, const uint8_t *rgbe), void *ctx,
                         struct ps_err *e)
{
	struct cursor c = { data, len, off, name ? name : "(picture)", e };
	uint8_t *sl;
	int rc = 0;
	if (pic->orientation != ORIENT_STANDARD)
		return ps_err_set(e, PS_EUNSUPPORTED, "%s: scanlines are not rows (orientation)", c.name);
	sl = malloc((size_t)pic->width * 4);
	if (!sl)
		return ps_err_set(e, PS_ENOMEM, "%s: out of memory", c.name);
	for (int y = y0; y < y1; y++) {
		int use = !want || want[y];
		/* a row nobody wants is checked and passed, not decoded */
		if (read_scanline(&c, use ? sl : NULL, pic->width, y) != 0) {
			rc = -1;
			break;
		}
		if (use && (rc = row(ctx, y, sl)) != 0)
			break;
	}
	free(sl);
	return rc;
}

/* ---- writing -------------------------------------------------------------- */

/* One component plane of a new-style scanline: runs of at least RLE_MIN_RUN
 * equal bytes (up to 127) as 128+n, value; everything else as literals of
 * up to 128 bytes. */
static void put_plane(FILE *fp, const uint8_t *sl, long len, int comp)
{
	long j = 0;
	while (j < len) {
		long lit_end = j, run = 0;
		/* find where the next run of RLE_MIN_RUN or more starts */
		while (lit_end < len) {
			run = 1;
			while (run < 127 && lit_end + run < len &&
			       sl[4 * (lit_end + run) + comp] == sl[4 * lit_end + comp])
				run++;
			if (run >= RLE_MIN_RUN)
				break;
			lit_end += run;
			run = 0;
		}
		while (j < lit_end) {
			long n = lit_end - j > 128 ? 128 : lit_end - j;
			putc((int)n, fp);
			for (long k = 0; k < n; k++)
				putc(sl[4 * (j + k) + comp], fp);
			j += n;
		}
		if (run >= RLE_MIN_RUN) {
			putc((int)(128 + run), fp);
			putc(sl[4 * j + comp], fp);
			j += run;
		}
	}
}

int ps_picture_write_fp(FILE *fp, const char *path, int width, int height, const double *rgb,
                        const char *view, const char *extra_header, struct ps_err *e)
{
	uint8_t *sl;
	if (width <= 0 || height <= 0)
		return ps_err_set(e, PS_EINVAL, "%s: bad picture size %d x %d", path, width, height);
	sl = malloc((size_t)width * 4);
	if (!sl)
		return ps_err_set(e, PS_ENOMEM, "%s: out of memory", path);
	fputs("#?RADIANCE\n", fp);
	if (extra_header)
		fputs(extra_header, fp);
	if (view)
		fprintf(fp, "VIEW= %s\n", view);
	fputs("FORMAT=32-bit_rle_rgbe\n\n", fp);
	fprintf(fp, "-Y %d +X %d\n", height, width);
	for (int y = 0; y < height; y++) {
		for (int x = 0; x < width; x++)
			ps_picture_rgbe_encode(rgb + 3 * ((size_t)y * (size_t)width + (size_t)x), sl + 4 * x);
		if (width < RLE_MIN_LEN || width > RLE_MAX_LEN) {
			fwrite(sl, 4, (size_t)width, fp);
			continue;
		}
		putc(2, fp);
		putc(2, fp);
		putc(width >> 8, fp);
		putc(width & 0xff, fp);
		for (int comp = 0; comp < 4; comp++)
			put_plane(fp, sl, width, comp);
	}
	free(sl);
	if (ferror(fp))
		return ps_err_sys(e, "%s: write error", path);
	return 0;
}

int ps_picture_write(const char *path, int width, int height, const double *rgb, const char *view,
                     const char *extra_header, struct ps_err *e)
{
	FILE *fp = fopen(path, "wb");
	int rc;
	if (!fp)
		return ps_err_sys(e, "%s", path);
	rc = ps_picture_write_fp(fp, path, width, height, rgb, view, extra_header, e);
	if (fclose(fp) != 0 && rc == 0)
		rc = ps_err_sys(e, "%s: write error", path);
	return rc;
}
