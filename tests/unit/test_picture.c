/* SPDX-License-Identifier: ISC */
/* Radiance pictures: decoding exactly as Radiance does, every orientation and
 * scanline encoding, and hostile input.  Pictures are built here byte by
 * byte, so the expectations come from the format's definition, not from the
 * reader. */
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

struct buf {
	uint8_t *p;
	size_t n, cap;
};

static void put(struct buf *b, const void *data, size_t n)
{
	if (b->n + n > b->cap) {
		b->cap = (b->n + n) * 2 + 64;
		b->p = realloc(b->p, b->cap);
	}
	memcpy(b->p + b->n, data, n);
	b->n += n;
}

static void puts_(struct buf *b, const char *s)
{
	put(b, s, strlen(s));
}

static void put4(struct buf *b, int r, int g, int bl, int e)
{
	uint8_t px[4] = { (uint8_t)r, (uint8_t)g, (uint8_t)bl, (uint8_t)e };
	put(b, px, 4);
}

/* Radiance's rule, written out independently of the reader. */
static double radiance_decode(int m, int e)
{
	return e == 0 ? 0.0 : (m + 0.5) * ldexp(1.0, e - 136);
}

static void one_reads_as_1_00390625(void **state)
{
	uint8_t px[4];
	double in[3] = { 1.0, 1.0, 1.0 }, out[3];
	(void)state;
	ps_picture_rgbe_encode(in, px);
	assert_int_equal(px[0], 128);
	assert_int_equal(px[3], 129);
	ps_picture_rgbe_decode(px, out);
	assert_true(out[0] == 1.00390625);
	for (int e = 1; e < 256; e++)
		assert_true(ps_picture_rgbe_scale[e] == ldexp(1.0, e - 136));
	assert_true(ps_picture_rgbe_scale[0] == 0.0);
}

static void exposure_and_colorcorr(void **state)
{
	struct buf b = { 0 };
	struct ps_picture pic;
	struct ps_err e;
	double v[3];
	(void)state;
	puts_(&b, "#?RADIANCE\nEXPOSURE=2\nEXPOSURE=2\nCOLORCORR=1 2 4\nPIXASPECT=1.5\n"
	          "FORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 1\n");
	put4(&b, 128, 128, 128, 129);
	assert_int_equal(ps_picture_read_mem(&pic, b.p, b.n, "t.hdr", &e), 0);
	ps_picture_get(&pic, 0, 0, v);
	assert_true(v[0] == 1.00390625 / 4);
	assert_true(v[1] == 1.00390625 / 8);
	assert_true(v[2] == 1.00390625 / 16);
	assert_true(pic.pixaspect == 1.5);
	ps_picture_free(&pic);
	free(b.p);
}

/* The eight resolution strings: a 3 x 2 picture whose pixel at (x, y)
 * (y counted up from the bottom) has mantissas x, y, 7. */
