/* SPDX-License-Identifier: ISC */
/* DALI bus load of a zone with a DALI-2 multisensor (a 304 light sensor and
 * a 303 occupancy sensor) and its gear, from the driver's own input model
 * (drivers/dali_input.c) run over simulated hours: the frames psensd sends
 * (configuration, polls with their latches), the frames the sensor sends
 * (event messages: its repeats every T_report and its changes beyond the
 * hysteresis, not within T_deadtime), and the zone's gear commands (one
 * DAPC a control period when the level moves).  Frame times at 1200 bit/s
 * (IEC 62386-101): a bit 833.3 us; a 16-bit forward frame 1 start + 16 + 2
 * stop bits = 15.8 ms, a 24-bit one 22.5 ms, a backward frame 9.2 ms; the
 * settling time before a backward frame 5.5-10.5 ms, before the next
 * forward frame 13.5-21.2 ms by priority.  Printed: frames per second per
 * zone and the bus time they take, at T_report 30 s with events and by
 * polling, and during a night calibration session (six levels, 20 s each,
 * the zone stepping every 2 s, the session polling for a fresh value when
 * the sensor sent nothing since its last step); the configuration at
 * connect apart;
 * the sensor event to gear command latency in bus frames and time; the
 * time from a lost sensor's last value until the zone reads the loss. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dali_input.h"

#define BIT (1.0 / 1200)
#define FWD16 (19 * BIT)
#define FWD24 (27 * BIT)
#define BACK (11 * BIT)
#define SETTLE_BACK 0.008     /* mean settling before a backward frame */
#define SETTLE_FWD 0.0175     /* mean settling before a forward frame, priorities 2-5 */

struct load {
	unsigned long tx, answers, events, dapc;
	unsigned long config;     /* frames of the configuration at connect (not in the rates) */
	double busy;              /* seconds of bus time */
};

static void conf(struct ps_dali_input *in, int type, int events, double report)
{
	struct ps_dali_input_conf c = { .address = 5, .instance = type == PS_DALI_TYPE_LIGHT ? 1 : 0, .type = type,
		                        .report = report, .deadtime = 1.5, .hysteresis = type == PS_DALI_TYPE_LIGHT ? 10 : -1,
		                        .hysteresis_min = type == PS_DALI_TYPE_LIGHT ? 50 : -1, .hold = -1, .events = events };
	char why[120];
	if (ps_dali_input_init(in, &c, why, sizeof why) != 0)
		fprintf(stderr, "bench_dali_bus: %s\n", why);
	ps_dali_input_connected(in, 0);
}

/* one transaction of ours: a 24-bit frame, maybe twice, maybe answered */
static void ours(struct load *l, const struct ps_dali_input_tx *tx, int config)
{
	if (config) {
		l->config += (tx->twice ? 2 : 1) + (tx->answer != 0);
		return;
	}
	l->tx += tx->twice ? 2 : 1;
	l->busy += (tx->twice ? 2 : 1) * (FWD24 + SETTLE_FWD);
	if (tx->answer) {
		l->answers++;
		l->busy += SETTLE_BACK + BACK;
	}
}

/* The light at time t: a slow day swing, or the steps of a night session. */
static int light_at(double t, int session)
{
	if (session) {
		static const double lv[6] = { 1, 0.75, 0.5, 0.25, 0.1, 0 };
		int k = (int)(t / 20) % 6;
		return (int)(80 + 800 * lv[k]);
	}
	return (int)(500 + 300 * sin(2 * M_PI * t / 3600));
}

/* Simulate seconds of one zone: the light sensor and the occupancy sensor
 * (occupied all along), the daemon reading every period and commanding
 * the gear when the level moves. */
static void run(struct load *l, int events, double report, double seconds, double period, int session)
{
	struct ps_dali_input light, occ;
	double next_rep_l = 0, next_rep_o = 0, last_ev_l = -1e9, fed = -INFINITY;
	int sent = -1, level = -1, asked = 0;
	memset(l, 0, sizeof *l);
	conf(&light, PS_DALI_TYPE_LIGHT, events, report);
	conf(&occ, PS_DALI_TYPE_OCCUPANCY, events, report);
	long per = lround(period / 0.05);
	for (long k = 0; k * 0.05 < seconds; k++) {
		double t = k * 0.05;
		struct ps_dali_input_tx tx;
		double due;
		int v = light_at(t, session);
		/* the devices' events: repeats, and the light's changes */
		if (events) {
			int moved = sent < 0 || abs(v - sent) > fmax(0.1 * sent, 50);
			if (t >= next_rep_l || (moved && t >= last_ev_l + 1.5)) {
				uint32_t f = 5u << 17 | 1u << 15 | 1u << 10 | (unsigned)v;
				ps_dali_input_event(&light, t, f);
				l->events++;
				l->busy += FWD24 + SETTLE_FWD;
				sent = v;
				last_ev_l = t;
				next_rep_l = t + report;
			}
			if (t >= next_rep_o) {
				ps_dali_input_event(&occ, t, 5u << 17 | 1u << 15 | 0u << 10 | 0x0E);
				l->events++;
				l->busy += FWD24 + SETTLE_FWD;
				next_rep_o = t + report;
			}
		}
		/* ours: configuration and polls, answered as the devices would */
		while (ps_dali_input_next(&light, t, &tx, &due) == 1) {
			ours(l, &tx, light.icfg < light.ncfg);
			ps_dali_input_result(&light, t, tx.answer ? 1 : 0, (tx.frame & 0xFF) == 0x81 ? 10 : v >> 2);
		}
		while (ps_dali_input_next(&occ, t, &tx, &due) == 1) {
			ours(l, &tx, occ.icfg < occ.ncfg);
			ps_dali_input_result(&occ, t, tx.answer ? 1 : 0, (tx.frame & 0xFF) == 0x81 ? 2 : 0xAA);
		}
		/* a session's poll answered: the zone steps on it and feeds it */
		if (asked && !ps_dali_input_refreshing(&light)) {
			fed = light.last;
			asked = 0;
		}
		/* the zone's step: a DAPC when the level moves; in a session, a
		 * value fed once, and a poll when nothing new came (calsession.h) */
		if (session && k % per == 0 && !asked) {
			if (light.last > fed)
				fed = light.last;
			else
				ps_dali_input_refresh(&light, t), asked = 1;
		}
		if (k % per == 0) {
			double x;
			int err;
			char why[200];
			if (ps_dali_input_value(&light, t, &x, &err, why, sizeof why) == 0) {
				int want = (int)(254 - x / 8);
				if (session)
					want = 1 + (int)(t / 20) % 6 * 40;
				if (want != level) {
					level = want;
					l->dapc++;
					l->busy += FWD16 + SETTLE_FWD;
				}
			}
		}
	}
}

