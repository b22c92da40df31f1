/* SPDX-License-Identifier: ISC */
/* The occupancy state machine (daemon/occupancy.h) against the rules its
 * header states, with times worked by hand: the vacant level exactly at the
 * report plus the hold and not a moment before, the daylight control at
 * once on arrival, a manual off through a vacancy up to the next arrival,
 * no override above the vacant level past the hold, an input fault counted
 * as occupied with the hold starting again at its end, and the hours and
 * the saved output of a day of whole steps. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <math.h>
#include <cmocka.h>

#include "occupancy.h"

static int rule(const struct psd_occupancy *o, double now, int on, double level, int *drop)
{
	return psd_occupancy_rule(o, now, on, level, drop);
}

static void no_report_is_occupied(void **state)
{
	struct psd_occupancy o;
	int drop;
	(void)state;
	psd_occupancy_init(&o, 900, 0, 0);
	assert_int_equal(psd_occupancy_occupied(&o), 1);
	assert_int_equal(rule(&o, 1e6, 0, 0, &drop), PSD_OCC_DAYLIGHT);
	assert_int_equal(psd_occupancy_report(&o, 10, 1), 0);   /* the first report: no arrival */
	assert_int_equal(psd_occupancy_report(&o, 20, 1), 0);   /* the same again: nothing */
}

static void vacant_level_after_the_hold_and_back_on_arrival(void **state)
{
	struct psd_occupancy o;
	int drop;
	(void)state;
	psd_occupancy_init(&o, 900, 0, 0);
	psd_occupancy_report(&o, 0, 1);
	assert_int_equal(psd_occupancy_report(&o, 100, 0), -1);
	assert_int_equal(psd_occupancy_occupied(&o), 0);
	assert_int_equal(rule(&o, 999.999, 0, 0, &drop), PSD_OCC_DAYLIGHT);   /* within the hold */
	assert_int_equal(rule(&o, 1000, 0, 0, &drop), PSD_OCC_VACANT);         /* 100 + 900 */
	assert_int_equal(drop, 0);
	assert_int_equal(psd_occupancy_report(&o, 1200, 1), 1);                /* an arrival */
	assert_int_equal(rule(&o, 1200, 0, 0, &drop), PSD_OCC_DAYLIGHT);
	/* a vacancy shorter than the hold never reaches the vacant level, and
	 * the next one counts its hold from its own start */
	psd_occupancy_report(&o, 2000, 0);
	psd_occupancy_report(&o, 2899, 1);
	assert_int_equal(rule(&o, 2900, 0, 0, &drop), PSD_OCC_DAYLIGHT);
	psd_occupancy_report(&o, 3000, 0);
	assert_int_equal(rule(&o, 3899, 0, 0, &drop), PSD_OCC_DAYLIGHT);
	assert_int_equal(rule(&o, 3900, 0, 0, &drop), PSD_OCC_VACANT);
}

static void manual_off_holds_until_the_next_arrival(void **state)
{
	struct psd_occupancy o;
	int drop, ch;
	(void)state;
	psd_occupancy_init(&o, 600, 0, 0);
	psd_occupancy_report(&o, 0, 1);
	/* off at 100 while occupied: the occupants keep it off */
	assert_int_equal(rule(&o, 100, 1, 0, &drop), PSD_OCC_OVERRIDE);
	ch = psd_occupancy_report(&o, 200, 1);   /* a repeated occupied report */
	assert_false(psd_occupancy_ends_override(&o, ch, 0));
	/* they leave at 300: off through the hold and after it */
	ch = psd_occupancy_report(&o, 300, 0);
	assert_false(psd_occupancy_ends_override(&o, ch, 0));
	assert_int_equal(rule(&o, 500, 1, 0, &drop), PSD_OCC_OVERRIDE);
	assert_int_equal(rule(&o, 5000, 1, 0, &drop), PSD_OCC_OVERRIDE);
	assert_int_equal(drop, 0);
	/* someone comes in at 6000: the manual off ends there */
	ch = psd_occupancy_report(&o, 6000, 1);
	assert_int_equal(ch, 1);
	assert_true(psd_occupancy_ends_override(&o, ch, 0));
	assert_int_equal(rule(&o, 6000, 0, 0, &drop), PSD_OCC_DAYLIGHT);
	/* an override above the vacant level is no manual off: an arrival keeps it */
	assert_false(psd_occupancy_ends_override(&o, ch, 0.5));
}

