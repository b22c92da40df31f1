/* Control laws: pure functions of a reading and their state, so each is
 * tested alone (psensd.conf(5) documents the constants). */
#ifndef PSD_CONTROL_H
#define PSD_CONTROL_H

enum psd_algorithm { PSD_ALG_SETPOINT = 0, PSD_ALG_CLOSED_PROPORTIONAL, PSD_ALG_COUNT };

struct psd_control {
	int algorithm;
	double target_lux;       /* wanted task illuminance */
	double min_level;        /* lowest dim level (0 to 1) */
	double max_step;         /* largest change per control period (fade limit) */
	double hysteresis;       /* ignore changes smaller than this (fraction) */
	/* the model, from the scene's results and the sensor's gain */
	double sensor_gain;      /* volts per unit of sensor response */
	double daylight_ratio;   /* task lux per unit of daylight sensor response */
	double elec_sensor;      /* sensor response at full electric output */
	double elec_task_lux;    /* task lux at full electric output */
	/* closed-loop proportional: output = 1 - k (volts - v_night) / v_night */
	double k;
	double v_night;          /* volts at night with the lights full (night calibration) */
	/* state */
	double level;            /* last commanded level */
	double est_task_lux;     /* the last estimate of the task illuminance */
	double daylight_volts;   /* the daylight part of the last reading */
};

/* Next level from a sensor reading (volts) with the lights at level c->level. */
double psd_control_step(struct psd_control *c, double volts);

#endif
