/* SPDX-License-Identifier: ISC */
/* Pictures to look at: luminance, exposure, the tone curves, false colour
 * and its legend, contours, and the PNG files (read back with libpng's own
 * reader, not through the project's writer).
 *
 * Pixel values are stated from the curves' definitions: a grey RGBE pixel
 * (128, 128, 128, e 127) decodes to (128 + 0.5) 2^(127 - 136) = 0.2509765625
 * (Radiance's colr_color()), and its luminance is 179 times that, since the
 * Y coefficients add up to 1.  Bytes are floor(255 v + 0.5); the expected
 * bytes below were computed by hand (Python) from those definitions. */
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

#include <png.h>

#include "canvas.h"
#include "contour.h"
#include "falsecolor.h"
#include "integrate.h"
#include "lum.h"
#include "picdraw.h"
#include "picture.h"
#include "tonemap.h"

#define GREY 0.2509765625   /* (128.5) 2^-9 */

/* A flat-scanline RGBE picture in memory: w x h pixels of one value, or
 * given pixels. */
static void make_picture(struct ps_picture *pic, int w, int h, const uint8_t *pixels,
                         const uint8_t one[4], const char *extra_header)
{
	char head[512];
	size_t n = (size_t)w * (size_t)h * 4, hl;
	uint8_t *buf;
	struct ps_err e;
	snprintf(head, sizeof head, "#?RADIANCE\n%sFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n",
	         extra_header ? extra_header : "", h, w);
	hl = strlen(head);
	buf = malloc(hl + n);
	assert_non_null(buf);
	memcpy(buf, head, hl);
	for (size_t i = 0; i < n; i += 4)
		memcpy(buf + hl + i, pixels ? pixels + i : one, 4);
	assert_int_equal(ps_picture_read_mem(pic, buf, hl + n, "mem", &e), 0);
	free(buf);
}

/* ---- a PNG read with libpng's classic reader, no transformations ---- */
struct png_read {
	int w, h, color_type, bit_depth, has_srgb, has_gamma;
	double gamma;
	uint8_t *rgb;   /* w * h * 3 */
	char text[4][2][256];
	int ntext;
};

static void read_png(const char *path, struct png_read *r)
{
	FILE *fp = fopen(path, "rb");
	png_structp png;
	png_infop info;
	png_bytepp rows;
	png_textp text;
	int nt = 0;
	assert_non_null(fp);
	memset(r, 0, sizeof *r);
	png = png_create_read_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
	info = png_create_info_struct(png);
	assert_non_null(png);
	assert_non_null(info);
	if (setjmp(png_jmpbuf(png)))
		fail_msg("libpng could not read %s", path);
	png_init_io(png, fp);
	png_read_png(png, info, PNG_TRANSFORM_IDENTITY, NULL);
	r->w = (int)png_get_image_width(png, info);
	r->h = (int)png_get_image_height(png, info);
	r->color_type = png_get_color_type(png, info);
	r->bit_depth = png_get_bit_depth(png, info);
	r->has_srgb = png_get_valid(png, info, PNG_INFO_sRGB) != 0;
	r->has_gamma = png_get_gAMA(png, info, &r->gamma) != 0;
	png_get_text(png, info, &text, &nt);
	for (int i = 0; i < nt && i < 4; i++) {
		snprintf(r->text[i][0], sizeof r->text[i][0], "%s", text[i].key);
		snprintf(r->text[i][1], sizeof r->text[i][1], "%s", text[i].text);
		r->ntext++;
	}
	assert_int_equal(r->color_type, PNG_COLOR_TYPE_RGB);
	assert_int_equal(r->bit_depth, 8);
	rows = png_get_rows(png, info);
	r->rgb = malloc((size_t)r->w * (size_t)r->h * 3);
	assert_non_null(r->rgb);
	for (int y = 0; y < r->h; y++)
		memcpy(r->rgb + (size_t)y * (size_t)r->w * 3, rows[y], (size_t)r->w * 3);
	png_destroy_read_struct(&png, &info, NULL);
	fclose(fp);
}

