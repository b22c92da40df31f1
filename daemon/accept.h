/* SPDX-License-Identifier: ISC */
/* Acceptance of a zone, from its sample log (a task meter needed): how well
 * the constants in force estimate the measured task lux over a verification
 * window, and functional tests of the kind building codes require of
 * daylight controls (California Title 24 NA7.6.1, IECC C408.3):
 *
 *   verification   the estimate against the meter over the window's good
 *                  samples: rms and worst relative error, the number of
 *                  samples and the daylight levels they span (daylight at
 *                  the task over the target, in bands below 50 %, 50-150 %
 *                  and 150 % and more); PASS when there are at least
 *                  min_samples, at least two bands, rms <= rms_max and worst
 *                  <= worst_max.
 *   full daylight  with daylight at the task at 150 % of the target or
 *                  more, the light output is at most 35 % (power).
 *   low daylight   with daylight below 10 % of the target, the task stays
 *                  at 90 % of the target or more.
 *   cycling        swings of the output (changes of more than swing of full
 *                  output, each against the last one's direction) never
 *                  closer together than the configured delay.
 *   occupancy      only in a zone whose log has occupancy (schema 7) and
 *                  whose occupancy constants are on record, the occupancy
 *                  sensor's functional test (Title 24 NA7.6.2; ASHRAE 90.1
 *                  9.4.1.1): in every vacancy that outlasted the hold, the
 *                  first sample at or after the vacancy plus the hold is at
 *                  the vacant level (the lights reach it within the hold and
 *                  one period); with a vacant level of 0 the lights are on
 *                  (output above 0) at every arrival; and the hold is at
 *                  most the codes' 20 minutes (1200 s).  A vacancy with a
 *                  fault or a session in it is not judged.
 *
 * Daylight at the task is what the meter measures less the electric light:
 * task_lux - elec_task_lux x output, at the output of the step before (the
 * one the lights were at when the sample's readings were taken; the
 * sample's own output is the control's answer to them).  While a
 * calibration session held the lights (its span in cal_sessions) and for
 * settle_s after it ended (the lamps fading from the session's level to
 * the control's: readings and estimate then belong to different levels)
 * no sample counts for any test: the session judges the sensor, these tests
 * the control; cycling starts again after it.  The verification says how
 * many samples it left out so.  Samples the occupancy input said vacant
 * (schema 7) count for none of the first four tests either: the lights
 * are the vacancy's, not the daylight control's; the verification says
 * how many.  The commissioning record shows this same
 * verification (psd_accept_verification).  A test with no sample in its
 * range is NOT TESTED, never a pass.  Each result says what it measured. */
#ifndef PSD_ACCEPT_H
#define PSD_ACCEPT_H

#include <stddef.h>

struct psd_db;

/* the most tests a zone gets: the occupancy test only where it applies (a
 * result's test is NULL where it does not) */
enum { PSD_ACCEPT_NTESTS = 5 };
/* codes' longest hold of an occupancy sensor, s (20 min) */
#define PSD_ACCEPT_HOLD_MAX_S 1200.0
/* s after a calibration session ended that no test judges (the lamps fade
 * from the session's level to the control's); psensd's summary leaves the
 * same span out */
#define PSD_ACCEPT_SETTLE_S 60.0
enum psd_accept_verdict { PSD_ACCEPT_NOT_TESTED = -1, PSD_ACCEPT_FAIL = 0, PSD_ACCEPT_PASS = 1 };

struct psd_accept_params {
	double target_lux;        /* the zone's design task illuminance */
	double elec_task_lux;     /* task lux at full electric output */
	double delay;             /* s: the fastest cycling allowed */
	double since_utc;         /* the window: samples from this UTC on (NAN: all) */
	double rms_max, worst_max;/* verification limits, % (10, 25) */
	long min_samples;         /* verification: at least this many (30) */
	double swing;             /* cycling: a change this large (fraction of full output, 0.05) */
	double settle_s;          /* s after a calibration session not judged (60) */
	double vacancy_hold;      /* occupancy: the zone's hold, s (NAN: no occupancy on record) */
	double vacant_level;      /* occupancy: the zone's vacant level */
};

struct psd_accept_result {
	const char *test;         /* "verification", "full daylight", "low daylight", "cycling",
	                             "occupancy"; NULL: the test does not apply to the zone */
	int verdict;              /* enum psd_accept_verdict */
	double value, limit;      /* the measured figure and its limit */
	const char *unit;         /* theirs: "%" or "s" */
	const char *bound;        /* how the value must meet the limit: "at most", "at least",
	                             "by the first step after" (occupancy: the hold) */
	long samples;             /* samples judged */
	long left_out;            /* verification: samples of sessions and their settling not judged */
	double settle_s;          /* verification: the settling time after a session, s */
	char measured[400];       /* what was measured, in words */
};

/* Defaults for what the caller does not set. */
void psd_accept_defaults(struct psd_accept_params *p);
/* Run every test on zone's samples in db.  -1 with a message in err. */
int psd_accept_run(struct psd_db *db, const char *zone, const struct psd_accept_params *p,
                   struct psd_accept_result out[PSD_ACCEPT_NTESTS], char *err, size_t errlen);
extern const char *const psd_accept_verdict_names[];   /* indexed by verdict + 1 */

/* The verification alone, as psensctl accept-test runs it with its
 * defaults (the zone's design constants from db): what the commissioning
 * record shows.  -1 with a message in err (the zone is not on record). */
int psd_accept_verification(struct psd_db *db, const char *zone, struct psd_accept_result *r, char *err,
                            size_t errlen);

/* The outcome of a whole run. */
struct psd_accept_summary {
	int count;                /* the tests that apply to the zone (4, or 5 with occupancy) */
	int tested, failed;       /* tests run (not NOT TESTED), and failed */
	int unstored;             /* the results are in out but could not be stored */
};
/* The acceptance of a zone as psensctl -d and psensd's control socket run
 * it: the zone's design constants from db (psensd records them when it
 * starts) into p, every test, and each result stored as run at utc (epoch
 * s).  -1 with a message in err: the zone is not on record, the log could
 * not be read, or (sum->unstored) the results could not be stored. */
int psd_accept_zone(struct psd_db *db, const char *zone, struct psd_accept_params *p, double utc,
                    struct psd_accept_result out[PSD_ACCEPT_NTESTS], struct psd_accept_summary *sum, char *err,
                    size_t errlen);
/* One option of accept-test (psensctl's and the control socket's): 1 when
 * opt is --since DATE or --samples N and val is good (p set), 0 when opt
 * is neither, -1 with a message in err when val is bad. */
int psd_accept_option(struct psd_accept_params *p, const char *opt, const char *val, char *err, size_t errlen);
/* The tests run and failed of a run's results. */
void psd_accept_summarize(const struct psd_accept_result r[PSD_ACCEPT_NTESTS], struct psd_accept_summary *sum);
/* "ACCEPTED" (every test run, none failed), "NOT ACCEPTED" (one failed) or
 * "INCOMPLETE" (one not run). */
const char *psd_accept_overall(const struct psd_accept_summary *sum);

#endif
