/* SPDX-License-Identifier: ISC */
/* A year of control (daemon/annual.c) against analytic answers:
 *   - a year of night: the set-point law holds target / electric task lux
 *     every occupied hour: energy exactly 50 % with 500 lx of 1000;
 *   - constant daylight (250 lx at the task for 1 unit of response, every
 *     hour of every day): output (500 - 250) / 1000 = 0.25 when occupied,
 *     the ideal photocell the same (effectiveness 100 %), the estimate exact
 *     with either ratio, no hour below target, no change after the first;
 *   - the devices: a lamp lag of 1e6 s over a year of night, where the law
 *     commands its floor 0.5 from 08:00 to 18:00 and 0 otherwise, gives the closed
 *     form of the first-order lag from full output at midnight (the room's
 *     start): the light never comes near the command; a lag, fade and
 *     minimum of 0 give the instant ballast's numbers; the power curve's
 *     full-power hours and kWh against a hand computation; a DALI output
 *     gives arc power level 229's 50.53 % for a command of 0.5;
 *   - the sun's discretisation error bar is the scene's own: two scenes of
 *     constant daylight 250 lx whose sun, moved to its nearest patch, gives
 *     300 lx (x 1.2) in one and 200 lx (x 0.8) in the other (sensor alike)
 *     give bars of +20 % and -20 % on the hours and energy 20 % and 30 % of
 *     full against 25 % (the law's closed form (500 - daylight) / 1000); a
 *     results file without the moved sun gives no bar;
 *   - an effectiveness above 100 % (a law on one mean ratio under-lighting
 *     the dark days of a year whose bright days hold the ideal photocell at
 *     its floor): the hours short of target, the lux they are short by,
 *     the energy saved there and the effectiveness at target in closed form;
 *   - the lean run (occupied_only: the unoccupied steps run the law and the
 *     ballast without looking at the room) gives every figure of the full
 *     run bit for bit, and the same occupied steps to the step hook, for
 *     every law over a year of changing daylight with a fading, lagging
 *     ballast (the ballast must run the same however the room is looked at). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <math.h>
#include <string.h>
#include <cmocka.h>

#include "annual.h"

static void base(struct ps_results *r, struct psd_control *c, struct psd_annual_opt *o)
{
	memset(r, 0, sizeof *r);
	r->have_year = 1;
	r->electric_sensor_response = 2.0;
	r->electric_task_lux = 1000.0;
	memset(c, 0, sizeof *c);
	c->algorithm = PSD_ALG_SETPOINT;
	c->target_lux = 500;
	c->min_level = 0.1;
	c->sensor_gain = 1.0;
	memset(o, 0, sizeof *o);
	o->period = 60;
	o->occ_start = 8 * 3600.0;
	o->occ_end = 18 * 3600.0;
	o->dated = 1;
}

static void year_of_night(void **state)
{
	struct ps_results r;
	struct psd_control c;
	struct psd_annual_opt o;
	struct psd_annual a;
	(void)state;
	base(&r, &c, &o);
	ps_year_tabulate(&r.year);
	assert_int_equal(psd_annual_run(&r, &c, &o, &a), 0);
	assert_true(a.steps == 525600);
	assert_true(fabs(a.occ_h - 3650) < 1e-6);
	assert_true(fabs(a.energy_h / a.occ_h - 0.5) < 1e-12);
	assert_true(fabs(a.savings - 0.5) < 1e-12 && fabs(a.effectiveness - 1) < 1e-12);
	assert_true(a.below_h == 0 && a.overdim_h == 0 && a.est_n == 0);
}

static void constant_daylight(void **state)
{
	static const int md[12] = { 31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31 };
	struct ps_results r;
	struct psd_control c;
	struct psd_annual_opt o;
	struct psd_annual a;
	size_t n = 0;
	(void)state;
	base(&r, &c, &o);
	r.year.h = calloc(8760, sizeof *r.year.h);
	for (int m = 1; m <= 12; m++)
		for (int d = 1; d <= md[m - 1]; d++)
			for (int h = 0; h < 24; h++)
				r.year.h[n++] = (struct ps_year_hour){ m, d, h + 0.5, 1.0, 250.0, 1, 2.0, NAN, NAN, NAN };
	r.year.n = n;
	ps_year_tabulate(&r.year);
	assert_true(r.year.mean_ratio == 250.0);
	for (int dated = 0; dated < 2; dated++) {
		o.dated = dated;
		assert_int_equal(psd_annual_run(&r, &c, &o, &a), 0);
		assert_true(fabs(a.energy_h / a.occ_h - 0.25) < 1e-9);
		assert_true(fabs(a.ideal_h / a.occ_h - 0.25) < 1e-9);
		assert_true(fabs(a.effectiveness - 1) < 1e-9);
		assert_true(a.below_h == 0 && a.overdim_h == 0);
		assert_true(a.changes == 0);
		assert_true(a.est_n > 0 && fabs(a.est_rms[0]) < 1e-9 && fabs(a.est_rms[1]) < 1e-9);
		for (int m = 0; m < 12; m++)
			assert_true(fabs(a.month[m].energy_h / a.month[m].occ_h - 0.25) < 1e-9);
	}
	free(r.year.h);
}

static void lag_never_dims(void **state)
{
	struct ps_results r;
	struct psd_control c;
	struct psd_annual_opt o;
	struct psd_annual a;
	struct psd_roomsetup_ballast b = { 0, 0, 1e6, 1 };
	double tau = 1e6, t1 = 8 * 3600.0, D = 10 * 3600.0, y1 = exp(-t1 / tau), want;
	(void)state;
	base(&r, &c, &o);
	ps_year_tabulate(&r.year);
	/* the law held at its floor: 0.5 whatever the sensor reads */
	c.target_lux = 0;
	c.min_level = 0.5;
	o.ballast = b;
	o.power_at_min = -1;
	assert_int_equal(psd_annual_run(&r, &c, &o, &a), 0);
	/* y = 0.5 + (y1 - 0.5) e^{-(t - t1)/tau} over the occupied hours */
	want = (0.5 * D + (y1 - 0.5) * tau * -expm1(-D / tau)) / D;
	assert_true(fabs(a.light_h / a.occ_h - want) < 1e-9);
	assert_true(want > 0.95);
	assert_true(fabs(a.energy_h - a.light_h) < 1e-9);
	/* the ideal photocell is the same (no devices): 0.5 */
	assert_true(fabs(a.ideal_h / a.occ_h - 0.5) < 1e-12);
}

