/* SPDX-License-Identifier: ISC */
#include "dbwriter.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "errbuf.h"
#include "log.h"
#include "replace.h"
#include "time.h"

enum { BATCH = 256, ZONE = 48, WORD = 40, TEXT = 256 };
static const double BACKOFF_MIN = 0.05, BACKOFF_MAX = 5;   /* s between attempts */
static const double REPEAT = 60;                           /* s between reminders of a fault */

/* One queued row: a sample, an event (its kind in word), or an MQTT
 * cursor (its site in zone, the sample id in s.t). */
enum { SAMPLE, EVENT, CURSOR };
struct entry {
	int event;
	int has_zone;
	struct psd_sample s;      /* its strings point nowhere until written */
	int has_cond, has_fault;
	unsigned long lost;       /* an event recording a previous run's loss: its count */
	double lost_last;         /* ... and its newest sample's UTC (s.utc: the oldest) */
	long lost_pid;            /* ... and the pid that held them */
	char zone[ZONE], word[WORD], text[TEXT];
};

/* What the state file beside the database says: the samples held in
 * memory (and dropped, not yet recorded) that a SIGKILL would lose. */
struct held {
	unsigned long count;
	double t, utc, last_utc;  /* the oldest's clock time and UTC, the newest's UTC */
	long pid;
};

struct psd_dbwriter {
	pthread_mutex_t mu;
	pthread_cond_t work;      /* entries queued, or stop */
	pthread_cond_t room;      /* entries left the ring */
	pthread_cond_t idle;      /* nothing held */
	pthread_cond_t wake;      /* stop (the back-off waits on it) */
	pthread_t thread;
	struct psd_db *db;
	char path[4096];
	struct entry *ring, *batch;
	size_t cap, head, n, nb;
	int wait, stop;
	double stop_at;           /* monotonic: give up writing at close */
	double epoch0;
	unsigned long committed, dropped, errors, gap;
	unsigned long queued;     /* what the ring's and the batch's entries would
	                             lose to a kill (weight()), kept as they move */
	int degraded, kind;
	double since, told_at;
	unsigned long errors_at_start, dropped_at_start;
	char cause[320];
	char heldpath[4112];      /* <database>.held */
	unsigned long held_told;  /* the count in it (0: no file) */
	int held_failed;          /* writing it failed (told once) */
};

static struct timespec abs_mono(double t)
{
	struct timespec ts;
	ts.tv_sec = (time_t)floor(t);
	ts.tv_nsec = (long)((t - floor(t)) * 1e9);
	return ts;
}

static void copy(char *dst, size_t n, const char *src)
{
	snprintf(dst, n, "%s", src ? src : "");
}

/* What an entry counts toward a kill's loss: a sample one, a previous
 * run's loss its count, other events and cursors nothing. */
static unsigned long weight(const struct entry *e)
{
	return e->event == SAMPLE ? 1 : e->lost;
}

/* Entry i of what is held, in queue order: the batch, then the ring. */
static const struct entry *held_at(const struct psd_dbwriter *w, size_t i)
{
	return i < w->nb ? &w->batch[i] : &w->ring[(w->head + i - w->nb) % w->cap];
}

/* Room for one more entry: in real time the oldest goes (counted); a
 * waiting writer waits for room unless the database is failing (a
 * simulated day must not hang on a corrupt file: it drops and counts). */
static struct entry *slot(struct psd_dbwriter *w)
{
	while (w->wait && w->n == w->cap && !w->stop && !w->degraded)
		pthread_cond_wait(&w->room, &w->mu);
	if (w->n == w->cap) {
		w->queued -= weight(&w->ring[w->head]);
		w->gap += w->ring[w->head].lost;   /* a previous run's loss goes on in the count */
		w->head = (w->head + 1) % w->cap;
		w->n--;
		w->dropped++;
		w->gap++;
	}
	pthread_cond_signal(&w->wake);   /* a writer backing off updates the state file */
	return &w->ring[(w->head + w->n++) % w->cap];
}

