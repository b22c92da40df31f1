/* SPDX-License-Identifier: ISC */
/* Compensated (Neumaier) summation: every accumulation in the simulation goes
 * through this, so that a 1e9 sun next to 1e-2 walls loses nothing. */
#ifndef PS_SUM_H
#define PS_SUM_H

#include <math.h>

struct ps_sum {
	double s;   /* running sum */
	double c;   /* running compensation: the low-order bits s lost */
};

static inline void ps_sum_init(struct ps_sum *a)
{
	a->s = 0.0;
	a->c = 0.0;
}

static inline void ps_sum_add(struct ps_sum *a, double x)
{
	double t = a->s + x;
	if (fabs(a->s) >= fabs(x))
		a->c += (a->s - t) + x;
	else
		a->c += (x - t) + a->s;
	a->s = t;
}

static inline double ps_sum_get(const struct ps_sum *a)
{
	return a->s + a->c;
}

/* Merge b into a (for pairwise or per-thread partial sums). */
static inline void ps_sum_merge(struct ps_sum *a, const struct ps_sum *b)
{
	ps_sum_add(a, b->s);
	ps_sum_add(a, b->c);
}

#endif
