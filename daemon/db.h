/* SPDX-License-Identifier: ISC */
/* The database: one SQLite file (WAL) holding the sample log and the
 * calibration records, readable while psensd writes it.  This module owns
 * the whole schema, every statement and the migrations: the version is
 * meta 'schema', and opening for writing takes an older file forward in
 * place, keeping every row (db.c lists the steps; adding a column is one
 * more step there).
 *
 *   samples       one row per zone per control period (struct psd_sample)
 *   cal_sessions  one row per calibration session: zone, kind, state
 *                 (running, done, aborted, accepted, superseded), start and
 *                 end, the config's and the scene's SHA-256, results (JSON)
 *   cal_samples   every sample of a session, committed as it is taken
 *   events        faults, their end, sessions, starts and reloads (schema 5)
 *   mqtt_cursor   per MQTT site, the last sample id the broker acknowledged
 *   mqtt_announced  per MQTT site, the zones announced to Home Assistant
 *   zone_consts, acceptance_tests  (schema 6) psensctl accept-test
 *   samples.occupied, samples.true_task_lux  (schema 7) occupancy, the
 *                 simulated room's truth
 *
 * Each sample row has utc (schema 4): the time its clock showed (the
 * clock's day + t), or the wall-clock time it was logged when no clock
 * date was given; since schema 5 also its local date and time, and
 * sessions, session samples and events carry UTC and local too.  t stays
 * the daemon's clock (seconds from the local midnight of the run's first
 * day). */
#ifndef PSD_DB_H
#define PSD_DB_H

#include <stddef.h>

/* The schema version this build writes. */
enum { PSD_DB_SCHEMA = 7 };
/* PRAGMA application_id of a psensd file ("PSND"): a file with another
 * non-zero id is another application's and is never written. */
enum { PSD_DB_APP_ID = 0x50534E44 };
/* What a failure was (psd_db_cause). */
enum { PSD_DB_OTHER, PSD_DB_FULL, PSD_DB_LOCKED, PSD_DB_CORRUPT };

struct psd_sample {
	double t;             /* seconds on the daemon's clock */
	double tod_s;         /* seconds since local midnight */
	double sensor_v;      /* NAN when the reading failed */
	double output;        /* commanded light output, 0..1 */
	double est_task_lux;  /* NAN at a fault */
	double task_lux;      /* measured by a task meter, NAN when none */
	double daylight_v;    /* daylight part of the signal */
	double daylight_lux;  /* estimated daylight part of the task lux */
	const char *condition;/* the scene condition the ratio came from */
	double ratio;         /* task lux per unit of sensor response used */
	const char *fault;    /* NULL or a short text */
	const char *zone;     /* the zone's name */
	/* when, as UTC (epoch seconds; schema 4: the clock's day's local
	 * midnight + t) and as the local date and time for display
	 * ("YYYY-MM-DD HH:MM:SS", schema 5); NAN and NULL in a row logged
	 * before.  psd_db_add takes utc when finite, else the epoch the
	 * database was given (psd_db_set_epoch) + t, else the wall clock. */
	double utc;
	const char *local;
	/* schema 7: the zone's occupancy (1 occupied, 0 vacant, -1 no
	 * occupancy input: NULL) and a simulated room's true task lux (NAN
	 * in a real room: NULL); -1 and NAN in a row logged before */
	int occupied;
	double true_task_lux;
};

struct psd_db;

/* Open for writing (creating or migrating the schema); ":memory:" for a
 * private in-memory database.  NULL with a message in err naming the
 * cause: a directory, another application's SQLite file, a corrupt file
 * (with the commands that set it aside or recover it), "disk full",
 * "locked by pid N". */
struct psd_db *psd_db_open(const char *path, char *err, size_t errlen);
/* A second connection to a file psd_db_open opened (the log's writer
 * thread, daemon/dbwriter.h): no lock file, no migration. */
struct psd_db *psd_db_open_peer(const char *path, char *err, size_t errlen);
/* How long a statement waits for another connection's lock (ms; 2000 by
 * default). */
void psd_db_set_busy(struct psd_db *db, int ms);
/* The last failure's real cause in out ("disk full (...)", "locked by pid
 * N (...)", "corrupt (...)", or SQLite's words with the system error):
 * PSD_DB_FULL, _LOCKED, _CORRUPT or _OTHER. */
int psd_db_cause(struct psd_db *db, char *out, size_t n);

/* Open an existing database read-only (psensctl export and report); a
 * file that is not psensd's, or newer than this psensd, is an error naming
 * it. */
struct psd_db *psd_db_open_readonly(const char *path, char *err, size_t errlen);
/* Open an existing psensd database for writing (psensctl -d accept-test):
 * never creates a file, and refuses one that is not psensd's before
 * touching it; the writer's lock as psd_db_open. */
