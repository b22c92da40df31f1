/* SPDX-License-Identifier: ISC */
/* Compact symmetric weight maps (weights.h: PS_WB_COMPACT, a quarter of the
 * weights stored, runs read as palindromes, mirrored rows sharing theirs)
 * against the full maps of ps_weights_build and the analytic answers:
 * - every pixel of the full map has the same weight in the compact one
 *   (within 1e-13 of the largest weight: the full map computes the few
 *   pixels its mirror misses on their own), and every pixel the compact map
 *   adds to make its ranges symmetric weighs nothing;
 * - the cosine sensor's total is pi within 1e-12 on square pictures, and
 *   the uniform sensor's the picture's solid angle (the closed line
 *   integral around the whole picture, one computation), at even and odd
 *   sizes; on oblong ones the totals equal the full map's;
 * - a uniform picture integrates to pi x its decoded radiance within 1e-12,
 *   through the whole-picture route and the streamed one, at 1 and 2
 *   threads, the same as with the full map;
 * - the same on a hemispherical fisheye, one wider than high and one that
 *   misses part of the sensitivity;
 * - a sensor that changes with azimuth gets a full map (mirror 0);
 * - the cache keeps a compact map as it is (hit: the same weights and
 *   runs), and a payload whose run shares weights it cannot is refused. */
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

#include "fileio.h"
#include "integrate.h"
#include "picture.h"
#include "sensor.h"
#include "stream.h"
#include "view.h"
#include "wcache.h"
#include "weights.h"

#define DECODED_ONE 1.00390625   /* RGBE's 1 as Radiance decodes it */

static const int sizes[][2] = { { 1, 1 }, { 2, 2 }, { 3, 3 }, { 8, 5 }, { 33, 33 }, { 64, 64 },
                                { 101, 77 }, { 256, 256 }, { 511, 512 }, { 1000, 1000 } };

/* The weight of pixel (x, row) in w, or NAN when no run holds it (rr:
 * row -> run, -1 none). */
static double weight_at(const struct ps_weights *w, const int *rr, int x, int row)
{
	const struct ps_weights_run *r;
	if (rr[row] < 0)
		return NAN;
	r = &w->runs[rr[row]];
	return x >= r->x0 && x < r->x0 + r->n ? ps_weights_run_at(w, r, x - r->x0) : NAN;
}

static int *row_runs(const struct ps_weights *w)
{
	int *rr = malloc((size_t)w->height * sizeof *rr);
	assert_non_null(rr);
	for (int i = 0; i < w->height; i++)
		rr[i] = -1;
	for (size_t i = 0; i < w->nruns; i++) {
		assert_int_equal(rr[w->runs[i].row], -1);   /* one run a row */
		rr[w->runs[i].row] = (int)i;
	}
	return rr;
}

/* exact_total: NAN for the picture's solid angle, below 0 for none (the
 * full map's total only) */
