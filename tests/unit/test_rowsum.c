/* SPDX-License-Identifier: ISC */
/* The integration's run kernel (sim/weights/rowsum.c): every instruction set gives
 * the same bits; the sum is as good as a compensated sum of the pixels'
 * own responses (ps_integrate_pixel_response); the brightest pixel is the first of
 * equals; a mirrored map reads as its full map. */
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
#include "rowsum.h"
#include "sum.h"

static const double kc[3] = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B };

static uint64_t rng = 88172645463325252ull;
static uint32_t next(void)
{
	rng ^= rng << 13;
	rng ^= rng >> 7;
	rng ^= rng << 17;
	return (uint32_t)rng;
}

/* A run of len pixels: random mantissas, exponents near 128 with one
 * pixel in eight black, one in six weights zero. */
static void fill(uint8_t *px, double *wt, int len)
{
	for (int i = 0; i < len; i++) {
		for (int c = 0; c < 3; c++)
			px[4 * i + c] = (uint8_t)next();
		px[4 * i + 3] = next() % 8 == 0 ? 0 : (uint8_t)(120 + next() % 20);
		wt[i] = next() % 6 == 0 ? 0.0 : (double)(next() % 100000) / 7e6;
	}
}

/* The kernel k on len pixels with weights wt: one run of a map, compact
 * (the first (len + 1) / 2 weights stored) when mirror. */
static void run_on(enum ps_rowsum_kernel k, const uint8_t *px, const double *wt, int len, int mirror,
                   struct ps_rowsum *out)
{
	struct ps_weights w;
	struct ps_weights_run run = { 0, 0, len, 0 };
	memset(&w, 0, sizeof w);
	w.w = (double *)wt;
	w.mirror = mirror;
	ps_rowsum_with(k, px, &w, &run, kc, out);
}

static int same(const struct ps_rowsum *a, const struct ps_rowsum *b)
{
	return memcmp(&a->sum, &b->sum, sizeof a->sum) == 0 && memcmp(a->raw, b->raw, sizeof a->raw) == 0 &&
	       memcmp(&a->best, &b->best, sizeof a->best) == 0 && a->best_i == b->best_i && a->n == b->n;
}

/* The reference: each pixel's response alone, summed with compensation. */
static void reference(const uint8_t *px, const double *wt, int len, double *sum, double *best, int *best_i,
                      size_t *n)
{
	struct ps_sum s;
	double raws[3] = { 0, 0, 0 };
	ps_sum_init(&s);
	*best = -1;
	*best_i = -1;
	*n = 0;
	for (int i = 0; i < len; i++) {
		double b;
		if (px[4 * i + 3] == 0)
			continue;
		b = ps_integrate_pixel_response(px + 4 * i, wt[i], kc, raws);
		ps_sum_add(&s, b);
		++*n;
		if (b > *best) {
			*best = b;
			*best_i = i;
		}
	}
	*sum = ps_sum_get(&s);
}

static void kernels_give_the_same_bits(void **state)
{
	enum { MAX = 4003 };
	uint8_t *px = malloc(4 * MAX);
	double *wt = malloc(sizeof(double) * MAX);
	int ran[3] = { 0, 0, 0 }, lens[] = { 0, 1, 2, 3, 4, 5, 7, 8, 9, 13, 64, 255, 1001, 4003 };
	(void)state;
	for (size_t t = 0; t < sizeof lens / sizeof lens[0]; t++)
		for (int rep = 0; rep < 20; rep++)
			for (int mirror = 0; mirror < 2; mirror++) {
				struct ps_rowsum c, k;
				fill(px, wt, lens[t]);
				run_on(PS_ROWSUM_C, px, wt, lens[t], mirror, &c);
				for (int kk = PS_ROWSUM_SSE2; kk <= PS_ROWSUM_AVX2; kk++) {
					if (!ps_rowsum_have((enum ps_rowsum_kernel)kk))
						continue;
					run_on((enum ps_rowsum_kernel)kk, px, wt, lens[t], mirror, &k);
					if (!same(&c, &k))
						fail_msg("%s and C differ: length %d, mirror %d, try %d: %.17g %.17g",
						         ps_rowsum_name((enum ps_rowsum_kernel)kk), lens[t], mirror, rep,
						         ps_sum_get(&k.sum), ps_sum_get(&c.sum));
					ran[kk]++;
				}
			}
	print_message("compared with C: SSE2 %d runs, AVX2 %d runs (0: not on this machine); ps_rowsum runs %s\n",
	              ran[PS_ROWSUM_SSE2], ran[PS_ROWSUM_AVX2], ps_rowsum_name(ps_rowsum_best()));
	free(px);
	free(wt);
}

static void sum_count_and_brightest_match_the_pixels(void **state)
{
	enum { MAX = 4003 };
	uint8_t *px = malloc(4 * MAX);
	double *wt = malloc(sizeof(double) * MAX);
	(void)state;
	for (int len = 0; len <= MAX; len += len < 40 ? 1 : 397) {
		struct ps_rowsum r;
		double sum, best, raws[3] = { 0, 0, 0 }, rgb_sum = 0;
		int best_i;
		size_t n;
		fill(px, wt, len);
		reference(px, wt, len, &sum, &best, &best_i, &n);
		run_on(ps_rowsum_best(), px, wt, len, 0, &r);
		assert_true(fabs(ps_sum_get(&r.sum) - sum) <= 2e-16 * fabs(sum));
		assert_int_equal(r.n, n);
		assert_int_equal(r.best_i, best_i);
		assert_true(r.best == best);
		/* the channel sums: kc . raw is the response (plain sums, n eps) */
		for (int i = 0; i < len; i++)
			if (px[4 * i + 3])
				ps_integrate_pixel_response(px + 4 * i, wt[i], kc, raws);
		for (int c = 0; c < 3; c++) {
			assert_true(fabs(r.raw[c] - raws[c]) <= 1e-13 * fabs(raws[c]) + 1e-300);
			rgb_sum += kc[c] * r.raw[c];
		}
		assert_true(fabs(rgb_sum - sum) <= 1e-13 * fabs(sum) + 1e-300);
	}
	free(px);
	free(wt);
}

