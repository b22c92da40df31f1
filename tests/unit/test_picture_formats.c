/* SPDX-License-Identifier: ISC */
/* Radiance pictures, part two: every orientation in every scanline encoding,
 * the encoder's choice of encoding by width, RGBE rounding against its
 * analytic definition, header details, hostile sizes and a real rpict render.
 * The pictures are built here by an encoder of our own (runs of 2 or more,
 * unlike the library's 4), so the reader is checked against the format, not
 * against the library's writer. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <unistd.h>
#include <cmocka.h>

#include "picture.h"
#include "sum.h"

struct buf {
	uint8_t *p;
	size_t n, cap;
};

static void put(struct buf *b, const void *data, size_t n)
{
	if (b->n + n > b->cap) {
		b->cap = (b->n + n) * 2 + 64;
		b->p = realloc(b->p, b->cap);
		assert_non_null(b->p);
	}
	memcpy(b->p + b->n, data, n);
	b->n += n;
}

static void put_str(struct buf *b, const char *s)
{
	put(b, s, strlen(s));
}

static void put_byte(struct buf *b, int v)
{
	uint8_t c = (uint8_t)v;
	put(b, &c, 1);
}

enum enc { ENC_FLAT, ENC_OLD, ENC_NEW };

/* Flat: 4 bytes a pixel. */
static void emit_flat(struct buf *b, const uint8_t *sl, int len)
{
	put(b, sl, (size_t)len * 4);
}

/* Old style: a pixel equal to the previous one is counted, and the count is
 * written as repeat markers 1 1 1 n, low byte first, each further marker
 * worth 256 times more. */
static void emit_old(struct buf *b, const uint8_t *sl, int len)
{
	int j = 0;
	while (j < len) {
		int k = 0;
		put(b, sl + 4 * j, 4);
		while (j + 1 + k < len && memcmp(sl + 4 * (j + 1 + k), sl + 4 * j, 4) == 0)
			k++;
		for (int rest = k; rest > 0; rest >>= 8) {
			uint8_t m[4] = { 1, 1, 1, (uint8_t)(rest & 255) };
			put(b, m, 4);
		}
		j += 1 + k;
	}
}

/* New style: 2 2 hi lo, then each component plane as runs (128 + n, value)
 * of 2..127 equal bytes and literals (n, n bytes) of 1..128. */
static void emit_new(struct buf *b, const uint8_t *sl, int len)
{
	uint8_t h[4] = { 2, 2, (uint8_t)(len >> 8), (uint8_t)(len & 255) };
	put(b, h, 4);
	for (int c = 0; c < 4; c++) {
		int j = 0;
		while (j < len) {
			int run = 1, lit = 0;
			while (j + run < len && run < 127 && sl[4 * (j + run) + c] == sl[4 * j + c])
				run++;
			if (run >= 2) {
				put_byte(b, 128 + run);
				put_byte(b, sl[4 * j + c]);
				j += run;
				continue;
			}
			while (j + lit < len && lit < 128 &&
			       (j + lit + 1 >= len || sl[4 * (j + lit + 1) + c] != sl[4 * (j + lit) + c]))
				lit++;
			if (lit == 0)
				lit = 1;
			put_byte(b, lit);
			for (int k = 0; k < lit; k++)
				put_byte(b, sl[4 * (j + k) + c]);
			j += lit;
		}
	}
}

static void emit_scanline(struct buf *b, const uint8_t *sl, int len, enum enc enc)
{
	if (enc == ENC_NEW)
		emit_new(b, sl, len);
	else if (enc == ENC_OLD)
		emit_old(b, sl, len);
	else
		emit_flat(b, sl, len);
}

/* The test picture: W x H, asymmetric in both axes, with runs.  (x, y) with y
 * counted up from the bottom. */
static void test_pixel(int x, int y, uint8_t px[4])
{
	px[0] = (uint8_t)(10 + x);
	px[1] = (uint8_t)(40 + y);
	px[2] = (uint8_t)(x < 4 ? 200 : 100 + (y % 3));
	px[3] = 130;
}

