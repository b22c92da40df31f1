/* SPDX-License-Identifier: ISC */
/* One input instance of a DALI-2 control device as a point: a 304 light
 * sensor's 10-bit relative reading, or a 303 occupancy sensor's occupied
 * (1) or vacant (0).  Pure: no I/O, no clock; the driver asks for the next
 * transaction, puts it on the bus and hands back what came of it, and
 * hands in the event messages it sees.
 *
 * At (re)connect the instance is configured: T_report (and for a light
 * sensor hysteresis, its minimum and T_deadtime; for occupancy the hold
 * timer), the device/instance event scheme (the event names the device's
 * short address and the instance number), the event filter (illuminance;
 * occupied, vacant and their repeats), then ENABLE INSTANCE and QUERY
 * RESOLUTION.  Each setting is DTR0 (and DTR1, DTR2 for the filter) then
 * the command sent twice.
 *
 * A value comes from an event message or, when none has come for
 * poll_after seconds, from QUERY INPUT VALUE and as many QUERY INPUT VALUE
 * LATCH as the resolution needs.  The sensor repeats its value every
 * T_report, so with events flowing no frame is sent at all; without events
 * (an interface that does not pass bus traffic) a poll costs 1 + latches
 * frames per T_report.  A value older than 2 x T_report is lost: the
 * sensor stopped answering and reporting.
 *
 * A value is as old as the event, report or answer it came in: between
 * reports a light sensor may drift up to its hysteresis band unseen.  A
 * caller that needs a value measured from a moment on (a calibration
 * sample paired with a task meter) asks for one with refresh(): the next
 * transaction is then QUERY INPUT VALUE at once, whatever came lately. */
#ifndef PS_DALI_INPUT_H
#define PS_DALI_INPUT_H

#include <stdint.h>

#include "dali_device.h"

#define PS_DALI_INPUT_MAX_TX 24

struct ps_dali_input_tx {
	uint32_t frame;   /* 24-bit forward frame */
	int twice;
	int answer;
};

struct ps_dali_input_conf {
	int address;          /* device short address 0..63 */
	int instance;         /* instance number 0..31 */
	int type;             /* PS_DALI_TYPE_LIGHT or PS_DALI_TYPE_OCCUPANCY */
	double report;        /* T_report, seconds: 1..255 */
	double deadtime;      /* T_deadtime, seconds (0..12.75), < 0 leave it */
	int hysteresis;       /* percent, < 0 leave it */
	int hysteresis_min;   /* input units, < 0 leave it */
	double hold;          /* 303 hold timer, seconds (10..2550), < 0 leave it */
	int events;           /* the interface passes event messages */
};

struct ps_dali_input {
	struct ps_dali_input_conf c;
	/* the configuration still to send, in order */
	struct ps_dali_input_tx cfg[PS_DALI_INPUT_MAX_TX];
	int ncfg, icfg;
	int bits;             /* resolution, from QUERY RESOLUTION (default: 10 light, 2 occupancy) */
	int busy;             /* a transaction is on the bus */
	int stage;            /* polling: bytes asked so far (0: none) */
	uint8_t bytes[4];
	double last;          /* when the value last came, -INFINITY never */
	double wanted;        /* a value measured at or after this is asked for (refresh), -INFINITY none */
	double next_poll;
	long value;           /* the raw value: 10-bit reading, or the occupancy state (1/0) */
	unsigned long frames, events, polls, failures;
	char why[120];        /* the last failure */
};

/* Check conf, build the configuration.  0, or -1 with why. */
int ps_dali_input_init(struct ps_dali_input *in, const struct ps_dali_input_conf *c, char *why, size_t n);
/* The link is (back) up at now: configure again, poll at once. */
void ps_dali_input_connected(struct ps_dali_input *in, double now);
/* 1 with tx filled when a transaction is due at now; 0 none (then *due is
 * when one will be, INFINITY never). */
int ps_dali_input_next(struct ps_dali_input *in, double now, struct ps_dali_input_tx *tx, double *due);
/* What came of the transaction next() gave: rx as in dali_commission.h
 * (0 no answer, 1 answer value, 2 collision, 3 failed). */
void ps_dali_input_result(struct ps_dali_input *in, double now, int rx, unsigned value);
/* An event message seen on the bus: 1 when it was this instance's (the
 * value taken), 0 otherwise. */
int ps_dali_input_event(struct ps_dali_input *in, double now, uint32_t frame);
/* A value measured at or after now is wanted: poll at once (after the
 * configuration, if any is still to send) unless one comes first. */
void ps_dali_input_refresh(struct ps_dali_input *in, double now);
/* 1 while a refresh asked for is not yet met. */
int ps_dali_input_refreshing(const struct ps_dali_input *in);
/* Seconds since the value came (INFINITY: none yet). */
double ps_dali_input_age(const struct ps_dali_input *in, double now);
/* The point's value at now: the 10-bit reading, or 1 occupied / 0 vacant.
 * 0 ok; -1 with why: ETIMEDOUT no value yet, ENODEV lost (older than
 * 2 x T_report). */
int ps_dali_input_value(const struct ps_dali_input *in, double now, double *v, int *err, char *why, size_t n);

#endif
