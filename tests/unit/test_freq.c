/* SPDX-License-Identifier: ISC */
/* Frequency from edge timestamps, the overrun rule and the TSL230R divider
 * choice, against exact answers. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <cmocka.h>

#include "freq.h"

static void steady_rate(void **state)
{
	struct ps_freq_gate g;
	(void)state;
	ps_freq_gate_reset(&g);
	/* 1234.5 Hz for 0.5 s, starting at an odd time: 617 or 618 edges */
	for (uint64_t t = 7000000001ull; t < 7000000001ull + 500000000ull; t += 810045)
		ps_freq_gate_edge(&g, t);
	assert_true(fabs(ps_freq_gate_hz(&g, 0.5) / (1e9 / 810045) - 1) < 1e-12);
	assert_false(ps_freq_gate_overran(&g, 3));
}

static void lost_edges_are_seen(void **state)
{
	struct ps_freq_gate g;
	(void)state;
	ps_freq_gate_reset(&g);
	/* 100 edges 1 ms apart, then 40 missing, then 100 more */
	for (int i = 0; i < 100; i++)
		ps_freq_gate_edge(&g, 1000000ull * (uint64_t)i);
	for (int i = 140; i < 240; i++)
		ps_freq_gate_edge(&g, 1000000ull * (uint64_t)i);
	assert_true(ps_freq_gate_overran(&g, 3));
	/* the naive count would have said 200 edges in 0.239 s = 833 Hz, not 1000 */
	assert_true(fabs(ps_freq_gate_hz(&g, 0.25) - 199 / 0.239) < 1e-9);
	/* a full buffer with too few edges to compare is an overrun too */
	ps_freq_gate_reset(&g);
	ps_freq_gate_read(&g, PS_FREQ_KERNEL_FIFO);
	ps_freq_gate_edge(&g, 5);
	assert_true(ps_freq_gate_overran(&g, 3));
	/* dark: fewer than two edges give n / gate */
	ps_freq_gate_reset(&g);
	ps_freq_gate_edge(&g, 5);
	assert_true(ps_freq_gate_hz(&g, 2.0) == 0.5);
}

static void divider_steps(void **state)
{
	int s2, s3;
	(void)state;
	assert_int_equal(ps_freq_next_divider(0, 5000, 2000, 0), 1);   /* too fast: up */
	assert_int_equal(ps_freq_next_divider(1, 500, 2000, 1), 2);    /* overran: up */
	assert_int_equal(ps_freq_next_divider(3, 5000, 2000, 0), 3);   /* already /100 */
	assert_int_equal(ps_freq_next_divider(2, 40, 2000, 0), 1);     /* slow: down to /2, 200 edges/s */
	assert_int_equal(ps_freq_next_divider(2, 100, 2000, 0), 2);    /* /2 would give 500: stays */
	assert_int_equal(ps_freq_next_divider(0, 10, 2000, 0), 0);
	/* no flapping: a step down never lands above max_rate */
	for (int idx = 1; idx < 4; idx++)
		for (double hz = 1; hz < 3000; hz *= 1.07) {
			int down = ps_freq_next_divider(idx, hz, 2000, 0);
			if (down < idx)
				assert_true(hz * ps_freq_dividers[idx] / ps_freq_dividers[down] <= 2000);
		}
	ps_freq_divider_pins(0, &s2, &s3);
	assert_true(s2 == 0 && s3 == 0);
	ps_freq_divider_pins(1, &s2, &s3);
	assert_true(s2 == 0 && s3 == 1);
	ps_freq_divider_pins(3, &s2, &s3);
	assert_true(s2 == 1 && s3 == 1);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(steady_rate),
		cmocka_unit_test(lost_edges_are_seen),
		cmocka_unit_test(divider_steps),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
