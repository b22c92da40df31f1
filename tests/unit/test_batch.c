/* SPDX-License-Identifier: ISC */
/* Batches (sim/weights/batch.h): every picture's result is the one-picture route's
 * (ps_integrate with the same weights) bit for bit, in input order with 1, 2
 * and 5 threads; a picture of another size or view, or one that cannot be
 * read, is an error of that picture naming its file, and the others are
 * unaffected. */
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

#include "batch.h"
#include "integrate.h"
#include "picture.h"
#include "sensor.h"
#include "view.h"
#include "weights.h"

enum { W = 40, H = 40, NPIC = 23 };

static char dir[64];
static char paths[NPIC + 3][128];

/* Picture k: a gradient whose brightness and colour depend on k, so that
 * every picture has its own response (an order swap cannot go unseen). */
static void write_picture(const char *path, int w, int h, int k, const char *view)
{
	double *rgb = malloc((size_t)w * h * 3 * sizeof *rgb);
	struct ps_err e;
	assert_non_null(rgb);
	for (int y = 0; y < h; y++)
		for (int x = 0; x < w; x++) {
			double *p = rgb + 3 * ((size_t)y * w + x);
			p[0] = (1 + k) * (0.1 + 0.01 * x);
			p[1] = (1 + k * 0.5) * (0.2 + 0.02 * y);
			p[2] = 0.3 + 0.001 * k * (x + y);
		}
	if (ps_picture_write(path, w, h, rgb, view, NULL, &e) != 0)
		fail_msg("%s", e.msg);
	free(rgb);
}

static int setup(void **state)
{
	(void)state;
	snprintf(dir, sizeof dir, "/tmp/test_batch.XXXXXX");
	if (!mkdtemp(dir))
		return -1;
	for (int k = 0; k < NPIC; k++) {
		snprintf(paths[k], sizeof paths[k], "%s/p%02d.hdr", dir, k);
		write_picture(paths[k], W, H, k, "-vta -vh 180 -vv 180");
	}
	/* another size, another view, and no picture at all */
	snprintf(paths[NPIC], sizeof paths[NPIC], "%s/small.hdr", dir);
	write_picture(paths[NPIC], W / 2, H, 1, "-vta -vh 180 -vv 180");
	snprintf(paths[NPIC + 1], sizeof paths[NPIC + 1], "%s/wide.hdr", dir);
	write_picture(paths[NPIC + 1], W, H, 1, "-vta -vh 200 -vv 200");
	snprintf(paths[NPIC + 2], sizeof paths[NPIC + 2], "%s/missing.hdr", dir);
	return 0;
}

static int teardown(void **state)
{
	(void)state;
	for (int k = 0; k < NPIC + 2; k++)
		unlink(paths[k]);
	rmdir(dir);
	return 0;
}

static void batch_for(struct ps_batch *b, struct ps_sensor *s, int nthreads)
{
	struct ps_view v;
	struct ps_err e;
	const double coef[3] = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B };
	assert_int_equal(ps_sensor_builtin(s, PS_SENS_COSINE, &e), 0);
	ps_view_default_fisheye(&v);
	struct ps_batch_spec sp = { .map = { s, 30.0, &v, W, H, PS_W_EXACT }, .coef = coef,
	                            .nthreads = nthreads };
	if (ps_batch_init(b, &sp, &e) != 0)
		fail_msg("%s", e.msg);
}

/* The one-picture route with the batch's weights. */
static struct ps_response direct(const struct ps_batch *b, const char *path)
{
	struct ps_picture pic;
	struct ps_response r;
	struct ps_err e;
	memset(&r, 0, sizeof r);
	if (ps_picture_read(&pic, path, &e) != 0 || ps_integrate(&b->w, &pic, b->coef, &r, &e) != 0)
		fail_msg("%s", e.msg);
	ps_picture_free(&pic);
	return r;
}

static void same_as_one_picture_in_order(void **state)
{
	static const int threads[] = { 1, 2, 5 };
	struct ps_response want[NPIC];
	const char *list[NPIC];
	(void)state;
	for (int k = 0; k < NPIC; k++)
		list[k] = paths[k];
	for (size_t t = 0; t < sizeof threads / sizeof threads[0]; t++) {
		struct ps_batch b;
		struct ps_sensor s;
		struct ps_batch_result out[NPIC];
		struct ps_err e;
		batch_for(&b, &s, threads[t]);
		if (t == 0)
			for (int k = 0; k < NPIC; k++)
				want[k] = direct(&b, paths[k]);
		assert_int_equal(ps_batch_run_files(&b, list, NPIC, out, &e), 0);
		for (int k = 0; k < NPIC; k++) {
			assert_int_equal(out[k].status, PS_BATCH_OK);
			/* exactly: same weights, same order of summation */
			assert_true(out[k].r.response == want[k].response);
			for (int c = 0; c < 3; c++)
				assert_true(out[k].r.rgb[c] == want[k].rgb[c]);
			assert_int_equal(out[k].width, W);
			assert_int_equal(out[k].view_assumed, 0);
			if (k)   /* every picture its own: order is seen */
				assert_true(out[k].r.response != out[k - 1].r.response);
		}
		ps_batch_free(&b);
		ps_sensor_free(&s);
	}
}

static void mismatches_name_their_file(void **state)
{
	const char *list[] = { paths[0], paths[NPIC], paths[1], paths[NPIC + 1], paths[NPIC + 2],
	                       paths[2] };
	struct ps_batch b;
	struct ps_sensor s;
	struct ps_batch_result out[6];
	struct ps_err e;
	(void)state;
	batch_for(&b, &s, 2);
	assert_int_equal(ps_batch_run_files(&b, list, 6, out, &e), 3);
	assert_int_equal(out[0].status, PS_BATCH_OK);
	assert_int_equal(out[2].status, PS_BATCH_OK);
	assert_int_equal(out[5].status, PS_BATCH_OK);
	assert_true(out[2].r.response == direct(&b, paths[1]).response);
	assert_int_equal(out[1].status, PS_BATCH_MISMATCH);
	assert_non_null(strstr(out[1].err.msg, paths[NPIC]));
	assert_non_null(strstr(out[1].err.msg, "20 x 40"));
	assert_int_equal(out[3].status, PS_BATCH_MISMATCH);
	assert_non_null(strstr(out[3].err.msg, paths[NPIC + 1]));
	assert_non_null(strstr(out[3].err.msg, "view"));
	assert_int_equal(out[4].status, PS_BATCH_FAILED);
	assert_non_null(strstr(out[4].err.msg, paths[NPIC + 2]));
	ps_batch_free(&b);
	ps_sensor_free(&s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(same_as_one_picture_in_order),
		cmocka_unit_test(mismatches_name_their_file),
	};
	return cmocka_run_group_tests(tests, setup, teardown);
}