static void lag_zero_is_instant(void **state)
{
	struct ps_results r;
	struct psd_control c;
	struct psd_annual_opt o;
	struct psd_annual a, i;
	struct psd_roomsetup_ballast b = { 0, 0.1, 0, 1 };
	static const int md[12] = { 31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31 };
	size_t n = 0;
	(void)state;
	base(&r, &c, &o);
	r.year.h = calloc(8760, sizeof *r.year.h);
	/* a day that rises and falls: the law moves every step */
	for (int m = 1; m <= 12; m++)
		for (int d = 1; d <= md[m - 1]; d++)
			for (int h = 6; h < 18; h++) {
				double s = sin(M_PI * (h + 0.5 - 6) / 12);
				r.year.h[n++] = (struct ps_year_hour){ m, d, h + 0.5, s, 400.0 * s, 1, 2.0, NAN, NAN, NAN };
			}
	r.year.n = n;
	ps_year_tabulate(&r.year);
	assert_int_equal(psd_annual_run(&r, &c, &o, &i), 0);
	o.ballast = b;
	assert_int_equal(psd_annual_run(&r, &c, &o, &a), 0);
	assert_true(i.energy_h > 100 && fabs(a.energy_h - i.energy_h) < 1e-9 * i.energy_h);
	assert_true(a.below_h == i.below_h && a.overdim_h == i.overdim_h && a.changes == i.changes);
	free(r.year.h);
}