void psd_dbwriter_sample(struct psd_dbwriter *w, const struct psd_sample *s)
{
	struct entry *e;
	pthread_mutex_lock(&w->mu);
	e = slot(w);
	e->event = SAMPLE;
	e->lost = 0;
	e->s = *s;
	e->has_zone = s->zone != NULL;
	e->has_cond = s->condition != NULL;
	e->has_fault = s->fault != NULL;
	copy(e->zone, sizeof e->zone, s->zone);
	copy(e->word, sizeof e->word, s->condition);
	copy(e->text, sizeof e->text, s->fault);
	e->s.zone = e->s.condition = e->s.fault = e->s.local = NULL;
	w->queued++;
	pthread_cond_signal(&w->work);
	pthread_mutex_unlock(&w->mu);
}

void psd_dbwriter_event(struct psd_dbwriter *w, double t, const char *zone, const char *kind, const char *text)
{
	struct entry *e;
	pthread_mutex_lock(&w->mu);
	e = slot(w);
	memset(e, 0, sizeof *e);
	e->event = EVENT;
	e->s.t = t;
	e->has_zone = zone != NULL;
	e->has_fault = text != NULL;
	copy(e->zone, sizeof e->zone, zone);
	copy(e->word, sizeof e->word, kind);
	copy(e->text, sizeof e->text, text);
	pthread_cond_signal(&w->work);
	pthread_mutex_unlock(&w->mu);
}

void psd_dbwriter_cursor(struct psd_dbwriter *w, const char *site, long long id)
{
	struct entry *e;
	pthread_mutex_lock(&w->mu);
	e = slot(w);
	memset(e, 0, sizeof *e);
	e->event = CURSOR;
	e->s.t = (double)id;   /* exact below 2^53 */
	copy(e->zone, sizeof e->zone, site);
	pthread_cond_signal(&w->work);
	pthread_mutex_unlock(&w->mu);
}

/* Write the batch in one transaction: the count of samples, -1 with the
 * cause (and its kind in *kind) when nothing was written. */
static long write_batch(struct psd_dbwriter *w, struct entry *b, size_t n, double epoch0, char *why, size_t whylen,
                        int *kind)
{
	char err[512];
	long samples = 0;
	psd_db_set_epoch(w->db, epoch0);
	if (psd_db_begin(w->db, err, sizeof err) != 0)
		goto bad;
	for (size_t i = 0; i < n; i++) {
		struct entry *e = &b[i];
		int rc;
		if (e->event == CURSOR) {
			rc = psd_db_mqtt_set_cursor(w->db, e->zone, (long long)e->s.t, err, sizeof err);
		} else if (e->event == EVENT) {
			rc = psd_db_event(w->db, e->s.t, e->has_zone ? e->zone : NULL, e->word,
			                  e->has_fault ? e->text : NULL, err, sizeof err);
		} else {
			struct psd_sample s = e->s;
			s.zone = e->has_zone ? e->zone : NULL;
			s.condition = e->has_cond ? e->word : NULL;
			s.fault = e->has_fault ? e->text : NULL;
			rc = psd_db_insert(w->db, &s, err, sizeof err);
			samples++;
		}
		if (rc != 0)
			goto bad;
	}
	if (psd_db_end(w->db, 1, err, sizeof err) != 0)
		goto bad;
	return samples;
bad:
	*kind = psd_db_cause(w->db, why, whylen);
	psd_db_end(w->db, 0, NULL, 0);
	return -1;
}

/* A failed write: the batch back at the front of the ring, as much of it
 * as there is room for (the oldest of it dropped), and the fault told. */
