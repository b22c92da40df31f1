/* SPDX-License-Identifier: ISC */
/* A DALI-2 input instance as a point (drivers/dali_input.c): the
 * configuration it sends (DTR0 then the command twice, frames written out by
 * hand from IEC 62386-103/304's layouts), the value from a 10-bit poll (QUERY
 * INPUT VALUE then its latch) and from event messages, polls only when no
 * event came, the loss after 2 x T_report and the recovery, and the
 * occupancy instance's occupied / vacant. */
#include <errno.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "dali_input.h"

enum { NONE = 0, ANSWER, COLLISION, FAILED };

static struct ps_dali_input_conf light_conf(int events)
{
	return (struct ps_dali_input_conf){ .address = 5, .instance = 1, .type = PS_DALI_TYPE_LIGHT, .report = 30,
		                            .deadtime = 1.5, .hysteresis = 10, .hysteresis_min = 50, .hold = -1,
		                            .events = events };
}

/* run the configuration, each frame answered as a device would */
static void configure(struct ps_dali_input *in, double now, uint32_t *frames, int *twice, int *n)
{
	struct ps_dali_input_tx tx;
	double due;
	*n = 0;
	while (in->icfg < in->ncfg) {
		assert_int_equal(ps_dali_input_next(in, now, &tx, &due), 1);
		frames[*n] = tx.frame;
		twice[(*n)++] = tx.twice;
		if ((tx.frame & 0xFF) == PS_DALI_DEVICE_QUERY_RESOLUTION && (tx.frame >> 16) != 0xC1)
			ps_dali_input_result(in, now, ANSWER, 10);
		else
			ps_dali_input_result(in, now, NONE, 0);
	}
}

static void configuration_frames(void **state)
{
	struct ps_dali_input in;
	struct ps_dali_input_conf c = light_conf(1);
	uint32_t f[PS_DALI_INPUT_MAX_TX];
	int tw[PS_DALI_INPUT_MAX_TX], n;
	char why[160];
	static const uint32_t want[] = {
		0xC1301E, 0x0B0130,   /* DTR0 30, SET REPORT TIMER */
		0xC1301E, 0x0B0132,   /* DTR0 30 (1.5 s / 50 ms), SET DEADTIME TIMER */
		0xC1300A, 0x0B0131,   /* DTR0 10, SET HYSTERESIS */
		0xC13032, 0x0B0133,   /* DTR0 50, SET HYSTERESIS MIN */
		0xC13002, 0x0B0167,   /* DTR0 2 (device/instance), SET EVENT SCHEME */
		0xC13100, 0xC13200, 0xC13001, 0x0B0168,   /* DTR1 0, DTR2 0, DTR0 1, SET EVENT FILTER */
		0x0B0162,             /* ENABLE INSTANCE */
		0x0B0181,             /* QUERY RESOLUTION */
	};
	static const int want_twice[] = { 0, 1, 0, 1, 0, 1, 0, 1, 0, 1, 0, 0, 0, 1, 1, 0 };
	(void)state;
	assert_int_equal(ps_dali_input_init(&in, &c, why, sizeof why), 0);
	ps_dali_input_connected(&in, 0);
	configure(&in, 0, f, tw, &n);
	assert_int_equal(n, (int)(sizeof want / sizeof want[0]));
	for (int i = 0; i < n; i++) {
		if (f[i] != want[i] || tw[i] != want_twice[i])
			fail_msg("frame %d: %06X twice %d, want %06X twice %d", i, f[i], tw[i], want[i], want_twice[i]);
	}
	c.report = 256;
	assert_int_equal(ps_dali_input_init(&in, &c, why, sizeof why), -1);
	assert_non_null(strstr(why, "report time"));
	c = light_conf(1);
	c.address = 64;
	assert_int_equal(ps_dali_input_init(&in, &c, why, sizeof why), -1);
}