static void compare_in(const struct ps_sensor *s, const struct ps_view *v, int width, int height,
                       double exact_total)
{
	struct ps_weights full, comp;
	struct ps_err e;
	double maxw = 0;
	size_t npix = 0;
	assert_int_equal(ps_weights_build(&full, s, 0, v, width, height, PS_W_EXACT, &e), 0);
	assert_int_equal(ps_weights_build_ex(&comp, s, 0, v, width, height, PS_W_EXACT,
	                                     PS_WB_COMPACT, &e), 0);
	assert_int_equal(full.mirror, 0);
	assert_int_equal(comp.mirror, 1);
	assert_true(comp.nw <= full.nw);
	for (size_t i = 0; i < full.nw; i++)
		maxw = fmax(maxw, full.w[i]);
	/* row by row: the full map's pixels, and the compact map's extra ones */
	int *rf = row_runs(&full), *rc = row_runs(&comp);
	for (int row = 0; row < height; row++)
		for (int x = 0; x < width; x++) {
			double a = weight_at(&full, rf, x, row), b = weight_at(&comp, rc, x, row);
			if (!isnan(a)) {
				assert_false(isnan(b));
				if (fabs(a - b) > 1e-13 * maxw)
					fail_msg("%d x %d: pixel %d, row %d: full %.17g, compact %.17g", width,
					         height, x, row, a, b);
			} else if (!isnan(b)) {
				assert_true(fabs(b) <= 1e-13 * maxw);
			}
		}
	free(rf);
	free(rc);
	for (size_t i = 0; i < comp.nruns; i++)
		npix += (size_t)comp.runs[i].n;
	assert_int_equal(npix, comp.npix);
	if (isnan(exact_total))
		exact_total = comp.solid_angle;
	if (width == height && exact_total >= 0 && fabs(comp.sens_sum / exact_total - 1) > 1e-12)
		fail_msg("%d x %d: total %.17g, exact %.17g", width, height, comp.sens_sum, exact_total);
	assert_true(fabs(comp.sens_sum / full.sens_sum - 1) <= 1e-13);
	assert_true(comp.solid_angle == full.solid_angle);
	ps_weights_free(&full);
	ps_weights_free(&comp);
}

static void compare(const struct ps_sensor *s, int width, int height, double exact_total)
{
	struct ps_view v;
	ps_view_default_fisheye(&v);
	compare_in(s, &v, width, height, exact_total);
}

/* Other fisheyes: hemispherical (the cosine's integral is still pi), a
 * field wider than high (no diagonal symmetry), a narrow one that misses
 * part of the sensitivity (the full map's total only). */
static void other_views(void **state)
{
	static const struct {
		const char *view;
		double cosine;   /* the cosine's exact total, or -1 */
	} views[] = { { "-vth -vh 180 -vv 180", M_PI }, { "-vta -vh 200 -vv 160", -1 },
	              { "-vta -vh 120 -vv 120", -1 } };
	static const int sizes2[][2] = { { 33, 33 }, { 64, 64 }, { 101, 77 }, { 300, 300 } };
	struct ps_sensor cosine;
	struct ps_err e;
	(void)state;
	assert_int_equal(ps_sensor_builtin(&cosine, PS_SENS_COSINE, &e), 0);
	for (size_t k = 0; k < sizeof views / sizeof views[0]; k++) {
		struct ps_view v;
		ps_view_default_fisheye(&v);   /* the options below change it */
		if (ps_view_parse(&v, views[k].view, "test", &e) != 0)
			fail_msg("%s", e.msg);
		for (size_t n = 0; n < sizeof sizes2 / sizeof sizes2[0]; n++)
			compare_in(&cosine, &v, sizes2[n][0], sizes2[n][1], views[k].cosine);
	}
	ps_sensor_free(&cosine);
}

static void compact_equals_full(void **state)
{
	/* a table the same at every azimuth: symmetric too */
	static const char table[] = "Elevation field 90\ndegrees 0 90 180 270\n0 1 1 1 1\n30 0.9 0.9 0.9 0.9\n"
	                            "60 0.5 0.5 0.5 0.5\n85 0.1 0.1 0.1 0.1\n90 0 0 0 0\n";
	struct ps_sensor cosine, uni, tab;
	struct ps_err e;
	(void)state;
	assert_int_equal(ps_sensor_builtin(&cosine, PS_SENS_COSINE, &e), 0);
	assert_int_equal(ps_sensor_builtin(&uni, PS_SENS_UNIFORM, &e), 0);
	assert_int_equal(ps_sensor_parse(&tab, table, sizeof table - 1, "t", &e), 0);
	assert_int_equal(ps_sensor_set_reading(&tab, PS_READ_LINEAR, &e), 0);
	for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
		compare(&tab, sizes[k][0], sizes[k][1], ps_sensor_integral(&tab));
		compare(&cosine, sizes[k][0], sizes[k][1], M_PI);
		compare(&uni, sizes[k][0], sizes[k][1], NAN);   /* the picture's solid angle */
	}
	ps_sensor_free(&cosine);
	ps_sensor_free(&uni);
	ps_sensor_free(&tab);
}

