/* SPDX-License-Identifier: ISC */
/* psvirt's virtual DALI bus (daemon/psvirt/dalibus.c) against the standards'
 * facts: the arc power curve of IEC 62386-102 (level n is
 * 10^((n-1)/(253/3)-1) percent, worked here with exp and log, not the
 * code's pow), DTR0 settings taking effect only when sent twice, a fade's
 * midpoint, and the random-address search of 102 (gear) and 103 (control
 * devices) run as an application controller runs it, each found address
 * checked against the devices' own random addresses; input values of a
 * 10-bit 304 instance read as QUERY INPUT VALUE then the latch; the faults
 * on demand. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "dalibus.h"

static struct psd_dalibus bus;

static int tx(int bits, uint32_t f, int twice, int *ans)
{
	uint8_t a = 0;
	int r = psd_dalibus_frame(&bus, 100.0, bits, f, twice, &a);
	*ans = r == PSD_DALIBUS_ANSWER ? a : -1;
	return r;
}

static int ask16(uint32_t f)
{
	int a;
	tx(16, f, 0, &a);
	return a;
}

static int ask24(uint32_t f)
{
	int a;
	tx(24, f, 0, &a);
	return a;
}

static void arc_curve_is_the_standards(void **state)
{
	(void)state;
	assert_true(psd_dalibus_arc(0) == 0);
	for (int n = 1; n <= 254; n++) {
		double percent = exp(log(10.0) * ((n - 1) * 3.0 / 253.0 - 1.0));
		assert_true(fabs(100 * psd_dalibus_arc(n) - percent) <= 1e-12 * percent);
	}
	/* the ends of the range: 0.1 % at level 1, 100 % at 254 */
	assert_true(fabs(psd_dalibus_arc(1) - 0.001) < 1e-15);
	assert_true(fabs(psd_dalibus_arc(254) - 1.0) < 1e-15);
	/* each level 2.77 % above the one below: 10^(3/253) */
	assert_true(fabs(psd_dalibus_arc(101) / psd_dalibus_arc(100) - 1.027679) < 1e-6);
}

static void dapc_drives_the_zone_output(void **state)
{
	(void)state;
	psd_dalibus_init(&bus, 4, 2, 1, 7);   /* gear 0, 1 light zone 0; 2, 3 zone 1 */
	assert_int_equal(ask16(0x01A0), 254);  /* short 0 QUERY ACTUAL LEVEL: on at full after power-up */
	assert_int_equal(ask16(0x0200 | 170), -1);   /* short 1 DAPC 170 */
	assert_int_equal(ask16(0x03A0), 170);
	assert_true(fabs(psd_dalibus_output(&bus, 0, 100) - (1.0 + pow(10, 169 * 3 / 253.0 - 3)) / 2) < 1e-12);
	assert_true(fabs(psd_dalibus_output(&bus, 1, 100) - 1.0) < 1e-12);
	/* group 3: gear 2 joins (sent twice), then the group's DAPC reaches it only */
	tx(16, 0x0563, 1, &(int){ 0 });
	assert_int_equal(ask16(0x05C0), 0x08);
	assert_int_equal(ask16(0x8600 | 1), -1);
	assert_int_equal(ask16(0x05A0), 1);
	assert_int_equal(ask16(0x07A0), 254);
	/* broadcast OFF, RECALL MAX */
	ask16(0xFF00);
	assert_true(psd_dalibus_output(&bus, 0, 100) == 0);
	ask16(0xFF05);
	assert_int_equal(ask16(0x01A0), 254);
}

