/* SPDX-License-Identifier: ISC */
/* Decoding fused with integration (sim/weights/stream.h) against decoding the whole
 * picture and ps_integrate: the same response, channels, brightest pixel and
 * top-1 % share bit for bit, with 1, 2 and 3 threads, for run-length and flat
 * scanlines, a picture with a sun (the second pass), XYZE, and a picture in
 * another orientation (decoded whole), with a sensor that sees every row and
 * with a narrow one whose rows without weights are skipped; a damaged picture is an error naming
 * the file and byte, whatever the threads. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "integrate.h"
#include "picture.h"
#include "sensor.h"
#include "stream.h"
#include "view.h"
#include "weights.h"

static const double coef[3] = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B };

/* A picture file in memory: Radiance's writer (run-length scanlines when
 * the width allows), with a sun at (sx, sy) when sx >= 0. */
static uint8_t *make(int w, int h, int sx, int sy, const char *extra, size_t *len)
{
	double *rgb = malloc(sizeof(double) * 3 * (size_t)w * h);
	char *buf = NULL;
	size_t n = 0;
	FILE *fp = open_memstream(&buf, &n);
	struct ps_err e;
	assert_non_null(rgb);
	for (int y = 0; y < h; y++)
		for (int x = 0; x < w; x++) {
			double *p = rgb + 3 * ((size_t)y * w + x);
			p[0] = 0.2 + 0.01 * ((x * 7 + y * 3) % 17);
			p[1] = 0.3 + 0.02 * ((x + 2 * y) % 5);
			p[2] = x < w / 3 ? 0.0 : 0.1 + 0.001 * x;   /* runs of equal bytes */
		}
	if (sx >= 0)
		for (int c = 0; c < 3; c++)
			rgb[3 * ((size_t)sy * w + sx) + c] = 1e6;
	assert_int_equal(ps_picture_write_fp(fp, "mem", w, h, rgb, "-vta -vh 180 -vv 180", extra, &e), 0);
	fclose(fp);
	free(rgb);
	*len = n;
	return (uint8_t *)buf;
}

/* A narrow sensor (nothing beyond 30 degrees): most rows have no weights,
 * and are only checked, not decoded. */
static const char narrow[] = "Elevation field 30\ndegrees 0 90 180 270\n0 1 1 1 1\n20 0.8 0.6 0.7 0.9\n30 0 0 0 0\n";

static void routes_with(const uint8_t *data, size_t len, int expect_standard, int use_narrow);

static void both_routes(const uint8_t *data, size_t len, int expect_standard)
{
	routes_with(data, len, expect_standard, 0);
	routes_with(data, len, expect_standard, 1);
}

static void routes_with(const uint8_t *data, size_t len, int expect_standard, int use_narrow)
{
	struct ps_picture pic, head;
	struct ps_sensor s;
	struct ps_view v;
	struct ps_weights w;
	struct ps_response want, got;
	struct ps_err e;
	size_t off;
	if (use_narrow) {
		if (ps_sensor_parse(&s, narrow, sizeof narrow - 1, "narrow", &e) != 0 ||
		    ps_sensor_set_reading(&s, PS_READ_LINEAR, &e) != 0)
			fail_msg("%s", e.msg);
	} else {
		assert_int_equal(ps_sensor_builtin(&s, PS_SENS_COSINE, &e), 0);
	}
	ps_view_default_fisheye(&v);
	if (ps_picture_read_mem(&pic, data, len, "mem", &e) != 0 ||
	    ps_picture_head_mem(&head, data, len, "mem", &off, &e) != 0)
		fail_msg("%s", e.msg);
	assert_int_equal(ps_picture_is_standard(&head), expect_standard);
	assert_null(head.pix);
	assert_int_equal(ps_weights_build(&w, &s, 25, &v, pic.width, pic.height, PS_W_EXACT, &e), 0);
	assert_int_equal(ps_integrate(&w, &pic, coef, &want, &e), 0);
	if (use_narrow)   /* rows without weights exist: they are skipped */
		assert_true(w.nruns < (size_t)pic.height);
	for (int nt = 1; nt <= 3; nt++) {
		if (ps_stream_integrate(&w, &head, data, len, off, "mem", coef, nt, &got, &e) != 0)
			fail_msg("%s", e.msg);
		assert_true(got.response == want.response);
		for (int c = 0; c < 3; c++)
			assert_true(got.rgb[c] == want.rgb[c]);
		assert_true(got.brightest_share == want.brightest_share);
		assert_int_equal(got.brightest_x, want.brightest_x);
		assert_int_equal(got.brightest_row, want.brightest_row);
		assert_int_equal(got.npixels, want.npixels);
		if (isnan(want.top1_share))
			assert_true(isnan(got.top1_share));
		else
			assert_true(got.top1_share == want.top1_share);
	}
	ps_weights_free(&w);
	ps_picture_free(&pic);
	ps_picture_free(&head);
	ps_sensor_free(&s);
}

