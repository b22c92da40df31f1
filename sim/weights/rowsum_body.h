/* SPDX-License-Identifier: ISC */
/* The run kernel's body (rowsum.h), written once over four lanes of
 * doubles and included once per instruction set: rowsum.c (plain C and
 * SSE2) and rowsum_avx2.c.  The includer defines
 *   RS(name)      the name with its instruction set's suffix
 *   V4, M4        four doubles; four "black pixel" flags
 *   v_dup v_add v_sub v_mul      lane by lane, IEEE double
 *   v_load(p)     p[0..3];  v_rev(p) p[3], p[2], p[1], p[0]
 *   v_set(a, b, c, d), v_get(v, l)
 *   v_decode(p, &c0, &c1, &c2, &sc, &black)  stored channels as doubles
 *                 and 2^(e-136) (0 for e = 0, as ps_picture_rgbe_scale); returns
 *                 how many of the four are lit (exponent > 0)
 *   v_keep(&best, &idx, b, at, black)   where lit and b > best: b, at
 * Every lane does the same operations in the same order whatever the
 * instruction set, so every build gives the same bits. */

struct RS(lanes) {
	V4 s, c;          /* TwoSum: running sum and the exact errors it dropped */
	V4 r0, r1, r2;    /* the channel sums */
	V4 best, idx;     /* brightest lit response and its index (as a double) */
};

/* Four pixels p[0..15], pixel k to lane k, weights w, run indices at. */
RS_HOT unsigned RS(quad)(struct RS(lanes) *L, const uint8_t *p, V4 w, V4 at, V4 k0, V4 k1, V4 k2)
{
	const V4 half = v_dup(0.5);
	V4 c0, c1, c2, sc, f, r0, r1, r2, b, t, bp;
	M4 black;
	unsigned lit = v_decode(p, &c0, &c1, &c2, &sc, &black);
	f = v_mul(sc, w);
	/* (m + 0.5) 2^(e-136) w per channel, as ps_integrate_pixel_response */
	r0 = v_mul(v_add(c0, half), f);
	r1 = v_mul(v_add(c1, half), f);
	r2 = v_mul(v_add(c2, half), f);
	L->r0 = v_add(L->r0, r0);
	L->r1 = v_add(L->r1, r1);
	L->r2 = v_add(L->r2, r2);
	b = v_add(v_add(v_mul(k0, r0), v_mul(k1, r1)), v_mul(k2, r2));
	t = v_add(L->s, b);
	bp = v_sub(t, L->s);
	L->c = v_add(L->c, v_add(v_sub(L->s, v_sub(t, bp)), v_sub(b, bp)));
	L->s = t;
	v_keep(&L->best, &L->idx, b, at, black);
	return lit;
}

void RS(ps_rowsum)(const uint8_t *px, const struct ps_weights *wm, const struct ps_weights_run *run,
                   const double kc[3], struct ps_rowsum *out)
{
	struct RS(lanes) L;
	const double *wt = wm->w + run->off;
	int len = run->n;
	const V4 k0 = v_dup(kc[0]), k1 = v_dup(kc[1]), k2 = v_dup(kc[2]), four = v_dup(4.0);
	V4 at = v_set(0, 1, 2, 3);   /* the indices of the four pixels in hand */
	int half = ps_weights_run_stored(wm, run), i = 0;   /* weights read forwards */
	size_t n = 0;
	L.s = L.c = L.r0 = L.r1 = L.r2 = v_dup(0.0);
	L.best = L.idx = v_dup(-1.0);
	for (; i + 4 <= len; i += 4, at = v_add(at, four)) {
		V4 w;
		if (i + 4 <= half)
			w = v_load(wt + i);
		else if (i >= half)
			w = v_rev(wt + (len - 4 - i));   /* ps_weights_run_at(i + k) = wt[len - 1 - i - k] */
		else
			w = v_set(ps_weights_run_at(wm, run, i), ps_weights_run_at(wm, run, i + 1), ps_weights_run_at(wm, run, i + 2),
			          ps_weights_run_at(wm, run, i + 3));
		n += RS(quad)(&L, px + 4 * (size_t)i, w, at, k0, k1, k2);
	}
	if (i < len) {
		/* the last 1 to 3 pixels, padded with black pixels of weight 0:
		 * they add exact zeros and are never counted or the brightest */
		uint8_t pad[16] = { 0 };
		double w[4] = { 0, 0, 0, 0 };
		memcpy(pad, px + 4 * (size_t)i, 4 * (size_t)(len - i));
		for (int j = 0; i + j < len; j++)
			w[j] = ps_weights_run_at(wm, run, i + j);
		n += RS(quad)(&L, pad, v_load(w), at, k0, k1, k2);
	}
	/* the lanes merged in order 0 to 3 */
	ps_sum_init(&out->sum);
	out->raw[0] = out->raw[1] = out->raw[2] = 0.0;
	out->best = -1.0;
	out->best_i = -1;
	for (int l = 0; l < 4; l++) {
		struct ps_sum part = { v_get(L.s, l), v_get(L.c, l) };
		double best = v_get(L.best, l), idx = v_get(L.idx, l);
		ps_sum_merge(&out->sum, &part);
		out->raw[0] += v_get(L.r0, l);
		out->raw[1] += v_get(L.r1, l);
		out->raw[2] += v_get(L.r2, l);
		/* the first of equal brightest: the lowest index */
		if (idx >= 0 && (best > out->best || (best == out->best && idx < out->best_i))) {
			out->best = best;
			out->best_i = (int)idx;
		}
	}
	out->n = n;
}