/* A uniform picture through both routes with both maps. */
static void uniform_picture_integrates_to_pi(void **state)
{
	static const int n[] = { 33, 256, 1000 };
	const double coef[3] = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B };
	struct ps_sensor cosine;
	struct ps_view v;
	struct ps_err e;
	char path[] = "/tmp/test_weights_compact.XXXXXX";
	int fd = mkstemp(path);
	(void)state;
	assert_true(fd >= 0);
	close(fd);
	assert_int_equal(ps_sensor_builtin(&cosine, PS_SENS_COSINE, &e), 0);
	ps_view_default_fisheye(&v);
	for (size_t k = 0; k < sizeof n / sizeof n[0]; k++) {
		double *rgb = malloc(sizeof(double) * 3 * (size_t)n[k] * (size_t)n[k]);
		struct ps_weights full, comp;
		struct ps_picture pic, head;
		struct ps_response rf, rc;
		struct ps_fileio_map m;
		size_t off;
		assert_non_null(rgb);
		for (size_t i = 0; i < 3 * (size_t)n[k] * (size_t)n[k]; i++)
			rgb[i] = 1.0;
		assert_int_equal(ps_picture_write(path, n[k], n[k], rgb,
		                                  "-vta -vd 0 0 -1 -vu 0 1 0 -vh 180 -vv 180", NULL, &e), 0);
		free(rgb);
		assert_int_equal(ps_picture_read(&pic, path, &e), 0);
		assert_int_equal(ps_weights_build(&full, &cosine, 0, &v, n[k], n[k], PS_W_EXACT, &e), 0);
		assert_int_equal(ps_weights_build_ex(&comp, &cosine, 0, &v, n[k], n[k], PS_W_EXACT,
		                                     PS_WB_COMPACT, &e), 0);
		assert_int_equal(ps_integrate(&full, &pic, coef, &rf, &e), 0);
		assert_int_equal(ps_integrate(&comp, &pic, coef, &rc, &e), 0);
		assert_true(fabs(rc.response / (DECODED_ONE * M_PI) - 1) <= 1e-12);
		assert_true(fabs(rc.response / rf.response - 1) <= 1e-14);
		/* the pixels counted: the symmetric ranges may add some of weight 0 */
		assert_true(rc.npixels >= rf.npixels);
		assert_int_equal(ps_fileio_map(path, (size_t)1 << 30, &m, &e), 0);
		assert_int_equal(ps_picture_head_mem(&head, m.data, m.len, path, &off, &e), 0);
		for (int nt = 1; nt <= 2; nt++) {
			struct ps_response rs;
			assert_int_equal(ps_stream_integrate(&comp, &head, m.data, m.len, off, path, coef, nt,
			                                     &rs, &e), 0);
			/* the streamed route sums in the same order: bit for bit */
			assert_true(rs.response == rc.response);
		}
		ps_picture_free(&head);
		ps_fileio_unmap(&m);
		ps_picture_free(&pic);
		ps_weights_free(&full);
		ps_weights_free(&comp);
	}
	unlink(path);
	ps_sensor_free(&cosine);
}

static void azimuthal_sensor_gets_a_full_map(void **state)
{
	static const char table[] = "Elevation field 90\ndegrees 0 90 180 270\n0 1 1 1 1\n30 0.9 0.7 0.8 0.6\n"
	                            "90 0 0 0 0\n";
	struct ps_sensor s;
	struct ps_weights w;
	struct ps_view v;
	struct ps_err e;
	(void)state;
	assert_int_equal(ps_sensor_parse(&s, table, sizeof table - 1, "t", &e), 0);
	ps_view_default_fisheye(&v);
	assert_int_equal(ps_weights_build_ex(&w, &s, 0, &v, 64, 64, PS_W_EXACT, PS_WB_COMPACT, &e), 0);
	assert_int_equal(w.mirror, 0);
	assert_int_equal(w.nw, w.npix);
	ps_weights_free(&w);
	ps_sensor_free(&s);
}

