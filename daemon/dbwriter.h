/* SPDX-License-Identifier: ISC */
/* The sample log's writer: a thread of its own with its own connection
 * (db.h psd_db_open_peer) and a bounded queue in memory, so that the
 * control never waits for the database.  The control thread queues
 * samples and events and goes on; the thread writes what is queued in one
 * transaction at a time.  A database that cannot be written (locked by
 * another process, a full disk, an I/O error, corruption) is retried with
 * back-off, from 50 ms doubling to 5 s, until it works again: the thread
 * logs one LOG_ERR line naming the cause when the fault starts, a
 * LOG_WARNING every minute while it lasts (the count of failed writes),
 * and one LOG_ERR line when it ends with the count of samples held and of
 * any dropped.
 *
 * The bound: `hold` entries (psensd.conf(5) log_hold, 4096 by default,
 * each about 500 bytes: 2 MiB), samples and events together.  Past it, in
 * real time, the oldest entry is dropped and counted: the count goes in
 * the log, in status, and in the record itself (an event "log gap" once
 * the database works again).  A simulated clock instead waits for room
 * while the database works: a simulated day has no lights to keep and
 * loses nothing (a failing database drops and counts, never hangs it).
 *
 * What a SIGKILL would lose is counted: while samples are held (or
 * dropped and not yet recorded) the thread keeps <path>.held up to date
 * ("held N", the oldest's "clock" time and "utc", the newest's
 * "last_utc", "pid"; written and renamed, no fsync) and removes it once
 * they are written and at close.  psd_dbwriter_open reads one left by a
 * killed run: one LOG_ERR line, and a "log gap" event with the count,
 * the file removed once that event is written. */
#ifndef PSD_DBWRITER_H
#define PSD_DBWRITER_H

#include <stddef.h>

#include "db.h"

enum { PSD_DBWRITER_HOLD = 4096 };

struct psd_dbwriter;

/* What status shows. */
struct psd_dbwriter_stats {
	int degraded;             /* the last write failed */
	unsigned long held;       /* queued or being written */
	unsigned long dropped;    /* dropped past the bound since the start */
	unsigned long errors;     /* failed writes since the start */
	unsigned long committed;  /* samples committed by the thread */
	double since;             /* monotonic seconds the fault started (degraded) */
	char cause[320];          /* the fault's cause ("" when none) */
};

/* Start the thread on path (a file psd_db_open opened: the schema is
 * there); hold entries at most (0: PSD_DBWRITER_HOLD); wait: 1 to wait for
 * room when full instead of dropping (a simulated clock).  NULL with a
 * message in err. */
struct psd_dbwriter *psd_dbwriter_open(const char *path, size_t hold, int wait, char *err, size_t errlen);
/* The clock's date (db.h psd_db_set_epoch) for the rows written from now. */
void psd_dbwriter_set_epoch(struct psd_dbwriter *w, double epoch0);
/* Queue a sample (its strings are copied).  Never waits unless opened
 * with wait. */
void psd_dbwriter_sample(struct psd_dbwriter *w, const struct psd_sample *s);
/* Queue an event (db.h psd_db_event). */
void psd_dbwriter_event(struct psd_dbwriter *w, double t, const char *zone, const char *kind, const char *text);
/* Queue MQTT's cursor for a site (db.h psd_db_mqtt_set_cursor): it is
 * written in order with the samples, and a failed write keeps it queued. */
void psd_dbwriter_cursor(struct psd_dbwriter *w, const char *site, long long id);
/* Samples committed so far. */
unsigned long psd_dbwriter_committed(struct psd_dbwriter *w);
void psd_dbwriter_stats(struct psd_dbwriter *w, struct psd_dbwriter_stats *st);
/* Wait up to timeout_s for everything queued to be written: 0 when it is,
 * -1 when entries are still held. */
int psd_dbwriter_sync(struct psd_dbwriter *w, double timeout_s);
/* Write what is queued (up to timeout_s), stop the thread and close; what
 * could not be written is counted and logged at LOG_ERR. */
void psd_dbwriter_close(struct psd_dbwriter *w, double timeout_s);

#endif