/* Emit the W x H test picture with resolution string res (e.g. "+X 10 -Y 13"),
 * scanline s in encoding enc_of(s). */
static void emit_picture(struct buf *b, const char *res, int w, int h, enum enc (*enc_of)(int))
{
	char a1 = res[1], s1 = res[0], s2 = res[strlen(res) - 1];
	int n1 = a1 == 'Y' ? h : w, n2 = a1 == 'Y' ? w : h;
	uint8_t *sl = malloc((size_t)n2 * 4);
	char line[64];
	/* the second sign is at the start of the second axis */
	s2 = strchr(res + 2, a1 == 'Y' ? 'X' : 'Y')[-1];
	put_str(b, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n");
	snprintf(line, sizeof line, "%c%c %d %c%c %d\n", s1, a1, n1, s2, a1 == 'Y' ? 'X' : 'Y', n2);
	put_str(b, line);
	for (int s = 0; s < n1; s++) {
		for (int p = 0; p < n2; p++) {
			int c1 = s1 == '+' ? s : n1 - 1 - s, c2 = s2 == '+' ? p : n2 - 1 - p;
			test_pixel(a1 == 'Y' ? c2 : c1, a1 == 'Y' ? c1 : c2, sl + 4 * p);
		}
		emit_scanline(b, sl, n2, enc_of(s));
	}
	free(sl);
}

static void check_test_picture(const struct ps_picture *pic, int w, int h)
{
	assert_int_equal(pic->width, w);
	assert_int_equal(pic->height, h);
	for (int row = 0; row < h; row++)
		for (int x = 0; x < w; x++) {
			uint8_t want[4];
			test_pixel(x, h - 1 - row, want);   /* row 0 is the top */
			if (memcmp(pic->pix + 4 * ((size_t)row * (size_t)w + (size_t)x), want, 4) != 0)
				fail_msg("pixel x=%d row=%d differs", x, row);
		}
}

static enum enc all_flat(int s) { (void)s; return ENC_FLAT; }
static enum enc all_old(int s) { (void)s; return ENC_OLD; }
static enum enc all_new(int s) { (void)s; return ENC_NEW; }
static enum enc mixed(int s) { return (enum enc)(s % 3); }

static const char *const orientations[8] = { "-Y +X", "-Y -X", "+Y -X", "+Y +X",
                                             "+X -Y", "+X +Y", "-X +Y", "-X -Y" };

/* 10 x 13: both axes are in new-style range (8..32767), so every scanline of
 * every orientation can take every encoding. */
static void orientations_in_every_encoding(void **state)
{
	enum enc (*encs[4])(int) = { all_flat, all_old, all_new, mixed };
	(void)state;
	for (int k = 0; k < 8; k++)
		for (int m = 0; m < 4; m++) {
			struct buf b = { 0 };
			struct ps_picture pic;
			struct ps_err e;
			emit_picture(&b, orientations[k], 10, 13, encs[m]);
			if (ps_picture_read_mem(&pic, b.p, b.n, orientations[k], &e) != 0)
				fail_msg("%s encoding %d: %s", orientations[k], m, e.msg);
			check_test_picture(&pic, 10, 13);
			ps_picture_free(&pic);
			free(b.p);
		}
}

static void tiny_pictures(void **state)
{
	(void)state;
	for (int n = 1; n <= 2; n++)
		for (int k = 0; k < 8; k++) {
			struct buf b = { 0 };
			struct ps_picture pic;
			struct ps_err e;
			emit_picture(&b, orientations[k], n, n, n == 1 ? all_flat : all_old);
			assert_int_equal(ps_picture_read_mem(&pic, b.p, b.n, "tiny", &e), 0);
			check_test_picture(&pic, n, n);
			ps_picture_free(&pic);
			free(b.p);
		}
}

/* Widths beyond 0x7fff can only be old-style.  Scanline 0 is one pixel and
 * two consecutive repeat markers (0x3f + 0x9c << 8 = 39999 repeats); scanline
 * 1 is flat (a file must hold at least a byte per 256 pixels to be believed). */
static void wide_old_style_repeats(void **state)
{
	struct buf b = { 0 };
	struct ps_picture pic;
	struct ps_err e;
	static const uint8_t px[4] = { 9, 8, 7, 140 }, r1[4] = { 1, 1, 1, 0x3f },
	                     r2[4] = { 1, 1, 1, 0x9c };
	size_t marker;
	(void)state;
	put_str(&b, "#?RADIANCE\n\n-Y 2 +X 40000\n");
	put(&b, px, 4);
	put(&b, r1, 4);
	marker = b.n;
	put(&b, r2, 4);
	for (int x = 0; x < 40000; x++) {
		uint8_t q[4] = { (uint8_t)x, (uint8_t)(x >> 8), 3, 130 };
		put(&b, q, 4);
	}
	assert_int_equal(ps_picture_read_mem(&pic, b.p, b.n, "wide", &e), 0);
	assert_int_equal(pic.width, 40000);
	assert_int_equal(pic.height, 2);
	for (int x = 0; x < 40000; x++) {
		assert_memory_equal(pic.pix + 4 * x, px, 4);
		assert_int_equal(pic.pix[4 * (40000 + x)], x & 255);
		assert_int_equal(pic.pix[4 * (40000 + x) + 1], x >> 8);
	}
	ps_picture_free(&pic);
	/* one more pixel's worth of repeat overruns the scanline */
	b.p[marker - 1] = 0x40;
	assert_int_equal(ps_picture_read_mem(&pic, b.p, b.n, "wide", &e), -1);
	assert_non_null(strstr(e.msg, "overruns scanline 0"));
	free(b.p);
}

static uint8_t *slurp(const char *path, size_t *n)
{
	FILE *fp = fopen(path, "rb");
	uint8_t *d;
	long len;
	assert_non_null(fp);
	fseek(fp, 0, SEEK_END);
	len = ftell(fp);
	rewind(fp);
	d = malloc((size_t)len + 1);
	assert_int_equal(fread(d, 1, (size_t)len, fp), (size_t)len);
	fclose(fp);
	*n = (size_t)len;
	return d;
}

/* The writer run-length encodes widths 8..32767 and writes the rest flat. */
static void encoding_choice_by_width(void **state)
{
	static const int widths[] = { 7, 8, 32767, 32768 };
	(void)state;
	for (size_t k = 0; k < 4; k++) {
		int w = widths[k], h = 2;
		double *rgb = malloc(sizeof(double) * 3 * (size_t)w * (size_t)h);
		char path[] = "/tmp/pspicXXXXXX", res[64];
		int fd = mkstemp(path);
		struct ps_picture pic;
		struct ps_err e;
		uint8_t *d;
		size_t n, body;
		const uint8_t *start;
		for (int i = 0; i < w * h; i++)
			rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = (i % 1000) < 500 ? 2.0 : 0.5;
		close(fd);
		assert_int_equal(ps_picture_write(path, w, h, rgb, NULL, NULL, &e), 0);
		d = slurp(path, &n);
		snprintf(res, sizeof res, "\n-Y %d +X %d\n", h, w);
		start = memmem(d, n, res, strlen(res));
		assert_non_null(start);
		body = n - (size_t)(start + strlen(res) - d);
		start += strlen(res);
		if (w >= 8 && w <= 32767) {
			assert_int_equal(start[0], 2);
			assert_int_equal(start[1], 2);
			assert_int_equal(start[2] << 8 | start[3], w);
			assert_true(body < (size_t)w * (size_t)h * 4);   /* smaller than flat */
		} else {
			assert_int_equal(body, (size_t)w * (size_t)h * 4);   /* flat */
		}
		assert_int_equal(ps_picture_read_mem(&pic, d, n, path, &e), 0);
		assert_int_equal(pic.width, w);
		for (int i = 0; i < w * h; i++) {
			double v[3];
			/* 2.0 -> m 128, e 130: 128.5 * 2^-6; 0.5 -> 128.5 * 2^-8 */
			ps_picture_get(&pic, i % w, i / w, v);
			assert_true(v[0] == ((i % 1000) < 500 ? 128.5 / 64 : 128.5 / 256));
		}
		ps_picture_free(&pic);
		free(d);
		free(rgb);
		unlink(path);
	}
}

/* setcolr() by its definition: with 2^(E-1) <= max < 2^E, the exponent byte
 * is E + 128 and each mantissa floor(c * 2^(8 - E)). */
static void rgbe_rounding_is_radiance_s(void **state)
{
	int n = 0;
	(void)state;
	for (double v = 1e-30; v <= 1e30; v *= 1.37) {
		double in[3] = { v, v * 0.61, v * 0.0031 }, out[3];
		uint8_t px[4];
		int big = ilogb(v) + 1;
		ps_picture_rgbe_encode(in, px);
		assert_int_equal(px[3], big + 128);
		for (int c = 0; c < 3; c++) {
			double m = floor(ldexp(in[c], 8 - big));
			assert_int_equal(px[c], (int)m);
		}
		ps_picture_rgbe_decode(px, out);
		for (int c = 0; c < 3; c++)
			assert_true(out[c] == ldexp(px[c] + 0.5, px[3] - 136));
		/* the largest channel: relative error at most 2^-8 */
		assert_true(fabs(out[0] - v) <= ldexp(v, -8));
		n++;
	}
	assert_true(n > 400);
	/* powers of two hit the bound exactly: m = 128 reads as 128.5 */
	{
		uint8_t px[4];
		double out[3];
		ps_picture_rgbe_encode((double[3]){ 0x1p-90, 0x1p-90, 0x1p-90 }, px);
		ps_picture_rgbe_decode(px, out);
		assert_true(out[0] == 0x1p-90 * (1 + 0x1p-8));
	}
	/* black, tiny, negative and not-a-number encode as 0 0 0 0 */
	{
		uint8_t px[4];
		ps_picture_rgbe_encode((double[3]){ 1e-33, -5, NAN }, px);
		assert_int_equal(px[0] | px[1] | px[2] | px[3], 0);
	}
}

static int read_text(const char *text, struct ps_picture *pic, struct ps_err *e)
{
	return ps_picture_read_mem(pic, (const uint8_t *)text, strlen(text), "t.hdr", e);
}

static void header_details(void **state)
{
	struct ps_picture pic;
	struct ps_err e;
	double v[3];
	(void)state;
	/* no FORMAT line: rgbe, as Radiance assumes; any "#?" program id; CRLF */
	assert_int_equal(read_text("#?RGBE\r\nSOFTWARE= x\r\n\r\n-Y 1 +X 1\r\n\x80\x40\x20\x81", &pic, &e), 0);
	assert_int_equal(pic.format, PS_PIC_RGBE);
	ps_picture_get(&pic, 0, 0, v);
	assert_true(v[0] == 128.5 / 128 && v[1] == 64.5 / 128 && v[2] == 32.5 / 128);
	assert_non_null(strstr(pic.header, "SOFTWARE= x"));
	assert_null(pic.view);
	ps_picture_free(&pic);
	/* trailing bytes after the last scanline are ignored, as by Radiance */
	assert_int_equal(read_text("#?RADIANCE\n\n-Y 1 +X 1\n\x80\x40\x20\x81 trailing", &pic, &e), 0);
	ps_picture_free(&pic);
	/* EXPOSURE with surrounding blanks; several multiply */
	assert_int_equal(read_text("#?RADIANCE\nEXPOSURE= 0.5 \nEXPOSURE=8\n\n-Y 1 +X 1\n\x80\x80\x80\x81",
	                           &pic, &e), 0);
	ps_picture_get(&pic, 0, 0, v);
	assert_true(v[0] == 1.00390625 / 4);
	ps_picture_free(&pic);
	/* the resolution line as rpict writes it, with padded numbers */
	assert_int_equal(read_text("#?RADIANCE\n\n-Y      1 +X      1\n\x80\x80\x80\x81", &pic, &e), 0);
	ps_picture_free(&pic);
}

static void header_errors_name_the_line(void **state)
{
	static const struct {
		const char *text, *want;
	} cases[] = {
		{ "#?RADIANCE\nA=1\nB=2\nCOLORCORR=1 2\n\n-Y 1 +X 1\n", "t.hdr: header line 4: bad COLORCORR" },
		{ "#?RADIANCE\nPIXASPECT=0\n\n-Y 1 +X 1\n", "t.hdr: header line 2: bad PIXASPECT" },
		{ "#?RADIANCE\nX=1\nFORMAT=32-bit_rle_rgbf\n\n-Y 1 +X 1\n", "t.hdr: header line 3: unsupported FORMAT" },
		{ "#?RADIANCE\nEXPOSURE=1e999\n\n-Y 1 +X 1\n", "t.hdr: header line 2: bad EXPOSURE" },
		{ "#?RADIANCE\nEXPOSURE=2 3\n\n-Y 1 +X 1\n", "t.hdr: header line 2: bad EXPOSURE" },
		{ "#?RADIANCE\n\n", "t.hdr: byte 12: file ends inside the resolution line" },
		{ "#?RADIANCE\n\n\x80\x80\x80\x81", "t.hdr: byte 12: no resolution line" },
		{ "#?RADIANCE\n\n-Y 1 +Y 1\n", "t.hdr: byte 12: bad resolution line" },
		{ "#?RADIANCE\n\n-Y 1 +X 1 +Z\n", "t.hdr: byte 12: bad resolution line" },
		{ "#?RADIANCE\n\n-Y -1 +X 1\n", "t.hdr: byte 12: bad resolution line" },
		{ "#?RADIANCE\n\n-Y 99999999999999999999 +X 1\n", "t.hdr: byte 12: bad picture size" },
		{ "#?RADIANCE\n\n+X 0 +Y 5\n", "t.hdr: byte 12: bad picture size" },
	};
	(void)state;
	for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
		struct ps_picture pic;
		struct ps_err e;
		assert_int_equal(read_text(cases[k].text, &pic, &e), -1);
		if (!strstr(e.msg, cases[k].want))
			fail_msg("case %zu: '%s' lacks '%s'", k, e.msg, cases[k].want);
		assert_null(pic.pix);
	}
}

