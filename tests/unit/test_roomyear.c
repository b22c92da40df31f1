/* SPDX-License-Identifier: ISC */
/* The loopback room playing a date of the results' year (daemon/roomsetup.c,
 * psd_roomsetup_from_year): the hours of that date at their middles, linear
 * between them, dark an hour before the first and after the last; a date
 * without light is dark all day; results without a year keep the clear-sky
 * profile. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <errno.h>
#include <math.h>
#include <string.h>
#include <cmocka.h>

#include "room.h"
#include "roomsetup.h"

static void plays_the_date(void **state)
{
	struct ps_year_hour h[] = {
		{ 3, 17, 12.5, 9.0, 900.0, 0, 5, 90000.0, NAN, NAN },
		{ 3, 18, 7.5, 1.0, 100.0, 2, 1, 2000.0, NAN, NAN },
		{ 3, 18, 8.5, 3.0, 500.0, 2, 1, 10000.0, NAN, NAN },
		{ 3, 18, 9.5, 2.0, 300.0, 1, 2, 6000.0, NAN, NAN },
		{ 3, 19, 12.5, 7.0, 700.0, 0, 5, 70000.0, NAN, NAN },
	};
	struct ps_results r;
	struct ps_room_daypoint day[PSD_DAY_POINTS];
	struct ps_room_params p;
	struct ps_room *room;
	double v, l;
	(void)state;
	memset(&r, 0, sizeof r);
	r.have_year = 1;
	r.year.h = h;
	r.year.n = 5;
	r.electric_sensor_response = 1.0;
	r.electric_task_lux = 1000.0;
	assert_int_equal(psd_roomsetup_from_year(&r, psd_roomsetup_day_of_year("03-18"), day, &p), 0);
	assert_int_equal(p.ndaylight, 5);
	assert_true(day[0].t == 6.5 * 3600 && day[0].task_lux == 0);
	assert_true(day[1].t == 7.5 * 3600 && day[1].task_lux == 100.0);
	assert_true(day[4].t == 10.5 * 3600 && day[4].sensor == 0);
	p.gain = 2.0;
	room = ps_room_new(&p, 0.0);
	assert_non_null(room);
	/* 08:00 is halfway between 07:30 (100 lx) and 08:30 (500 lx) */
	ps_room_daylight(room, 8 * 3600.0, &v, &l);
	assert_true(fabs(l - 300.0) < 1e-9 && fabs(v - 2.0 * 2.0) < 1e-9);
	/* 07:00: halfway up from the dark point */
	ps_room_daylight(room, 7 * 3600.0, &v, &l);
	assert_true(fabs(l - 50.0) < 1e-9);
	/* the rooftop reads the hours' global horizontal lux, linear between */
	assert_int_equal(ps_room_rooftop(room, 8 * 3600.0, &l), 0);
	assert_true(fabs(l - 6000.0) < 1e-9);
	assert_int_equal(ps_room_rooftop(room, 7 * 3600.0, &l), 0);
	assert_true(fabs(l - 1000.0) < 1e-9);
	assert_int_equal(ps_room_rooftop(room, 3 * 3600.0, &l), 0);
	assert_true(l == 0.0);
	/* the next day's noon is not this day's */
	ps_room_daylight(room, 12.5 * 3600.0, &v, &l);
	assert_true(l == 0.0 && v == 0.0);
	ps_room_free(room);
	/* the clear-sky profile carries no rooftop reading: ENODATA */
	{
		struct ps_room_daypoint d2[PSD_DAY_POINTS];
		struct ps_room_params p2;
		r.ncond = 0;
		assert_int_equal(psd_roomsetup_from_year(&r, psd_roomsetup_day_of_year("03-18"), d2, &p2), 0);
		for (size_t k = 0; k < p2.ndaylight; k++)
			d2[k].rooftop_lux = NAN;
		room = ps_room_new(&p2, 0.0);
		assert_non_null(room);
		errno = 0;
		assert_int_equal(ps_room_rooftop(room, 8 * 3600.0, &l), -1);
		assert_int_equal(errno, ENODATA);
		ps_room_free(room);
	}
	/* a date without hours: dark all day */
	assert_int_equal(psd_roomsetup_from_year(&r, psd_roomsetup_day_of_year("06-01"), day, &p), 0);
	assert_int_equal(p.ndaylight, 0);
	/* no electric condition: refused */
	r.electric_sensor_response = NAN;
	assert_int_equal(psd_roomsetup_from_year(&r, 77, day, &p), -1);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(plays_the_date),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