static void settings_need_twice(void **state)
{
	(void)state;
	psd_dalibus_init(&bus, 1, 1, 1, 7);
	ask16(0xA300 | 100);                  /* DTR0 100 */
	ask16(0x012B);                        /* SET MIN LEVEL once: ignored */
	assert_int_equal(ask16(0x01A2), 1);
	tx(16, 0x012B, 1, &(int){ 0 });       /* sent twice by the interface */
	assert_int_equal(ask16(0x01A2), 100);
	/* two copies in a row are a pair as well */
	ask16(0xA300 | 200);
	ask16(0x012A);
	ask16(0x012A);
	assert_int_equal(ask16(0x01A1), 200);
	/* DAPC clamps to min and max; 255 (MASK) changes nothing */
	ask16(0x0000 | 50);
	assert_int_equal(ask16(0x01A0), 100);
	ask16(0x0000 | 250);
	assert_int_equal(ask16(0x01A0), 200);
	ask16(0x0000 | 255);
	assert_int_equal(ask16(0x01A0), 200);
	/* queries the driver uses */
	assert_int_equal(ask16(0x0191), 0xFF);
	assert_int_equal(ask16(0x019A), 1);
	assert_int_equal(ask16(0x0199), 6);
	assert_int_equal(ask16(0x0196), -1);  /* not missing its short address */
}

static void a_fade_runs_the_fade_time(void **state)
{
	uint8_t a;
	(void)state;
	psd_dalibus_init(&bus, 1, 1, 1, 7);
	/* fade time code 4: 0.5 * 2^(4/2) = 2 s */
	psd_dalibus_frame(&bus, 10.0, 16, 0xA304, 0, &a);
	psd_dalibus_frame(&bus, 10.0, 16, 0x012E, 1, &a);
	psd_dalibus_frame(&bus, 10.0, 16, 0x0000 | 54, 0, &a);
	assert_int_equal(psd_dalibus_level(&bus.gear[0], 10.0), 254);
	assert_int_equal(psd_dalibus_level(&bus.gear[0], 11.0), 154);
	assert_int_equal(psd_dalibus_level(&bus.gear[0], 12.0), 54);
	assert_int_equal(psd_dalibus_frame(&bus, 11.0, 16, 0x0190, 0, &a), PSD_DALIBUS_ANSWER);
	assert_int_equal(a & 0x14, 0x14);     /* lamp on, fade running */
}

/* The lowest random address among the selected, not withdrawn devices,
 * found as a controller finds it: 24 COMPAREs of a binary search. */
static uint32_t search_lowest(int dev)
{
	uint32_t lo = 0, hi = 0xFFFFFF;
	while (lo < hi) {
		uint32_t mid = lo + (hi - lo) / 2;
		if (dev) {
			ask24(0xC10500 | (mid >> 16));
			ask24(0xC10600 | (mid >> 8 & 0xFF));
			ask24(0xC10700 | (mid & 0xFF));
		} else {
			ask16(0xB100 | (mid >> 16));
			ask16(0xB300 | (mid >> 8 & 0xFF));
			ask16(0xB500 | (mid & 0xFF));
		}
		if ((dev ? ask24(0xC10300) : ask16(0xA900)) == 0xFF)
			hi = mid;
		else
			lo = mid + 1;
	}
	if (dev) {
		ask24(0xC10500 | (lo >> 16));
		ask24(0xC10600 | (lo >> 8 & 0xFF));
		ask24(0xC10700 | (lo & 0xFF));
	} else {
		ask16(0xB100 | (lo >> 16));
		ask16(0xB300 | (lo >> 8 & 0xFF));
		ask16(0xB500 | (lo & 0xFF));
	}
	return lo;
}

static uint32_t truth_lowest(int dev, const int *done)
{
	uint32_t m = 0xFFFFFFFF;
	for (int i = 0; i < (dev ? bus.ndev : bus.ngear); i++)
		if (!done[i] && (dev ? bus.dev[i].random : bus.gear[i].random) < m)
			m = dev ? bus.dev[i].random : bus.gear[i].random;
	return m;
}

