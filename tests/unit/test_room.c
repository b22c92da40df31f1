/* The virtual room: daylight interpolation, fault windows (also across
 * midnight), and the sensor's faults. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <errno.h>
#include <math.h>
#include <cmocka.h>

#include "room.h"

static void daylight_is_interpolated_linearly(void **state)
{
	struct ps_room_daypoint day[4] = { { 0, 0, 0 }, { 3600, 1, 100 }, { 7200, 3, 300 }, { 10800, 3, 300 } };
	struct ps_room_params p = { 0 };
	struct ps_room *r;
	double v, l;
	(void)state;
	p.daylight = day;
	p.ndaylight = 4;
	p.gain = 2;
	r = ps_room_new(&p, 0);
	assert_non_null(r);
	ps_room_daylight(r, 5400, &v, &l);   /* half way between 1 and 3 */
	assert_true(fabs(v - 4.0) < 1e-12 && fabs(l - 200) < 1e-12);
	ps_room_daylight(r, 3600, &v, &l);
	assert_true(fabs(v - 2.0) < 1e-12);
	ps_room_daylight(r, 20000, &v, &l);  /* after the last point: none */
	assert_true(v == 0 && l == 0);
	ps_room_free(r);
}

static void fault_windows(void **state)
{
	struct ps_room_fault_window f[2] = { { PS_ROOM_FAULT_OPEN, 43200, 44400 },
	                                     { PS_ROOM_FAULT_DROP, 82800, 3600 } };
	struct ps_room_params p = { 0 };
	struct ps_room *r;
	double v;
	(void)state;
	p.faults = f;
	p.nfaults = 2;
	p.gain = 1;
	p.elec_sensor = 1;
	p.saturation = 10;
	r = ps_room_new(&p, 0);
	assert_int_equal(ps_room_fault(r, 43200), PS_ROOM_FAULT_OPEN);
	assert_int_equal(ps_room_fault(r, 44400), PS_ROOM_FAULT_NONE);
	assert_int_equal(ps_room_sensor(r, 43300, &v), 0);
	assert_true(v == 0.0);
	/* 23:00 to 01:00 crosses midnight */
	assert_int_equal(ps_room_fault(r, 1800), PS_ROOM_FAULT_DROP);
	assert_int_equal(ps_room_fault(r, 84000), PS_ROOM_FAULT_DROP);
	assert_int_equal(ps_room_fault(r, 86400 + 1800), PS_ROOM_FAULT_DROP);
	assert_int_equal(ps_room_fault(r, 7200), PS_ROOM_FAULT_NONE);
	assert_int_equal(ps_room_sensor(r, 1800, &v), -1);
	assert_int_equal(errno, ETIMEDOUT);
	ps_room_free(r);
}

/* Looking ahead at the truth (psensd asks what the desk gets just before
 * its next step) must not move the room's clock: a command that comes in
 * between, an override say, takes effect when it is given. */
static void truth_ahead_does_not_move_the_room(void **state)
{
	struct ps_room_params p = { 0 };
	struct ps_room *r;
	(void)state;
	p.gain = 1;
	p.elec_sensor = 1;
	p.elec_task_lux = 1000;
	p.saturation = 10;
	r = ps_room_new(&p, 0);                /* no fade, no lag: output follows at once */
	ps_room_command(r, 0, 0.1);
	assert_true(fabs(ps_room_true_task_lux(r, 59.94) - 100) < 1e-9);
	ps_room_command(r, 5, 1.0);            /* an override at 5 s */
	assert_true(fabs(ps_room_output(r, 6) - 1.0) < 1e-12);
	/* energy from 0 to 10 s: 0.1 x 5 + 1 x 5 */
	assert_true(fabs(ps_room_energy(r, 10) - 5.5) < 1e-9);
	ps_room_free(r);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(daylight_is_interpolated_linearly),
		cmocka_unit_test(fault_windows),
		cmocka_unit_test(truth_ahead_does_not_move_the_room),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