static const uint8_t *px(const struct png_read *r, int x, int y)
{
	return r->rgb + ((size_t)y * (size_t)r->w + (size_t)x) * 3;
}

/* ---- luminance ---- */

static void luminance_coefficients(void **state)
{
	double m[3][3];
	struct ps_picture pic;
	struct ps_lum l;
	uint8_t g[4] = { 128, 128, 128, 127 };
	(void)state;
	/* Radiance's color.h: CIE_rf .265074126, CIE_gf .670114631, CIE_bf .064811243 */
	ps_integrate_rgb_to_xyz(ps_integrate_std_primaries, m);
	assert_true(fabs(m[1][0] - 0.265074126) < 1e-9);
	assert_true(fabs(m[1][1] - 0.670114631) < 1e-9);
	assert_true(fabs(m[1][2] - 0.064811243) < 1e-9);
	make_picture(&pic, 1, 1, NULL, g, NULL);
	ps_lum_init(&l, &pic);
	for (int k = 0; k < 3; k++)
		assert_true(fabs(l.y[k] - m[1][k]) < 1e-15);
	{
		double rgb[3];
		ps_lum_rgb(&l, &pic, 0, 0, rgb);
		assert_true(fabs(rgb[0] - GREY) < 1e-15);
		assert_true(fabs(PS_LUM_EFFICACY * ps_lum_y(&l, rgb) - 179 * GREY) < 1e-9);
	}
	ps_picture_free(&pic);
	/* EXPOSURE= is divided out: a picture exposed by 2 holds half the radiance */
	make_picture(&pic, 1, 1, NULL, g, "EXPOSURE=2\n");
	ps_lum_init(&l, &pic);
	{
		double rgb[3];
		ps_lum_rgb(&l, &pic, 0, 0, rgb);
		assert_true(fabs(ps_lum_y(&l, rgb) - GREY / 2) < 1e-15);
	}
	ps_picture_free(&pic);
}

static void luminance_xyze(void **state)
{
	/* XYZE: Y is stored luminance in cd/m2 (Radiance's XYZE is luminance-
	 * based: ra_xyze writes EXPOSURE=1/179 on unchanged XYZ), whatever X
	 * and Z are; the radiance-based Y is Y / 179 */
	const char head[] = "#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 1\n";
	uint8_t buf[sizeof head - 1 + 4];
	struct ps_picture pic;
	struct ps_lum l;
	struct ps_err e;
	double rgb[3];
	(void)state;
	memcpy(buf, head, sizeof head - 1);
	buf[sizeof head - 1] = 40;       /* X */
	buf[sizeof head] = 128;          /* Y */
	buf[sizeof head + 1] = 200;      /* Z */
	buf[sizeof head + 2] = 127;
	assert_int_equal(ps_picture_read_mem(&pic, buf, sizeof buf, "xyz", &e), 0);
	ps_lum_init(&l, &pic);
	ps_lum_rgb(&l, &pic, 0, 0, rgb);
	assert_true(fabs(PS_LUM_EFFICACY * ps_lum_y(&l, rgb) - GREY) < 1e-12);
	ps_picture_free(&pic);
}

/* ---- exposure and curves on a uniform grey picture ---- */

static uint8_t map_grey(int curve, double exposure, double gamma, double white)
{
	struct ps_picture pic;
	struct ps_tonemap t;
	uint8_t g[4] = { 128, 128, 128, 127 }, out[3];
	double rgb[3];
	make_picture(&pic, 4, 3, NULL, g, NULL);
	ps_tonemap_init(&t, &pic, curve, exposure, gamma, white);
	ps_lum_rgb(&t.lum, &pic, 2, 1, rgb);
	ps_tonemap_rgb(&t, rgb, out);
	assert_int_equal(out[0], out[1]);
	assert_int_equal(out[1], out[2]);
	ps_picture_free(&pic);
	return out[0];
}

