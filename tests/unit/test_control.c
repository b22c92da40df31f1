/* SPDX-License-Identifier: ISC */
/* Control laws against their analytic steady states on a plant
 *   S = g (e_s u + d),   E = R_d d + E_E u
 * (g sensor volts per unit, d the daylight response, R_d the daylight task
 * lux per unit), with the formulas of the literature (doc/control.md). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <math.h>
#include <cmocka.h>

#include "control.h"

static const double g = 0.5, e_s = 1.094, R_d = 236.15, E_E = 1265.4;

static struct psd_control make(int alg)
{
	struct psd_control c = { 0 };
	c.algorithm = alg;
	c.target_lux = 500;
	c.min_level = 0.0;
	c.sensor_gain = g;
	c.daylight_ratio = R_d;
	c.elec_sensor = e_s;
	c.elec_task_lux = E_E;
	c.level = 1.0;
	return c;
}

static double volts(double u, double d)
{
	return g * (e_s * u + d);
}

static double task(double u, double d)
{
	return R_d * d + E_E * u;
}

static void setpoint_and_closed_loop_hold_the_target(void **state)
{
	(void)state;
	for (double d = 0.0; d <= 3.0; d += 0.25) {
		struct psd_control sp = make(PSD_ALG_SETPOINT), cl = make(PSD_ALG_CLOSED_PROPORTIONAL);
		double u = 1.0, ucl = 0.7;
		/* both read the signal with the lights at their current level; the
		 * closed loop's fixed point is its steady state */
		for (int k = 0; k < 60; k++) {
			u = psd_control_step(&sp, volts(u, d), k);
			ucl = psd_control_step(&cl, volts(ucl, d), k);
		}
		if (R_d * d < 500) {
			assert_true(fabs(task(u, d) - 500) < 1e-9);
			assert_true(fabs(task(ucl, d) - 500) < 1e-9);
			assert_true(fabs(sp.est_task_lux - 500) < 1e-9);
		} else {
			assert_true(u == 0.0 && ucl == 0.0);   /* daylight alone is enough */
		}
	}
}

static void integral_reset_under_lights_as_the_literature_says(void **state)
{
	/* steady state S = S_set, so u = (S_set - S_D)/S_E and
	 * E = E_target + E_D (1 - r_D / r_E) with r = sensor volts per task lux */
	double r_E = g * e_s / E_E, r_D = g / R_d;
	(void)state;
	for (double d = 0.1; d <= 0.8; d += 0.1) {
		struct psd_control c = make(PSD_ALG_INTEGRAL_RESET);
		double u = 1.0, E_D = R_d * d;
		for (int k = 0; k < 200; k++)
			u = psd_control_step(&c, volts(u, d), k);
		if (u > 0) {
			assert_true(fabs(task(u, d) - (500 + E_D * (1 - r_D / r_E))) < 1e-6);
			assert_true(task(u, d) < 500);   /* r_D > r_E here: it under-lights */
		}
	}
}

static void open_loop_proportional(void **state)
{
	/* the sensor sees daylight only: u = 1 - S/S_full */
	struct psd_control c = make(PSD_ALG_OPEN_PROPORTIONAL);
	(void)state;
	c.s_full = 2.0;
	assert_true(fabs(psd_control_step(&c, 0.5, 0) - 0.75) < 1e-15);
	assert_true(psd_control_step(&c, 3.0, 1) == 0.0);
	c.s_full = 0;   /* from the model: the volts at which daylight alone gives the target */
	assert_true(fabs(psd_control_step(&c, g / R_d * 250, 2) - 0.5) < 1e-12);
}

static void switching_waits_and_keeps_its_deadband(void **state)
{
	struct psd_control c = make(PSD_ALG_SWITCHING);
	(void)state;
	c.s_off = 3.0;
	c.s_on = 2.0;
	c.delay = 300;
	c.steps = 2;
	assert_true(psd_control_step(&c, 3.5, 0) == 1.0);     /* above: wait */
	assert_true(psd_control_step(&c, 3.5, 299) == 1.0);
	assert_true(psd_control_step(&c, 3.5, 300) == 0.5);   /* one step down after the delay */
	assert_true(psd_control_step(&c, 2.5, 400) == 0.5);   /* inside the deadband: hold */
	assert_true(psd_control_step(&c, 3.5, 500) == 0.5);   /* the wait starts again */
	assert_true(psd_control_step(&c, 1.5, 600) == 0.5);   /* crossing down resets it */
	assert_true(psd_control_step(&c, 1.5, 899) == 0.5);
	assert_true(psd_control_step(&c, 1.5, 900) == 1.0);
	assert_true(psd_control_step(&c, 1.5, 2000) == 1.0);  /* cannot go above full */
}