struct psd_db *psd_db_open_existing(const char *path, char *err, size_t errlen);
void psd_db_close(struct psd_db *db);
/* The schema version of the open file (meta 'schema'), -1 on error. */
int psd_db_schema(struct psd_db *db);
/* UTC (epoch seconds) of the daemon's clock time 0, the local midnight of
 * the run's first day: every row written from now on stores utc = epoch0
 * + t and the local date and time of it (NAN, the default: neither). */
void psd_db_set_epoch(struct psd_db *db, double epoch0);
/* The latest UTC on record in the sample log (NAN: none). */
double psd_db_last_utc(struct psd_db *db);
/* An event (a fault, its end, a session, a start or a reload) at clock
 * time t, for a zone (NULL: the daemon), in the events table. */
int psd_db_event(struct psd_db *db, double t, const char *zone, const char *kind, const char *text, char *err,
                 size_t errlen);
/* The UTC of every start of psensd on record, oldest first. */
int psd_db_run_starts(struct psd_db *db, void (*fn)(void *user, double utc), void *user, char *err, size_t errlen);

/* ---- acceptance (schema 5, daemon/accept.h) -------------------------------- */

/* The zone's design constants in force (psensd writes them at start and when
 * the target changes): what the acceptance tests judge against. */
int psd_db_zone_consts_set(struct psd_db *db, const char *zone, double target_lux, double elec_task_lux,
                           double delay, char *err, size_t errlen);
/* 0 found, 1 none, -1 error. */
int psd_db_zone_consts_get(struct psd_db *db, const char *zone, double *target_lux, double *elec_task_lux,
                           double *delay);
/* A zone's occupancy constants (schema 7: vacancy_hold s and vacant_level,
 * after psd_db_zone_consts_set, which clears them; the occupancy
 * acceptance test judges against them).  get: 0 found, 1 none (no
 * occupancy input, or a file from before), -1 error. */
int psd_db_zone_occupancy_set(struct psd_db *db, const char *zone, double hold, double vacant_level, char *err,
                              size_t errlen);
int psd_db_zone_occupancy_get(struct psd_db *db, const char *zone, double *hold, double *vacant_level);
/* One acceptance test's result, dated now (UTC). */
int psd_db_accept_add(struct psd_db *db, const char *zone, double utc, const char *test, const char *verdict,
                      double value, double limit, long samples, const char *measured, char *err, size_t errlen);
/* A zone's acceptance results, oldest first (strings valid during the callback). */
struct psd_db_accept {
	const char *zone, *local, *test, *verdict, *measured;
	double utc, value, limit;
	long samples;
};
typedef void (*psd_db_accept_fn)(void *user, const struct psd_db_accept *a);
int psd_db_accept_results(struct psd_db *db, const char *zone, psd_db_accept_fn fn, void *user, char *err,
                          size_t errlen);

/* ---- the sample log -------------------------------------------------------- */

/* Samples per transaction (default 60; 1 commits every sample at once). */
void psd_db_set_batch(struct psd_db *db, int batch);
/* Queue a sample; every `batch` samples are committed in one transaction. */
int psd_db_add(struct psd_db *db, const struct psd_sample *s, char *err, size_t errlen);
/* Commit what is queued.  A batch SQLite rolled back by itself (a full
 * disk) is an error naming how many samples it held, never committed. */
int psd_db_commit(struct psd_db *db, char *err, size_t errlen);
/* The writer thread's own transactions: BEGIN IMMEDIATE, one insert per
 * sample, then commit (1) or roll back (0); -1 with the cause in err (a
 * failed commit leaves the transaction to be rolled back: psd_db_cause
 * first, then psd_db_end(db, 0)). */
int psd_db_begin(struct psd_db *db, char *err, size_t errlen);
int psd_db_insert(struct psd_db *db, const struct psd_sample *s, char *err, size_t errlen);
int psd_db_end(struct psd_db *db, int commit, char *err, size_t errlen);
/* A zone's samples (and those logged before samples named their zone), in
 * the order they were logged; fn gets each.  -1 with a message in err. */
typedef void (*psd_db_sample_fn)(void *user, const struct psd_sample *s);
long long psd_db_zone_count(struct psd_db *db, const char *zone, char *err, size_t errlen);
int psd_db_zone_samples(struct psd_db *db, const char *zone, psd_db_sample_fn fn, void *user, char *err,
                        size_t errlen);
/* Write the samples as CSV (header: t,tod_s,sensor_v,output,est_task_lux,
 * task_lux,daylight_v,daylight_lux,condition,ratio,fault,zone,utc,local) to fp. */
int psd_db_export_csv(const char *path, void *fp, char *err, size_t errlen);
/* The samples of zone (NULL: every zone) with since <= utc <= until (NAN:
 * no bound), in log order; only the last `last` when last > 0 (psensctl log
 * and export).  -1 with a message in err. */