static void curves_on_grey(void **state)
{
	(void)state;
	assert_int_equal(map_grey(PS_TONE_LINEAR, 1, 0, 0), 64);     /* 255 x 0.25098 = 64.0 */
	assert_int_equal(map_grey(PS_TONE_LINEAR, 2, 0, 0), 128);    /* 128.0 */
	assert_int_equal(map_grey(PS_TONE_LINEAR, 4, 0, 0), 255);    /* 1.004: clipped */
	assert_int_equal(map_grey(PS_TONE_SRGB, 1, 0, 0), 137);      /* sRGB(0.25098) = 0.5371 */
	assert_int_equal(map_grey(PS_TONE_GAMMA, 1, 2.2, 0), 136);   /* 0.25098^(1/2.2) = 0.5330 */
	/* Reinhard, Lw = 1 (radiance units, exposure 1): Ld = L (1 + L) / (1 + L) = L */
	assert_int_equal(map_grey(PS_TONE_REINHARD, 1, 0, 1.0), 137);
	/* exposure 2, Lw = 2 x 2 = 4: L = 0.50195, Ld = L (1 + L/16) / (1 + L) = 0.34468 */
	assert_int_equal(map_grey(PS_TONE_REINHARD, 2, 0, 2.0), 159);
	/* default white: the picture's largest, which here is every pixel: white */
	assert_int_equal(map_grey(PS_TONE_REINHARD, 1, 0, 0), 255);
	/* auto exposure maps the log-average to 0.18: linear 255 x 0.18 = 45.9 */
	assert_int_equal(map_grey(PS_TONE_LINEAR, 0, 0, 0), 46);
}

static void auto_exposure_is_log_average(void **state)
{
	/* half the pixels at a = 128.5 x 2^-10, half at b = 128.5 x 2^-6:
	 * log-average sqrt(a b), auto exposure 0.18 / sqrt(a b) = 0.3585992 */
	uint8_t pix[8 * 4];
	struct ps_picture pic;
	struct ps_tonemap t;
	double la, ym;
	(void)state;
	for (int i = 0; i < 8; i++) {
		pix[4 * i] = pix[4 * i + 1] = pix[4 * i + 2] = 128;
		pix[4 * i + 3] = i % 2 ? 126 : 130;
	}
	make_picture(&pic, 4, 2, pix, NULL, NULL);
	ps_tonemap_init(&t, &pic, PS_TONE_SRGB, 0, 0, 0);
	assert_true(fabs(t.exposure - 0.35859922178988324) < 1e-12);
	ps_tonemap_stats(&pic, &t.lum, &la, &ym);
	assert_true(fabs(ym - 2.0078125) < 1e-15);
	ps_picture_free(&pic);
}

static void exposure_parsing(void **state)
{
	double m = 0;
	(void)state;
	assert_int_equal(ps_tonemap_exposure_parse("auto", &m), 1);
	assert_int_equal(ps_tonemap_exposure_parse("2.5", &m), 0);
	assert_true(m == 2.5);
	assert_int_equal(ps_tonemap_exposure_parse("+2", &m), 0);
	assert_true(m == 4.0);
	assert_int_equal(ps_tonemap_exposure_parse("-1", &m), 0);
	assert_true(m == 0.5);
	assert_int_equal(ps_tonemap_exposure_parse("0", &m), -1);
	assert_int_equal(ps_tonemap_exposure_parse("nan", &m), -1);
	assert_int_equal(ps_tonemap_exposure_parse("2x", &m), -1);
	assert_int_equal(ps_tonemap_exposure_parse("+1000", &m), -1);
	assert_int_equal(ps_tonemap_parse("reinhard"), PS_TONE_REINHARD);
	assert_int_equal(ps_tonemap_parse("log"), -1);
}

