/* SPDX-License-Identifier: ISC */
/* The running control: the configuration's devices opened, their points
 * attached, and per zone the control state, its faults and its statistics.
 * It does no waiting and reads no clock but the monotonic one it hands the
 * drivers for their wire timing (drivers/driver.h): the event loop (daemon/loop.c)
 * hands it `now` and asks for its next deadline, so a simulated day and
 * real time run the same code. */
#ifndef PSD_ENGINE_H
#define PSD_ENGINE_H

#include <poll.h>
#include <stddef.h>

#include "calsession.h"
#include "config.h"
#include "control.h"
#include "db.h"
#include "dbwriter.h"
#include "devio.h"
#include "driver.h"
#include "occupancy.h"
#include "results.h"

/* What a simulated zone's truth says about the control, for the summary. */
struct psd_zone_stats {
	double samples, below, worst_lux, fault_steps;
	double err_sum, err2_sum, err_max, err_n;
	double energy0;           /* the room's energy when this engine started the zone */
	double energy_last;       /* the room's energy at the zone's last step */
	double energy_prior;      /* energy used under the engines a reload replaced */
	double since;             /* when the statistics began (kept across reloads) */
	/* calibration sessions: the periods they held the lights and the
	 * settling after each (PSD_ACCEPT_SETTLE_S) are counted here, not in
	 * below nor the estimate's errors; the first PSD_STATS_MAX_CAL spans */
	double cal_steps, cal_until;
	double vacant_steps;      /* periods a zone's occupancy input said vacant:
	                             not counted in below nor the estimate's errors */
	double cal_from[8], cal_to[8];
	int ncal, in_cal;
};
enum { PSD_STATS_MAX_CAL = 8 };
/* The energy a zone used since its statistics began (full-output seconds),
 * given the room's energy now. */
double psd_engine_zone_energy(const struct psd_zone_stats *s, double energy_now);

/* One control step as it happened, every value of the same moment (what
 * status and watch show): the reading, the estimate made from it at the
 * level the lights had, and the level the step then commanded. */
struct psd_zone_sample {
	double t;                 /* clock seconds; NAN before the first step */
	double level;             /* the output while the sensor was read */
	double volts, daylight_v; /* the reading, its daylight part */
	double est_task_lux;      /* estimated from this reading (NAN in a fault) */
	double task_lux;          /* the task meter at this step (NAN: none) */
	double true_task_lux;     /* the simulated room's truth at t (NAN: a real room) */
	int occupied;             /* the occupancy at t: -1 no input, 0 vacant, 1 occupied */
	double commanded;         /* the level this step commanded */
	int fault;                /* the step ended in a fault */
};

struct psd_zone {
	const struct psd_zone_conf *zc;
	struct psd_control ctl;
	double next;              /* time of the next control step */
	int asap;                 /* an event wants a step now, off the schedule */
	int waiting;              /* its reads are asked of I/O threads (devio.h): the step
	                             completes when they answer or at the next step */
	double wait_since;
	double started;
	int in_fault;             /* at the safe level */
	char why[256];            /* the fault, when in_fault */
	int unsafe;               /* the safe level could not be commanded (logged once) */
	double last_ok;           /* time of the last good reading */
	double last_volts, same_since;  /* stuck detection */
	double volts, task_lux;   /* last readings (NAN if none) */
	double volts_t, task_t;   /* when they were measured, on the clock (calsession.h) */
	double level;             /* last commanded output */
	double override_level, override_until;   /* override: level until a time */
	int daylight_off;         /* daylight control off: the level that meets the target
	                             without daylight (psd_engine_set_daylighting) */
	/* occupancy (daemon/occupancy.h): the zone's state machine, each input's
	 * last report (-1 none yet), its last good read and its fault */
	int occupancy;            /* -1 no occupancy input, 0 vacant, 1 occupied (a
	                             fault counted occupied): psd_engine_zone_occupied */
	struct psd_occupancy occ;
	int occ_in[PSD_MAX_ZONE_OUT];
	double occ_ok[PSD_MAX_ZONE_OUT];
	int occ_bad[PSD_MAX_ZONE_OUT];
	char occ_why[256];        /* the input's fault, when occ.fault */
	double verify_at;         /* when the dim points should show `level` */
	unsigned long steps, fault_steps;
	struct ps_dev *sim;       /* the sensor's device when it is simulated (has a truth hook) */
	const struct ps_results *res;  /* the zone's simulation: its own results or the engine's
	                                  (NULL: none) */
	struct psd_calsession cal;     /* the calibration session (daemon/calsession.c) */
	struct psd_calfit_drift drift; /* measured against simulated ratio, with a task meter */
	long long cal_night_id, cal_day_id;   /* the accepted calibrations in force, 0: none */
	int sky_class;            /* the rooftop sensor's sky class this step, -1: none
	                             (the typical class is used) */
	int rooftop_failed;       /* a rooftop read failed (logged once until it reads again) */
	struct psd_zone_stats st;
	struct psd_zone_sample last;   /* the last step */
};

