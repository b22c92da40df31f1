/* SPDX-License-Identifier: ISC */
#include "ballast.h"

#include <math.h>

/* what the ballast does with a command: off below the minimum (or clamp) */
static double effective(const struct ps_ballast_params *p, double level)
{
	if (!(level > 0.0))
		return 0.0;
	if (level > 1.0)
		level = 1.0;
	if (level < p->min_level)
		return p->off_below_min ? 0.0 : p->min_level;
	return level;
}

void ps_ballast_init(struct ps_ballast *b, const struct ps_ballast_params *p, double t0, double level)
{
	b->p = *p;
	b->t = t0;
	b->command = level;
	b->fade = b->output = effective(p, level);
	b->energy = 0.0;
}

/* Exact lag over h seconds with f(s) = f0 + s' s (s' = slope):
 *   y(h) = f0 + s' h - s' tau + (y0 - f0 + s' tau) e^{-h/tau}
 * and its integral over [0, h]:
 *   f0 h + s' h^2 / 2 - s' tau h + (y0 - f0 + s' tau) tau (1 - e^{-h/tau}). */
/* 1 - e^{-x}: a run steps by the same few spans (its period, the
 * truth's millisecond), so the last few are kept, per thread */
static double one_minus_exp(double x)
{
	static _Thread_local double memo_x[4] = { NAN, NAN, NAN, NAN }, memo_y[4];
	static _Thread_local unsigned next;
	for (int i = 0; i < 4; i++)
		if (memo_x[i] == x)
			return memo_y[i];
	next = (next + 1) & 3;
	memo_x[next] = x;
	return memo_y[next] = -expm1(-x);
}

static void lag_step(struct ps_ballast *b, double h, double f0, double slope)
{
	double tau = b->p.lag_tau, a, em1, y;
	if (h <= 0)
		return;
	if (tau <= 0) {
		b->energy += f0 * h + 0.5 * slope * h * h;
		b->output = f0 + slope * h;
		return;
	}
	a = b->output - f0 + slope * tau;
	em1 = one_minus_exp(h / tau);    /* 1 - e^{-h/tau}, accurate for small h/tau */
	y = f0 + slope * h - slope * tau + a * (1.0 - em1);
	b->energy += f0 * h + 0.5 * slope * h * h - slope * tau * h + a * tau * em1;
	/* rounding must not leave [0, 1] */
	b->output = y < 0 ? 0 : y > 1 ? 1 : y;
}

void ps_ballast_advance(struct ps_ballast *b, double t)
{
	double target = effective(&b->p, b->command), h = t - b->t;
	if (!(h > 0))
		return;
	if (target == 0 && b->fade == 0 && b->output == 0) {
		b->t = t;   /* off and settled: the lag's step gives 0 and adds 0 */
		return;
	}
	if (b->p.fade_rate > 0 && b->fade != target) {
		double dir = target > b->fade ? 1.0 : -1.0;
		double reach = fabs(target - b->fade) / b->p.fade_rate;   /* seconds to the target */
		double h1 = reach < h ? reach : h;
		lag_step(b, h1, b->fade, dir * b->p.fade_rate);
		b->fade = h1 == reach ? target : b->fade + dir * b->p.fade_rate * h1;
		h -= h1;
	} else {
		b->fade = target;
	}
	lag_step(b, h, b->fade, 0.0);
	b->t = t;
}

void ps_ballast_command(struct ps_ballast *b, double t, double level)
{
	ps_ballast_advance(b, t);
	b->command = level;
	if (b->p.fade_rate <= 0)
		b->fade = effective(&b->p, level);
}
