/* SPDX-License-Identifier: ISC */
/* The run kernel (rowsum.h) in AVX2: four lanes in one register.  Built
 * with -mavx2 on x86 (sim/module.mk) and run only where the processor has
 * it (rowsum.c asks); elsewhere ps_rowsum_avx2_built is 0. */
#include "rowsum.h"

#include <string.h>

#include "picture.h"

void ps_rowsum_avx2(const uint8_t *px, const struct ps_weights *w, const struct ps_weights_run *run,
                    const double kc[3], struct ps_rowsum *out);
extern const int ps_rowsum_avx2_built;

#ifdef __AVX2__
#include <immintrin.h>

const int ps_rowsum_avx2_built = 1;

#define RS_HOT static inline __attribute__((always_inline))

static inline __m256d a_dup(double a) { return _mm256_set1_pd(a); }
static inline __m256d a_set(double a, double b, double c, double d) { return _mm256_set_pd(d, c, b, a); }
static inline __m256d a_load(const double *p) { return _mm256_loadu_pd(p); }
static inline __m256d a_rev(const double *p) { return _mm256_permute4x64_pd(_mm256_loadu_pd(p), 0x1B); }
static inline double a_get(__m256d a, int l)
{
	double v[4];
	_mm256_storeu_pd(v, a);
	return v[l];
}
static inline unsigned a_decode(const uint8_t *p, __m256d *c0, __m256d *c1, __m256d *c2, __m256d *sc,
                                __m256d *black)
{
	/* little-endian: byte c of pixel k is bits 8c..8c+7 of 32-bit lane k */
	__m128i x = _mm_loadu_si128((const __m128i *)(const void *)p), ff = _mm_set1_epi32(0xff);
	__m128i e = _mm_srli_epi32(x, 24), bl = _mm_cmpeq_epi32(e, _mm_setzero_si128());
	__m256i bl64 = _mm256_cvtepi32_epi64(bl);
	/* 2^(e-136) built as a double's bits, (e - 136 + 1023) << 52: exact,
	 * the same as ps_picture_rgbe_scale; black (e = 0) masked to 0 */
	__m256i bits = _mm256_slli_epi64(_mm256_add_epi64(_mm256_cvtepu32_epi64(e), _mm256_set1_epi64x(1023 - 136)), 52);
	*sc = _mm256_castsi256_pd(_mm256_andnot_si256(bl64, bits));
	*c0 = _mm256_cvtepi32_pd(_mm_and_si128(x, ff));
	*c1 = _mm256_cvtepi32_pd(_mm_and_si128(_mm_srli_epi32(x, 8), ff));
	*c2 = _mm256_cvtepi32_pd(_mm_and_si128(_mm_srli_epi32(x, 16), ff));
	*black = _mm256_castsi256_pd(bl64);
	return 4 - (unsigned)__builtin_popcount((unsigned)_mm_movemask_ps(_mm_castsi128_ps(bl)));
}
static inline void a_keep(__m256d *best, __m256d *idx, __m256d b, __m256d at, __m256d black)
{
	__m256d m = _mm256_andnot_pd(black, _mm256_cmp_pd(b, *best, _CMP_GT_OQ));
	*best = _mm256_blendv_pd(*best, b, m);
	*idx = _mm256_blendv_pd(*idx, at, m);
}

#define RS(name) name##_avx2
#define V4 __m256d
#define M4 __m256d
#define v_dup a_dup
#define v_set a_set
#define v_add _mm256_add_pd
#define v_sub _mm256_sub_pd
#define v_mul _mm256_mul_pd
#define v_load a_load
#define v_rev a_rev
#define v_get a_get
#define v_decode a_decode
#define v_keep a_keep
#include "rowsum_body.h"

#else
const int ps_rowsum_avx2_built = 0;

void ps_rowsum_avx2(const uint8_t *px, const struct ps_weights *w, const struct ps_weights_run *run,
                    const double kc[3], struct ps_rowsum *out)
{
	(void)px, (void)w, (void)run, (void)kc, (void)out;
}
#endif