static void run_length_pictures(void **state)
{
	size_t len;
	uint8_t *d;
	(void)state;
	d = make(97, 61, -1, 0, NULL, &len);
	both_routes(d, len, 1);
	free(d);
	d = make(64, 64, 40, 20, "EXPOSURE=0.5\n", &len);   /* with a sun */
	both_routes(d, len, 1);
	free(d);
}

static void flat_pictures(void **state)
{
	size_t len;
	uint8_t *d;
	(void)state;
	d = make(7, 9, 3, 4, NULL, &len);   /* under 8 wide: flat scanlines */
	both_routes(d, len, 1);
	free(d);
}

static void xyze_picture(void **state)
{
	size_t len;
	uint8_t *d = make(40, 40, -1, 0, NULL, &len);
	char *p = memmem(d, len, "32-bit_rle_rgbe", 15);
	(void)state;
	assert_non_null(p);
	memcpy(p, "32-bit_rle_xyze", 15);
	both_routes(d, len, 1);
	free(d);
}

/* +Y: rows run bottom to top in the file; decoded whole. */
static void other_orientation(void **state)
{
	enum { W = 5, H = 6 };
	const char head[] = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n+Y 6 +X 5\n";
	uint8_t buf[sizeof head - 1 + 4 * W * H];
	(void)state;
	memcpy(buf, head, sizeof head - 1);
	for (int i = 0; i < W * H; i++) {
		uint8_t *px = buf + sizeof head - 1 + 4 * i;
		px[0] = (uint8_t)(100 + i);
		px[1] = (uint8_t)(200 - i);
		px[2] = 150;
		px[3] = 128;
	}
	both_routes(buf, sizeof buf, 0);
}

/* Several maps with one decoding (ps_stream_integrate_multi): each map's
 * numbers are ps_integrate's alone bit for bit - a full map, a compact one
 * and a narrow table turned by 25 degrees, whose rows differ - with and
 * without a sun (the second pass), at 1 to 3 threads. */
