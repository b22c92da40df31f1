/* The sample log: every control period's sample in SQLite (WAL, batched
 * transactions), readable while psensd writes it. */
#ifndef PSD_DB_H
#define PSD_DB_H

#include <stddef.h>

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
};

struct psd_db;

/* Open (creating the schema); -1 with a message in err. */
struct psd_db *psd_db_open(const char *path, char *err, size_t errlen);
/* Samples per transaction (default 60; 1 commits every sample at once). */
void psd_db_set_batch(struct psd_db *db, int batch);
/* Samples committed so far by this connection: what a SIGKILL cannot take. */
unsigned long psd_db_committed(const struct psd_db *db);
/* Queue a sample; every `batch` samples are committed in one transaction. */
int psd_db_add(struct psd_db *db, const struct psd_sample *s, char *err, size_t errlen);
/* Commit what is queued. */
int psd_db_commit(struct psd_db *db, char *err, size_t errlen);
void psd_db_close(struct psd_db *db);
/* The connection, for the calibration records that share the file. */
struct sqlite3 *psd_db_sqlite(struct psd_db *db);
/* Write the samples as CSV (header: t,tod_s,sensor_v,output,est_task_lux,
 * task_lux,daylight_v,daylight_lux,condition,ratio,fault,zone) to fp. */
int psd_db_export_csv(const char *path, void *fp, char *err, size_t errlen);

#endif