/* Over-dimming is a question of light: a power curve (30 % of full power
 * at 10 % light) must not change which hours count.  Daylight alternates
 * by day, the law holds the year's mean ratio: with 240 and 250 lx it
 * commands 0.255 where 0.26 is ideal (within the 0.01 allowance: never
 * over-dimmed); with 200 and 300 lx it commands 0.25 where 0.3 is ideal
 * on the dark days (over-dimmed then: half the occupied hours). */
static void overdim_is_light_not_power(void **state)
{
	static const int md[12] = { 31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31 };
	static const double lux[2][2] = { { 240, 250 }, { 200, 300 } };
	(void)state;
	for (int k = 0; k < 2; k++) {
		struct ps_results r;
		struct psd_control c;
		struct psd_annual_opt o;
		struct psd_annual lin, curve;
		size_t n = 0;
		int day = 0;
		base(&r, &c, &o);
		o.dated = 0;
		r.year.h = calloc(8760, sizeof *r.year.h);
		for (int m = 1; m <= 12; m++)
			for (int d = 1; d <= md[m - 1]; d++, day++)
				for (int h = 0; h < 24; h++)
					r.year.h[n++] = (struct ps_year_hour){ m, d, h + 0.5, 1.0, lux[k][day % 2], 1, 2.0,
					                                       NAN, NAN, NAN };
		r.year.n = n;
		ps_year_tabulate(&r.year);
		o.light_min = 0.1;
		o.power_at_min = -1;
		assert_int_equal(psd_annual_run(&r, &c, &o, &lin), 0);
		o.power_at_min = 0.3;
		assert_int_equal(psd_annual_run(&r, &c, &o, &curve), 0);
		assert_true(curve.energy_h > lin.energy_h);
		if (k == 0)
			assert_true(lin.overdim_h == 0 && curve.overdim_h == 0);
		else
			assert_true(fabs(lin.overdim_h - 1830) < 1e-6 && fabs(curve.overdim_h - 1830) < 1e-6);
		free(r.year.h);
	}
}

/* An effectiveness above 100 % comes with its reason.  Daylight 200 lx at
 * the task on the 183 even days of the year and 450 lx on the 182 odd ones
 * (1 unit of response every hour); the law on the mean ratio
 * mr = (183 x 200 + 182 x 450) / 365 = 118500 / 365 lx, instant ballast,
 * power proportional to light.  The law commands 0.5 - mr / 1000 every
 * occupied step: energy 3650 x 0.5 - 1185 = 640 full-power hours.  The
 * ideal photocell commands 0.3 on the dark days and its floor 0.1 on the
 * bright ones (450 lx needs 0.05): 0.3 x 1830 + 0.1 x 1820 = 731.  The law
 * "saves" more than the ideal by leaving the task at 200 + 500 - mr lx,
 * mr - 200 under the 500 lx target, for the 1830 dark hours, which saves
 * (mr / 1000 - 0.2) x 1830 full-power hours.  Charged the ideal's power in
 * those hours (lighting delivered at target), its energy is
 * 0.3 x 1830 + (0.5 - mr / 1000) x 1820. */
static void effectiveness_above_ideal_says_why(void **state)
{
	static const int md[12] = { 31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31 };
	const double mr = 118500.0 / 365, law = 0.5 - mr / 1000, ideal_s = 1 - 731 / 3650.0;
	struct ps_results r;
	struct psd_control c;
	struct psd_annual_opt o;
	struct psd_annual a;
	size_t n = 0;
	int day = 0;
	(void)state;
	base(&r, &c, &o);
	o.dated = 0;
	o.power_at_min = -1;
	r.year.h = calloc(8760, sizeof *r.year.h);
	for (int m = 1; m <= 12; m++)
		for (int d = 1; d <= md[m - 1]; d++, day++)
			for (int h = 0; h < 24; h++)
				r.year.h[n++] = (struct ps_year_hour){ m, d, h + 0.5, 1.0, day % 2 ? 450.0 : 200.0, 1,
				                                       2.0, NAN, NAN, NAN };
	r.year.n = n;
	ps_year_tabulate(&r.year);
	assert_true(fabs(r.year.mean_ratio - mr) < 1e-9);
	assert_int_equal(psd_annual_run(&r, &c, &o, &a), 0);
	print_message("effectiveness %.6f; short of target %.3f h by %.4f lx, saving %.4f h; at target "
	              "%.6f\n", a.effectiveness, a.short_h, a.short_lxh / a.short_h, a.short_saved_h,
	              a.effectiveness_at_target);
	assert_true(fabs(a.energy_h - 640) < 1e-6 && fabs(a.ideal_h - 731) < 1e-6);
	assert_true(fabs(a.effectiveness - (1 - 640 / 3650.0) / ideal_s) < 1e-9);
	assert_true(a.effectiveness > 1.03);
	assert_true(fabs(a.short_h - 1830) < 1e-6);
	assert_true(fabs(a.short_lxh / a.short_h - (mr - 200)) < 1e-6);
	assert_true(fabs(a.short_saved_h - (mr / 1000 - 0.2) * 1830) < 1e-6);
	assert_true(fabs(a.effectiveness_at_target - (1 - (0.3 * 1830 + law * 1820) / 3650) / ideal_s) <
	            1e-9);
	assert_true(a.effectiveness_at_target < 1);
	free(r.year.h);
}