static void report_load(const char *what, const struct load *l, double seconds)
{
	printf("%-54s %7.4f frames/s (psensd's polls %.4f, sensor events %.4f, gear %.4f); bus busy %.3f %%\n",
	       what, (double)(l->tx + l->answers + l->events + l->dapc) / seconds,
	       (double)(l->tx + l->answers) / seconds, (double)l->events / seconds, (double)l->dapc / seconds,
	       100 * l->busy / seconds);
}

/* A sensor that falls silent at a random moment after its last report:
 * seconds from that report until a zone stepping every period reads the
 * loss, worst over many phases. */
static double lost_after(double report, double period, int events)
{
	double worst = 0;
	for (int ph = 0; ph < 97; ph++) {
		struct ps_dali_input in;
		struct ps_dali_input_tx tx;
		double due, v, last = 0, step = 100 + period * ph / 97.0;
		int err;
		char why[200];
		conf(&in, PS_DALI_TYPE_LIGHT, events, report);
		for (long k = 0;; k++) {
			double t = k * 0.05;
			if (t < 100 && events && k % lround(report / 0.05) == 0) {
				ps_dali_input_event(&in, t, 5u << 17 | 1u << 15 | 1u << 10 | 500);
				last = t;
			}
			while (ps_dali_input_next(&in, t, &tx, &due) == 1) {
				int alive = t < 100;
				ps_dali_input_result(&in, t, alive ? (tx.answer ? 1 : 0) : 3, 0x80);
				if (alive && tx.answer && (tx.frame & 0xFF) == 0x8D)
					last = t;
			}
			if (t >= step) {
				step += period;
				if (ps_dali_input_value(&in, t, &v, &err, why, sizeof why) != 0) {
					worst = fmax(worst, t - last);
					break;
				}
			}
			if (t > 1000)
				break;   /* not reached: the loss is read by 100 + 2 x T_report + period */
		}
	}
	return worst;
}

int main(void)
{
	struct load l;
	double hour = 3600;
	printf("DALI frame times at 1200 bit/s: 16-bit forward %.1f ms, 24-bit forward %.1f ms, backward %.1f ms\n",
	       1e3 * FWD16, 1e3 * FWD24, 1e3 * BACK);
	run(&l, 1, 30, hour, 60, 0);
	printf("configuration at each connect: %lu frames (both instances, backward frames counted)\n", l.config);
	report_load("one zone, T_report 30 s, events, period 60 s:", &l, hour);
	run(&l, 0, 30, hour, 60, 0);
	report_load("one zone, T_report 30 s, polling, period 60 s:", &l, hour);
	run(&l, 1, 30, 120, 2, 1);
	report_load("night session (6 levels x 20 s), events, period 2 s:", &l, 120);
	run(&l, 0, 30, 120, 2, 1);
	report_load("night session (6 levels x 20 s), polling, period 2 s:", &l, 120);
	printf("a lost sensor, T_report 30 s: the zone reads the loss at most %.1f s after its last value (events, "
	       "period 1 s), %.1f s (polling, period 1 s), %.1f s (events, period 60 s): 2 x T_report, then the zone's "
	       "next step\n",
	       lost_after(30, 1, 1), lost_after(30, 1, 0), lost_after(30, 60, 1));
	/* an event, then the command: nothing of ours in between */
	printf("sensor event to gear command: 1 bus frame after the event (the DAPC is the next frame psensd sends); "
	       "bus time %.1f ms (event %.1f + settling %.1f + DAPC %.1f), the zone stepping on the event "
	       "(bench_dali_event.sh measures it)\n",
	       1e3 * (FWD24 + SETTLE_FWD + FWD16), 1e3 * FWD24, 1e3 * SETTLE_FWD, 1e3 * FWD16);
	return 0;
}
