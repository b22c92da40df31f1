/* SPDX-License-Identifier: ISC */
/* The daemon's clock: one type for real time and for a simulated day, so the
 * tests run a day in seconds through the same event loop and control code.
 *
 * Time is seconds on the room's clock: the time of day at which the clock
 * started plus the time elapsed since.  Real time follows CLOCK_MONOTONIC
 * (never jumps with NTP or DST), optionally sped up; simulated time jumps
 * straight to the next deadline. */
#ifndef PSD_CLOCK_H
#define PSD_CLOCK_H

#include <stddef.h>
#include <time.h>

struct psd_clock {
	int simulated;
	double origin;            /* clock value at start (seconds since local midnight) */
	double speed;             /* real: clock seconds per wall second */
	double mono0;             /* real: psd_time_mono() at start */
	double now;               /* simulated: the current time */
	double epoch0;            /* UTC (epoch seconds) of clock time 0: the local
	                             midnight of the run's first day (NAN: not known) */
};

void psd_clock_real(struct psd_clock *c, double origin, double speed);
void psd_clock_simulated(struct psd_clock *c, double origin);
double psd_clock_now(struct psd_clock *c);
/* Milliseconds poll() should wait for deadline: 0 when simulated or past,
 * -1 for an infinite deadline, at most max_ms. */
int psd_clock_wait_ms(struct psd_clock *c, double deadline, int max_ms);
/* Simulated: move to deadline (never back).  Real: nothing. */
void psd_clock_advance(struct psd_clock *c, double deadline);
/* Seconds since local midnight now, from the wall clock. */
double psd_clock_local_tod(void);
/* Time of day of a clock time t: seconds since midnight (t modulo a day). */
double psd_clock_tod(double t);
/* How far local time is ahead of standard time at utc (epoch seconds):
 * 3600 in summer time in most zones, 0 in winter, with no date (NAN) or
 * in a zone without summer time.  The weather's hours, the results' year
 * and the dated ratio table are in standard time; the clock is local. */
double psd_clock_dst_shift(double utc);
/* The same at noon of a run's day: the local midnight midnight_utc, or
 * when that is NAN (a run's date not yet set) the date "MM-DD" this year;
 * 0 when neither is a date. */
double psd_clock_dst_shift_day(const char *mmdd, double midnight_utc);
/* "HH:MM" of a clock time t. */
void psd_clock_hhmm(double t, char out[8]);
/* UTC of the local midnight that starts a date; -1 when it is no date. */
int psd_clock_midnight(int year, int month, int day, double *epoch);
/* Parse "YYYY-MM-DD" into its midnight (psd_clock_midnight); -1 if not one. */
int psd_clock_parse_date(const char *s, double *epoch);
/* The local "YYYY-MM-DD HH:MM" of clock time t on a clock whose time 0 is
 * epoch0 ("HH:MM" when epoch0 is NAN); out at least 20 bytes. */
void psd_clock_stamp(double epoch0, double t, char *out, size_t n);
/* A duration in seconds as "3 h 58 min" (or "12 min", "45 s"). */
void psd_clock_duration(double s, char *out, size_t n);

#endif
