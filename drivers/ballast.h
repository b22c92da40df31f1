/* SPDX-License-Identifier: ISC */
/* A dimming ballast and its lamp: commands pass through a fade-rate limit and
 * a minimum level, and the light output follows with a first-order lag
 * dy/dt = (f - y) / tau.  Between events the fade target f is linear in time,
 * so the lag has a closed form: the model steps exactly, and stays stable for
 * a tau of a millisecond under a control period of seconds. */
#ifndef PS_BALLAST_H
#define PS_BALLAST_H

#include "room.h"

struct ps_ballast {
	struct ps_ballast_params p;
	double t;            /* time of the state */
	double command;      /* last command (fraction) */
	double fade;         /* fade-limited level f(t) */
	double output;       /* lamp output y(t) */
	double energy;       /* integral of y dt since start (fraction x seconds) */
};

void ps_ballast_init(struct ps_ballast *b, const struct ps_ballast_params *p, double t0,
                     double level);
/* Advance to time t (t >= b->t; earlier is ignored). */
void ps_ballast_advance(struct ps_ballast *b, double t);
/* Command a level at time t (advances first). */
void ps_ballast_command(struct ps_ballast *b, double t, double level);

#endif
