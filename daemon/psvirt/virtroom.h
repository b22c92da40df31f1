/* SPDX-License-Identifier: ISC */
/* One zone's virtual room for psvirt: the loopback room psensd -s runs,
 * opened through the driver registry and built from the scene's results as
 * psensd builds it (roomsetup.h, the table's setup hook), with the loopback
 * device's own options (psensd.conf(5): gain, noise, ballast, faults,
 * replay).
 *
 * This file is all psvirt knows of the room: create it, read the sensor and
 * the task meter, command the ballast, ask the truth (output, true lux,
 * energy, the fault it plays) through the table's truth hook.  Everything
 * else in psvirt is Modbus. */
#ifndef PSD_VIRTROOM_H
#define PSD_VIRTROOM_H

#include <stddef.h>

#include "driver.h"
#include "results.h"

struct psd_virtroom;

/* The day every zone plays: the results and the date, sunrise and sunset. */
struct psd_virtday {
	const struct ps_results *res;
	const char *date;              /* "MM-DD" */
	double sunrise, sunset;        /* seconds since midnight */
	int year;                      /* 1: the date from the results' year ([simulate] year) */
};

/* What the room does with a request now (its drop and late faults). */
enum { PSD_VIRTROOM_ANSWER, PSD_VIRTROOM_DROP, PSD_VIRTROOM_LATE };
/* The sensor's state beside its volts (the room's open and saturated faults). */
enum { PSD_VIRTROOM_OPEN = 1, PSD_VIRTROOM_SATURATED = 2 };

/* Check options as a loopback device's: 0, or -1 with "FILE:LINE: why" in
 * err.  Marks the keys it knows as used (struct ps_opt.used): a key left
 * unused is not a room option. */
int psd_virtroom_check(const struct ps_opts *opts, char *err, size_t n);
/* A room for the day with these options (checked as above), its clock at
 * start (seconds on the room's clock); NULL with the reason in err. */
struct psd_virtroom *psd_virtroom_new(const struct psd_virtday *day, const struct ps_opts *opts,
                                      double start, char *err, size_t n);
void psd_virtroom_free(struct psd_virtroom *r);

/* PSD_VIRTROOM_ANSWER, _DROP or _LATE for a request now. */
int psd_virtroom_comms(const struct psd_virtroom *r, double now);
/* The sensor's volts now and its state (PSD_VIRTROOM_OPEN, _SATURATED);
 * -1 when the sensor has no reading (dropped or late). */
int psd_virtroom_sensor(struct psd_virtroom *r, double now, double *volts, int *state);
/* The task meter's lux now (with its noise). */
double psd_virtroom_task(struct psd_virtroom *r, double now);
/* Command the ballast: light output 0..1. */
void psd_virtroom_command(struct psd_virtroom *r, double now, double level);
/* The truth: light output now (0..1), task lux without noise or faults,
 * and the integral of the output since the start (fraction x seconds). */
double psd_virtroom_output(struct psd_virtroom *r, double now);
double psd_virtroom_truth(struct psd_virtroom *r, double now);
/* The rooftop's global horizontal lux of the hour the room plays ([simulate]
 * year = yes), 0 when its day carries none (the clear-sky profile). */
double psd_virtroom_rooftop(struct psd_virtroom *r, double now);
double psd_virtroom_energy(struct psd_virtroom *r, double now);
/* Seconds since midnight on the room's clock. */
double psd_virtroom_tod(double now);

#endif
