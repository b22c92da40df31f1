/* SPDX-License-Identifier: ISC */
#include "occupancy.h"

#include <math.h>

void psd_occupancy_init(struct psd_occupancy *o, double hold, double vacant_level, double now)
{
	*o = (struct psd_occupancy){ .hold = hold, .vacant_level = vacant_level, .input = -1,
		                     .vacant_since = now, .t_last = NAN, .acc_state = 1 };
}

int psd_occupancy_report(struct psd_occupancy *o, double now, int occupied)
{
	int was = o->input;
	o->input = occupied ? 1 : 0;
	if (was == o->input)
		return 0;
	if (!occupied) {
		o->vacant_since = now;
		return -1;
	}
	return was == 0 ? 1 : 0;   /* the first report, occupied, is no arrival */
}

int psd_occupancy_ends_override(const struct psd_occupancy *o, int change, double override_level)
{
	return change > 0 && override_level <= o->vacant_level;
}

int psd_occupancy_fault(struct psd_occupancy *o, double now, int fault)
{
	fault = fault != 0;
	if (o->fault == fault)
		return 0;
	o->fault = fault;
	if (!fault)
		o->vacant_since = now;
	return 1;
}

int psd_occupancy_occupied(const struct psd_occupancy *o)
{
	return o->fault || o->input != 0;
}

int psd_occupancy_vacant(const struct psd_occupancy *o, double now)
{
	return !psd_occupancy_occupied(o) && now - o->vacant_since >= o->hold;
}

int psd_occupancy_rule(const struct psd_occupancy *o, double now, int override_on, double override_level,
                       int *drop)
{
	int vacant = psd_occupancy_vacant(o, now);
	*drop = 0;
	if (override_on) {
		if (!vacant || override_level <= o->vacant_level)
			return PSD_OCC_OVERRIDE;   /* a manual off (or one at or below the vacant level) holds */
		*drop = 1;
	}
	return vacant ? PSD_OCC_VACANT : PSD_OCC_DAYLIGHT;
}

void psd_occupancy_account(struct psd_occupancy *o, double now, double daylight_level, double level)
{
	if (isfinite(o->t_last) && now > o->t_last) {
		double dt = now - o->t_last;
		if (o->acc_state == 1)
			o->occupied_s += dt;
		else
			o->vacant_s += dt;
		if (o->acc_state == 2) {
			o->held_s += dt;
			o->saved += o->acc_rate * dt;
		}
	}
	if (!isfinite(o->t_last) || now > o->t_last)
		o->t_last = now;
	o->acc_state = psd_occupancy_vacant(o, now) ? 2 : psd_occupancy_occupied(o);
	o->acc_rate = 0;
	if (o->acc_state == 2 && isfinite(daylight_level) && isfinite(level) && daylight_level > level)
		o->acc_rate = daylight_level - level;
}
