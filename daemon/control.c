#include "control.h"

#include <math.h>

static double clamp(double x, double lo, double hi)
{
	return x < lo ? lo : x > hi ? hi : x;
}

double psd_control_step(struct psd_control *c, double volts)
{
	double want;
	/* the daylight part of the signal: what the lights do not explain */
	double resp = volts / c->sensor_gain;
	double day = resp - c->level * c->elec_sensor;
	if (day < 0)
		day = 0;
	c->daylight_volts = day * c->sensor_gain;
	c->est_task_lux = c->daylight_ratio * day + c->elec_task_lux * c->level;
	switch (c->algorithm) {
	case PSD_ALG_CLOSED_PROPORTIONAL:
		want = 1.0 - c->k * (volts - c->v_night) / c->v_night;
		break;
	case PSD_ALG_SETPOINT:
	default:
		/* the level that brings the estimated task lux to the target */
		want = (c->target_lux - c->daylight_ratio * day) / c->elec_task_lux;
		break;
	}
	want = clamp(want, c->min_level, 1.0);
	if (c->max_step > 0)
		want = clamp(want, c->level - c->max_step, c->level + c->max_step);
	if (fabs(want - c->level) < c->hysteresis)
		want = c->level;
	c->level = want;
	return want;
}
