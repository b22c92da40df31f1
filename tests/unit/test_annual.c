/* SPDX-License-Identifier: ISC */
/* A year of control (daemon/annual.c) against analytic answers:
 *   - a year of night: the set-point law holds target / electric task lux
 *     every occupied hour: energy exactly 50 % with 500 lx of 1000;
 *   - constant daylight (250 lx at the task for 1 unit of response, every
 *     hour of every day): output (500 - 250) / 1000 = 0.25 when occupied,
 *     the ideal photocell the same (effectiveness 100 %), the estimate exact
 *     with either ratio, no hour below target, no change after the first. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
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
				r.year.h[n++] = (struct ps_year_hour){ m, d, h + 0.5, 1.0, 250.0, 1, 2.0, NAN };
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

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(year_of_night),
		cmocka_unit_test(constant_daylight),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