static void limits_minimum_step_and_hysteresis(void **state)
{
	struct psd_control c = make(PSD_ALG_SETPOINT);
	(void)state;
	c.min_level = 0.1;
	c.max_step = 0.2;
	assert_true(fabs(psd_control_step(&c, volts(1.0, 5.0), 0) - 0.8) < 1e-15);   /* fade limit */
	c.max_step = 0;
	assert_true(psd_control_step(&c, volts(0.8, 5.0), 1) == 0.1);                 /* minimum */
	c.hysteresis = 0.05;
	c.level = 0.4;
	/* the target needs 0.37: a change of 0.03 is ignored, one of 0.07 is not */
	{
		double d = (500 - E_E * 0.37) / R_d;
		assert_true(psd_control_step(&c, volts(0.4, d), 2) == 0.4);
		c.level = 0.44;
		assert_true(fabs(psd_control_step(&c, volts(0.44, d), 3) - 0.37) < 1e-12);
	}
}

/* Each law on its own: a NaN or infinite reading in the middle of a
 * steady run returns the last level, and the next finite readings bring
 * the law back to the same steady state as a run that never saw one
 * (the plant's analytic fixed point for the laws that have one). */
static void law_holds_and_recovers(int alg, double d)
{
	static const double bad[] = { NAN, INFINITY, -INFINITY };
	for (size_t b = 0; b < sizeof bad / sizeof bad[0]; b++) {
		struct psd_control c = make(alg), ref = make(alg);
		double u = 1.0, uref = 1.0, held;
		c.s_off = ref.s_off = 1.0;
		c.s_on = ref.s_on = 0.6;
		c.steps = ref.steps = 4;
		for (int k = 0; k < 200; k++) {
			u = psd_control_step(&c, volts(u, d), k);
			uref = psd_control_step(&ref, volts(uref, d), k);
		}
		held = u;
		for (int k = 200; k < 205; k++) {
			u = psd_control_step(&c, bad[b], k);
			if (u != held)
				fail_msg("law %d, reading %g: level %g, held %g", alg, bad[b], u, held);
			assert_true(isfinite(c.est_task_lux) && isfinite(c.daylight_volts));
		}
		for (int k = 205; k < 400; k++) {
			u = psd_control_step(&c, volts(u, d), k);
			uref = psd_control_step(&ref, volts(uref, d), k);
		}
		if (!(fabs(u - uref) < 1e-9))
			fail_msg("law %d after %g: level %g, never-faulted run %g", alg, bad[b], u, uref);
	}
}

static void setpoint_holds_on_nan(void **state)
{
	(void)state;
	law_holds_and_recovers(PSD_ALG_SETPOINT, 0.8);
	/* the steady state is the analytic one */
	struct psd_control c = make(PSD_ALG_SETPOINT);
	double u = 1.0;
	for (int k = 0; k < 50; k++)
		u = psd_control_step(&c, k == 20 ? NAN : volts(u, 0.8), k);
	assert_true(fabs(task(u, 0.8) - 500) < 1e-9);
}

static void closed_proportional_holds_on_nan(void **state)
{
	(void)state;
	law_holds_and_recovers(PSD_ALG_CLOSED_PROPORTIONAL, 0.8);
}

static void open_proportional_holds_on_nan(void **state)
{
	(void)state;
	law_holds_and_recovers(PSD_ALG_OPEN_PROPORTIONAL, 0.8);
}

static void integral_reset_holds_on_nan(void **state)
{
	(void)state;
	law_holds_and_recovers(PSD_ALG_INTEGRAL_RESET, 0.8);
}

static void switching_holds_on_nan(void **state)
{
	(void)state;
	/* above s_off: steps down to off; an Inf reading is not "above" */
	law_holds_and_recovers(PSD_ALG_SWITCHING, 3.0);
	law_holds_and_recovers(PSD_ALG_SWITCHING, 0.2);
}

/* A level that is not finite (state set from outside) does not stick. */
static void nan_level_recovers(void **state)
{
	(void)state;
	for (int alg = 0; alg < PSD_ALG_COUNT; alg++) {
		struct psd_control c = make(alg);
		double u;
		c.level = NAN;
		u = psd_control_step(&c, volts(1.0, 0.5), 0);
		assert_true(isfinite(u) && isfinite(c.level));
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(setpoint_and_closed_loop_hold_the_target),
		cmocka_unit_test(integral_reset_under_lights_as_the_literature_says),
		cmocka_unit_test(open_loop_proportional),
		cmocka_unit_test(switching_waits_and_keeps_its_deadband),
		cmocka_unit_test(limits_minimum_step_and_hysteresis),
		cmocka_unit_test(setpoint_holds_on_nan),
		cmocka_unit_test(closed_proportional_holds_on_nan),
		cmocka_unit_test(open_proportional_holds_on_nan),
		cmocka_unit_test(integral_reset_holds_on_nan),
		cmocka_unit_test(switching_holds_on_nan),
		cmocka_unit_test(nan_level_recovers),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
