/* On-site calibration sessions, one zone at a time, driven by the zone's
 * control steps (the engine calls psd_cal_level and psd_cal_feed).
 *
 * night  the lights step through PSD_CAL_LEVELS (full, dim levels, off);
 *        at each the sensor's reading is fed to a settling detector, and
 *        the settled mean and its standard error are recorded; then the
 *        night line (offset, electric gain, linearity, the meter's lux per
 *        unit output) is fitted.
 * day    the lights are held at a level; a sample (volts, task lux) is
 *        taken every `interval` from a task meter, or whenever the
 *        installer types the lux (`calibrate ZONE lux N`); `finish` (or
 *        `samples` reached) gives the measured ratio, compared with the
 *        simulated ratio of the condition nearest in time of day.
 *
 * Every sample is committed to the database as it is taken
 * (daemon/calstore.c), so a session interrupted by a crash or SIGKILL
 * resumes where it was when psensd starts again.  A fault in a session
 * aborts it (the lights go to the safe level as always).  `accept` makes a
 * finished session the zone's calibration: its constants replace the
 * simulated ones, and the one it supersedes stays in the history. */
#ifndef PSD_CALSESSION_H
#define PSD_CALSESSION_H

#include <stddef.h>

#include "calib.h"

enum { PSD_CAL_NONE = 0, PSD_CAL_NIGHT, PSD_CAL_DAY };
enum { PSD_CAL_IDLE = 0, PSD_CAL_RUNNING, PSD_CAL_DONE, PSD_CAL_ABORTED, PSD_CAL_ACCEPTED };
enum { PSD_CAL_NLEVELS = 6, PSD_CAL_MAX_DAY = 64 };

extern const double psd_cal_levels[PSD_CAL_NLEVELS];
extern const char *const psd_cal_kind_names[];    /* "none", "night", "day" */
extern const char *const psd_cal_state_names[];   /* "idle", "running", ... */

struct psd_cal {
	int kind, state;
	long long id;             /* the session's row in cal_sessions */
	double started;
	/* night */
	int step;                 /* index into psd_cal_levels */
	double step_started;
	struct psd_settle settle;
	double settle_timeout;    /* seconds at one level before it gives up */
	struct psd_night_point pt[PSD_CAL_NLEVELS];
	int npt;
	double level_since;       /* when the current level was first commanded (INFINITY: not yet) */
	int commanded;            /* the step (night) whose level was commanded */
	double lux_t[PSD_SETTLE_MAX], lux_v[PSD_SETTLE_MAX];   /* the meter at this level */
	int nlux;
	/* day */
	double hold_level;
	double interval, next_sample;
	int want_samples;
	struct psd_day_sample ds[PSD_CAL_MAX_DAY];
	int nds;
	/* results */
	struct psd_night_fit night;
	struct psd_day_fit day;
	double sim_ratio;         /* simulated lux per volt of the nearest condition */
	char sim_condition[64];
	double error_pct;         /* 100 (simulated - measured) / measured */
	char msg[384];            /* why it ended, or what it waits for */
};

#endif
