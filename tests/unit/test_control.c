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

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(setpoint_and_closed_loop_hold_the_target),
		cmocka_unit_test(integral_reset_under_lights_as_the_literature_says),
		cmocka_unit_test(open_loop_proportional),
		cmocka_unit_test(switching_waits_and_keeps_its_deadband),
		cmocka_unit_test(limits_minimum_step_and_hysteresis),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
