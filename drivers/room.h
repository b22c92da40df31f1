/* SPDX-License-Identifier: ISC */
/* The virtual room: a stateful model of one daylit zone, used by the loopback
 * driver and by psvirt.  It knows numbers, not the simulation: the daemon fills
 * struct ps_room_params from the scene's precomputed results.
 *
 *   sensor volts = gain * (daylight_sensor(t) * daylight_scale(t)
 *                          + output(t) * elec_sensor) + offset + noise
 *   task lux     = daylight_task(t) * daylight_scale(t) + output(t) * elec_task_lux
 *
 * output(t) is the ballast model's light output (fraction of full), which
 * follows commands through a fade-rate limit, a minimum level and a
 * first-order lamp lag integrated exactly (stable for any step). */
#ifndef PS_ROOM_H
#define PS_ROOM_H

#include <stddef.h>
#include <stdint.h>

/* One daylight condition at a time of day. */
struct ps_room_daypoint {
	double t;             /* seconds since local midnight */
	double sensor;        /* sensor response to daylight (response units, x gain = volts) */
	double task_lux;      /* task illuminance from daylight, lux */
	double rooftop_lux;   /* global horizontal illuminance outdoors (what a rooftop
	                         sensor reads), lux; NAN when the day carries none */
};

struct ps_ballast_params {
	double fade_rate;     /* max change of commanded level per second (fraction/s); <= 0: instant */
	double min_level;     /* lowest non-zero output (fraction), e.g. 0.01 for DALI, 0.1 for 0-10 V */
	double lag_tau;       /* lamp response time constant, s (may be 1e-3 while the step is 1 s) */
	int off_below_min;    /* command below min_level: 1 = switch off, 0 = clamp to min */
};

enum ps_room_fault {
	PS_ROOM_FAULT_NONE = 0,
	PS_ROOM_FAULT_STUCK,      /* sensor repeats its last value */
	PS_ROOM_FAULT_OPEN,       /* sensor reads 0 V */
	PS_ROOM_FAULT_SATURATED,  /* sensor reads the saturation voltage */
	PS_ROOM_FAULT_DROP,       /* replies are dropped (reads time out) */
	PS_ROOM_FAULT_LATE,       /* replies come late */
	PS_ROOM_FAULT_BALLAST,    /* ballast ignores commands */
	PS_ROOM_FAULT_OBSTRUCT,   /* something covers half the sensor's view of the daylight */
	PS_ROOM_FAULT_COUNT
};

struct ps_room_fault_window {
	int kind;             /* enum ps_room_fault */
	double start, end;    /* seconds on the room's clock (time of day) */
};

struct ps_room_params {
	const struct ps_room_daypoint *daylight;  /* sorted by t; interpolated linearly, */
	size_t ndaylight;                         /* zero before the first and after the last */
	double elec_sensor;   /* sensor response with the lights at full output */
	double elec_task_lux; /* task lux with the lights at full output */
	double gain;          /* volts per response unit */
	double offset;        /* volts */
	double noise;         /* standard deviation of sensor noise, volts */
	double saturation;    /* volts where the sensor clips (e.g. 10) */
	double task_noise;    /* standard deviation of task meter noise, lux */
	uint64_t seed;        /* noise is reproducible */
	struct ps_ballast_params ballast;
	const struct ps_room_fault_window *faults;
	size_t nfaults;
	double late_s;        /* delay of a late reply */
};

/* The model. */
struct ps_room;

/* Copies the arrays; NULL with errno on failure. */
struct ps_room *ps_room_new(const struct ps_room_params *p, double t0);
void ps_room_free(struct ps_room *r);
/* Command the ballast (ignored during a BALLAST fault). */
void ps_room_command(struct ps_room *r, double now, double level);
/* The sensor's volts, with noise; -1 and errno (ETIMEDOUT for a dropped or
 * late reply) during such faults, odd values during sensor faults. */
int ps_room_sensor(struct ps_room *r, double now, double *volts);
/* The task meter's lux, with noise. */
int ps_room_task(struct ps_room *r, double now, double *lux);
/* The rooftop sensor's global horizontal lux (no noise); -1 with errno
 * ENODATA when the day carries no rooftop reading. */
int ps_room_rooftop(struct ps_room *r, double now, double *lux);
/* Light output (fraction of full) now. */
double ps_room_output(struct ps_room *r, double now);
/* Task lux without noise or faults: the truth a summary compares with.
 * Asking does not advance the room (any time, even ahead of its clock). */
double ps_room_true_task_lux(const struct ps_room *r, double now);
/* Everything true at now (driver.h's struct ps_truth), without advancing
 * the room: true task lux, light output, energy since t0, daylight parts. */
struct ps_truth;
void ps_room_truth(const struct ps_room *r, double now, struct ps_truth *t);
/* Daylight parts now: sensor volts and task lux. */
void ps_room_daylight(const struct ps_room *r, double now, double *volts, double *lux);
/* Integral of the light output over time since t0 (fraction x seconds). */
double ps_room_energy(struct ps_room *r, double now);
/* The fault active now (enum ps_room_fault). */
int ps_room_fault(const struct ps_room *r, double now);
/* Seconds since midnight of time now (the room's clock: now modulo a day). */
double ps_room_tod(double now);

#endif