/* A truncated picture says at which byte and in which scanline. */
static void truncation_names_byte_and_scanline(void **state)
{
	struct buf b = { 0 };
	struct ps_picture pic;
	struct ps_err e;
	size_t hdr;
	(void)state;
	put_str(&b, "#?RADIANCE\n\n-Y 3 +X 2\n");
	hdr = b.n;
	for (int i = 0; i < 6; i++) {
		uint8_t px[4] = { (uint8_t)(20 + i), 5, 5, 128 };
		put(&b, px, 4);
	}
	/* cut in the middle of scanline 1's second pixel (bytes hdr+12..hdr+15) */
	assert_int_equal(ps_picture_read_mem(&pic, b.p, hdr + 14, "cut.hdr", &e), -1);
	{
		char want[80];
		snprintf(want, sizeof want, "cut.hdr: byte %zu: file ends inside a pixel of scanline 1",
		         hdr + 12);
		assert_string_equal(e.msg, want);
	}
	free(b.p);
}

static void hostile_sizes(void **state)
{
	static const char *const texts[] = {
		"#?RADIANCE\n\n-Y 16384 +X 16384\n\x02\x02\x40\x00\xff\x00",
		"#?RADIANCE\n\n-Y 1000000000 +X 1000000000\n",
		"#?RADIANCE\n\n+X 536870911 +Y 536870911\n0123456789",
	};
	(void)state;
	for (size_t k = 0; k < 3; k++) {
		struct ps_picture pic;
		struct ps_err e;
		/* refused before any allocation of the pixels */
		assert_int_equal(read_text(texts[k], &pic, &e), -1);
		if (!strstr(e.msg, "cannot be in the"))
			fail_msg("case %zu: %s", k, e.msg);
	}
}