static void failed(struct psd_dbwriter *w, const char *why, int kind)
{
	size_t keep = w->cap - w->n < w->nb ? w->cap - w->n : w->nb;
	double now = psd_time_mono();
	w->dropped += w->nb - keep;
	w->gap += w->nb - keep;
	for (size_t i = 0; i < w->nb - keep; i++) {
		w->gap += w->batch[i].lost;
		w->queued -= weight(&w->batch[i]);
	}
	for (size_t i = 0; i < keep; i++) {
		w->head = (w->head + w->cap - 1) % w->cap;
		w->ring[w->head] = w->batch[w->nb - 1 - i];
	}
	w->n += keep;
	w->nb = 0;
	w->errors++;
	pthread_cond_broadcast(&w->room);   /* a waiting producer drops instead */
	if (!w->degraded) {
		w->degraded = 1;
		w->since = w->told_at = now;
		w->errors_at_start = w->errors - 1;
		w->dropped_at_start = w->dropped;
		w->kind = kind;
		copy(w->cause, sizeof w->cause, why);
		psd_log_errx("%s: the sample log cannot be written: %s; holding up to %zu samples in memory and retrying%s",
		         w->path, why, w->cap, kind == PSD_DB_CORRUPT ? " (a corrupt log: psensd(8) DATABASE FAULTS)" : "");
	} else if (kind != w->kind || now - w->told_at >= REPEAT) {
		w->told_at = now;
		w->kind = kind;
		copy(w->cause, sizeof w->cause, why);
		psd_log_warnx("%s: the sample log still cannot be written after %.0f s: %s (%lu failed writes, %zu samples "
		          "held, %lu dropped)", w->path, now - w->since, why, w->errors - w->errors_at_start, w->n,
		          w->dropped - w->dropped_at_start);
	}
}

/* A write went through: the end of a fault told, a gap recorded. */
static void written(struct psd_dbwriter *w, long samples, double t_last)
{
	unsigned long gap = w->gap;
	w->committed += (unsigned long)samples;
	if (w->degraded) {
		w->degraded = 0;
		psd_log_errx("%s: the sample log is written again after %.1f s (%lu failed writes): %zu samples were held, "
		         "%lu dropped", w->path, psd_time_mono() - w->since, w->errors - w->errors_at_start, w->n + w->nb,
		         w->dropped - w->dropped_at_start);
		w->cause[0] = 0;
	}
	for (size_t i = 0; i < w->nb; i++)
		w->queued -= weight(&w->batch[i]);
	w->nb = 0;
	if (gap) {
		unsigned long recorded = gap;
		char text[160], err[256];
		snprintf(text, sizeof text, "%lu samples dropped: the log could not be written and %zu were held",
		         gap, w->cap);
		pthread_mutex_unlock(&w->mu);
		if (psd_db_begin(w->db, err, sizeof err) == 0 &&
		    psd_db_event(w->db, t_last, NULL, "log gap", text, err, sizeof err) == 0 &&
		    psd_db_end(w->db, 1, err, sizeof err) == 0)
			gap = 0;
		else
			psd_db_end(w->db, 0, NULL, 0);
		pthread_mutex_lock(&w->mu);
		if (!gap)
			w->gap -= recorded;   /* drops while it was written wait for the next */
	}
}

/* The state file: what a SIGKILL now would lose (with the lock held): the
 * count kept as entries come and go, the dates from the first and the last
 * entry that counts in queue order (samples are queued as they are taken,
 * a previous run's loss first), so a state file costs no walk over a held
 * queue of up to log_hold entries. */
static void held_count(struct psd_dbwriter *w, struct held *h)
{
	size_t total = w->nb + w->n;
	h->count = w->gap + w->queued;
	h->t = h->utc = h->last_utc = NAN;
	h->pid = (long)getpid();
	for (size_t i = 0; i < total; i++) {
		const struct entry *e = held_at(w, i);
		if (weight(e)) {
			h->utc = e->s.utc;
			h->t = e->s.t;
			break;
		}
	}
	for (size_t i = total; i-- > 0;) {
		const struct entry *e = held_at(w, i);
		if (weight(e)) {
			h->last_utc = e->event == SAMPLE ? e->s.utc : e->lost_last;
			break;
		}
	}
}

