/* SPDX-License-Identifier: ISC */
/* The virtual room: daylight interpolation, fault windows (also across
 * midnight), the sensor's faults, and the loopback's occupancy input. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <errno.h>
#include <math.h>
#include <cmocka.h>

#include "driver.h"
#include "loopback.h"
#include "room.h"

static void daylight_is_interpolated_linearly(void **state)
{
	struct ps_room_daypoint day[4] = { { 0, 0, 0, NAN }, { 3600, 1, 100, NAN }, { 7200, 3, 300, NAN }, { 10800, 3, 300, NAN } };
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
	struct ps_truth t;
	(void)state;
	p.gain = 1;
	p.elec_sensor = 1;
	p.elec_task_lux = 1000;
	p.saturation = 10;
	r = ps_room_new(&p, 0);                /* no fade, no lag: output follows at once */
	ps_room_command(r, 0, 0.1);
	assert_true(fabs(ps_room_true_task_lux(r, 59.94) - 100) < 1e-9);
	/* the truth hook's view: everything at 59.94 s, the room still at 0 */
	ps_room_truth(r, 59.94, &t);
	assert_true(fabs(t.task_lux - 100) < 1e-9 && fabs(t.output - 0.1) < 1e-12);
	assert_true(fabs(t.energy - 5.994) < 1e-9);
	ps_room_command(r, 5, 1.0);            /* an override at 5 s */
	assert_true(fabs(ps_room_output(r, 6) - 1.0) < 1e-12);
	/* energy from 0 to 10 s: 0.1 x 5 + 1 x 5 */
	assert_true(fabs(ps_room_energy(r, 10) - 5.5) < 1e-9);
	ps_room_free(r);
}

/* The truth hook names the fault the room plays, as the faults key does
 * (psvirt holds or drops a reply on "late" and "drop"): the first kind, a
 * middle one and the last, and none between the windows. */
static void truth_names_the_fault(void **state)
{
	struct ps_opt o[] = { { "faults", "stuck 01:00-02:00, drop 03:00-04:00, obstruct 05:00-06:00", 1, 0 } };
	struct ps_opts opts = { o, 1, "test.conf" };
	struct ps_room_params p = { 0 };
	struct ps_dev dev = { 0 };
	struct ps_truth t;
	(void)state;
	p.gain = 1;
	p.elec_sensor = 1;
	p.saturation = 10;
	dev.drv = &ps_driver_loopback;
	assert_int_equal(dev.drv->open(&dev, &opts), 0);
	assert_int_equal(dev.drv->setup(&dev, &p, 0), 0);
	assert_int_equal(dev.drv->truth(&dev, 5400, &t), 0);
	assert_string_equal(t.fault, "stuck");
	assert_int_equal(dev.drv->truth(&dev, 12600, &t), 0);
	assert_string_equal(t.fault, "drop");
	assert_int_equal(dev.drv->truth(&dev, 19800, &t), 0);
	assert_string_equal(t.fault, "obstruct");
	assert_int_equal(dev.drv->truth(&dev, 25200, &t), 0);
	assert_null(t.fault);
	dev.drv->close(&dev);
}

struct events {
	int n, value[64];
	double t[64];
};

static void take_event(void *user, struct ps_dev *dev, struct ps_point *pt, double now, double value)
{
	struct events *ev = user;
	(void)dev;
	(void)pt;
	if (ev->n < 64) {
		ev->t[ev->n] = now;
		ev->value[ev->n] = value > 0.5;
	}
	ev->n++;
}

/* The loopback's occupancy input over a day, its events taken at its
 * deadlines: occupied 08:00-12:00 with 3 absences of 600 to 1200 s, and no
 * answer 14:00-15:00.  The reports alternate and agree with a read at the
 * same time; the absences fall inside the occupied times and last, in all,
 * between one shortest absence (600 s, when they overlap) and three longest
 * (3600 s); the input is vacant outside the window and fails as a device
 * gone while dead, with no event then, and reports afresh at 15:00; the
 * same seed replays the same day. */
