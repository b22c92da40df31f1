/* SPDX-License-Identifier: ISC */
/* The run kernel (rowsum.h) in plain C and in SSE2, and the choice of
 * kernel: AVX2 (rowsum_avx2.c) where the processor has it, else SSE2,
 * else plain C.  All give the same bits (rowsum_body.h). */
#include "rowsum.h"

#include <string.h>

#include "picture.h"

/* The lanes must live in registers: the kernel's helpers are inlined even
 * where the compiler would rather call them. */
#if defined(__GNUC__)
#define RS_HOT static inline __attribute__((always_inline))
#else
#define RS_HOT static inline
#endif

/* ---- plain C: four doubles in a struct -------------------------------- */
typedef struct { double v[4]; } v4c;
typedef struct { int v[4]; } m4c;
static inline v4c c_dup(double a) { return (v4c){ { a, a, a, a } }; }
static inline v4c c_set(double a, double b, double c, double d) { return (v4c){ { a, b, c, d } }; }
static inline v4c c_add(v4c a, v4c b)
{
	for (int l = 0; l < 4; l++)
		a.v[l] += b.v[l];
	return a;
}
static inline v4c c_sub(v4c a, v4c b)
{
	for (int l = 0; l < 4; l++)
		a.v[l] -= b.v[l];
	return a;
}
static inline v4c c_mul(v4c a, v4c b)
{
	for (int l = 0; l < 4; l++)
		a.v[l] *= b.v[l];
	return a;
}
static inline v4c c_load(const double *p) { return c_set(p[0], p[1], p[2], p[3]); }
static inline v4c c_rev(const double *p) { return c_set(p[3], p[2], p[1], p[0]); }
static inline double c_get(v4c a, int l) { return a.v[l]; }
static inline unsigned c_decode(const uint8_t *p, v4c *c0, v4c *c1, v4c *c2, v4c *sc, m4c *black)
{
	unsigned lit = 0;
	for (int l = 0; l < 4; l++) {
		c0->v[l] = p[4 * l];
		c1->v[l] = p[4 * l + 1];
		c2->v[l] = p[4 * l + 2];
		sc->v[l] = ps_picture_rgbe_scale[p[4 * l + 3]];
		black->v[l] = p[4 * l + 3] == 0;
		lit += p[4 * l + 3] != 0;
	}
	return lit;
}
static inline void c_keep(v4c *best, v4c *idx, v4c b, v4c at, m4c black)
{
	for (int l = 0; l < 4; l++)
		if (!black.v[l] && b.v[l] > best->v[l]) {
			best->v[l] = b.v[l];
			idx->v[l] = at.v[l];
		}
}

#define RS(name) name##_c
#define V4 v4c
#define M4 m4c
#define v_dup c_dup
#define v_set c_set
#define v_add c_add
#define v_sub c_sub
#define v_mul c_mul
#define v_load c_load
#define v_rev c_rev
#define v_get c_get
#define v_decode c_decode
#define v_keep c_keep
static void ps_rowsum_c(const uint8_t *px, const struct ps_weights *w, const struct ps_weights_run *run, const double kc[3],
                        struct ps_rowsum *out);
#include "rowsum_body.h"
#undef RS
#undef V4
#undef M4
#undef v_dup
#undef v_set
#undef v_add
#undef v_sub
#undef v_mul
#undef v_load
#undef v_rev
#undef v_get
#undef v_decode
#undef v_keep

/* ---- SSE2: four doubles in two registers ------------------------------ */
#ifdef __SSE2__
#include <emmintrin.h>

typedef struct { __m128d lo, hi; } v4s;   /* lanes 0, 1 and 2, 3 */
static inline v4s s_dup(double a) { return (v4s){ _mm_set1_pd(a), _mm_set1_pd(a) }; }
static inline v4s s_set(double a, double b, double c, double d)
{
	return (v4s){ _mm_set_pd(b, a), _mm_set_pd(d, c) };
}
static inline v4s s_add(v4s a, v4s b) { return (v4s){ _mm_add_pd(a.lo, b.lo), _mm_add_pd(a.hi, b.hi) }; }
static inline v4s s_sub(v4s a, v4s b) { return (v4s){ _mm_sub_pd(a.lo, b.lo), _mm_sub_pd(a.hi, b.hi) }; }
static inline v4s s_mul(v4s a, v4s b) { return (v4s){ _mm_mul_pd(a.lo, b.lo), _mm_mul_pd(a.hi, b.hi) }; }
static inline v4s s_load(const double *p) { return (v4s){ _mm_loadu_pd(p), _mm_loadu_pd(p + 2) }; }
static inline v4s s_rev(const double *p)
{
	__m128d a = _mm_loadu_pd(p + 2), b = _mm_loadu_pd(p);
	return (v4s){ _mm_shuffle_pd(a, a, 1), _mm_shuffle_pd(b, b, 1) };
}
static inline double s_get(v4s a, int l)
{
	__m128d h = l < 2 ? a.lo : a.hi;
	return l % 2 ? _mm_cvtsd_f64(_mm_unpackhi_pd(h, h)) : _mm_cvtsd_f64(h);
}
static const unsigned char bits4[16] = { 0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4 };
/* 2^(e-136) built as a double's bits, (e - 136 + 1023) << 52: exact, and
 * the same as ps_picture_rgbe_scale; black (e = 0) masked to 0 */