static void srgb_encoding(void **state)
{
	(void)state;
	/* IEC 61966-2-1: linear below 0.0031308, 1.055 v^(1/2.4) - 0.055 above */
	assert_true(fabs(ps_tonemap_srgb_encode(0.002) - 0.02584) < 1e-12);
	assert_true(fabs(ps_tonemap_srgb_encode(0.5) - 0.7353569830524495) < 1e-12);
	assert_true(ps_tonemap_srgb_encode(1.0) == 1.0);
	assert_true(ps_tonemap_srgb_encode(-1) == 0.0);
	assert_int_equal(ps_tonemap_byte(0.5), 128);       /* 127.5 rounds up */
	assert_int_equal(ps_tonemap_byte(127.49 / 255), 127);
}

/* ---- PNG files ---- */

static char *tmp_path(const char *name)
{
	static char buf[4][256];
	static int k;
	char *p = buf[k++ % 4];
	snprintf(p, sizeof buf[0], "/tmp/psensd-test-%d-%s", (int)getpid(), name);
	return p;
}

static void png_of_tone_curves(void **state)
{
	static const struct { int curve; double e; int expect; int srgb; double gamma; } c[] = {
		{ PS_TONE_LINEAR, 1, 64, 0, 1.0 },
		{ PS_TONE_GAMMA, 1, 136, 0, 1 / 2.2 },
		{ PS_TONE_SRGB, 1, 137, 1, 0 },
	};
	uint8_t g[4] = { 128, 128, 128, 127 }, bg[3] = { 0, 0, 0 };
	(void)state;
	for (size_t i = 0; i < sizeof c / sizeof c[0]; i++) {
		struct ps_picture pic;
		struct ps_tonemap t;
		struct ps_canvas cv;
		struct ps_err e;
		struct png_read r;
		const char *path = tmp_path("tone.png");
		make_picture(&pic, 5, 3, NULL, g, NULL);
		ps_tonemap_init(&t, &pic, c[i].curve, c[i].e, 2.2, 0);
		assert_int_equal(ps_canvas_init(&cv, 10, 6, bg, &e), 0);
		ps_picdraw_tone(&cv, &pic, &t, 0, 0, 2);
		if (!c[i].srgb) {
			cv.encoding = PS_PNG_GAMMA;
			cv.gamma = c[i].curve == PS_TONE_LINEAR ? 1.0 : 2.2;
		}
		ps_canvas_text_chunk(&cv, "Software", "test");
		assert_int_equal(ps_canvas_save_png(&cv, path, &e), 0);
		ps_canvas_free(&cv);
		read_png(path, &r);
		assert_int_equal(r.w, 10);
		assert_int_equal(r.h, 6);
		for (int y = 0; y < r.h; y++)
			for (int x = 0; x < r.w; x++)
				for (int k = 0; k < 3; k++)
					assert_int_equal(px(&r, x, y)[k], c[i].expect);
		assert_int_equal(r.has_srgb, c[i].srgb);
		if (!c[i].srgb) {
			assert_true(r.has_gamma);
			assert_true(fabs(r.gamma - c[i].gamma) < 1e-5);
		}
		assert_int_equal(r.ntext, 1);
		assert_string_equal(r.text[0][0], "Software");
		free(r.rgb);
		ps_picture_free(&pic);
		unlink(path);
	}
}

static void png_write_failure_keeps_old_file(void **state)
{
	struct ps_canvas cv;
	struct ps_err e;
	uint8_t bg[3] = { 1, 2, 3 };
	(void)state;
	assert_int_equal(ps_canvas_init(&cv, 2, 2, bg, &e), 0);
	assert_int_equal(ps_canvas_save_png(&cv, "/nonexistent-dir/x.png", &e), -1);
	assert_non_null(strstr(e.msg, "/nonexistent-dir/x.png"));
	ps_canvas_free(&cv);
	assert_int_equal(ps_canvas_init(&cv, 0, 2, bg, &e), -1);
	assert_int_equal(ps_canvas_init(&cv, 32768, 32768, bg, &e), -1);
	assert_non_null(strstr(e.msg, "a smaller zoom"));
}