static void power_curve_kwh(void **state)
{
	struct ps_results r;
	struct psd_control c;
	struct psd_annual_opt o;
	struct psd_annual a;
	(void)state;
	base(&r, &c, &o);
	ps_year_tabulate(&r.year);
	/* 30 % of full power at 10 % light, linear to full; 40 W */
	o.light_min = 0.1;
	o.power_at_min = 0.3;
	o.watts = 40;
	assert_true(psd_annual_power(&o, 0) == 0 && fabs(psd_annual_power(&o, 1) - 1) < 1e-15);
	assert_true(fabs(psd_annual_power(&o, 0.05) - 0.15) < 1e-15);
	assert_int_equal(psd_annual_run(&r, &c, &o, &a), 0);
	/* by hand: P(0.5) = 0.3 + 0.7 x 0.4 / 0.9 = 0.61111; x 3650 h x 40 W = 89.222 kWh */
	assert_true(fabs(a.light_h - 1825) < 1e-6);
	assert_true(fabs(a.energy_h - 0.611111111111 * 3650) < 1e-6);
	assert_true(fabs(a.kwh - 89.2222222222) < 1e-6);
	assert_true(fabs(a.savings - (1 - 0.611111111111)) < 1e-9);
}

static void dali_levels(void **state)
{
	struct ps_results r;
	struct psd_control c;
	struct psd_annual_opt o;
	struct psd_annual a;
	(void)state;
	base(&r, &c, &o);
	ps_year_tabulate(&r.year);
	o.dali = 1;
	o.power_at_min = -1;
	assert_int_equal(psd_annual_run(&r, &c, &o, &a), 0);
	/* level 229: 10^((229 - 1) / (253 / 3) - 1) % = 50.53 % */
	assert_true(fabs(a.light_h / a.occ_h - pow(10, 228 * 3.0 / 253 - 3)) < 1e-9);
	assert_true(fabs(a.light_h / a.occ_h - 0.5053) < 5e-5);
}

static void sun_bar_per_scene(void **state)
{
	static const int md[12] = { 31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31 };
	static const double factor[2] = { 1.2, 0.8 };
	(void)state;
	for (int scene = 0; scene < 2; scene++) {
		struct ps_results r;
		struct psd_control c;
		struct psd_annual_opt o;
		struct psd_annual a;
		struct psd_annual_sunbar b;
		double f = factor[scene];
		size_t n = 0;
		base(&r, &c, &o);
		r.year.h = calloc(8760, sizeof *r.year.h);
		for (int m = 1; m <= 12; m++)
			for (int d = 1; d <= md[m - 1]; d++)
				for (int h = 0; h < 24; h++)
					r.year.h[n++] = (struct ps_year_hour){ m, d, h + 0.5, 1.0, 250.0, 1, 2.0, NAN,
					                                       f, 250.0 * f };
		r.year.n = n;
		ps_year_tabulate(&r.year);
		assert_int_equal(psd_annual_sunbar(&r, &c, &o, &b), -1);   /* no moved sun */
		r.year.have_alt = 1;
		assert_int_equal(psd_annual_run(&r, &c, &o, &a), 0);
		assert_int_equal(psd_annual_sunbar(&r, &c, &o, &b), 0);
		assert_true(b.hours == 3650);   /* 08:30 to 17:30, every day */
		assert_true(fabs(b.task_max - fabs(f - 1)) < 1e-12 && fabs(b.task_p95 - fabs(f - 1)) < 1e-12 &&
		            fabs(b.task_median - fabs(f - 1)) < 1e-12);
		assert_true(fabs(b.task_sum - (f - 1)) < 1e-12);
		assert_true(fabs(a.energy_h / a.occ_h - 0.25) < 1e-9);
		assert_true(fabs(b.alt.energy_h / b.alt.occ_h - (500 - 250 * f) / 1000) < 1e-9);
		assert_true(fabs(b.alt.savings - (1 - (500 - 250 * f) / 1000)) < 1e-9);
		assert_true(b.seconds >= 0);
		free(r.year.h);
	}
}