static int held_write(const char *file, const struct held *h)
{
	char buf[256];
	int len = snprintf(buf, sizeof buf, "held %lu\nclock %.3f\nutc %.3f\nlast_utc %.3f\npid %ld\n", h->count, h->t,
	                   h->utc, h->last_utc, h->pid);
	return ps_replace_file(file, 0644, buf, (size_t)len, NULL);
}

/* Read the state file: 1 with *h, 0 when there is none, -1 with the
 * line at fault in *line. */
static int held_read(const char *file, struct held *h, int *line)
{
	static const char *const key[] = { "held", "clock", "utc", "last_utc", "pid" };
	char buf[128];
	FILE *f = fopen(file, "re");
	*line = 0;
	if (!f)
		return errno == ENOENT ? 0 : -1;
	for (int i = 0; i < 5; i++) {
		char *v, *end;
		size_t k = strlen(key[i]);
		double d;
		*line = i + 1;
		if (!fgets(buf, sizeof buf, f) || strncmp(buf, key[i], k) != 0 || buf[k] != ' ')
			goto bad;
		v = buf + k + 1;
		errno = 0;
		d = strtod(v, &end);
		if (end == v || (*end != '\n' && *end) || errno)
			goto bad;
		if (i == 0 || i == 4) {
			if (!(d >= 0 && d < 1e15) || d != floor(d))
				goto bad;
		}
		if (i == 0)
			h->count = (unsigned long)d;
		else if (i == 1)
			h->t = d;
		else if (i == 2)
			h->utc = d;
		else if (i == 3)
			h->last_utc = d;
		else
			h->pid = (long)d;
	}
	fclose(f);
	return 1;
bad:
	fclose(f);
	return -1;
}

/* Keep the state file up to date (the writer thread, with the lock held):
 * written while the log cannot be written and what is held changes,
 * removed once nothing is held. */
static void held_keep(struct psd_dbwriter *w)
{
	struct held h;
	if (!w->degraded && !w->held_told)
		return;   /* the common case: the log is written, no file */
	held_count(w, &h);
	if (h.count == w->held_told || (h.count && !w->degraded && !w->held_told))
		return;
	w->held_told = h.count;
	pthread_mutex_unlock(&w->mu);
	if (h.count == 0) {
		if (unlink(w->heldpath) != 0 && errno != ENOENT)
			psd_log_warnx("%s: %s", w->heldpath, strerror(errno));
	} else if (held_write(w->heldpath, &h) != 0 && !w->held_failed) {
		w->held_failed = 1;
		psd_log_warnx("%s: %s: the count of samples held will not survive a kill", w->heldpath, strerror(errno));
	}
	pthread_mutex_lock(&w->mu);
}

static const char *date_of(double utc, char *buf, size_t n)
{
	struct tm tm;
	time_t tt = (time_t)utc;
	if (!isfinite(utc) || !gmtime_r(&tt, &tm) || !strftime(buf, n, "%Y-%m-%d %H:%M:%S UTC", &tm))
		snprintf(buf, n, "an unknown date");
	return buf;
}

/* At the start: a state file left by a run that was killed holding
 * samples.  Told at LOG_ERR and queued as a "log gap" event; the file
 * goes once that event is written. */
static void held_previous(struct psd_dbwriter *w)
{
	struct held h = { 0, NAN, NAN, NAN, 0 };
	int line, rc = held_read(w->heldpath, &h, &line);
	char a[48], b[48];
	struct entry *e;
	if (rc == 0)
		return;
	if (rc < 0) {
		if (line)
			psd_log_errx("%s: line %d: not a count of held samples; removed", w->heldpath, line);
		else
			psd_log_errx("%s: %s", w->heldpath, strerror(errno));
		unlink(w->heldpath);
		return;
	}
	if (h.count == 0) {
		unlink(w->heldpath);
		return;
	}
	date_of(h.utc, a, sizeof a);
	date_of(h.last_utc, b, sizeof b);
	psd_log_errx("%s: %lu samples were lost: psensd (pid %ld) ended holding them in memory while the log could not "
	             "be written, taken from %s to %s", w->path, h.count, h.pid, a, b);
	e = &w->ring[(w->head + w->n++) % w->cap];
	memset(e, 0, sizeof *e);
	e->event = EVENT;
	e->s.t = h.t;
	e->s.utc = h.utc;
	e->lost = h.count;
	e->lost_last = h.last_utc;
	e->lost_pid = h.pid;
	e->has_fault = 1;
	w->queued += h.count;
	copy(e->word, sizeof e->word, "log gap");
	snprintf(e->text, sizeof e->text, "%lu samples lost: psensd (pid %ld) ended holding them in memory, from %s to %s",
	         h.count, h.pid, a, b);
	w->held_told = h.count;
}

