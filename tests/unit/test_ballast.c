/* SPDX-License-Identifier: ISC */
/* The ballast and lamp model against its analytic solution, at time
 * constants from a microsecond to eleven days and steps from a millisecond to
 * three hours: exact, monotone and inside [0, 1] at any step. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <cmocka.h>

#include "ballast.h"

static void step_response_is_exact_at_any_step(void **state)
{
	static const double taus[] = { 1e-6, 1e-3, 1, 1e6 };
	static const double steps[] = { 1e-3, 0.1, 1, 60, 1e4 };
	struct ps_ballast_params p = { 0, 0, 0, 1 };   /* no fade, no minimum */
	(void)state;
	for (size_t a = 0; a < 4; a++)
		for (size_t b = 0; b < 5; b++) {
			struct ps_ballast bl;
			double prev = 1.0;
			p.lag_tau = taus[a];
			ps_ballast_init(&bl, &p, 0.0, 1.0);
			ps_ballast_command(&bl, 0.0, 0.2);
			for (int k = 1; k <= 50; k++) {
				double t = k * steps[b], want = 0.2 + 0.8 * exp(-t / taus[a]);
				double energy = 0.2 * t + 0.8 * taus[a] * -expm1(-t / taus[a]);
				ps_ballast_advance(&bl, t);
				assert_true(fabs(bl.output - want) <= 1e-12);
				assert_true(fabs(bl.energy - energy) <= 1e-12 * (1 + energy));
				assert_true(bl.output <= prev && bl.output >= 0.2 - 1e-15);   /* monotone, no overshoot */
				prev = bl.output;
			}
		}
}

static void fade_rate_and_minimum(void **state)
{
	struct ps_ballast_params p = { 0.5, 0.1, 0, 1 };   /* 50 %/s, 10 % minimum, no lag */
	struct ps_ballast b;
	(void)state;
	ps_ballast_init(&b, &p, 0.0, 0.0);
	ps_ballast_command(&b, 0.0, 1.0);
	ps_ballast_advance(&b, 1.0);
	assert_true(fabs(b.output - 0.5) < 1e-15);          /* half way after 1 s */
	ps_ballast_advance(&b, 3.0);
	assert_true(b.output == 1.0);                       /* 1 / fade_rate = 2 s to full */
	/* energy of the ramp and the plateau: 0.5 * 2 * 1 + 1 * 1 */
	assert_true(fabs(b.energy - 2.0) < 1e-12);
	ps_ballast_command(&b, 3.0, 0.05);                  /* below the minimum: off */
	ps_ballast_advance(&b, 10.0);
	assert_true(b.output == 0.0);
	p.off_below_min = 0;                                /* or clamped to the minimum */
	ps_ballast_init(&b, &p, 0.0, 0.05);
	assert_true(b.output == 0.1);
}

static void fade_and_lag_together(void **state)
{
	/* ramp f(t) = t (fade 1/s from 0) through a lag of tau = 0.25 s:
	 * y(t) = t - tau + tau e^{-t/tau} until the ramp ends at t = 1 */
	struct ps_ballast_params p = { 1.0, 0.0, 0.25, 1 };
	struct ps_ballast b;
	(void)state;
	ps_ballast_init(&b, &p, 0.0, 0.0);
	ps_ballast_command(&b, 0.0, 1.0);
	for (double t = 0.1; t <= 1.0 + 1e-9; t += 0.1) {
		ps_ballast_advance(&b, t);
		assert_true(fabs(b.output - (t - 0.25 + 0.25 * exp(-t / 0.25))) < 1e-12);
	}
	/* one big step across the ramp's end equals many small ones */
	{
		struct ps_ballast one;
		double y1;
		ps_ballast_init(&one, &p, 0.0, 0.0);
		ps_ballast_command(&one, 0.0, 1.0);
		ps_ballast_advance(&one, 3.0);
		y1 = 1.0 + (1.0 - 0.25 + 0.25 * exp(-4.0) - 1.0) * exp(-2.0 / 0.25);
		assert_true(fabs(one.output - y1) < 1e-12);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(step_response_is_exact_at_any_step),
		cmocka_unit_test(fade_rate_and_minimum),
		cmocka_unit_test(fade_and_lag_together),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