static void orientation_standardised(void **state)
{
	/* "+Y 2 +X 3": the file's first scanline is the picture's bottom row.
	 * Its pixels are (e 127 + k) for k = 0..5 in file order; drawn in
	 * standard orientation the PNG's top row holds the file's second
	 * scanline: linear at exposure 1, 255 x 0.25098 x 2^k clipped */
	const char head[] = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n+Y 2 +X 3\n";
	uint8_t buf[sizeof head - 1 + 24], bg[3] = { 0, 0, 0 };
	struct ps_picture pic;
	struct ps_tonemap t;
	struct ps_canvas cv;
	struct ps_err e;
	struct png_read r;
	const char *path = tmp_path("orient.png");
	static const int want[2][3] = { { 255, 255, 255 }, { 64, 128, 255 } };
	(void)state;
	memcpy(buf, head, sizeof head - 1);
	for (int k = 0; k < 6; k++) {
		uint8_t p[4] = { 128, 128, 128, (uint8_t)(127 + k) };
		memcpy(buf + sizeof head - 1 + 4 * k, p, 4);
	}
	assert_int_equal(ps_picture_read_mem(&pic, buf, sizeof buf, "orient", &e), 0);
	ps_tonemap_init(&t, &pic, PS_TONE_LINEAR, 1, 0, 0);
	assert_int_equal(ps_canvas_init(&cv, 3, 2, bg, &e), 0);
	ps_picdraw_tone(&cv, &pic, &t, 0, 0, 1);
	assert_int_equal(ps_canvas_save_png(&cv, path, &e), 0);
	ps_canvas_free(&cv);
	read_png(path, &r);
	for (int y = 0; y < 2; y++)
		for (int x = 0; x < 3; x++)
			assert_int_equal(px(&r, x, y)[1], want[y][x]);
	free(r.rgb);
	ps_picture_free(&pic);
	unlink(path);
}

/* ---- false colour ---- */

static void falsecolor_scale(void **state)
{
	struct ps_falsecolor_scale lin = { 2000, 0, 0 }, lg = { 5000, 1, 3 };
	double t[16];
	uint8_t a[3], b[3];
	(void)state;
	assert_true(fabs(ps_falsecolor_scale_fraction(&lin, 500) - 0.25) < 1e-15);
	assert_true(fabs(ps_falsecolor_scale_fraction(&lg, 50) - 1.0 / 3) < 1e-12);
	assert_true(fabs(ps_falsecolor_scale_fraction(&lg, 5) - 0.0) < 1e-12);
	assert_true(ps_falsecolor_scale_fraction(&lg, 0) < 0);
	assert_true(ps_falsecolor_nice_ceil(2456) == 2500);
	assert_true(ps_falsecolor_nice_ceil(2000) == 2000);
	assert_true(ps_falsecolor_nice_ceil(0.0123) == 0.015);
	assert_true(ps_falsecolor_nice_ceil(7.2) == 8);
	assert_int_equal(ps_falsecolor_scale_ticks(&lg, t, 16), 4);
	assert_true(fabs(t[0] - 5) < 1e-9 && fabs(t[3] - 5000) < 1e-9);
	assert_int_equal(ps_falsecolor_scale_ticks(&lin, t, 16), 6);   /* step nice(2000 / 6) = 400: 0 .. 2000 */
	assert_true(t[1] == 400 && t[5] == 2000);
	/* above the scale: white; below: the bottom colour */
	ps_falsecolor_rgb8(1.0001, a);
	assert_true(a[0] == 255 && a[1] == 255 && a[2] == 255);
	ps_falsecolor_rgb8(-3, a);
	ps_falsecolor_rgb8(0, b);
	assert_memory_equal(a, b, 3);
	/* the palette's ends: navy (0.05, 0.03, 0.22) and red (0.90, 0.12, 0.10) */
	assert_true(b[0] == 13 && b[1] == 8 && b[2] == 56);
	ps_falsecolor_rgb8(1.0, a);
	assert_true(a[0] == 230 && a[1] == 31 && a[2] == 26);
}