struct psd_engine {
	struct psd_config *cf;    /* owned: freed by psd_engine_close */
	struct ps_dev dev[PSD_MAX_DEVICES];
	int dev_open[PSD_MAX_DEVICES];
	struct ps_point pt[PSD_MAX_POINTS];
	double full_scale[PSD_MAX_POINTS];  /* a sensor's full scale from its driver, NAN or 0: none */
	struct psd_zone zone[PSD_MAX_ZONES];
	size_t nzone;
	struct ps_results res;    /* [psensd]'s results */
	int have_res;
	struct ps_results zres[PSD_MAX_ZONES];   /* zone i's own results (zone results = / scene =) */
	int have_zres[PSD_MAX_ZONES];
	int month;                /* the dated estimate's month (dated.h), 1-12 */
	int doy;                  /* and day of the year, for a rooftop sensor's sun */
	struct psd_db *db;        /* the control thread's connection: reads, calibration records */
	struct psd_dbwriter *log; /* the samples' and events' writer thread (dbwriter.h) */
	int log_borrowed;         /* log is prev's (a reload) until the open succeeds */
	int db_batch;             /* samples per transaction (1 in real time) */
	unsigned long logged;     /* samples committed to the database */
	unsigned long logged_base;/* committed by the engines this one replaced */
	unsigned long log_errors;
	double lat_max, lat_sum;  /* reading-to-command latency, wall seconds */
	unsigned long lat_n;
	double late_max;          /* worst lateness of a step against its schedule, clock s */
	struct psd_devio *io[PSD_MAX_DEVICES];   /* a device's I/O thread, NULL: called in the loop */
	char ioerr[256];          /* the message of the last failed point read or write */
	double utc0;              /* Unix time of clock 0 (its day's local midnight); NAN: unknown; dates in the log */
	double speed;             /* clock seconds per monotonic second (psensd -x; 1 simulated): a reading's age */
};

/* Open cf's devices and points at time now and prepare the zones (cf is then
 * the engine's).  prev, when given, is the engine being replaced: zones of
 * the same name keep their level and override.  -1 with a message in err;
 * the engine is then closed and cf is still the caller's. */
int psd_engine_open(struct psd_engine *e, struct psd_config *cf, double now, int db_batch,
                    const struct psd_engine *prev, char *err, size_t errlen);
/* The UTC of clock time 0 (the local midnight of the run's first day):
 * every row the engine logs from now on carries its date, and its log
 * lines the date and time. */
void psd_engine_set_epoch(struct psd_engine *e, double epoch0);
/* Local "YYYY-MM-DD HH:MM" of clock time t ("HH:MM" with no epoch). */
void psd_engine_stamp(const struct psd_engine *e, double t, char *out, size_t n);
/* The same, and in real time (clock not simulated, not NULL) the I/O
 * threads started before the first commands: each device with blocking
 * I/O (psd_devio_wanted) gets its I/O thread, which reads clock (a copy).
 * Until then, and in a simulated day, the loop calls the drivers itself.  A
 * thread that cannot start leaves its device called in the loop (logged). */
int psd_engine_open_io(struct psd_engine *e, struct psd_config *cf, double now, int db_batch,
                       const struct psd_engine *prev, const struct psd_clock *clock, char *err, size_t errlen);