static void device_search_103(void **state)
{
	int done[PSD_DALIBUS_MAX_DEV] = { 0 }, a;
	(void)state;
	psd_dalibus_init(&bus, 3, 3, 0, 12345);   /* three unaddressed multisensors */
	assert_int_equal(ask24(0xFFFE33), 0xFF);  /* QUERY MISSING SHORT ADDRESS: yes (all alike) */
	tx(24, 0xC1017F, 1, &a);                   /* INITIALISE the unaddressed */
	tx(24, 0xC10200, 1, &a);                   /* RANDOMISE */
	assert_true(bus.dev[0].random != bus.dev[1].random && bus.dev[1].random != bus.dev[2].random);
	/* different random addresses answered at once: a garbled backward frame */
	assert_int_equal(tx(24, 0xFFFE39, 0, &a),
	                 (bus.dev[0].random >> 16) == (bus.dev[1].random >> 16) &&
	                 (bus.dev[1].random >> 16) == (bus.dev[2].random >> 16) ? PSD_DALIBUS_ANSWER : PSD_DALIBUS_GARBLED);
	for (int k = 0; k < 3; k++) {
		uint32_t want = truth_lowest(1, done), got = search_lowest(1);
		assert_int_equal(got, want);
		ask24(0xC10800 | (uint32_t)(10 + k));       /* PROGRAM SHORT ADDRESS 10 + k */
		assert_int_equal(ask24(0xC10900 | (uint32_t)(10 + k)), 0xFF);   /* VERIFY */
		assert_int_equal(ask24(0xC10A00), 10 + k);  /* QUERY SHORT ADDRESS */
		ask24(0xC10400);                            /* WITHDRAW */
		for (int i = 0; i < 3; i++)
			if (bus.dev[i].random == want)
				done[i] = 1;
	}
	assert_int_equal(ask24(0xC10300), -1);     /* no one left to compare */
	ask24(0xC10000);                            /* TERMINATE */
	assert_int_equal(ask24(0xFFFE33), -1);     /* no one misses a short address */
	for (int k = 0; k < 3; k++)
		assert_int_equal(ask24(0x010000 | (uint32_t)(10 + k) << 17 | 0xFE35), 2);   /* 2 instances */
}

static void gear_search_102(void **state)
{
	int done[PSD_DALIBUS_MAX_GEAR] = { 0 }, a;
	(void)state;
	psd_dalibus_init(&bus, 4, 1, 0, 999);
	tx(16, 0xA5FF, 1, &a);   /* INITIALISE the unaddressed */
	tx(16, 0xA700, 1, &a);   /* RANDOMISE */
	for (int k = 0; k < 4; k++) {
		uint32_t want = truth_lowest(0, done), got = search_lowest(0);
		assert_int_equal(got, want);
		ask16(0xB700 | (uint32_t)(k << 1 | 1));
		assert_int_equal(ask16(0xBB00), k << 1 | 1);
		ask16(0xAB00);
		for (int i = 0; i < 4; i++)
			if (bus.gear[i].random == want)
				done[i] = 1;
	}
	ask16(0xA100);
	for (int k = 0; k < 4; k++)
		assert_int_equal(ask16((uint32_t)(k << 9 | 0x100 | 0x91)), 0xFF);
}

static void input_values_and_latch(void **state)
{
	int hi, lo;
	(void)state;
	psd_dalibus_init(&bus, 2, 1, 1, 7);
	psd_dalibus_sense(&bus, 0, 845, 1);
	assert_int_equal(ask24(0x010180), 4);      /* instance 1: light sensor (304) */
	assert_int_equal(ask24(0x010181), 10);     /* 10 bits */
	assert_int_equal(ask24(0x010080), 3);      /* instance 0: occupancy (303) */
	assert_int_equal(ask24(0x01C480), 4);      /* addressed by type */
	hi = ask24(0x01018C);
	lo = ask24(0x01018D);
	assert_int_equal(hi, 845 >> 2);
	assert_int_equal((hi << 8 | lo) >> 6, 845);
	/* the latch's low bits repeat the value's top bits (103) */
	assert_int_equal(lo & 0x3F, 845 >> 4);
	assert_int_equal(ask24(0x01008C), 0xFF);   /* occupied: 0b11 filled */
	psd_dalibus_sense(&bus, 0, 3, 0);
	assert_int_equal(ask24(0x01018C), 0);
	assert_int_equal(ask24(0x01018D), 3 << 6);
	assert_int_equal(ask24(0x01008C), 0);
}