/* Known luminances in false colour: each pixel has the palette's colour of
 * its fraction of the scale, and the legend's bar has that colour at the
 * row where that value sits. */
static void falsecolor_png_and_legend(void **state)
{
	/* grey pixels of exponent 127 + k: radiance GREY 2^k, luminance 179 GREY 2^k */
	uint8_t pix[6 * 4];
	double lum[6];
	struct ps_picture pic;
	struct ps_lum l;
	struct ps_falsecolor_scale s = { 0, 0, 0 };
	struct ps_falsecolor_legend leg;
	struct ps_canvas cv;
	struct ps_err e;
	struct png_read r;
	uint8_t bg[3] = { 28, 28, 28 };
	const char *path = tmp_path("false.png");
	int zoom = 8;
	(void)state;
	for (int i = 0; i < 6; i++) {
		pix[4 * i] = pix[4 * i + 1] = pix[4 * i + 2] = 128;
		pix[4 * i + 3] = (uint8_t)(127 + i);
		lum[i] = 179 * GREY * pow(2, i);
	}
	make_picture(&pic, 6, 1, pix, NULL, NULL);
	ps_lum_init(&l, &pic);
	/* largest 179 x 0.25098 x 32 = 1437.6: the scale tops at 1500 */
	assert_true(fabs(ps_picdraw_max_cdm2(&pic, &l) - lum[5]) < 1e-9);
	for (int logscale = 0; logscale < 2; logscale++) {
		s.max = ps_falsecolor_nice_ceil(lum[5]);
		assert_true(s.max == 1500);
		s.log = logscale;
		s.decades = 2;
		assert_int_equal(ps_canvas_init(&cv, 6 * zoom + 120, 300, bg, &e), 0);
		ps_picdraw_false(&cv, &pic, &l, &s, 0, 0, zoom);
		ps_falsecolor_legend_layout(&leg, 6 * zoom, 0, 120, 300);
		ps_falsecolor_legend_draw(&cv, &leg, &s, "cd/m2");
		assert_int_equal(ps_canvas_save_png(&cv, path, &e), 0);
		ps_canvas_free(&cv);
		read_png(path, &r);
		for (int i = 0; i < 6; i++) {
			double f = ps_falsecolor_scale_fraction(&s, lum[i]);
			uint8_t want[3];
			const uint8_t *got = px(&r, i * zoom + zoom / 2, zoom / 2);
			const uint8_t *bar;
			int row = ps_falsecolor_legend_row(&leg, f);
			ps_falsecolor_rgb8(f, want);
			assert_memory_equal(got, want, 3);
			/* the bar's row centre is within half a row of f: the palette
			 * moves at most 255 x 0.6 / 0.13 per unit fraction, so within
			 * 3 levels over half a row of a 260-row bar */
			bar = px(&r, leg.x + leg.width / 2, row);
			for (int k = 0; k < 3; k++)
				assert_true(abs((int)bar[k] - (int)got[k]) <= 3);
		}
		free(r.rgb);
	}
	ps_picture_free(&pic);
	unlink(path);
}

/* ---- contours ---- */

struct seg_check {
	double cx, cy, r, worst;
	long n;
};

static void seg_radius(void *arg, double x0, double y0, double x1, double y1)
{
	struct seg_check *c = arg;
	double d0 = fabs(hypot(x0 - c->cx, y0 - c->cy) - c->r);
	double d1 = fabs(hypot(x1 - c->cx, y1 - c->cy) - c->r);
	c->worst = fmax(c->worst, fmax(d0, d1));
	c->n++;
}

