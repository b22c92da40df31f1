/* SPDX-License-Identifier: ISC */
/* psvirt's rooms as a DALI bus (psvirt(1), DALI BUS): the bus (dalibus.h)
 * and its interfaces (daliserve.h) joined to the zones' rooms (virtroom.h).
 * Each turn the rooms' sensor signals (1023 = 10 V) and the occupancy
 * schedule feed the multisensors, the traffic is served, and each zone's
 * gear's arc power commands its room's ballast. */
#ifndef PSD_VIRTDALI_H
#define PSD_VIRTDALI_H

#include <stddef.h>

#include "dalibus.h"
#include "daliserve.h"
#include "virtmap.h"
#include "virtroom.h"

enum { PSD_VIRTDALI_MAX_OCC = 8 };

struct psd_virtdali_opts {
	const char *tcp;        /* ADDR:PORT, or NULL */
	const char *pty;        /* the file for the pty's path, or NULL */
	int protocol;           /* the pty's: PSD_DALISERVE_FOXTRON or _ATX */
	int gear;               /* per zone */
	int unaddressed;
	const char *occupancy;  /* "always", "never" or HH:MM-HH:MM,... */
	int trace;
};

struct psd_virtdali {
	struct psd_dalibus bus;
	struct psd_daliserve *serve;
	struct psd_virtroom *room[PSD_VIRT_MAX_ZONES];   /* owned by the caller */
	int nzone, power_on, nocc;
	double occ[PSD_VIRTDALI_MAX_OCC][2];   /* occupied from, to (seconds of the day) */
	double out[PSD_VIRT_MAX_ZONES];        /* the output each room was last given */
	double sensed;                         /* when the inputs were last set */
	double start, speed, t0;               /* the rooms' clock: start + speed (mono - t0), set by the caller */
};

/* Check an occupancy schedule: 0, or -1 after saying why. */
int psd_virtdali_occupancy(struct psd_virtdali *d, const char *spec);
/* The bus for nzone rooms and its interfaces; "dali-tcp PORT" and
 * "dali-pty PATH" appended to where (a line each).  0, or -1 after saying
 * why (then psd_virtdali_free). */
int psd_virtdali_open(struct psd_virtdali *d, const struct psd_virtdali_opts *o, struct psd_virtroom *const *room,
                      int nzone, char *where, size_t wlen);
/* One turn: the fault (dalibus.h) and its target; wait at most max_wait
 * seconds for traffic.  0, or -1 when poll failed. */
int psd_virtdali_turn(struct psd_virtdali *d, int fault, int target, double max_wait);
void psd_virtdali_free(struct psd_virtdali *d);

#endif