static void events_follow_report_timer(void **state)
{
	uint32_t ev[PSD_DALIBUS_MAX_EVENTS];
	uint8_t a;
	(void)state;
	psd_dalibus_init(&bus, 2, 1, 1, 7);
	psd_dalibus_sense(&bus, 0, 500, 0);
	assert_int_equal(psd_dalibus_events(&bus, 0, ev), 0);   /* instances disabled */
	psd_dalibus_frame(&bus, 0, 24, 0xC13001, 0, &a);         /* DTR0 1: the device scheme */
	psd_dalibus_frame(&bus, 0, 24, 0x010167, 1, &a);
	psd_dalibus_frame(&bus, 0, 24, 0xC13000, 0, &a);         /* DTR0 0: no T_report */
	psd_dalibus_frame(&bus, 0, 24, 0x010130, 1, &a);
	psd_dalibus_frame(&bus, 0, 24, 0xC13002, 0, &a);         /* DTR0 2: T_deadtime 100 ms */
	psd_dalibus_frame(&bus, 0, 24, 0x010132, 1, &a);
	psd_dalibus_frame(&bus, 0, 24, 0x010162, 1, &a);         /* ENABLE INSTANCE */
	assert_int_equal(psd_dalibus_events(&bus, 1, ev), 1);
	/* device scheme: short 0 in bits 22..17, type 4 in 14..10, the value */
	assert_int_equal(ev[0], 4u << 10 | 500);
	assert_int_equal(psd_dalibus_events(&bus, 5, ev), 0);    /* no change, no T_report */
	psd_dalibus_sense(&bus, 0, 530, 0);                       /* inside the 10 % band */
	assert_int_equal(psd_dalibus_events(&bus, 6, ev), 0);
	psd_dalibus_sense(&bus, 0, 700, 0);                       /* out of it */
	assert_int_equal(psd_dalibus_events(&bus, 6.05, ev), 1);
	assert_int_equal(ev[0] & 0x3FF, 700);
	psd_dalibus_sense(&bus, 0, 100, 0);
	assert_int_equal(psd_dalibus_events(&bus, 6.1, ev), 0);  /* within T_deadtime */
	assert_int_equal(psd_dalibus_events(&bus, 6.2, ev), 1);
	assert_int_equal(ev[0] & 0x3FF, 100);
	/* T_report 1 s: the value again though it has not changed */
	psd_dalibus_frame(&bus, 6.2, 24, 0xC13001, 0, &a);
	psd_dalibus_frame(&bus, 6.2, 24, 0x010130, 1, &a);
	assert_int_equal(psd_dalibus_events(&bus, 7.0, ev), 0);
	assert_int_equal(psd_dalibus_events(&bus, 7.3, ev), 1);
	assert_int_equal(ev[0] & 0x3FF, 100);
}

static void faults_on_demand(void **state)
{
	int a;
	(void)state;
	psd_dalibus_init(&bus, 2, 1, 1, 7);
	bus.fault = PSD_DALIBUS_SILENT;
	bus.target = 0;
	assert_int_equal(ask16(0x01A0), -1);          /* gear 0 silent */
	assert_int_equal(ask16(0x03A0), 254);         /* gear 1 answers */
	bus.target = PSD_DALIBUS_DEVICE + 0;
	assert_int_equal(ask24(0x010180), -1);        /* the sensor silent */
	bus.fault = PSD_DALIBUS_COLLIDE;
	bus.target = 1;
	assert_int_equal(tx(16, 0x03A0, 0, &a), PSD_DALIBUS_GARBLED);
	assert_int_equal(tx(16, 0x01A0, 0, &a), PSD_DALIBUS_ANSWER);
	bus.fault = PSD_DALIBUS_SHORT;
	assert_int_equal(tx(16, 0x01A0, 0, &a), PSD_DALIBUS_NOPOWER);
	bus.fault = PSD_DALIBUS_OK;
	assert_int_equal(ask16(0x01A0), 254);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(arc_curve_is_the_standards),
		cmocka_unit_test(dapc_drives_the_zone_output),
		cmocka_unit_test(settings_need_twice),
		cmocka_unit_test(a_fade_runs_the_fade_time),
		cmocka_unit_test(device_search_103),
		cmocka_unit_test(gear_search_102),
		cmocka_unit_test(input_values_and_latch),
		cmocka_unit_test(events_follow_report_timer),
		cmocka_unit_test(faults_on_demand),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