static void contour_of_a_cone(void **state)
{
	/* f = 1 - rho / R on a grid: linear along every edge except for the
	 * curvature of rho, so every crossing lies on the circle rho = R (1 - level)
	 * to within the chord error of one cell (< 1/(8 rho) cells) */
	enum { N = 101 };
	static double f[N * N];
	double R = 40;
	(void)state;
	for (int j = 0; j < N; j++)
		for (int i = 0; i < N; i++)
			f[j * N + i] = 1 - hypot(i - 50.0, j - 50.0) / R;
	for (double level = 0.1; level < 0.95; level += 0.2) {
		struct seg_check c = { 50, 50, R * (1 - level), 0, 0 };
		long n = ps_contour(f, N, N, level, seg_radius, &c);
		assert_true(n == c.n && n > 20);
		assert_true(c.worst < 1.0 / (8 * c.r) + 1e-9);
	}
	/* a NaN corner leaves its cells out */
	f[50 * N + 50] = NAN;
	{
		struct seg_check c = { 50, 50, R * (1 - 0.999), 0, 0 };
		assert_int_equal(ps_contour(f, N, N, 0.999, seg_radius, &c), 0);
	}
}

struct segs {
	double s[4][4];
	int n;
};

static void seg_keep(void *arg, double x0, double y0, double x1, double y1)
{
	struct segs *c = arg;
	if (c->n < 4) {
		c->s[c->n][0] = x0;
		c->s[c->n][1] = y0;
		c->s[c->n][2] = x1;
		c->s[c->n][3] = y1;
	}
	c->n++;
}

static void contour_saddle(void **state)
{
	/* one cell, top row 1 0, bottom row 0 1, level 0.4: the centre's mean
	 * 0.5 is on the high corners' side, so they join and the segments cut
	 * off the low corners: top-right (0.6, 0)-(1, 0.4) and bottom-left
	 * (0.4, 1)-(0, 0.6); at level 0.6 the low corners join instead:
	 * top-left (0.4, 0)-(0, 0.4) and bottom-right (1, 0.6)-(0.6, 1) */
	double f[4] = { 1, 0, 0, 1 };
	struct segs c = { { { 0 } }, 0 };
	(void)state;
	assert_int_equal(ps_contour(f, 2, 2, 0.4, seg_keep, &c), 2);
	assert_true(fabs(c.s[0][0] - 0.6) < 1e-12 && c.s[0][1] == 0 && c.s[0][2] == 1 &&
	            fabs(c.s[0][3] - 0.4) < 1e-12);
	assert_true(fabs(c.s[1][0] - 0.4) < 1e-12 && c.s[1][1] == 1 && c.s[1][2] == 0 &&
	            fabs(c.s[1][3] - 0.6) < 1e-12);
	c.n = 0;
	assert_int_equal(ps_contour(f, 2, 2, 0.6, seg_keep, &c), 2);
	assert_true(fabs(c.s[0][0] - 0.4) < 1e-12 && c.s[0][1] == 0 && c.s[0][2] == 0 &&
	            fabs(c.s[0][3] - 0.4) < 1e-12);
	assert_true(c.s[1][0] == 1 && fabs(c.s[1][1] - 0.6) < 1e-12 && fabs(c.s[1][2] - 0.6) < 1e-12 &&
	            c.s[1][3] == 1);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(luminance_coefficients),
		cmocka_unit_test(luminance_xyze),
		cmocka_unit_test(curves_on_grey),
		cmocka_unit_test(auto_exposure_is_log_average),
		cmocka_unit_test(exposure_parsing),
		cmocka_unit_test(srgb_encoding),
		cmocka_unit_test(png_of_tone_curves),
		cmocka_unit_test(png_write_failure_keeps_old_file),
		cmocka_unit_test(orientation_standardised),
		cmocka_unit_test(falsecolor_scale),
		cmocka_unit_test(falsecolor_png_and_legend),
		cmocka_unit_test(contour_of_a_cone),
		cmocka_unit_test(contour_saddle),
	};
	int rc = cmocka_run_group_tests(tests, NULL, NULL);
	ps_canvas_shutdown();
	return rc;
}