static void several_maps_one_decoding(void **state)
{
	static const int suns[][2] = { { -1, 0 }, { 40, 20 } };
	struct ps_sensor cos, nar;
	struct ps_view v;
	struct ps_err e;
	(void)state;
	assert_int_equal(ps_sensor_builtin(&cos, PS_SENS_COSINE, &e), 0);
	if (ps_sensor_parse(&nar, narrow, sizeof narrow - 1, "narrow", &e) != 0 ||
	    ps_sensor_set_reading(&nar, PS_READ_LINEAR, &e) != 0)
		fail_msg("%s", e.msg);
	ps_view_default_fisheye(&v);
	for (size_t k = 0; k < 2; k++) {
		struct ps_picture pic, head;
		struct ps_weights w[3];
		const struct ps_weights *ws[3] = { &w[0], &w[1], &w[2] };
		struct ps_response want[3], got[3];
		size_t len, off;
		uint8_t *d = make(64, 64, suns[k][0], suns[k][1], NULL, &len);
		if (ps_picture_read_mem(&pic, d, len, "mem", &e) != 0 ||
		    ps_picture_head_mem(&head, d, len, "mem", &off, &e) != 0)
			fail_msg("%s", e.msg);
		assert_int_equal(ps_weights_build(&w[0], &cos, 0, &v, 64, 64, PS_W_EXACT, &e), 0);
		assert_int_equal(ps_weights_build_ex(&w[1], &cos, 0, &v, 64, 64, PS_W_EXACT,
		                                     PS_WB_COMPACT, &e), 0);
		assert_int_equal(ps_weights_build(&w[2], &nar, 25, &v, 64, 64, PS_W_EXACT, &e), 0);
		assert_int_equal(w[1].mirror, 1);
		for (int m = 0; m < 3; m++)
			assert_int_equal(ps_integrate(&w[m], &pic, coef, &want[m], &e), 0);
		if (k == 1)   /* the sun: the second pass runs */
			assert_false(isnan(want[0].top1_share));
		for (int nt = 1; nt <= 3; nt++) {
			if (ps_stream_integrate_multi(ws, 3, &head, d, len, off, "mem", coef, nt, got, &e) != 0)
				fail_msg("%s", e.msg);
			for (int m = 0; m < 3; m++) {
				assert_true(got[m].response == want[m].response);
				for (int c = 0; c < 3; c++)
					assert_true(got[m].rgb[c] == want[m].rgb[c]);
				assert_true(got[m].brightest_share == want[m].brightest_share);
				assert_int_equal(got[m].brightest_x, want[m].brightest_x);
				assert_int_equal(got[m].brightest_row, want[m].brightest_row);
				if (isnan(want[m].top1_share))
					assert_true(isnan(got[m].top1_share));
				else
					assert_true(got[m].top1_share == want[m].top1_share);
			}
		}
		/* the compact map and the full one: the same sensor, the same answer */
		assert_true(fabs(got[1].response / got[0].response - 1) <= 1e-14);
		for (int m = 0; m < 3; m++)
			ps_weights_free(&w[m]);
		ps_picture_free(&pic);
		ps_picture_free(&head);
		free(d);
	}
	ps_sensor_free(&cos);
	ps_sensor_free(&nar);
}

static void damage_is_named(void **state)
{
	size_t len;
	uint8_t *d = make(64, 64, -1, 0, NULL, &len);
	struct ps_picture head, pic;
	struct ps_sensor s;
	struct ps_view v;
	struct ps_weights w;
	struct ps_response r;
	struct ps_err e, ref;
	size_t off;
	(void)state;
	assert_int_equal(ps_sensor_builtin(&s, PS_SENS_COSINE, &e), 0);
	ps_view_default_fisheye(&v);
	assert_int_equal(ps_weights_build(&w, &s, 0, &v, 64, 64, PS_W_EXACT, &e), 0);
	assert_int_equal(ps_picture_head_mem(&head, d, len, "cut.hdr", &off, &e), 0);
	/* cut in the middle of the scanlines */
	assert_int_equal(ps_picture_read_mem(&pic, d, len - len / 3, "cut.hdr", &ref), -1);
	for (int nt = 1; nt <= 3; nt++) {
		assert_int_equal(ps_stream_integrate(&w, &head, d, len - len / 3, off, "cut.hdr", coef, nt,
		                                     &r, &e), -1);
		/* the message ps_picture_read_mem gives: the same byte */
		assert_string_equal(e.msg, ref.msg);
	}
	ps_picture_free(&head);
	ps_weights_free(&w);
	ps_sensor_free(&s);
	free(d);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(run_length_pictures),
		cmocka_unit_test(flat_pictures),
		cmocka_unit_test(xyze_picture),
		cmocka_unit_test(other_orientation),
		cmocka_unit_test(several_maps_one_decoding),
		cmocka_unit_test(damage_is_named),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
