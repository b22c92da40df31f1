/* SPDX-License-Identifier: ISC */
/* On-site calibration sessions, one per zone, driven by the zone's control
 * steps.
 *
 * night  the lights step through psd_calsession_levels (full, dim levels,
 *        off); at each the sensor's reading is fed to a settling detector,
 *        and the settled mean and its standard error are recorded; then the
 *        night line (offset, electric gain, linearity, the meter's lux per
 *        unit output) is fitted (daemon/calfit.h).
 * day    the lights are held at a level; a sample (volts, task lux) is
 *        taken every cal_day_interval from a task meter, or whenever the
 *        installer types the lux; finish (or cal_day_samples reached) gives
 *        the measured ratio, compared with the simulated ratio of the
 *        condition nearest in time of day.
 *
 * A reading counts only if it was measured after the session's level was
 * commanded, and each measurement counts once.  A sensor that reports by
 * itself (a DALI-2 304: on a change past its hysteresis, else every
 * T_report) may hand up the same value step after step; the session then
 * asks for a fresh one (ask->refresh_sensor: the driver polls at once).  A
 * day sample pairs the meter with a sensor value measured within
 * PSD_CAL_PAIR_SKEW of it, or else with the first measured after the
 * session asked for one, never with a report minutes old.
 *
 * Every sample is committed to the database as it is taken (daemon/db.c),
 * so a session interrupted by a crash or SIGKILL resumes where it was when
 * psensd starts again (psd_calsession_resume).  A fault aborts a session (the
 * engine calls psd_calsession_abort and drives the lights to the safe level
 * as always).  Accepting a finished session makes it the zone's
 * calibration; the one it supersedes stays in the history.
 *
 * A session sees its zone only through struct psd_calsession_ctx, which the
 * engine fills for each call, and never writes into the zone: every call
 * says in struct psd_calsession_ask what it wants done (step the zone now,
 * apply accepted constants), and the engine does it. */
#ifndef PSD_CALSESSION_H
#define PSD_CALSESSION_H

#include <stddef.h>

#include "calfit.h"

struct psd_db;
struct psd_zone_conf;
struct psd_control;
struct ps_results;

enum psd_calsession_kind { PSD_CAL_NONE = 0, PSD_CAL_NIGHT, PSD_CAL_DAY };
enum psd_calsession_state { PSD_CAL_IDLE = 0, PSD_CAL_RUNNING, PSD_CAL_DONE, PSD_CAL_ABORTED, PSD_CAL_ACCEPTED };
enum { PSD_CAL_NLEVELS = 6, PSD_CAL_MAX_DAY = 64 };
/* Seconds on the daemon's clock: a day sample's sensor and meter readings
 * measured further apart than this are not paired as they are; a fresh one
 * is asked for.  Daylight moves a few per cent a minute at most when the
 * sky is steady; a second keeps the pair within a fraction of that. */
#define PSD_CAL_PAIR_SKEW 1.0

extern const double psd_calsession_levels[PSD_CAL_NLEVELS];   /* 1, 0.75, 0.5, 0.25, 0.1, 0 */
extern const char *const psd_calsession_kind_names[];        /* "none", "night", "day", NULL */
extern const char *const psd_calsession_state_names[];       /* "idle", "running", ..., NULL */

/* What a session may know of its zone, filled by the engine for each call. */
struct psd_calsession_ctx {
	const char *zone;                    /* the zone's name: records and messages */
	const struct psd_zone_conf *zc;      /* the cal_* keys; zc->task >= 0: a task meter */
	const struct psd_control *ctl;       /* the constants in force (read only) */
	const struct ps_results *res;        /* the simulated ratios; NULL: none */
	struct psd_db *db;                   /* the records; NULL: sessions are refused */
	const char *config_path;             /* hashed into each session's record */
	double now;                          /* seconds on the daemon's clock */
	/* the simulation's sun ([simulate]): up between sunrise and sunset
	 * (seconds since midnight; sunset <= sunrise: unknown) on date */
	const char *date;
	double sunrise, sunset;
	/* the zone's last good reading and its output then (have_reading 0: none) */
	int have_reading;
	double volts, level;
	double epoch0;                       /* UTC of clock time 0 (NAN: not known): log lines' dates */
	/* when the sensor's reading and the task meter's were measured, on the
	 * daemon's clock: now for a point read anew at each step, earlier for
	 * a value a device reports by itself (a DALI-2 sensor) */
	double volts_t, lux_t;
};

/* Constants an accepted calibration gives the zone's control; NAN (or not
 * above 0 for the gains and ratios) keeps the one in force. */
struct psd_calsession_consts {
	int kind;                 /* enum psd_calsession_kind */
	long long id;             /* the accepted session */
	double offset;            /* night: volts in the dark */
	double sensor_gain;       /* night: volts per unit of sensor response */
	double elec_task_lux;     /* night, with a task meter: lux at full output */
	double daylight_ratio;    /* day: task lux per unit of daylight response */
};