static void *run(void *arg)
{
	struct psd_dbwriter *w = arg;
	double backoff = BACKOFF_MIN;
	pthread_mutex_lock(&w->mu);
	for (;;) {
		char why[320];
		int kind = PSD_DB_OTHER;
		long samples;
		double epoch0, t_last;
		while (w->n == 0 && !w->stop)
			pthread_cond_wait(&w->work, &w->mu);
		if (w->n == 0 || (w->stop && psd_time_mono() >= w->stop_at))
			break;
		w->nb = w->n < BATCH ? w->n : BATCH;
		for (size_t i = 0; i < w->nb; i++)
			w->batch[i] = w->ring[(w->head + i) % w->cap];
		w->head = (w->head + w->nb) % w->cap;
		w->n -= w->nb;
		t_last = w->batch[w->nb - 1].s.t;
		epoch0 = w->epoch0;
		pthread_cond_broadcast(&w->room);
		pthread_mutex_unlock(&w->mu);
		samples = write_batch(w, w->batch, w->nb, epoch0, why, sizeof why, &kind);
		pthread_mutex_lock(&w->mu);
		if (samples >= 0) {
			written(w, samples, t_last);
			held_keep(w);
			backoff = BACKOFF_MIN;
			if (w->n == 0)
				pthread_cond_broadcast(&w->idle);
			continue;
		}
		failed(w, why, kind);
		{
			double until = psd_time_mono() + backoff;
			struct timespec ts;
			if (w->stop && until > w->stop_at)
				until = w->stop_at;
			ts = abs_mono(until);
			held_keep(w);
			while (psd_time_mono() < until && pthread_cond_timedwait(&w->wake, &w->mu, &ts) != ETIMEDOUT)
				held_keep(w);
		}
		backoff = backoff * 2 < BACKOFF_MAX ? backoff * 2 : BACKOFF_MAX;
	}
	pthread_cond_broadcast(&w->idle);
	pthread_mutex_unlock(&w->mu);
	return NULL;
}

struct psd_dbwriter *psd_dbwriter_open(const char *path, size_t hold, int wait, char *err, size_t errlen)
{
	struct psd_dbwriter *w = calloc(1, sizeof *w);
	pthread_condattr_t ca;
	if (!w) {
		psd_errbuf(err, errlen, "%s: the log's writer: out of memory", path);
		return NULL;
	}
	w->cap = hold ? hold : PSD_DBWRITER_HOLD;
	w->wait = wait;
	w->epoch0 = NAN;
	copy(w->path, sizeof w->path, path);
	snprintf(w->heldpath, sizeof w->heldpath, "%s.held", path);
	if (!(w->ring = calloc(w->cap, sizeof *w->ring)) || !(w->batch = calloc(BATCH, sizeof *w->batch))) {
		psd_errbuf(err, errlen, "%s: the log's writer: no memory for %zu samples", path, w->cap);
		goto bad;
	}
	if (!(w->db = psd_db_open_peer(path, err, errlen)))
		goto bad;
	psd_db_set_busy(w->db, 100);   /* a reader's checkpoint passes; a lock held longer is a fault */
	held_previous(w);
	pthread_mutex_init(&w->mu, NULL);
	pthread_condattr_init(&ca);
	pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
	pthread_cond_init(&w->work, NULL);
	pthread_cond_init(&w->room, NULL);
	pthread_cond_init(&w->idle, &ca);
	pthread_cond_init(&w->wake, &ca);
	pthread_condattr_destroy(&ca);
	{
		/* the thread takes no signal: the loop's signalfd has them */
		sigset_t all, old;
		int rc;
		sigfillset(&all);
		pthread_sigmask(SIG_BLOCK, &all, &old);
		rc = pthread_create(&w->thread, NULL, run, w);
		pthread_sigmask(SIG_SETMASK, &old, NULL);
		if (rc != 0) {
			psd_errbuf(err, errlen, "%s: the log's writer: %s", path, strerror(rc));
			psd_db_close(w->db);
			w->db = NULL;
			goto bad;
		}
	}
	return w;
bad:
	free(w->ring);
	free(w->batch);
	free(w);
	return NULL;
}