static void poll_then_events_then_loss(void **state)
{
	struct ps_dali_input in;
	struct ps_dali_input_conf c = light_conf(1);
	struct ps_dali_input_tx tx;
	uint32_t f[PS_DALI_INPUT_MAX_TX];
	int tw[PS_DALI_INPUT_MAX_TX], n, err;
	double due, v;
	char why[200];
	(void)state;
	assert_int_equal(ps_dali_input_init(&in, &c, why, sizeof why), 0);
	ps_dali_input_connected(&in, 0);
	configure(&in, 0, f, tw, &n);
	assert_int_equal(ps_dali_input_value(&in, 0.5, &v, &err, why, sizeof why), -1);
	assert_int_equal(err, ETIMEDOUT);
	/* the first value by a poll: 300 = 0x4B12 left-aligned with its top bits repeated */
	assert_int_equal(ps_dali_input_next(&in, 1, &tx, &due), 1);
	assert_int_equal(tx.frame, 0x0B018C);
	assert_true(tx.answer);
	ps_dali_input_result(&in, 1, ANSWER, 0x4B);
	assert_int_equal(ps_dali_input_next(&in, 1, &tx, &due), 1);
	assert_int_equal(tx.frame, 0x0B018D);
	ps_dali_input_result(&in, 1, ANSWER, 0x12);
	assert_int_equal(ps_dali_input_value(&in, 1, &v, &err, why, sizeof why), 0);
	assert_true(v == 300);
	/* events: the next poll waits 1.25 x T_report from the last value */
	assert_int_equal(ps_dali_input_next(&in, 2, &tx, &due), 0);
	assert_true(fabs(due - (1 + 37.5)) < 1e-9);
	/* device 5 instance 1 (device/instance scheme), 700; another instance's and device's are not ours */
	assert_int_equal(ps_dali_input_event(&in, 31, 0x0B018C), 0);   /* a command, not an event */
	assert_int_equal(ps_dali_input_event(&in, 31, 0x0A8000 | 700), 0);   /* instance 0 */
	assert_int_equal(ps_dali_input_event(&in, 31, 0x0C8400 | 700), 0);   /* device 6 */
	assert_int_equal(ps_dali_input_event(&in, 31, 0x0A8400 | 700), 1);
	assert_int_equal(ps_dali_input_value(&in, 31, &v, &err, why, sizeof why), 0);
	assert_true(v == 700);
	/* device scheme, type 4: also ours */
	assert_int_equal(ps_dali_input_event(&in, 61, 0x0A1000 | 650), 1);
	assert_int_equal(ps_dali_input_next(&in, 62, &tx, &due), 0);
	assert_true(fabs(due - (61 + 37.5)) < 1e-9);
	/* silent from 61 on: polls at 98.5, failing; lost after 2 x 30 s */
	assert_int_equal(ps_dali_input_next(&in, 98.5, &tx, &due), 1);
	ps_dali_input_result(&in, 98.5, FAILED, 0);
	assert_int_equal(ps_dali_input_next(&in, 99, &tx, &due), 0);
	assert_true(fabs(due - (98.5 + 7.5)) < 1e-9);   /* retried after T_report / 4 */
	assert_int_equal(ps_dali_input_value(&in, 121, &v, &err, why, sizeof why), 0);
	assert_int_equal(ps_dali_input_value(&in, 121.01, &v, &err, why, sizeof why), -1);
	assert_int_equal(err, ENODEV);
	assert_non_null(strstr(why, "device 5 instance 1: no value for 60 s"));
	/* back: an event brings it */
	assert_int_equal(ps_dali_input_event(&in, 130, 0x0A8400 | 640), 1);
	assert_int_equal(ps_dali_input_value(&in, 130, &v, &err, why, sizeof why), 0);
	assert_true(v == 640);
}

/* A value wanted from a moment on: with a value 10 s old and events
 * flowing, the next poll would be 27.5 s away; a refresh polls at once,
 * ends when the answer comes (or an event first), and asks nothing when
 * the value is already newer. */
static void refresh_polls_at_once(void **state)
{
	struct ps_dali_input in;
	struct ps_dali_input_conf c = light_conf(1);
	struct ps_dali_input_tx tx;
	uint32_t f[PS_DALI_INPUT_MAX_TX];
	int tw[PS_DALI_INPUT_MAX_TX], n, err;
	double due, v;
	char why[200];
	(void)state;
	assert_int_equal(ps_dali_input_init(&in, &c, why, sizeof why), 0);
	assert_true(isinf(ps_dali_input_age(&in, 0)));
	ps_dali_input_connected(&in, 0);
	configure(&in, 0, f, tw, &n);
	assert_int_equal(ps_dali_input_event(&in, 10, 0x0A8400 | 700), 1);
	assert_true(fabs(ps_dali_input_age(&in, 20) - 10) < 1e-12);
	assert_int_equal(ps_dali_input_next(&in, 20, &tx, &due), 0);
	assert_true(fabs(due - 47.5) < 1e-9);
	ps_dali_input_refresh(&in, 20);
	assert_true(ps_dali_input_refreshing(&in));
	assert_int_equal(ps_dali_input_next(&in, 20, &tx, &due), 1);
	assert_int_equal(tx.frame, 0x0B018C);
	ps_dali_input_result(&in, 20.03, ANSWER, 0x4B);
	assert_true(ps_dali_input_refreshing(&in));   /* half a value: still wanted */
	assert_int_equal(ps_dali_input_next(&in, 20.03, &tx, &due), 1);
	assert_int_equal(tx.frame, 0x0B018D);
	ps_dali_input_result(&in, 20.06, ANSWER, 0x12);
	assert_false(ps_dali_input_refreshing(&in));
	assert_int_equal(ps_dali_input_value(&in, 20.06, &v, &err, why, sizeof why), 0);
	assert_true(v == 300);
	assert_true(fabs(ps_dali_input_age(&in, 20.1) - 0.04) < 1e-9);
	/* then the usual wait again */
	assert_int_equal(ps_dali_input_next(&in, 21, &tx, &due), 0);
	assert_true(fabs(due - (20.06 + 37.5)) < 1e-9);
	/* a value no older than the moment asked: nothing to do */
	ps_dali_input_refresh(&in, 20.06);
	assert_false(ps_dali_input_refreshing(&in));
	/* an event before the poll meets the refresh too */
	ps_dali_input_refresh(&in, 25);
	assert_int_equal(ps_dali_input_event(&in, 25.01, 0x0A8400 | 710), 1);
	assert_false(ps_dali_input_refreshing(&in));
	assert_int_equal(ps_dali_input_next(&in, 25.01, &tx, &due), 0);
	/* a failed poll is retried after T_report / 4, the refresh still wanted */
	ps_dali_input_refresh(&in, 30);
	assert_int_equal(ps_dali_input_next(&in, 30, &tx, &due), 1);
	ps_dali_input_result(&in, 30.02, NONE, 0);
	assert_true(ps_dali_input_refreshing(&in));
	assert_int_equal(ps_dali_input_next(&in, 31, &tx, &due), 0);
	assert_true(fabs(due - (30.02 + 7.5)) < 1e-9);
	assert_int_equal(ps_dali_input_next(&in, 37.52, &tx, &due), 1);
	assert_int_equal(tx.frame, 0x0B018C);
}