static void all_eight_orientations(void **state)
{
	static const char *const res[8] = { "-Y 2 +X 3", "-Y 2 -X 3", "+Y 2 -X 3", "+Y 2 +X 3",
	                                    "+X 3 -Y 2", "+X 3 +Y 2", "-X 3 +Y 2", "-X 3 -Y 2" };
	(void)state;
	for (int k = 0; k < 8; k++) {
		struct buf b = { 0 };
		struct ps_picture pic;
		struct ps_err e;
		char hdr[128];
		char a1 = res[k][1], s1 = res[k][0], s2 = res[k][5];
		int n1 = a1 == 'Y' ? 2 : 3, n2 = a1 == 'Y' ? 3 : 2;
		snprintf(hdr, sizeof hdr, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n%s\n", res[k]);
		puts_(&b, hdr);
		for (int s = 0; s < n1; s++)
			for (int p = 0; p < n2; p++) {
				int c1 = s1 == '+' ? s : n1 - 1 - s, c2 = s2 == '+' ? p : n2 - 1 - p;
				int x = a1 == 'Y' ? c2 : c1, y = a1 == 'Y' ? c1 : c2;
				put4(&b, 10 + x, 20 + y, 7, 130);
			}
		assert_int_equal(ps_picture_read_mem(&pic, b.p, b.n, res[k], &e), 0);
		assert_int_equal(pic.width, 3);
		assert_int_equal(pic.height, 2);
		for (int row = 0; row < 2; row++)
			for (int x = 0; x < 3; x++) {
				const uint8_t *px = pic.pix + 4 * (row * 3 + x);
				assert_int_equal(px[0], 10 + x);
				assert_int_equal(px[1], 20 + (1 - row));   /* row 0 is the top: y = 1 */
			}
		ps_picture_free(&pic);
		free(b.p);
	}
}

static void write_read_round_trip(void **state)
{
	static const int widths[] = { 1, 2, 7, 8, 9, 127, 128, 129, 300 };
	(void)state;
	for (size_t k = 0; k < sizeof widths / sizeof *widths; k++) {
		int w = widths[k], h = 3;
		double *rgb = malloc(sizeof(double) * 3 * w * h);
		char path[] = "/tmp/pstestXXXXXX";
		int fd = mkstemp(path);
		struct ps_picture pic;
		struct ps_err e;
		for (int i = 0; i < w * h; i++)
			for (int c = 0; c < 3; c++)   /* runs, literals and variety */
				rgb[3 * i + c] = (i % 17 < 9) ? 0.25 * (c + 1) : 1e-3 * (i + c) + (i % 5) * 1e3;
		close(fd);
		assert_int_equal(ps_picture_write(path, w, h, rgb, "-vta -vh 180 -vv 180", "SOFTWARE= test\n", &e), 0);
		assert_int_equal(ps_picture_read(&pic, path, &e), 0);
		assert_int_equal(pic.width, w);
		assert_int_equal(pic.height, h);
		assert_string_equal(pic.view, "-vta -vh 180 -vv 180");
		for (int i = 0; i < w * h; i++) {
			uint8_t px[4];
			ps_picture_rgbe_encode(rgb + 3 * i, px);
			assert_memory_equal(pic.pix + 4 * i, px, 4);
			for (int c = 0; c < 3; c++)
				assert_true(fabs(radiance_decode(px[c], px[3]) - rgb[3 * i + c]) <=
				            rgb[3 * i + c] / 128 + 1e-300);
		}
		ps_picture_free(&pic);
		unlink(path);
		free(rgb);
	}
}

static void extreme_radiances_round_trip(void **state)
{
	(void)state;
	for (double v = 1e-30; v <= 1e30; v *= 7.3) {
		double in[3] = { v, v / 3, v * 0.9 }, out[3];
		uint8_t px[4];
		ps_picture_rgbe_encode(in, px);
		ps_picture_rgbe_decode(px, out);
		/* the largest channel keeps 8 bits; the others are relative to it */
		assert_true(fabs(out[0] - v) <= v / 256 * 1.0001);
		assert_true(fabs(out[2] - v * 0.9) <= v / 256 * 1.0001);
		assert_true(out[0] == radiance_decode(px[0], px[3]));
	}
}

/* Old-style run-length: 1 1 1 n repeats the previous pixel n << shift times,
 * the shift growing by 8 with each consecutive marker. */
static void old_style_runs(void **state)
{
	struct buf b = { 0 };
	struct ps_picture pic;
	struct ps_err e;
	(void)state;
	puts_(&b, "#?RADIANCE\n\n-Y 2 +X 300\n");
	/* row 0: pixel A, repeat 43 (44 total), then 1 1 1 1 with shift 8 -> 256 more */
	put4(&b, 50, 60, 70, 128);
	put4(&b, 1, 1, 1, 43);
	put4(&b, 1, 1, 1, 1);
	/* 300 - 44 - 256 = 0 left */
	/* row 1 as a new-style scanline: 300 = 0x12c */
	put4(&b, 2, 2, 1, 0x2c);
	for (int c = 0; c < 4; c++) {
		uint8_t run[] = { 128 + 127, (uint8_t)(c + 3), 128 + 127, (uint8_t)(c + 3), 46 };
		put(&b, run, sizeof run);
		for (int i = 0; i < 46; i++) {
			uint8_t v = (uint8_t)(c + 3 + i % 2);
			put(&b, &v, 1);
		}
	}
	assert_int_equal(ps_picture_read_mem(&pic, b.p, b.n, "old.hdr", &e), 0);
	for (int x = 0; x < 300; x++) {
		assert_int_equal(pic.pix[4 * x], 50);
		assert_int_equal(pic.pix[4 * x + 3], 128);
		assert_int_equal(pic.pix[4 * (300 + x) + 1], x < 254 ? 4 : 4 + (x - 254) % 2);
	}
	ps_picture_free(&pic);
	free(b.p);
}

static void every_truncation_fails_cleanly(void **state)
{
	double rgb[3 * 40 * 5];
	char path[] = "/tmp/pstestXXXXXX";
	int fd = mkstemp(path);
	FILE *fp;
	uint8_t data[8192];
	size_t n;
	(void)state;
	for (int i = 0; i < 40 * 5 * 3; i++)
		rgb[i] = (i % 7) * 0.5 + i * 1e-3;
	close(fd);
	assert_int_equal(ps_picture_write(path, 40, 5, rgb, NULL, NULL, NULL), 0);
	fp = fopen(path, "rb");
	n = fread(data, 1, sizeof data, fp);
	fclose(fp);
	unlink(path);
	for (size_t len = 0; len < n; len++) {
		struct ps_picture pic;
		struct ps_err e;
		assert_int_equal(ps_picture_read_mem(&pic, data, len, "cut.hdr", &e), -1);
		assert_non_null(strstr(e.msg, "cut.hdr"));
		/* the offset named is where the incomplete item starts: within the prefix */
		{
			const char *at = strstr(e.msg, "byte ");
			assert_non_null(at);
			assert_true(strtoul(at + 5, NULL, 10) <= len);
		}
		assert_null(pic.pix);
	}
	/* and every single-bit flip either reads or fails with a message */
	for (size_t i = 0; i < n; i++)
		for (int bit = 0; bit < 8; bit++) {
			struct ps_picture pic;
			struct ps_err e;
			data[i] ^= (uint8_t)(1 << bit);
			if (ps_picture_read_mem(&pic, data, n, "flip.hdr", &e) == 0)
				ps_picture_free(&pic);
			else
				assert_true(e.msg[0] != '\0');
			data[i] ^= (uint8_t)(1 << bit);
		}
}

static void hostile_headers(void **state)
{
	static const struct {
		const char *text, *want;
	} cases[] = {
		{ "P6\n", "byte 0: not a Radiance picture" },
		{ "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n", "file ends inside the header" },
		{ "#?RADIANCE\nFORMAT=ascii\n\n-Y 1 +X 1\n", "header line 2: unsupported FORMAT=ascii" },
		{ "#?RADIANCE\nEXPOSURE=-1\n\n-Y 1 +X 1\n", "header line 2: bad EXPOSURE" },
		{ "#?RADIANCE\nPRIMARIES=1 2 3\n\n-Y 1 +X 1\n", "header line 2: PRIMARIES needs 8" },
		{ "#?RADIANCE\n\n-Y 1 +Z 1\n", "bad resolution line" },
		{ "#?RADIANCE\n\n-Y 0 +X 1\n", "bad picture size" },
		{ "#?RADIANCE\n\n-Y 100000 +X 100000\n\x01\x02", "cannot be in the 2 bytes left" },
		{ "#?RADIANCE\n\n-Y 1 +X 2\n\x01\x01\x01\x05", "starts with a repeat of no pixel" },
	};
	(void)state;
	for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
		struct ps_picture pic;
		struct ps_err e;
		assert_int_equal(ps_picture_read_mem(&pic, (const uint8_t *)cases[k].text,
		                                     strlen(cases[k].text), "h.hdr", &e), -1);
		if (!strstr(e.msg, cases[k].want))
			fail_msg("case %zu: '%s' lacks '%s'", k, e.msg, cases[k].want);
	}
	{
		/* a NUL byte in the header */
		static const uint8_t nul[] = "#?RADIANCE\nA\0B\n\n-Y 1 +X 1\n";
		struct ps_picture pic;
		struct ps_err e;
		assert_int_equal(ps_picture_read_mem(&pic, nul, sizeof nul - 1, "n.hdr", &e), -1);
		assert_non_null(strstr(e.msg, "header line 2"));
	}
}

