/* SPDX-License-Identifier: ISC */
/* A zone's occupancy: the state machine between its occupancy inputs and
 * the lights, a pure function of the reports, the input's faults and time
 * (doc/control.md, "Occupancy"), so that each transition is tested alone.
 *
 *  - Occupied: the daylight control runs as without an input.
 *  - Vacant: the daylight control runs on for the hold time (vacancy_hold,
 *    the energy codes' "automatic off within 20 minutes" with a margin:
 *    900 s by default), then the lights go to the vacant level (vacant_level,
 *    0: off; a level above 0 is a partial off, which ASHRAE 90.1 allows down
 *    to half the power or less).  Occupied again: the daylight control at
 *    once.
 *  - A manual off (an override at or below the vacant level: psensctl off,
 *    an override at 0 %) holds while the room stays occupied and through its
 *    vacancy; it ends at the next change from vacant to occupied (the next
 *    people to come in get their light back: no "manual on" is asked of
 *    them), at release, or at the end of its time.
 *  - An override above the vacant level ends when the hold of a vacancy ends:
 *    no switch defeats the automatic off.
 *  - An input that cannot be read (or none reported yet) counts as occupied:
 *    the lights stay under the daylight control, safe for the people in the
 *    room; the engine logs the fault and its end. */
#ifndef PSD_OCCUPANCY_H
#define PSD_OCCUPANCY_H

struct psd_occupancy {
	double hold;          /* s vacant before the vacant level */
	double vacant_level;  /* light output when vacant for the hold, 0 to 1 */
	int input;            /* the inputs' last report: 1 occupied, 0 vacant, -1 none yet */
	int fault;            /* an input cannot be read: counted as occupied */
	double vacant_since;  /* when the report last went from occupied to vacant */
	/* the hours, for the summary: occupied (a fault counted in), vacant,
	 * and of the vacant the time at the vacant level; the light output
	 * the vacancy saved (full-output seconds) */
	double t_last;        /* accounted up to here (NAN: not yet) */
	int acc_state;        /* since t_last: 1 occupied, 0 vacant, 2 at the vacant level */
	double acc_rate;      /* since t_last: the output saved per second */
	double occupied_s, vacant_s, held_s, saved;
};

/* What rules the lights at a step (psd_occupancy_rule). */
enum psd_occ_rule {
	PSD_OCC_DAYLIGHT = 0,   /* the daylight control (occupied, or within the hold) */
	PSD_OCC_OVERRIDE,       /* the override in force */
	PSD_OCC_VACANT,         /* vacant for the hold: the vacant level */
};

/* No report yet (occupied), at time now. */
void psd_occupancy_init(struct psd_occupancy *o, double hold, double vacant_level, double now);
/* The inputs report occupied (1) or vacant (0) at now.  Returns 1 on a
 * change from vacant to occupied (a manual off ends there), -1 on a change
 * to vacant, 0 when nothing changed. */
int psd_occupancy_report(struct psd_occupancy *o, double now, int occupied);
/* 1 when an override at override_level ends at a report's change
 * (psd_occupancy_report's return): a manual off at the next arrival. */
int psd_occupancy_ends_override(const struct psd_occupancy *o, int change, double override_level);
/* An input read failed (1) or reads again (0) at now.  Returns 1 when the
 * fault state changed (the engine logs it).  At the fault's end a vacant
 * room's hold starts again: nobody knows who came and went meanwhile. */
int psd_occupancy_fault(struct psd_occupancy *o, double now, int fault);
/* 1 occupied (a fault or no report yet counted so), 0 vacant. */
int psd_occupancy_occupied(const struct psd_occupancy *o);
/* 1 when vacant for the hold at now (the vacant level applies). */
int psd_occupancy_vacant(const struct psd_occupancy *o, double now);
/* What rules the lights at now, given the override in force (override_on)
 * at override_level; *drop is set to 1 when the override ends here (an
 * override above the vacant level at the end of the hold). */
int psd_occupancy_rule(const struct psd_occupancy *o, double now, int override_on, double override_level,
                       int *drop);
/* Count the time since the last call by the state the last call found,
 * then take the state at now: occupied, vacant, or at the vacant level with
 * the output saved there (daylight_level, what the daylight control asks,
 * less level, the output commanded, from now to the next call). */
void psd_occupancy_account(struct psd_occupancy *o, double now, double daylight_level, double level);

#endif
