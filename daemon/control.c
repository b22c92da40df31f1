/* SPDX-License-Identifier: ISC */
#include "control.h"

#include <math.h>
#include <stddef.h>

const char *const psd_control_algorithm_names[] = { "setpoint", "closed-proportional", "open-proportional",
                                            "integral-reset", "switching", NULL };

static double clamp(double x, double lo, double hi)
{
	return x < lo ? lo : x > hi ? hi : x;
}

/* switching: one step down (up) after the signal has stayed above s_off
 * (below s_on) for the delay; the deadband s_off - s_on keeps it from cycling */
static double switching(struct psd_control *c, double volts, double now)
{
	int steps = c->steps > 0 ? c->steps : 1;
	int dir = volts > c->s_off ? -1 : volts < c->s_on ? 1 : 0;
	double step = 1.0 / steps, level = c->level;
	if (dir == 0 || (dir < 0 && level <= 0) || (dir > 0 && level >= 1)) {
		c->pending_dir = 0;
		return level;
	}
	if (c->pending_dir != dir) {
		c->pending_dir = dir;
		c->pending_since = now;
	}
	if (now - c->pending_since < c->delay)
		return level;
	c->pending_dir = 0;
	level = step * (round(level / step) + dir);
	return clamp(level, 0.0, 1.0);
}

void psd_control_estimate(struct psd_control *c, double volts)
{
	if (!isfinite(volts))
		return;   /* no reading: the last estimate stands */
	/* the daylight part of the signal: what the offset and the lights do
	 * not explain */
	double day = (volts - c->offset) / c->sensor_gain - c->level * c->elec_sensor;
	if (day < 0)
		day = 0;
	c->daylight_volts = day * c->sensor_gain;
	c->est_task_lux = c->daylight_ratio * day + c->elec_task_lux * c->level;
}

double psd_control_step(struct psd_control *c, double volts, double now)
{
	double want, se = c->sensor_gain * c->elec_sensor;   /* S_E: volts at night, full output */
	double rd = c->sensor_gain / c->daylight_ratio;      /* r_D: daylight volts per task lux */
	double raw = volts;
	/* A reading that is not a number (NaN, Inf) says nothing about the
	 * room: every law holds its last level and its state, and goes on
	 * with the next finite reading.  A level that is not finite (a state
	 * set from outside) is taken as full output, the level a law can
	 * always step down from. */
	if (!isfinite(c->level))
		c->level = 1.0;
	if (!isfinite(volts))
		return c->level;
	psd_control_estimate(c, volts);
	volts -= c->offset;   /* the dark signal, once a night calibration measured it */
	switch (c->algorithm) {
	case PSD_ALG_CLOSED_PROPORTIONAL:
		want = (c->target_lux - volts / rd) / (c->elec_task_lux - se / rd);
		break;
	case PSD_ALG_OPEN_PROPORTIONAL: {
		double full = c->s_full > 0 ? c->s_full : rd * c->target_lux;
		want = 1.0 - volts / full;
		break;
	}
	case PSD_ALG_INTEGRAL_RESET: {
		double set = c->s_set > 0 ? c->s_set : se * c->target_lux / c->elec_task_lux;
		want = c->level + (c->ki > 0 ? c->ki : 1.0) * (set - volts) / se;
		break;
	}
	case PSD_ALG_SWITCHING:
		want = switching(c, raw, now);   /* thresholds are the installer's raw volts */
		c->level = want;
		return want;   /* steps: no minimum dim level, no fade limit */
	case PSD_ALG_SETPOINT:
	default:
		/* the level that brings the estimated task lux to the target */
		want = (c->target_lux - c->daylight_ratio * c->daylight_volts / c->sensor_gain) / c->elec_task_lux;
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