/* Run every zone whose step is due at now. */
void psd_engine_step(struct psd_engine *e, double now);
/* The next time something is due: a zone's step or a driver's deadline, on
 * the daemon's clock; *mono gets the earliest driver deadline on the
 * monotonic clock (INFINITY: none). */
double psd_engine_deadline(const struct psd_engine *e, double *mono);
/* Driver descriptors for poll(): fills up to max, returns the count; fd_dev
 * gets the device index of each. */
int psd_engine_pollfds(struct psd_engine *e, struct pollfd *fds, int *fd_dev, int max);
/* Let drivers whose fd fired or whose deadline passed do their work. */
void psd_engine_service(struct psd_engine *e, double now, const struct pollfd *fds,
                        const int *fd_dev, int nfds);
/* Every output to its zone's safe level (shutdown).  Returns the count of
 * zones that could not reach it (each logged at LOG_ERR). */
int psd_engine_safe(struct psd_engine *e, double now, const char *why);
/* A planned stop: every zone to its stop_level (psensd(8), STOPPING: a
 * zone in a fault to its safe level, a vacant one or stop_level = hold
 * left where it is).  The same return. */
int psd_engine_stop(struct psd_engine *e, double now, const char *why);
/* The earliest deadline of the devices that run step-wise on their own
 * descriptor (a driver with an fd method: DALI USB, GPIO): INFINITY when
 * all of them are idle, e.g. every frame asked for is on the bus; *mono the
 * same on the monotonic clock. */
double psd_engine_io_deadline(const struct psd_engine *e, double *mono);
/* An event in the log's events table (through the writer: never waits). */
void psd_engine_event(struct psd_engine *e, double now, const char *zone, const char *kind, const char *text);
/* Commit the log and close every device.  Returns the config to free (or NULL). */
struct psd_config *psd_engine_close(struct psd_engine *e);

/* What is true in a simulated zone's room at now (its sensor's device's
 * truth hook, driver.h); -1 when the zone's sensor is real hardware. */
int psd_engine_truth(const struct psd_zone *z, double now, struct ps_truth *t);

/* The zone of a name, NULL when there is none (the socket resolves a name
 * once; the actions below take the zone). */
struct psd_zone *psd_engine_zone(struct psd_engine *e, const char *name);

/* The zone's occupancy now: -1 it has no occupancy input, 0 vacant, 1
 * occupied (an input in a fault counts as occupied: daemon/occupancy.h). */
int psd_engine_zone_occupied(const struct psd_zone *z);

/* Control-socket actions; -1 with a message in err. */
int psd_engine_set_target(struct psd_zone *z, double lux, char *err, size_t n);
int psd_engine_override(struct psd_zone *z, double level, double seconds, double now, char *err, size_t n);
/* A manual off: the lights off until release, or in a zone with an
 * occupancy input until the next change from vacant to occupied. */
void psd_engine_off(struct psd_zone *z);
void psd_engine_release(struct psd_zone *z);
/* Daylight control on (the control law holds the target with the
 * daylight) or off (the zone holds the level that meets the target with
 * no daylight: target / electric task lux at full output, within the
 * zone's minimum and 1; full output when that is unknown).  A fault's safe
 * level, an override and the occupancy rule over it as over the control. */
void psd_engine_set_daylighting(struct psd_zone *z, int on);
/* The occupancy's vacancy hold, s (0 to 86400). */
int psd_engine_set_vacancy_hold(struct psd_zone *z, double seconds, char *err, size_t n);

/* Calibration sessions (daemon/calsession.h) on a zone.  Each -1 with a
 * message in err. */
int psd_engine_cal_start(struct psd_engine *e, struct psd_zone *z, int kind, double level, double now, char *err,
                         size_t n);
/* A lux reading the installer typed, paired with the zone's reading now. */
int psd_engine_cal_lux(struct psd_engine *e, struct psd_zone *z, double lux, double now, char *err, size_t n);
int psd_engine_cal_finish(struct psd_engine *e, struct psd_zone *z, double now, char *err, size_t n);
int psd_engine_cal_accept(struct psd_engine *e, struct psd_zone *z, double now, char *err, size_t n);
int psd_engine_cal_abort(struct psd_engine *e, struct psd_zone *z, double now, const char *why, char *err,
                         size_t n);

#endif