void psd_dbwriter_set_epoch(struct psd_dbwriter *w, double epoch0)
{
	pthread_mutex_lock(&w->mu);
	w->epoch0 = epoch0;
	pthread_mutex_unlock(&w->mu);
}

unsigned long psd_dbwriter_committed(struct psd_dbwriter *w)
{
	unsigned long n;
	pthread_mutex_lock(&w->mu);
	n = w->committed;
	pthread_mutex_unlock(&w->mu);
	return n;
}

void psd_dbwriter_stats(struct psd_dbwriter *w, struct psd_dbwriter_stats *st)
{
	pthread_mutex_lock(&w->mu);
	st->degraded = w->degraded;
	st->held = (unsigned long)(w->n + w->nb);
	st->dropped = w->dropped;
	st->errors = w->errors;
	st->committed = w->committed;
	st->since = w->since;
	copy(st->cause, sizeof st->cause, w->degraded ? w->cause : "");
	pthread_mutex_unlock(&w->mu);
}

int psd_dbwriter_sync(struct psd_dbwriter *w, double timeout_s)
{
	struct timespec ts = abs_mono(psd_time_mono() + timeout_s);
	int left;
	pthread_mutex_lock(&w->mu);
	while ((w->n || w->nb) && !w->stop && pthread_cond_timedwait(&w->idle, &w->mu, &ts) != ETIMEDOUT)
		;
	left = w->n || w->nb;
	pthread_mutex_unlock(&w->mu);
	return left ? -1 : 0;
}

void psd_dbwriter_close(struct psd_dbwriter *w, double timeout_s)
{
	size_t lost;
	if (!w)
		return;
	pthread_mutex_lock(&w->mu);
	w->stop = 1;
	w->stop_at = psd_time_mono() + timeout_s;
	pthread_cond_broadcast(&w->work);
	pthread_cond_broadcast(&w->wake);
	pthread_cond_broadcast(&w->room);
	pthread_mutex_unlock(&w->mu);
	pthread_join(w->thread, NULL);
	lost = w->n + w->nb;
	if (lost)
		psd_log_errx("%s: %zu samples held in memory could not be written before the log closed (%s): lost", w->path,
		         lost, w->cause[0] ? w->cause : "no time left");
	{
		/* told: the file goes, unless a previous run's loss is still
		 * not in the record */
		struct held h = { 0, NAN, NAN, NAN, 0 };
		for (size_t i = 0; i < w->nb + w->n; i++) {
			const struct entry *e = held_at(w, i);
			if (e->event != SAMPLE && e->lost && !h.count) {
				h.count = e->lost;
				h.t = e->s.t;
				h.utc = e->s.utc;
				h.last_utc = e->lost_last;
				h.pid = e->lost_pid;
			}
		}
		if (h.count)
			held_write(w->heldpath, &h);
		else if (w->held_told)
			unlink(w->heldpath);
	}
	psd_db_close(w->db);
	pthread_mutex_destroy(&w->mu);
	pthread_cond_destroy(&w->work);
	pthread_cond_destroy(&w->room);
	pthread_cond_destroy(&w->idle);
	pthread_cond_destroy(&w->wake);
	free(w->ring);
	free(w->batch);
	free(w);
}
