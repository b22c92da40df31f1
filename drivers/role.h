/* SPDX-License-Identifier: ISC */
/* A point's role: what its value means to the daemon (a photosensor's volts,
 * a task meter's lux, a dimming output ...), and the roles' names as the
 * configuration file writes them. */
#ifndef PS_ROLE_H
#define PS_ROLE_H

enum ps_role {
	PS_ROLE_SENSOR = 0,   /* photosensor signal, volts */
	PS_ROLE_TASK_LUX,     /* task illuminance meter, lux */
	PS_ROLE_DIM,          /* dimming output, light-output fraction 0..1 */
	PS_ROLE_RELAY,        /* switched output, 0 or 1 (a step of a stepped system) */
	PS_ROLE_INPUT,        /* button or occupancy input, 0 or 1, reported as events */
	PS_ROLE_ROOFTOP,      /* outdoor global horizontal illuminance, lux (the live
	                         estimate's sky class; not a control input) */
	PS_ROLE_COUNT
};

/* Role names as used in the config file ("sensor", "task", "dim", "relay", "input", "rooftop"). */
const char *ps_role_name(int role);
int ps_role_parse(const char *name);   /* -1 if unknown */

#endif