/* what the step hook saw of the occupied hours */
struct seen_sum {
	double n, t, level, output, truth, dl;
};

static void sum_step(void *ctx, int doy, double t, double level, double output, double truth, double dl)
{
	struct seen_sum *s = ctx;
	if (t < 8 * 3600.0 || t >= 18 * 3600.0)
		return;
	s->n++;
	s->t += doy * 86400.0 + t;
	s->level += level;
	s->output += output;
	s->truth += truth;
	s->dl += dl;
}

static void lean_is_the_same(void **state)
{
	static const int md[12] = { 31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31 };
	struct ps_results r;
	struct psd_control c;
	struct psd_annual_opt o;
	size_t n = 0;
	(void)state;
	base(&r, &c, &o);
	r.year.h = calloc(8760, sizeof *r.year.h);
	for (int m = 1; m <= 12; m++)
		for (int d = 1; d <= md[m - 1]; d++)
			for (int h = 6; h < 19; h++) {
				double s = (1 + sin(0.7 * n)) * (h - 5) * (19 - h) / 36.0, lux = 300.0 * s * (1 + 0.3 * cos(0.3 * (n + 1)));
				r.year.h[n++] = (struct ps_year_hour){ m, d, h, s, lux, 1, 2.0, NAN, NAN, NAN };
			}
	r.year.n = n;
	ps_year_tabulate(&r.year);
	o.period = 600;
	o.no_estimate = 1;
	o.ballast = (struct psd_roomsetup_ballast){ .fade_rate = 0.002, .min_level = 0.1, .lag_tau = 300 };
	o.light_min = 0.1;
	o.power_at_min = 0.2;
	o.step = sum_step;
	for (int alg = 0; alg < PSD_ALG_COUNT; alg++) {
		struct psd_annual a[2];
		struct seen_sum s[2];
		c.algorithm = alg;
		c.s_on = 100;
		c.s_off = 400;
		for (int lean = 0; lean < 2; lean++) {
			memset(&s[lean], 0, sizeof s[lean]);
			o.step_ctx = &s[lean];
			o.occupied_only = lean;
			assert_int_equal(psd_annual_run(&r, &c, &o, &a[lean]), 0);
			a[lean].seconds = 0;
		}
		assert_true(a[0].energy_h > 0 && a[0].energy_h < a[0].occ_h && s[0].n > 0);
		assert_memory_equal(&a[0], &a[1], sizeof a[0]);
		assert_memory_equal(&s[0], &s[1], sizeof s[0]);
	}
	free(r.year.h);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(year_of_night),
		cmocka_unit_test(constant_daylight),
		cmocka_unit_test(lag_never_dims),
		cmocka_unit_test(lag_zero_is_instant),
		cmocka_unit_test(power_curve_kwh),
		cmocka_unit_test(dali_levels),
		cmocka_unit_test(overdim_is_light_not_power),
		cmocka_unit_test(effectiveness_above_ideal_says_why),
		cmocka_unit_test(sun_bar_per_scene),
		cmocka_unit_test(lean_is_the_same),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