int psd_db_select(const char *path, const char *zone, double since, double until, long last,
                  psd_db_sample_fn fn, void *user, char *err, size_t errlen);

/* ---- calibration records --------------------------------------------------- *
 * Written through the sample log's connection: while a batch of samples
 * holds a transaction open (a simulated day) a record is committed with
 * it, otherwise at once. */

/* A new running session; its id, or -1 with a message. */
long long psd_db_cal_begin(struct psd_db *db, const char *zone, const char *kind, double started,
                           const char *config_sha256, const char *scene_sha256, char *err, size_t errlen);
/* Sample seq of session id (replaces one of the same seq). */
int psd_db_cal_sample(struct psd_db *db, long long id, int seq, double t, double level, double volts,
                      double volts_se, double lux, const char *source, char *err, size_t errlen);
/* End a session: state done or aborted, its results (JSON) and a note. */
int psd_db_cal_end(struct psd_db *db, long long id, const char *state, double ended, const char *results,
                   const char *note, char *err, size_t errlen);
/* Accept a done session: the zone's accepted one of that kind becomes
 * 'superseded' (it stays in the history). */
int psd_db_cal_accept(struct psd_db *db, long long id, char *err, size_t errlen);
/* The zone's running session, if any: 0 found (id, kind, start time), 1
 * none, -1 error. */
int psd_db_cal_running(struct psd_db *db, const char *zone, long long *id, char *kind, size_t kindlen,
                       double *started);
/* Every sample of a session in order. */
typedef void (*psd_db_cal_sample_fn)(void *user, double t, double level, double volts, double volts_se,
                                     double lux);
int psd_db_cal_samples(struct psd_db *db, long long id, psd_db_cal_sample_fn fn, void *user);
/* The results (JSON, malloc'd) of the zone's accepted session of a kind, or
 * NULL; its id in *id. */
char *psd_db_cal_accepted(struct psd_db *db, const char *zone, const char *kind, long long *id);

/* A session as the report reads it (strings valid during the callback). */
struct psd_db_cal_session {
	long long id;
	const char *zone, *kind, *state;
	double started, ended;    /* NAN when not recorded */
	const char *results;      /* JSON or NULL */
	const char *note;         /* NULL or why it was aborted */
	double started_utc, ended_utc;            /* schema 4; NAN when not recorded */
	const char *started_local, *ended_local;  /* "YYYY-MM-DD HH:MM:SS" or NULL */
};
typedef void (*psd_db_cal_session_fn)(void *user, const struct psd_db_cal_session *s);
/* A zone's sessions in the order they were started. */
int psd_db_cal_sessions(struct psd_db *db, const char *zone, psd_db_cal_session_fn fn, void *user, char *err,
                        size_t errlen);

/* ---- the report's readers ------------------------------------------------------ */
/* Every zone named by a sample or a calibration session, sorted. */
typedef void (*psd_db_name_fn)(void *user, const char *name);
int psd_db_zones(struct psd_db *db, psd_db_name_fn fn, void *user, char *err, size_t errlen);
/* The config's and the scene's SHA-256 of the zone's latest session: 1 when
 * found, 0 when none (both ""), -1 on a read error. */
int psd_db_cal_hashes(struct psd_db *db, const char *zone, char config_sha256[65], char scene_sha256[65]);
/* 1 when psensd recorded that zone's devices as simulated (a "simulated"
 * event at a start; its text in what), 0 when not, -1 on a read error. */
int psd_db_zone_simulated(struct psd_db *db, const char *zone, char *what, size_t n);

/* ---- the MQTT publisher (daemon/mqtt/mqtt.c) ----------------------------- */

/* A sample as the publisher reads it: its row id and the UTC second it was
 * logged (NAN for a row logged before schema 4). */
typedef void (*psd_db_sample_row_fn)(void *user, long long id, double utc, const struct psd_sample *s);
/* Up to limit samples with id > after, in id order; the count, -1 with a
 * message in err. */
int psd_db_samples_after(struct psd_db *db, long long after, int limit, psd_db_sample_row_fn fn, void *user, char *err,
                         size_t errlen);
/* The highest sample id, 0 for none, -1 on error. */
long long psd_db_last_id(struct psd_db *db);
/* The site's cursor: the last sample id acknowledged (0 none), -1 error. */
long long psd_db_mqtt_cursor(struct psd_db *db, const char *site);
int psd_db_mqtt_set_cursor(struct psd_db *db, const char *site, long long id, char *err, size_t errlen);
/* The zones announced for Home Assistant: fn gets each (psd_db_name_fn
 * above); add or forget one. */
int psd_db_mqtt_announced(struct psd_db *db, const char *site, psd_db_name_fn fn, void *user);
int psd_db_mqtt_announce(struct psd_db *db, const char *site, const char *zone, int add, char *err, size_t errlen);

#endif