/* What the zone should do after a call; the engine acts on it. */
struct psd_calsession_ask {
	int step_now;             /* step the zone at once, off its schedule */
	int refresh_sensor;       /* ask the sensor's device for a value measured from now on */
	int refresh_task;         /* and the task meter's */
	int napply;               /* constants to apply, in order */
	struct psd_calsession_consts apply[2];
};

/* One zone's session (the engine keeps it in its zone; the socket's status
 * reads it). */
struct psd_calsession {
	int kind, state;          /* enum psd_calsession_kind, psd_calsession_state */
	long long id;             /* the session's row in cal_sessions */
	double started;
	/* night */
	int step;                 /* index into psd_calsession_levels */
	double step_started;
	struct psd_calfit_settle settle;
	double settle_timeout;    /* seconds at one level before it gives up */
	struct psd_calfit_level pt[PSD_CAL_NLEVELS];
	int npt;
	double level_since;       /* when the current level was first commanded (INFINITY: not yet) */
	int commanded;            /* the step (night) whose level was commanded */
	double fed_t;             /* when the last reading fed was measured: each counts once */
	double fed_lux_t;         /* and the last meter reading */
	double asked_at;          /* when fresh readings were last asked for (-INFINITY none pending) */
	double lux_t[PSD_CALFIT_SETTLE_MAX], lux_v[PSD_CALFIT_SETTLE_MAX];   /* the meter at this level */
	int nlux;
	/* day */
	double hold_level;
	double interval, next_sample;
	double last_input;        /* when the last day sample came (or the session began) */
	int want_samples;
	struct psd_calfit_sample ds[PSD_CAL_MAX_DAY];
	int nds;
	double pair_skew;         /* the meter samples' largest time between sensor and meter reading, s (-1 none) */
	double typed_lux, typed_t;/* lux typed at typed_t, waiting for the sensor's reading (NAN none) */
	/* results */
	struct psd_calfit_line night;
	struct psd_calfit_ratio day;
	double sim_ratio;         /* simulated lux per volt of the nearest condition */
	char sim_condition[64];
	double error_pct;         /* 100 (simulated - measured) / measured */
	char msg[384];            /* why it ended, or what it waits for */
	char sun_warning[320];    /* day: the sun in the sensor's view ("" none) */
};

/* Each call fills *ask (cleared first).  Those returning int give -1 with a
 * message in err when the request is refused; the session is then as it
 * was. */

/* At engine open: the zone's accepted calibrations, to apply (ask->apply). */
void psd_calsession_accepted(const struct psd_calsession_ctx *c, struct psd_calsession_ask *ask);
/* Then: resume the zone's session left running, if any (level: the zone's
 * output now, a day session's hold level). */
void psd_calsession_resume(struct psd_calsession *s, const struct psd_calsession_ctx *c, double level,
                           struct psd_calsession_ask *ask);
/* Start a session of a kind; a day session holds the lights at level. */
int psd_calsession_start(struct psd_calsession *s, const struct psd_calsession_ctx *c, int kind, double level,
                         struct psd_calsession_ask *ask, char *err, size_t n);
/* A reading the installer typed (a hand-held meter): it waits for the
 * zone's next reading (ask->step_now; a reporting sensor is polled),
 * measured no earlier than PSD_CAL_PAIR_SKEW before the typing; volts is
 * the zone's last reading, which must be good. */
int psd_calsession_typed_lux(struct psd_calsession *s, const struct psd_calsession_ctx *c, double lux,
                             double volts, double level, struct psd_calsession_ask *ask, char *err, size_t n);
/* End a running day session and fit it. */
int psd_calsession_finish(struct psd_calsession *s, const struct psd_calsession_ctx *c,
                          struct psd_calsession_ask *ask, char *err, size_t n);
/* Accept a finished session: its constants are in ask->apply. */
int psd_calsession_accept(struct psd_calsession *s, const struct psd_calsession_ctx *c,
                          struct psd_calsession_ask *ask, char *err, size_t n);
/* Abort a running session (a fault, a request); -1 when none runs. */
int psd_calsession_abort(struct psd_calsession *s, const struct psd_calsession_ctx *c, const char *why,
                         struct psd_calsession_ask *ask);
/* From a zone's step: 1 and the level to hold while a session runs, else 0. */
int psd_calsession_level(struct psd_calsession *s, double now, double *level);
/* A good reading (volts; lux NAN without a meter) with the lights at level. */
void psd_calsession_feed(struct psd_calsession *s, const struct psd_calsession_ctx *c, double volts, double lux,
                         double level, struct psd_calsession_ask *ask);
/* 1 while a session runs. */
int psd_calsession_running(const struct psd_calsession *s);

#endif
