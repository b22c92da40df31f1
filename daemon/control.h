/* SPDX-License-Identifier: ISC */
/* Control laws: pure functions of a reading and their state, so each is
 * tested alone (psensd.conf(5) documents the constants).  Notation (the
 * literature's; doc/control.md): u the light output (0..1), S the
 * sensor's volts, S_E the night signal at full output, E_E the electric task
 * lux at full output, r_D the daylight volts per task lux. */
#ifndef PSD_CONTROL_H
#define PSD_CONTROL_H

enum psd_algorithm {
	PSD_ALG_SETPOINT = 0,        /* the simulated ratios: estimate the task lux, hold the target */
	PSD_ALG_CLOSED_PROPORTIONAL, /* u = (E_t - S/r_D) / (E_E - S_E/r_D): two calibrations */
	PSD_ALG_OPEN_PROPORTIONAL,   /* u = 1 - S/S_full: the sensor sees daylight only */
	PSD_ALG_INTEGRAL_RESET,      /* drive u until S = S_set */
	PSD_ALG_SWITCHING,           /* steps down above s_off, up below s_on, after a delay */
	PSD_ALG_COUNT
};

extern const char *const psd_control_algorithm_names[];   /* config names, NULL-terminated */

struct psd_control {
	int algorithm;
	double target_lux;       /* wanted task illuminance */
	double min_level;        /* lowest dim level (0 to 1) */
	double max_step;         /* largest change per control period (fade limit), 0: none */
	double hysteresis;       /* ignore changes smaller than this (fraction) */
	/* the model, from the scene's results and the sensor's gain */
	double sensor_gain;      /* volts per unit of sensor response */
	double offset;           /* the sensor's volts in the dark (a night calibration) */
	double daylight_ratio;   /* task lux per unit of daylight sensor response */
	double elec_sensor;      /* sensor response at full electric output */
	double elec_task_lux;    /* task lux at full electric output */
	/* open-loop proportional: volts at which daylight alone meets the target (0: from the model) */
	double s_full;
	/* integral reset: the maintained signal (0: night signal at the design level) and the gain */
	double s_set, ki;
	/* switching: thresholds (volts), hold time (s), number of steps (1 = on/off) */
	double s_off, s_on, delay;
	int steps;
	/* state */
	double level;            /* last commanded level */
	double est_task_lux;     /* the last estimate of the task illuminance */
	double daylight_volts;   /* the daylight part of the last reading */
	double pending_since;    /* switching: when the threshold was first crossed (-1: not) */
	int pending_dir;         /* switching: -1 down, +1 up, 0 none */
};

/* The estimate alone from a reading (volts), the lights being at c->level:
 * daylight_volts and est_task_lux, which psd_control_step also sets.  For
 * the steps where something else holds the lights (a calibration session),
 * so that the logged estimate follows the room. */
void psd_control_estimate(struct psd_control *c, double volts);
/* Next level from a reading (volts) at time now (seconds), the lights being
 * at c->level since the last step.  A reading that is not finite changes
 * nothing: the last level is returned and the next finite reading goes on
 * from it (psd_control_estimate ignores it likewise). */
double psd_control_step(struct psd_control *c, double volts, double now);

#endif