/* Headers are capped at 1 MiB; a long header below the cap (80000 VIEW=
 * lines) is read, its views joined in order. */
static void long_headers(void **state)
{
	struct buf b = { 0 };
	struct ps_picture pic;
	struct ps_err e;
	(void)state;
	put_str(&b, "#?RADIANCE\n");
	for (int i = 0; i < 80000; i++)
		put_str(&b, i % 2 ? "VIEW= -vh 2\n" : "VIEW= -vh 1\n");
	put_str(&b, "\n-Y 1 +X 1\n\x80\x80\x80\x81");
	assert_int_equal(ps_picture_read_mem(&pic, b.p, b.n, "long.hdr", &e), 0);
	assert_int_equal(strlen(pic.view), 80000 * 6 - 1);
	assert_memory_equal(pic.view, "-vh 1 -vh 2 -vh 1", 17);
	ps_picture_free(&pic);
	b.n = 11;
	for (int i = 0; i < 100000; i++)
		put_str(&b, "SOFTWARE= x\n");
	put_str(&b, "\n-Y 1 +X 1\n\x80\x80\x80\x81");
	assert_int_equal(ps_picture_read_mem(&pic, b.p, b.n, "long.hdr", &e), -1);
	assert_non_null(strstr(e.msg, "long.hdr: header line"));
	assert_non_null(strstr(e.msg, "header longer than 1048576 bytes"));
	free(b.p);
}