static inline __m128d s_pow2(__m128i e64, __m128i black64)
{
	__m128i bits = _mm_slli_epi64(_mm_add_epi64(e64, _mm_set1_epi64x(1023 - 136)), 52);
	return _mm_castsi128_pd(_mm_andnot_si128(black64, bits));
}
static inline unsigned s_decode(const uint8_t *p, v4s *c0, v4s *c1, v4s *c2, v4s *sc, v4s *black)
{
	/* little-endian: byte c of pixel k is bits 8c..8c+7 of 32-bit lane k */
	__m128i x = _mm_loadu_si128((const __m128i *)(const void *)p), ff = _mm_set1_epi32(0xff);
	__m128i e = _mm_srli_epi32(x, 24), z = _mm_setzero_si128();
	__m128i bl = _mm_cmpeq_epi32(e, z);
	__m128i bllo = _mm_unpacklo_epi32(bl, bl), blhi = _mm_unpackhi_epi32(bl, bl);
	*sc = (v4s){ s_pow2(_mm_unpacklo_epi32(e, z), bllo), s_pow2(_mm_unpackhi_epi32(e, z), blhi) };
	__m128i a = _mm_and_si128(x, ff), b = _mm_and_si128(_mm_srli_epi32(x, 8), ff),
	        c = _mm_and_si128(_mm_srli_epi32(x, 16), ff);
	*c0 = (v4s){ _mm_cvtepi32_pd(a), _mm_cvtepi32_pd(_mm_unpackhi_epi64(a, a)) };
	*c1 = (v4s){ _mm_cvtepi32_pd(b), _mm_cvtepi32_pd(_mm_unpackhi_epi64(b, b)) };
	*c2 = (v4s){ _mm_cvtepi32_pd(c), _mm_cvtepi32_pd(_mm_unpackhi_epi64(c, c)) };
	*black = (v4s){ _mm_castsi128_pd(bllo), _mm_castsi128_pd(blhi) };
	return 4 - bits4[_mm_movemask_ps(_mm_castsi128_ps(bl))];
}
static inline __m128d s_sel(__m128d m, __m128d a, __m128d b)   /* m ? a : b */
{
	return _mm_or_pd(_mm_and_pd(m, a), _mm_andnot_pd(m, b));
}
static inline void s_keep(v4s *best, v4s *idx, v4s b, v4s at, v4s black)
{
	__m128d mlo = _mm_andnot_pd(black.lo, _mm_cmpgt_pd(b.lo, best->lo));
	__m128d mhi = _mm_andnot_pd(black.hi, _mm_cmpgt_pd(b.hi, best->hi));
	best->lo = s_sel(mlo, b.lo, best->lo);
	best->hi = s_sel(mhi, b.hi, best->hi);
	idx->lo = s_sel(mlo, at.lo, idx->lo);
	idx->hi = s_sel(mhi, at.hi, idx->hi);
}

#define RS(name) name##_sse2
#define V4 v4s
#define M4 v4s
#define v_dup s_dup
#define v_set s_set
#define v_add s_add
#define v_sub s_sub
#define v_mul s_mul
#define v_load s_load
#define v_rev s_rev
#define v_get s_get
#define v_decode s_decode
#define v_keep s_keep
static void ps_rowsum_sse2(const uint8_t *px, const struct ps_weights *w, const struct ps_weights_run *run,
                           const double kc[3], struct ps_rowsum *out);
#include "rowsum_body.h"
#endif

/* ---- the choice ------------------------------------------------------- */
void ps_rowsum_avx2(const uint8_t *px, const struct ps_weights *w, const struct ps_weights_run *run,
                    const double kc[3], struct ps_rowsum *out);
extern const int ps_rowsum_avx2_built;

int ps_rowsum_have(enum ps_rowsum_kernel k)
{
	switch (k) {
	case PS_ROWSUM_C:
		return 1;
	case PS_ROWSUM_SSE2:
#ifdef __SSE2__
		return 1;
#else
		return 0;
#endif
	case PS_ROWSUM_AVX2:
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
		return ps_rowsum_avx2_built && __builtin_cpu_supports("avx2");
#else
		return 0;
#endif
	}
	return 0;
}

const char *ps_rowsum_name(enum ps_rowsum_kernel k)
{
	static const char *const names[] = { "C", "SSE2", "AVX2" };
	return (unsigned)k < 3 ? names[k] : "?";
}

enum ps_rowsum_kernel ps_rowsum_best(void)
{
	return ps_rowsum_have(PS_ROWSUM_AVX2) ? PS_ROWSUM_AVX2
	       : ps_rowsum_have(PS_ROWSUM_SSE2) ? PS_ROWSUM_SSE2
	                                        : PS_ROWSUM_C;
}

/* k, which this processor runs */
static void run_kernel(enum ps_rowsum_kernel k, const uint8_t *px, const struct ps_weights *w,
                       const struct ps_weights_run *run, const double kc[3], struct ps_rowsum *out)
{
	if (k == PS_ROWSUM_AVX2)
		ps_rowsum_avx2(px, w, run, kc, out);
#ifdef __SSE2__
	else if (k == PS_ROWSUM_SSE2)
		ps_rowsum_sse2(px, w, run, kc, out);
#endif
	else
		ps_rowsum_c(px, w, run, kc, out);
}

void ps_rowsum_with(enum ps_rowsum_kernel k, const uint8_t *px, const struct ps_weights *w,
                    const struct ps_weights_run *run, const double kc[3], struct ps_rowsum *out)
{
	run_kernel(ps_rowsum_have(k) ? k : PS_ROWSUM_C, px, w, run, kc, out);
}

/* The processor's best, asked at every run: __builtin_cpu_supports reads
 * a word libgcc filled at start, cheaper than sharing a cached answer
 * between threads. */
void ps_rowsum(const uint8_t *px, const struct ps_weights *w, const struct ps_weights_run *run, const double kc[3],
               struct ps_rowsum *out)
{
	run_kernel(ps_rowsum_best(), px, w, run, kc, out);
}