static void no_override_above_the_vacant_level_past_the_hold(void **state)
{
	struct psd_occupancy o;
	int drop;
	(void)state;
	psd_occupancy_init(&o, 900, 0.3, 0);
	psd_occupancy_report(&o, 0, 1);
	assert_int_equal(rule(&o, 50, 1, 1.0, &drop), PSD_OCC_OVERRIDE);
	psd_occupancy_report(&o, 100, 0);
	assert_int_equal(rule(&o, 999, 1, 1.0, &drop), PSD_OCC_OVERRIDE);   /* within the hold */
	assert_int_equal(drop, 0);
	assert_int_equal(rule(&o, 1000, 1, 1.0, &drop), PSD_OCC_VACANT);    /* the hold ends it */
	assert_int_equal(drop, 1);
	/* at or below the partial-off level (0.3) an override is a manual off: it holds */
	assert_int_equal(rule(&o, 1000, 1, 0.3, &drop), PSD_OCC_OVERRIDE);
	assert_int_equal(rule(&o, 1000, 1, 0.2, &drop), PSD_OCC_OVERRIDE);
	assert_int_equal(drop, 0);
	assert_true(psd_occupancy_ends_override(&o, psd_occupancy_report(&o, 2000, 1), 0.2));
}

static void an_input_fault_counts_as_occupied(void **state)
{
	struct psd_occupancy o;
	int drop;
	(void)state;
	psd_occupancy_init(&o, 900, 0, 0);
	psd_occupancy_report(&o, 0, 0);   /* vacant from the start */
	assert_int_equal(rule(&o, 900, 0, 0, &drop), PSD_OCC_VACANT);
	assert_int_equal(psd_occupancy_fault(&o, 1000, 1), 1);
	assert_int_equal(psd_occupancy_fault(&o, 1060, 1), 0);   /* no change */
	assert_int_equal(psd_occupancy_occupied(&o), 1);
	assert_int_equal(rule(&o, 1100, 0, 0, &drop), PSD_OCC_DAYLIGHT);
	/* it reads again at 5000, vacant: a hold from there */
	assert_int_equal(psd_occupancy_fault(&o, 5000, 0), 1);
	assert_int_equal(psd_occupancy_report(&o, 5000, 0), 0);
	assert_int_equal(rule(&o, 5899, 0, 0, &drop), PSD_OCC_DAYLIGHT);
	assert_int_equal(rule(&o, 5900, 0, 0, &drop), PSD_OCC_VACANT);
}

/* Steps every 60 s from 0 to 7200: occupied to 3600, vacant after, hold 900,
 * the daylight control asking 0.6 and the lights at 0 once vacant for the
 * hold (from 4500): occupied 3600 s, vacant 3600 s, of it 2700 s at the
 * vacant level, saving 0.6 x 2700 = 1620 full-output seconds. */
static void a_day_of_whole_steps_is_counted(void **state)
{
	struct psd_occupancy o;
	(void)state;
	psd_occupancy_init(&o, 900, 0, 0);
	psd_occupancy_report(&o, 0, 1);
	for (int k = 0; k <= 120; k++) {
		double t = 60.0 * k;
		if (t == 3600)
			psd_occupancy_report(&o, t, 0);
		psd_occupancy_account(&o, t, 0.6, psd_occupancy_vacant(&o, t) ? 0 : 0.6);
	}
	assert_float_equal(o.occupied_s, 3600, 1e-9);
	assert_float_equal(o.vacant_s, 3600, 1e-9);
	assert_float_equal(o.held_s, 2700, 1e-9);
	assert_float_equal(o.saved, 1620, 1e-9);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(no_report_is_occupied),
		cmocka_unit_test(vacant_level_after_the_hold_and_back_on_arrival),
		cmocka_unit_test(manual_off_holds_until_the_next_arrival),
		cmocka_unit_test(no_override_above_the_vacant_level_past_the_hold),
		cmocka_unit_test(an_input_fault_counts_as_occupied),
		cmocka_unit_test(a_day_of_whole_steps_is_counted),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
