/* SPDX-License-Identifier: ISC */
/* The pixel loop of every integration route: one run of a weight map
 * against the stored RGBE pixels under it.  ps_integrate (a picture in
 * memory) and ps_stream_integrate (rows decoded on the fly) both call it, so
 * they agree bit for bit.
 *
 * Pixel i of the run goes to lane i mod 4; each lane keeps its own
 * compensated sum (Knuth's TwoSum: the exact rounding error of every
 * addition, whatever the magnitudes, so a 1e9 sun next to 1e-2 walls
 * loses nothing), channel sums and brightest pixel, and the lanes are
 * merged in a fixed order at the end.  Four independent lanes let the
 * additions overlap instead of waiting on one chain; with SSE2 two lanes
 * go in one register, with AVX2 four.  The plain C kernel does the same
 * operations in the same order and gives the same bits (rowsum_body.h;
 * tests/unit/test_rowsum.c compares them). */
#ifndef PS_ROWSUM_H
#define PS_ROWSUM_H

#include <stddef.h>
#include <stdint.h>

#include "sum.h"
#include "weights.h"

struct ps_rowsum {
	struct ps_sum sum;   /* the run's response: sum over pixels of kc . raw */
	double raw[3];       /* per stored channel: sum of (m + 0.5) 2^(e-136) x weight */
	double best;         /* the largest single response (-1: no pixel with e > 0) */
	int best_i;          /* its index in the run, the first of equals (-1: none) */
	size_t n;            /* pixels with a non-zero exponent */
};

/* px: the pixels under run (its n, 4 bytes each) of map w, a full or a
 * compact one (its weights as ps_weights_run_at reads them); kc: stored channels
 * to response (ps_integrate_coef_k). */
void ps_rowsum(const uint8_t *px, const struct ps_weights *w, const struct ps_weights_run *run, const double kc[3],
               struct ps_rowsum *out);

/* The kernels; ps_rowsum runs the best this processor has.  Tests and the
 * bench run each (one not compiled in or not run here falls back to C). */
enum ps_rowsum_kernel { PS_ROWSUM_C, PS_ROWSUM_SSE2, PS_ROWSUM_AVX2 };
int ps_rowsum_have(enum ps_rowsum_kernel k);
enum ps_rowsum_kernel ps_rowsum_best(void);
const char *ps_rowsum_name(enum ps_rowsum_kernel k);
void ps_rowsum_with(enum ps_rowsum_kernel k, const uint8_t *px, const struct ps_weights *w,
                    const struct ps_weights_run *run, const double kc[3], struct ps_rowsum *out);

#endif