static void new_style_errors(void **state)
{
	struct buf b = { 0 };
	struct ps_picture pic;
	struct ps_err e;
	(void)state;
	puts_(&b, "#?RADIANCE\n\n-Y 1 +X 8\n");
	put4(&b, 2, 2, 0, 9);   /* says 9 pixels, the picture has 8 */
	assert_int_equal(ps_picture_read_mem(&pic, b.p, b.n, "n.hdr", &e), -1);
	assert_non_null(strstr(e.msg, "says 9 pixels"));
	b.n -= 4;
	put4(&b, 2, 2, 0, 8);
	{
		uint8_t over[] = { 128 + 9, 1 };   /* a run of 9 in a scanline of 8 */
		put(&b, over, 2);
	}
	assert_int_equal(ps_picture_read_mem(&pic, b.p, b.n, "n.hdr", &e), -1);
	assert_non_null(strstr(e.msg, "run of 9 overruns scanline 0"));
	b.n -= 2;
	{
		uint8_t zero[] = { 0 };
		put(&b, zero, 1);
	}
	assert_int_equal(ps_picture_read_mem(&pic, b.p, b.n, "n.hdr", &e), -1);
	assert_non_null(strstr(e.msg, "zero-length run"));
	free(b.p);
}

static void xyze_format_and_views(void **state)
{
	struct buf b = { 0 };
	struct ps_picture pic;
	struct ps_err e;
	(void)state;
	puts_(&b, "#?RADIANCE\n/usr/bin/rpict -vta -vh 180 -x 4 -y 4 scene.oct\n"
	          "VIEW= -vp 1 2 3\nFORMAT=32-bit_rle_xyze\n"
	          "PRIMARIES= 0.64 0.33 0.29 0.60 0.15 0.06 0.3333 0.3333\n\n+X 1 +Y 1\n");
	put4(&b, 1, 2, 3, 140);
	assert_int_equal(ps_picture_read_mem(&pic, b.p, b.n, "x.hdr", &e), 0);
	assert_int_equal(pic.format, PS_PIC_XYZE);
	assert_string_equal(pic.view, "-vta -vh 180 -x 4 -y 4 scene.oct -vp 1 2 3");
	assert_true(pic.has_primaries && pic.primaries[7] == 0.3333);
	ps_picture_free(&pic);
	free(b.p);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(one_reads_as_1_00390625),
		cmocka_unit_test(exposure_and_colorcorr),
		cmocka_unit_test(all_eight_orientations),
		cmocka_unit_test(write_read_round_trip),
		cmocka_unit_test(extreme_radiances_round_trip),
		cmocka_unit_test(old_style_runs),
		cmocka_unit_test(every_truncation_fails_cleanly),
		cmocka_unit_test(hostile_headers),
		cmocka_unit_test(new_style_errors),
		cmocka_unit_test(xyze_format_and_views),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