/* A 1e9 sun among 1e-2 walls, with weights of full mantissas (their
 * products do not fit a double exactly): the compensated sum keeps the
 * walls to 1e-12, in every lane the sun can fall in, with every kernel.
 * A plain sum keeps them to about 1e-6 only. */
static void the_sun_does_not_swallow_the_walls(void **state)
{
	enum { LEN = 1000 };
	uint8_t px[4 * LEN], wallpx[4], sunpx[4];
	double wt[LEN];
	(void)state;
	ps_picture_rgbe_encode((double[3]){ 1e-2, 1e-2, 1e-2 }, wallpx);
	ps_picture_rgbe_encode((double[3]){ 1e9, 1e9, 1e9 }, sunpx);
	for (int i = 0; i < LEN; i++)
		wt[i] = (1 + i % 7) / 3e3;
	for (int at = 0; at < 8; at++)
		for (int kk = PS_ROWSUM_C; kk <= PS_ROWSUM_AVX2; kk++) {
			struct ps_rowsum r;
			struct ps_sum walls;
			double raws[3] = { 0, 0, 0 }, sun = 0;
			ps_sum_init(&walls);
			for (int i = 0; i < LEN; i++) {
				memcpy(px + 4 * i, i == 500 + at ? sunpx : wallpx, 4);
				if (i == 500 + at)
					sun = ps_integrate_pixel_response(sunpx, wt[i], kc, raws);
				else
					ps_sum_add(&walls, ps_integrate_pixel_response(wallpx, wt[i], kc, raws));
			}
			run_on((enum ps_rowsum_kernel)kk, px, wt, LEN, 0, &r);
			/* the sum and its compensation, the sun taken out first
			 * (exact: the two are within a factor 2) */
			double rel = fabs(((r.sum.s - sun) + r.sum.c) / ps_sum_get(&walls) - 1);
			if (!(rel < 1e-12))
				fail_msg("%s, sun at %d: walls off by %.3g", ps_rowsum_name((enum ps_rowsum_kernel)kk), 500 + at, rel);
			assert_int_equal(r.best_i, 500 + at);
		}
}

/* Ties: the lowest index wins, in one lane or across lanes; black pixels
 * are never the brightest; a lit pixel of weight 0 is, when nothing else is. */
static void the_brightest_is_the_first_of_equals(void **state)
{
	uint8_t px[4 * 12];
	double wt[12];
	struct ps_rowsum r;
	(void)state;
	for (int kk = PS_ROWSUM_C; kk <= PS_ROWSUM_AVX2; kk++) {
		enum ps_rowsum_kernel k = (enum ps_rowsum_kernel)kk;
		for (int i = 0; i < 12; i++) {
			ps_picture_rgbe_encode((double[3]){ 1, 1, 1 }, px + 4 * i);
			wt[i] = 1;
		}
		wt[6] = wt[3] = 2;   /* lanes 2 and 3: 3 first */
		run_on(k, px, wt, 12, 0, &r);
		assert_int_equal(r.best_i, 3);
		wt[3] = 1;
		wt[10] = 2;          /* lane 2 twice: 6 first */
		run_on(k, px, wt, 12, 0, &r);
		assert_int_equal(r.best_i, 6);
		memset(px, 0, sizeof px);
		run_on(k, px, wt, 12, 0, &r);
		assert_int_equal(r.n, 0);
		assert_int_equal(r.best_i, -1);
		assert_true(ps_sum_get(&r.sum) == 0);
		ps_picture_rgbe_encode((double[3]){ 5, 5, 5 }, px + 4 * 9);
		wt[9] = 0;
		run_on(k, px, wt, 12, 0, &r);
		assert_int_equal(r.n, 1);
		assert_int_equal(r.best_i, 9);
		assert_true(r.best == 0);
	}
}

/* A compact map (the first (len + 1) / 2 weights, the rest mirrored) gives
 * the bits of its full map. */
static void a_mirrored_map_reads_as_its_full_map(void **state)
{
	enum { MAX = 203 };
	uint8_t px[4 * MAX];
	double half[MAX], full[MAX];
	(void)state;
	for (int len = 1; len <= MAX; len++) {
		struct ps_rowsum m, f;
		fill(px, half, len);
		for (int i = 0; i < len; i++)
			full[i] = i < (len + 1) / 2 ? half[i] : half[len - 1 - i];
		run_on(ps_rowsum_best(), px, half, len, 1, &m);
		run_on(ps_rowsum_best(), px, full, len, 0, &f);
		assert_true(same(&m, &f));
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(kernels_give_the_same_bits),
		cmocka_unit_test(sum_count_and_brightest_match_the_pixels),
		cmocka_unit_test(the_sun_does_not_swallow_the_walls),
		cmocka_unit_test(the_brightest_is_the_first_of_equals),
		cmocka_unit_test(a_mirrored_map_reads_as_its_full_map),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
