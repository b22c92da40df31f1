/* SPDX-License-Identifier: ISC */
/* Steps of the wall clock.  psensd times its periods and timeouts on
 * CLOCK_MONOTONIC (psd_clock), which an NTP step or settimeofday does not
 * move; the dates of what it logs come from the wall clock (CLOCK_REALTIME).
 * This module watches the one against the other: the wall clock minus the
 * monotonic one stays put while both run, and changes by exactly the size of
 * a step.  A change beyond the threshold is a step; smaller ones (NTP's
 * slewing, the two readings' jitter) are not.
 *
 * For the tests only: when the environment variable
 * PSENSD_TEST_WALL_OFFSET names a file, the number of seconds it holds
 * (read at every wall reading) is added to the wall clock, so a test steps
 * psensd's wall clock by writing that file, without root and without
 * touching the host's clock.  Nothing else reads it; psensd(8) says so. */
#ifndef PSD_WALLSTEP_H
#define PSD_WALLSTEP_H

/* psensd's threshold: a change of the wall clock against the monotonic one
 * beyond a second is a step (ntpd and chrony step at 0.128 s and 1 s by
 * default, and slew below; both clocks are slewed alike). */
enum { PSD_WALL_STEP_MS = 1000 };

struct psd_wallstep {
	double offset;            /* wall minus monotonic at the last reference, s */
	double threshold;         /* s: a larger change is a step */
};

/* The wall clock now, UTC seconds (with the tests' offset when set). */
double psd_wallstep_wall(void);
/* Take the current wall-minus-monotonic as the reference. */
void psd_wallstep_init(struct psd_wallstep *w, double threshold);
/* The wall clock's step since the reference, in seconds (positive: it went
 * forward), and the new reference; 0 when it moved less than the
 * threshold. */
double psd_wallstep_check(struct psd_wallstep *w);

#endif