static void occupancy_input_day(void **state)
{
	struct ps_opt dopt[] = { { "seed", "7", 1, 0 } };
	struct ps_opt popt[] = { { "occupied", "08:00-12:00", 2, 0 }, { "absences", "3", 3, 0 },
		                 { "absence_length", "1200", 4, 0 }, { "dead", "14:00-15:00", 5, 0 } };
	struct ps_opts dopts = { dopt, 1, "test.conf" }, popts = { popt, 4, "test.conf" };
	struct ps_room_params p = { 0 };
	struct ps_dev dev = { 0 };
	struct ps_point pt = { "pir", PS_ROLE_INPUT, NULL };
	struct events ev = { 0 }, again = { 0 };
	double v, away = 0;
	(void)state;
	p.gain = 1;
	p.saturation = 10;
	dev.drv = &ps_driver_loopback;
	dev.on_event = take_event;
	for (int run = 0; run < 2; run++) {
		struct events *e = run ? &again : &ev;
		dev.event_user = e;
		assert_int_equal(dev.drv->open(&dev, &dopts), 0);
		assert_int_equal(dev.drv->setup(&dev, &p, 0), 0);
		assert_int_equal(dev.drv->add_point(&dev, &pt, &popts), 0);
		for (double t = 0; t < 86400;) {
			dev.drv->service(&dev, t, t);
			t = dev.drv->deadline(&dev, &(double){ INFINITY });
			assert_true(t > 0);
		}
		dev.drv->close(&dev);
		if (!run) {   /* reads checked on a fresh device at the reports' times */
			assert_int_equal(dev.drv->open(&dev, &dopts), 0);
			assert_int_equal(dev.drv->setup(&dev, &p, 0), 0);
			assert_int_equal(dev.drv->add_point(&dev, &pt, &popts), 0);
			for (int i = 0; i < ev.n && i < 64; i++) {
				assert_int_equal(dev.drv->read(&dev, &pt, ev.t[i], ev.t[i], &v), 0);
				assert_int_equal((int)v, ev.value[i]);
			}
			assert_int_equal(dev.drv->read(&dev, &pt, 7 * 3600, 7 * 3600, &v), 0);
			assert_true(v == 0);
			assert_int_equal(dev.drv->read(&dev, &pt, 13 * 3600, 13 * 3600, &v), 0);
			assert_true(v == 0);
			errno = 0;
			assert_int_equal(dev.drv->read(&dev, &pt, 14.5 * 3600, 14.5 * 3600, &v), -1);
			assert_int_equal(errno, ENODEV);
			dev.drv->close(&dev);
		}
	}
	assert_true(ev.n >= 4 && ev.n <= 64);   /* vacant at 0, the window, at least one absence */
	assert_int_equal(ev.value[0], 0);
	assert_true(ev.t[1] == 8 * 3600 && ev.value[1] == 1);
	for (int i = 1; i < ev.n; i++) {
		if (ev.t[i] == 15 * 3600)   /* answering again: its state afresh */
			assert_int_equal(ev.value[i], 0);
		else
			assert_int_equal(ev.value[i], !ev.value[i - 1]);
		assert_false(ev.t[i] > 14 * 3600 && ev.t[i] < 15 * 3600);   /* dead: silent */
		if (ev.value[i] == 0 && ev.t[i] < 12 * 3600)
			away += (i + 1 < ev.n ? ev.t[i + 1] : 86400) - ev.t[i];
	}
	assert_true(away >= 600 && away <= 3600);
	assert_int_equal(again.n, ev.n);
	for (int i = 0; i < ev.n; i++)
		assert_true(again.t[i] == ev.t[i] && again.value[i] == ev.value[i]);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(daylight_is_interpolated_linearly),
		cmocka_unit_test(fault_windows),
		cmocka_unit_test(truth_ahead_does_not_move_the_room),
		cmocka_unit_test(truth_names_the_fault),
		cmocka_unit_test(occupancy_input_day),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