static void polling_without_events(void **state)
{
	struct ps_dali_input in;
	struct ps_dali_input_conf c = light_conf(0);
	struct ps_dali_input_tx tx;
	uint32_t f[PS_DALI_INPUT_MAX_TX];
	int tw[PS_DALI_INPUT_MAX_TX], n, polls = 0;
	double due;
	char why[120];
	(void)state;
	c.report = 10;
	assert_int_equal(ps_dali_input_init(&in, &c, why, sizeof why), 0);
	ps_dali_input_connected(&in, 0);
	configure(&in, 0, f, tw, &n);
	/* an hour: one value (2 frames) per T_report, 360 values */
	for (double t = 0; t < 3600; t += 0.25) {
		while (ps_dali_input_next(&in, t, &tx, &due) == 1) {
			polls += (tx.frame & 0xFF) == PS_DALI_DEVICE_QUERY_INPUT_VALUE;
			ps_dali_input_result(&in, t, ANSWER, 0x80);
		}
	}
	assert_int_equal(polls, 360);
	assert_int_equal((int)in.frames, n + 720);
}

static void occupancy(void **state)
{
	struct ps_dali_input in;
	struct ps_dali_input_conf c = { .address = 2, .instance = 0, .type = PS_DALI_TYPE_OCCUPANCY, .report = 20,
		                        .deadtime = -1, .hysteresis = -1, .hysteresis_min = -1, .hold = 600,
		                        .events = 1 };
	struct ps_dali_input_tx tx;
	uint32_t f[PS_DALI_INPUT_MAX_TX];
	int tw[PS_DALI_INPUT_MAX_TX], n, err;
	double due, v;
	char why[120];
	(void)state;
	assert_int_equal(ps_dali_input_init(&in, &c, why, sizeof why), 0);
	ps_dali_input_connected(&in, 0);
	configure(&in, 0, f, tw, &n);
	/* T_report 20 s (303's 0x22), hold 600 s = 60 x 10 s (0x21), filter occupied | vacant | repeat = 7 */
	assert_int_equal(f[0], 0xC13014);
	assert_int_equal(f[1], 0x050022);
	assert_int_equal(f[2], 0xC1303C);
	assert_int_equal(f[3], 0x050021);
	assert_int_equal(f[8], 0xC13007);
	assert_int_equal(f[9], 0x050068);
	(void)tx;
	(void)due;
	/* occupied + movement, then vacant (device/instance scheme, instance 0) */
	assert_int_equal(ps_dali_input_event(&in, 5, 0x048000 | 0x0B), 1);
	assert_int_equal(ps_dali_input_value(&in, 5, &v, &err, why, sizeof why), 0);
	assert_true(v == 1);
	assert_int_equal(ps_dali_input_event(&in, 9, 0x048000 | 0x08), 1);
	assert_int_equal(ps_dali_input_value(&in, 9, &v, &err, why, sizeof why), 0);
	assert_true(v == 0);
	/* a poll's 2-bit value: 0xAA = occupied, no movement */
	c.events = 0;
	assert_int_equal(ps_dali_input_init(&in, &c, why, sizeof why), 0);
	ps_dali_input_connected(&in, 0);
	configure(&in, 0, f, tw, &n);
	in.bits = 2;
	assert_int_equal(ps_dali_input_next(&in, 0, &tx, &due), 1);
	assert_int_equal(tx.frame, 0x05008C);
	ps_dali_input_result(&in, 0, ANSWER, 0xAA);
	assert_int_equal(ps_dali_input_value(&in, 0, &v, &err, why, sizeof why), 0);
	assert_true(v == 1);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(configuration_frames),
		cmocka_unit_test(poll_then_events_then_loss),
		cmocka_unit_test(refresh_polls_at_once),
		cmocka_unit_test(polling_without_events),
		cmocka_unit_test(occupancy),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