/* A real rpict render: the header fields it carries, and finite brightness.
 * (The integration tests check its sums against the fixture's reference
 * numbers.) */
static void real_rpict_render(void **state)
{
	char path[512];
	const char *top = getenv("TOP");
	struct ps_picture pic;
	struct ps_err e;
	struct ps_sum sum;
	(void)state;
	snprintf(path, sizeof path, "%s/tests/data/picture/day_0318_sensor_256.hdr", top ? top : ".");
	if (ps_picture_read(&pic, path, &e) != 0)
		fail_msg("%s", e.msg);
	assert_int_equal(pic.width, 256);
	assert_int_equal(pic.height, 256);
	assert_int_equal(pic.format, PS_PIC_RGBE);
	assert_true(pic.exposure[0] == 1.0 && pic.exposure[2] == 1.0);
	assert_true(pic.has_primaries);
	assert_true(pic.primaries[0] == 0.64 && pic.primaries[5] == 0.06 && pic.primaries[7] == 0.3333);
	/* the rpict command line, then the VIEW= line, in header order */
	assert_non_null(strstr(pic.view, "-vta -vp 1.85 2.285 2.2 -vd 0 0 -1"));
	assert_non_null(strstr(pic.view, "-vo 0 -va 0 -vs 0 -vl 0"));
	assert_true(strstr(pic.view, "-x 256") < strstr(pic.view, "-vo 0"));
	assert_non_null(strstr(pic.header, "SOFTWARE= RADIANCE"));
	ps_sum_init(&sum);
	for (int y = 0; y < pic.height; y++)
		for (int x = 0; x < pic.width; x++) {
			double v[3];
			ps_picture_get(&pic, x, y, v);
			ps_sum_add(&sum, 0.265 * v[0] + 0.670 * v[1] + 0.065 * v[2]);
		}
	assert_true(isfinite(ps_sum_get(&sum)) && ps_sum_get(&sum) > 0.0);
	ps_picture_free(&pic);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(orientations_in_every_encoding),
		cmocka_unit_test(tiny_pictures),
		cmocka_unit_test(wide_old_style_repeats),
		cmocka_unit_test(encoding_choice_by_width),
		cmocka_unit_test(rgbe_rounding_is_radiance_s),
		cmocka_unit_test(header_details),
		cmocka_unit_test(header_errors_name_the_line),
		cmocka_unit_test(truncation_names_byte_and_scanline),
		cmocka_unit_test(hostile_sizes),
		cmocka_unit_test(long_headers),
		cmocka_unit_test(real_rpict_render),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