static void cache_keeps_compact_maps(void **state)
{
	struct ps_sensor cosine;
	struct ps_weights a, b, c;
	struct ps_view v;
	struct ps_err e, warn;
	char dir[] = "/tmp/test_weights_compact_c.XXXXXX", cmd[128];
	int how;
	(void)state;
	assert_non_null(mkdtemp(dir));
	assert_int_equal(ps_sensor_builtin(&cosine, PS_SENS_COSINE, &e), 0);
	ps_view_default_fisheye(&v);
	assert_int_equal(ps_wcache_get(&a, &(struct ps_wcache_key){ &cosine, 0, &v, 101, 101, PS_W_EXACT }, &(struct ps_wcache_dir){ dir, 0 }, &how,
	                               &warn, &e), 0);
	assert_int_equal(how, PS_WC_STORED);
	assert_int_equal(a.mirror, 1);
	assert_int_equal(ps_wcache_get(&b, &(struct ps_wcache_key){ &cosine, 0, &v, 101, 101, PS_W_EXACT }, &(struct ps_wcache_dir){ dir, 0 }, &how,
	                               &warn, &e), 0);
	assert_int_equal(how, PS_WC_HIT);
	assert_int_equal(b.mirror, 1);
	assert_int_equal(a.nruns, b.nruns);
	assert_int_equal(a.nw, b.nw);
	assert_int_equal(a.npix, b.npix);
	for (size_t i = 0; i < a.nruns; i++) {
		assert_int_equal(a.runs[i].row, b.runs[i].row);
		assert_int_equal(a.runs[i].x0, b.runs[i].x0);
		assert_int_equal(a.runs[i].n, b.runs[i].n);
		assert_int_equal(a.runs[i].off, b.runs[i].off);
	}
	assert_memory_equal(a.w, b.w, a.nw * sizeof *a.w);
	/* the payload again, its last run made to share a run that is not its
	 * own (its share index pointing at itself, then at a shared run) */
	{
		size_t len = b.maplen - 128;
		uint8_t *p = malloc(len);
		int32_t k;
		assert_non_null(p);
		memcpy(p, (const uint8_t *)b.map + 128, len);
		assert_int_equal(ps_wcache_from_payload(&c, p, len, 101, 101, PS_W_EXACT, "p", &e), 0);
		assert_int_equal(c.mirror, 1);
		ps_weights_free(&(struct ps_weights){ .runs = c.runs });
		k = (int32_t)a.nruns;   /* itself */
		memcpy(p + 64 + (a.nruns - 1) * 16 + 12, &k, 4);
		assert_int_equal(ps_wcache_from_payload(&c, p, len, 101, 101, PS_W_EXACT, "p", &e), -1);
		k = (int32_t)a.nruns - 1;   /* the run before: shared too */
		memcpy(p + 64 + (a.nruns - 1) * 16 + 12, &k, 4);
		assert_int_equal(ps_wcache_from_payload(&c, p, len, 101, 101, PS_W_EXACT, "p", &e), -1);
		assert_non_null(strstr(e.msg, "shares"));
		free(p);
	}
	ps_weights_free(&a);
	ps_weights_free(&b);
	ps_sensor_free(&cosine);
	snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
	assert_int_equal(system(cmd), 0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(compact_equals_full),
		cmocka_unit_test(other_views),
		cmocka_unit_test(uniform_picture_integrates_to_pi),
		cmocka_unit_test(azimuthal_sensor_gets_a_full_map),
		cmocka_unit_test(cache_keeps_compact_maps),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
