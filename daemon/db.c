/* SPDX-License-Identifier: ISC */
#include "db.h"

#include <errno.h>
#include <math.h>
#include <sqlite3.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "csv.h"
#include "errbuf.h"
#include "pidlock.h"
#include "time.h"

enum { DB_BATCH = 60 };

struct psd_db {
	sqlite3 *h;
	sqlite3_stmt *ins;    /* the sample insert (NULL when read-only) */
	int pending;          /* samples in the open transaction */
	int batch;
	double epoch0;        /* UTC of clock time 0 (NAN: rows carry no date) */
	int lockfd;           /* the writer's flock on path.lock (daemon/pidlock.h), -1 none */
};

/* ---- the schema -------------------------------------------------------------
 * Step i takes a database at version i to version i + 1, in one transaction
 * with meta 'schema', so a file of any earlier version is brought forward in
 * place with every row kept.  To change the schema, add a step at the end
 * (e.g. "ALTER TABLE samples ADD COLUMN utc REAL;"), then the column to
 * struct psd_sample, the insert below and the readers. */
static const char *const steps[PSD_DB_SCHEMA] = {
	/* 0 -> 1: the sample log */
	"CREATE TABLE IF NOT EXISTS samples("
	" t REAL NOT NULL, tod_s REAL, sensor_v REAL, output REAL, est_task_lux REAL,"
	" task_lux REAL, daylight_v REAL, daylight_lux REAL, condition TEXT, ratio REAL, fault TEXT);"
	"CREATE INDEX IF NOT EXISTS samples_t ON samples(t);",
	/* 1 -> 2: the zone of each sample (several zones share one log) */
	"ALTER TABLE samples ADD COLUMN zone TEXT;",
	/* 2 -> 3: calibration sessions and their samples (a version-2 file may
	 * have them already, created apart under meta 'cal_schema') */
	"CREATE TABLE IF NOT EXISTS cal_sessions("
	" id INTEGER PRIMARY KEY, zone TEXT NOT NULL, kind TEXT NOT NULL, state TEXT NOT NULL,"
	" started REAL, ended REAL, config_sha256 TEXT, scene_sha256 TEXT, results TEXT, note TEXT);"
	"CREATE TABLE IF NOT EXISTS cal_samples("
	" session INTEGER NOT NULL REFERENCES cal_sessions(id), seq INTEGER NOT NULL, t REAL,"
	" level REAL, volts REAL, volts_se REAL, lux REAL, source TEXT, PRIMARY KEY(session, seq));",
	/* 3 -> 4: MQTT (daemon/mqtt/mqtt.c) and psensctl export --since/--until: the
	 * UTC time of each sample, the publisher's persisted cursor per site,
	 * the zones announced */
	"ALTER TABLE samples ADD COLUMN utc REAL;"
	"CREATE TABLE IF NOT EXISTS mqtt_cursor(site TEXT PRIMARY KEY, sample INTEGER NOT NULL);"
	"CREATE TABLE IF NOT EXISTS mqtt_announced(site TEXT NOT NULL, zone TEXT NOT NULL,"
	" PRIMARY KEY(site, zone));",
	/* 4 -> 5: dates: the local date and time of every sample,
	 * UTC and local of every session and session sample, and an event log.
	 * Older rows keep NULL there: the day they were logged on was never
	 * recorded.  Every ADD COLUMN is skipped when the column is there
	 * already (migrate(): a file from a development build had it), and
	 * samples.utc / the MQTT tables are made here too if such a file
	 * skipped 3 -> 4. */
	"ALTER TABLE samples ADD COLUMN utc REAL;"
	"ALTER TABLE samples ADD COLUMN local TEXT;"
	"CREATE INDEX IF NOT EXISTS samples_utc ON samples(utc);"
	"ALTER TABLE cal_sessions ADD COLUMN started_utc REAL;"
	"ALTER TABLE cal_sessions ADD COLUMN started_local TEXT;"
	"ALTER TABLE cal_sessions ADD COLUMN ended_utc REAL;"
	"ALTER TABLE cal_sessions ADD COLUMN ended_local TEXT;"
	"ALTER TABLE cal_samples ADD COLUMN utc REAL;"
	"ALTER TABLE cal_samples ADD COLUMN local TEXT;"
	"CREATE TABLE IF NOT EXISTS events("
	" t REAL, utc REAL, local TEXT, zone TEXT, kind TEXT NOT NULL, text TEXT);"
	"CREATE TABLE IF NOT EXISTS mqtt_cursor(site TEXT PRIMARY KEY, sample INTEGER NOT NULL);"
	"CREATE TABLE IF NOT EXISTS mqtt_announced(site TEXT NOT NULL, zone TEXT NOT NULL,"
	" PRIMARY KEY(site, zone));",
	/* 5 -> 6: acceptance: the zones' design constants and the
	 * results of the acceptance tests */
	"CREATE TABLE IF NOT EXISTS zone_consts(zone TEXT PRIMARY KEY, utc REAL, target_lux REAL,"
	" elec_task_lux REAL, delay REAL);"
	"CREATE TABLE IF NOT EXISTS acceptance_tests(id INTEGER PRIMARY KEY, zone TEXT NOT NULL, local TEXT,"
	" test TEXT NOT NULL, verdict TEXT NOT NULL, value REAL, limit_value REAL, samples INTEGER, measured TEXT,"
	" utc REAL);",
	/* 6 -> 7: occupancy (daemon/occupancy.h), NULL in a zone with no
	 * occupancy input, and a simulated room's true task illuminance, NULL
	 * in a real room; both NULL in the rows logged before; the zones'
	 * occupancy constants for the acceptance test */
	"ALTER TABLE samples ADD COLUMN occupied INTEGER;"
	"ALTER TABLE samples ADD COLUMN true_task_lux REAL;"
	"ALTER TABLE zone_consts ADD COLUMN vacancy_hold REAL;"
	"ALTER TABLE zone_consts ADD COLUMN vacant_level REAL;",
};

static const char sample_columns[] = "t, tod_s, sensor_v, output, est_task_lux, task_lux, daylight_v,"
                                     " daylight_lux, condition, ratio, fault, zone, utc, local, occupied,"
                                     " true_task_lux";
/* What the readers select: a file opened read-only is not migrated; one
 * from schema 5 or 6 has no occupancy nor truth, one from schema 4 has utc
 * but no local text either, one from before has neither (NULL then). */
static const char sample_columns_v6[] = "t, tod_s, sensor_v, output, est_task_lux, task_lux, daylight_v,"
                                        " daylight_lux, condition, ratio, fault, zone, utc, local, NULL, NULL";
static const char sample_columns_v4[] = "t, tod_s, sensor_v, output, est_task_lux, task_lux, daylight_v,"
                                        " daylight_lux, condition, ratio, fault, zone, utc, NULL, NULL, NULL";
static const char sample_columns_v3[] = "t, tod_s, sensor_v, output, est_task_lux, task_lux, daylight_v,"
                                        " daylight_lux, condition, ratio, fault, zone, NULL, NULL, NULL, NULL";
enum { SAMPLE_NCOLUMNS = 16 };

static int has_column(struct psd_db *db, const char *table, const char *column);
static const char *col_text(sqlite3_stmt *st, int i);

/* 1 when the file's samples have utc */
static int has_utc(struct psd_db *db)
{
	return has_column(db, "samples", "utc");
}

/* The columns a reader selects, by the file's schema. */
static const char *read_columns(struct psd_db *db)
{
	if (has_column(db, "samples", "true_task_lux"))
		return sample_columns;
	if (has_column(db, "samples", "local"))
		return sample_columns_v6;
	return has_utc(db) ? sample_columns_v4 : sample_columns_v3;
}

/* The process other than this one holding a write lock on file, 0 when
 * none is seen.  Read from /proc/locks by the file's inode: opening the
 * file to ask fcntl would drop SQLite's own locks on it at close. */
static long lock_holder(const char *file)
{
	struct stat st;
	char line[256];
	long pid = 0;
	FILE *fp;
	if (stat(file, &st) != 0 || !(fp = fopen("/proc/locks", "r")))
		return 0;
	while (!pid && fgets(line, sizeof line, fp)) {
		char kind[16], mode[16];
		unsigned maj, min;
		unsigned long long ino;
		long p;
		/* "1: POSIX  ADVISORY  WRITE 1234 08:01:5678 120 120" ("->" marks a waiter) */
		if (strstr(line, "->") || sscanf(line, "%*d: %15s %*s %15s %ld %x:%x:%llu", kind, mode, &p, &maj, &min, &ino) != 6)
			continue;
		if (strcmp(mode, "WRITE") == 0 && ino == (unsigned long long)st.st_ino && p != (long)getpid() && p > 0)
			pid = p;
	}
	fclose(fp);
	return pid;
}

/* The pid of another process holding a write lock on the database file
 * or its WAL index, 0 when none is seen. */
static long lock_holder_of(const char *path)
{
	char shm[4096];
	long pid = 0;
	/* WAL: a writer holds a byte of path-shm; a rollback journal: the file */
	if ((size_t)snprintf(shm, sizeof shm, "%s-shm", path) < sizeof shm)
		pid = lock_holder(shm);
	return pid ? pid : lock_holder(path);
}

static int cause_of(sqlite3 *h, char *out, size_t n)
{
	int rc = h ? sqlite3_extended_errcode(h) : SQLITE_NOMEM, prim = rc & 0xff;
	int sys = h ? sqlite3_system_errno(h) : 0;
	const char *msg = h ? sqlite3_errmsg(h) : "out of memory";
	const char *file = h ? sqlite3_db_filename(h, "main") : NULL;
	if (prim == SQLITE_FULL || sys == ENOSPC) {
		snprintf(out, n, "disk full (%s)", msg);
		return PSD_DB_FULL;
	}
	if (prim == SQLITE_BUSY || prim == SQLITE_LOCKED) {
		long pid = file && *file ? lock_holder_of(file) : 0;
		if (pid > 0)
			snprintf(out, n, "locked by pid %ld (%s)", pid, msg);
		else
			snprintf(out, n, "locked by another connection (%s)", msg);
		return PSD_DB_LOCKED;
	}
	if (prim == SQLITE_CORRUPT || prim == SQLITE_NOTADB) {
		snprintf(out, n, "corrupt (%s)", msg);
		return PSD_DB_CORRUPT;
	}
	if (sys && prim != SQLITE_OK && prim != SQLITE_ERROR && prim != SQLITE_MISUSE)
		snprintf(out, n, "%s (%s)", msg, strerror(sys));
	else
		snprintf(out, n, "%s", msg);
	return PSD_DB_OTHER;
}

static int fail(sqlite3 *h, const char *what, char *err, size_t errlen)
{
	char why[400];
	cause_of(h, why, sizeof why);
	return psd_errbuf(err, errlen, "%s: %s", what, why);
}

int psd_db_cause(struct psd_db *db, char *out, size_t n)
{
	return cause_of(db ? db->h : NULL, out, n);
}

int psd_db_schema(struct psd_db *db)
{
	sqlite3_stmt *st;
	int v = -1;
	if (sqlite3_prepare_v2(db->h, "SELECT value FROM meta WHERE key = 'schema'", -1, &st, NULL) != SQLITE_OK)
		return sqlite3_errcode(db->h) == SQLITE_ERROR ? 0 : -1;   /* no meta table: a new file */
	v = sqlite3_step(st) == SQLITE_ROW ? sqlite3_column_int(st, 0) : 0;
	sqlite3_finalize(st);
	return v;
}

/* Run one step's statements in turn.  An ADD COLUMN whose column is there
 * already is skipped: a file may have it from an earlier step or build. */
static int run_step(sqlite3 *h, const char *sql, char **msg)
{
	while (sql && *sql) {
		sqlite3_stmt *st;
		const char *tail = NULL;
		int rc;
		if (sqlite3_prepare_v2(h, sql, -1, &st, &tail) != SQLITE_OK) {
			const char *e = sqlite3_errmsg(h);
			if (strncmp(e, "duplicate column name", 21) != 0) {
				*msg = sqlite3_mprintf("%s", e);
				return SQLITE_ERROR;
			}
			sql = tail && tail != sql ? tail : strchr(sql, ';');   /* skip it */
			if (sql && *sql == ';')
				sql++;
			continue;
		}
		if (!st) {   /* white space or a comment */
			sql = tail;
			continue;
		}
		rc = sqlite3_step(st);
		sqlite3_finalize(st);
		if (rc != SQLITE_DONE && rc != SQLITE_ROW) {
			const char *e = sqlite3_errmsg(h);
			if (strncmp(e, "duplicate column name", 21) != 0) {
				*msg = sqlite3_mprintf("%s", e);
				return rc;
			}
		}
		sql = tail;
	}
	return SQLITE_OK;
}

static int migrate(struct psd_db *db, const char *path, char *err, size_t errlen)
{
	char *msg = NULL;
	int v;
	if (sqlite3_exec(db->h, "PRAGMA journal_mode=WAL; PRAGMA synchronous=NORMAL;"
	                        "CREATE TABLE IF NOT EXISTS meta(key TEXT PRIMARY KEY, value TEXT);",
	                 NULL, NULL, &msg) != SQLITE_OK)
		goto bad;
	if ((v = psd_db_schema(db)) < 0)
		return fail(db->h, path, err, errlen);
	if (v > PSD_DB_SCHEMA)
		return psd_errbuf(err, errlen, "%s: schema version %d is newer than this psensd's (%d)", path, v,
		                PSD_DB_SCHEMA);
	for (; v < PSD_DB_SCHEMA; v++) {
		char set[96];
		snprintf(set, sizeof set, "INSERT OR REPLACE INTO meta VALUES('schema', '%d');", v + 1);
		if (sqlite3_exec(db->h, "BEGIN IMMEDIATE", NULL, NULL, &msg) != SQLITE_OK)
			goto bad;
		if (run_step(db->h, steps[v], &msg) != SQLITE_OK ||
		    sqlite3_exec(db->h, set, NULL, NULL, &msg) != SQLITE_OK ||
		    sqlite3_exec(db->h, "COMMIT", NULL, NULL, &msg) != SQLITE_OK) {
			char why[400];
			cause_of(db->h, why, sizeof why);
			sqlite3_exec(db->h, "ROLLBACK", NULL, NULL, NULL);
			psd_errbuf(err, errlen, "%s: schema %d to %d: %s", path, v, v + 1, why);
			sqlite3_free(msg);
			return -1;
		}
	}
	return 0;
bad:
	fail(db->h, path, err, errlen);
	sqlite3_free(msg);
	return -1;
}

static struct psd_db *open_db(const char *path, int flags, char *err, size_t errlen)
{
	struct psd_db *db = calloc(1, sizeof *db);
	if (!db) {
		psd_errbuf(err, errlen, "%s: out of memory", path);
		return NULL;
	}
	if (sqlite3_open_v2(path, &db->h, flags, NULL) != SQLITE_OK) {
		fail(db->h, path, err, errlen);
		sqlite3_close(db->h);
		free(db);
		return NULL;
	}
	sqlite3_busy_timeout(db->h, 2000);   /* a reader or the writer may hold it briefly */
	db->batch = DB_BATCH;
	db->epoch0 = NAN;
	db->lockfd = -1;
	return db;
}

/* One writer per database: two daemons appending to one log would
 * interleave two clocks for the same zone.  The lock is a flock on a file
 * beside the database, not SQLite's locking_mode=EXCLUSIVE, which would
 * also shut out the readers (psensctl log, psreport, sqlite3) that must
 * read the log while the daemon writes it. */
/* The lock's descriptor; -1 for a private database (nothing to share);
 * -2 with a message in err when it is taken or cannot be made. */
static int lock_writer(const char *path, char *err, size_t errlen)
{
	char lock[4096];
	pid_t holder;
	int fd;
	if (!*path || strcmp(path, ":memory:") == 0)
		return -1;
	if ((size_t)snprintf(lock, sizeof lock, "%s.lock", path) >= sizeof lock) {
		psd_errbuf(err, errlen, "%s: path too long", path);
		return -2;
	}
	if ((fd = psd_pidlock_take(lock, &holder)) >= 0)
		return fd;
	if (errno == EWOULDBLOCK && holder > 0)
		psd_errbuf(err, errlen, "%s is in use by psensd pid %ld (it holds %s): one daemon per database", path,
		         (long)holder, lock);
	else if (errno == EWOULDBLOCK)
		psd_errbuf(err, errlen, "%s is in use: another process holds %s: one daemon per database", path, lock);
	else if (errno == ENOSPC || errno == EDQUOT)
		psd_errbuf(err, errlen, "%s: disk full (%s)", lock, strerror(errno));
	else
		psd_errbuf(err, errlen, "%s: %s", lock, strerror(errno));
	return -2;
}

/* A file psensd must not write: a directory, another application's
 * SQLite file (its own application_id, or tables but no sample log), or
 * a corrupt one (refused with the commands that set it aside or recover
 * it: psensd(8)).  0 when the file is absent, empty or psensd's. */
static int check_file(const char *path, char *err, size_t errlen)
{
	struct stat st;
	struct psd_db *db;
	sqlite3_stmt *q;
	char names[200] = "", why[400];
	size_t len = 0;
	int ntab = 0, rc, kind;
	long long app = 0;
	if (!*path || strcmp(path, ":memory:") == 0 || stat(path, &st) != 0)
		return 0;
	if (S_ISDIR(st.st_mode))
		return psd_errbuf(err, errlen, "%s: is a directory, not a database file", path);
	if (!S_ISREG(st.st_mode) || st.st_size == 0)
		return 0;
	if (!(db = open_db(path, SQLITE_OPEN_READONLY, err, errlen)))
		return -1;
	rc = sqlite3_prepare_v2(db->h, "SELECT name FROM sqlite_master WHERE type = 'table' ORDER BY name", -1, &q, NULL);
	while (rc == SQLITE_OK || rc == SQLITE_ROW) {
		if ((rc = sqlite3_step(q)) != SQLITE_ROW)
			break;
		const char *t = col_text(q, 0);
		ntab++;
		if (t && len < sizeof names - 1 && strcmp(t, "meta") != 0)
			len += (size_t)snprintf(names + len, sizeof names - len, "%s%s", len ? ", " : "", t);
	}
	if (rc == SQLITE_DONE) {
		sqlite3_finalize(q);
		q = NULL;
		if (sqlite3_prepare_v2(db->h, "PRAGMA application_id", -1, &q, NULL) == SQLITE_OK &&
		    sqlite3_step(q) == SQLITE_ROW)
			app = sqlite3_column_int64(q, 0);
		rc = SQLITE_DONE;
	}
	sqlite3_finalize(q);
	if (rc != SQLITE_DONE) {
		kind = cause_of(db->h, why, sizeof why);
		psd_db_close(db);
		if (kind == PSD_DB_CORRUPT)
			return psd_errbuf(err, errlen, "%s: %s: psensd will not write to it; set it aside and start a new "
			                "log (mv %s %s.corrupt), recovering its rows first if wanted (sqlite3 %s .recover "
			                "| sqlite3 %s.recovered)", path, why, path, path, path, path);
		return psd_errbuf(err, errlen, "%s: %s", path, why);
	}
	if (app != 0 && app != PSD_DB_APP_ID) {
		psd_db_close(db);
		return psd_errbuf(err, errlen, "%s: not a psensd database (application_id %lld): psensd writes only "
		                "its own files", path, app);
	}
	if (ntab > 0 && !has_column(db, "samples", "t") && psd_db_schema(db) <= 0) {
		psd_db_close(db);
		return psd_errbuf(err, errlen, "%s: not a psensd database (its tables: %s): psensd writes only its own "
		                "files", path, names);
	}
	psd_db_close(db);
	return 0;
}

static long long app_id(struct psd_db *db)
{
	sqlite3_stmt *q;
	long long app = -1;
	if (sqlite3_prepare_v2(db->h, "PRAGMA application_id", -1, &q, NULL) == SQLITE_OK && sqlite3_step(q) == SQLITE_ROW)
		app = sqlite3_column_int64(q, 0);
	sqlite3_finalize(q);
	return app;
}

struct psd_db *psd_db_open(const char *path, char *err, size_t errlen)
{
	int lockfd;
	struct psd_db *db;
	char sql[256];
	if (check_file(path, err, errlen) != 0)
		return NULL;
	if ((lockfd = lock_writer(path, err, errlen)) == -2)
		return NULL;
	if (!(db = open_db(path, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, err, errlen))) {
		psd_pidlock_release(lockfd);
		return NULL;
	}
	db->lockfd = lockfd;
	if (migrate(db, path, err, errlen) != 0)
		goto bad;
	/* marked once (a write: not at every start, which a held lock would stop) */
	snprintf(sql, sizeof sql, "PRAGMA application_id = %d", PSD_DB_APP_ID);
	if (app_id(db) != PSD_DB_APP_ID && sqlite3_exec(db->h, sql, NULL, NULL, NULL) != SQLITE_OK) {
		fail(db->h, path, err, errlen);
		goto bad;
	}
	snprintf(sql, sizeof sql, "INSERT INTO samples(%s) VALUES(?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?)", sample_columns);
	if (sqlite3_prepare_v2(db->h, sql, -1, &db->ins, NULL) != SQLITE_OK) {
		fail(db->h, path, err, errlen);
		goto bad;
	}
	return db;
bad:
	psd_db_close(db);
	return NULL;
}

struct psd_db *psd_db_open_peer(const char *path, char *err, size_t errlen)
{
	struct psd_db *db = open_db(path, SQLITE_OPEN_READWRITE, err, errlen);
	char sql[256];
	if (!db)
		return NULL;
	snprintf(sql, sizeof sql, "INSERT INTO samples(%s) VALUES(?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?)", sample_columns);
	if (sqlite3_exec(db->h, "PRAGMA synchronous=NORMAL", NULL, NULL, NULL) != SQLITE_OK ||
	    sqlite3_prepare_v2(db->h, sql, -1, &db->ins, NULL) != SQLITE_OK) {
		fail(db->h, path, err, errlen);
		psd_db_close(db);
		return NULL;
	}
	return db;
}

void psd_db_set_busy(struct psd_db *db, int ms)
{
	sqlite3_busy_timeout(db->h, ms);
}

/* A reader is not migrated, so it checks what it was given: SQLite opens
 * any file lazily, and its first query's words ("file is not a database",
 * "no such table: samples") would name neither the file nor what it
 * should have been. */
struct psd_db *psd_db_open_readonly(const char *path, char *err, size_t errlen)
{
	struct psd_db *db = open_db(path, SQLITE_OPEN_READONLY, err, errlen);
	int v;
	if (!db)
		return NULL;
	if ((v = psd_db_schema(db)) < 0)
		fail(db->h, path, err, errlen);
	else if (v > PSD_DB_SCHEMA)
		psd_errbuf(err, errlen, "%s: schema version %d is newer than this psensd's (%d)", path, v,
		         PSD_DB_SCHEMA);
	else if (!has_column(db, "samples", "t"))
		psd_errbuf(err, errlen, "%s: not a psensd database (no samples table)", path);
	else if (!has_column(db, "samples", "zone"))
		psd_errbuf(err, errlen, "%s: schema version %d, from before zones: psensd brings it forward "
		         "when it next opens it", path, v);
	else
		return db;
	psd_db_close(db);
	return NULL;
}

struct psd_db *psd_db_open_existing(const char *path, char *err, size_t errlen)
{
	/* checked first as a reader would, so that neither a lock file nor a
	 * schema is ever made beside or inside a file that is not psensd's */
	struct psd_db *db = psd_db_open_readonly(path, err, errlen);
	if (!db)
		return NULL;
	psd_db_close(db);
	return psd_db_open(path, err, errlen);
}

void psd_db_close(struct psd_db *db)
{
	char err[256];
	if (!db)
		return;
	if (db->ins)
		psd_db_commit(db, err, sizeof err);
	sqlite3_finalize(db->ins);
	sqlite3_close(db->h);
	psd_pidlock_release(db->lockfd);   /* after the last write */
	free(db);
}

/* ---- binding and reading values ---------------------------------------------- */

static void bind_num(sqlite3_stmt *st, int i, double v)
{
	if (isfinite(v))
		sqlite3_bind_double(st, i, v);
	else
		sqlite3_bind_null(st, i);
}

static void bind_text(sqlite3_stmt *st, int i, const char *s)
{
	if (s)
		sqlite3_bind_text(st, i, s, -1, SQLITE_TRANSIENT);
	else
		sqlite3_bind_null(st, i);
}

static double col_num(sqlite3_stmt *st, int i)
{
	return sqlite3_column_type(st, i) == SQLITE_NULL ? NAN : sqlite3_column_double(st, i);
}

static const char *col_text(sqlite3_stmt *st, int i)
{
	return (const char *)sqlite3_column_text(st, i);
}

/* Prepare sql and bind by the letters of fmt (t text, d double, i int64);
 * NULL with a message in err. */
static sqlite3_stmt *prepare(struct psd_db *db, const char *sql, char *err, size_t errlen, const char *fmt,
                             va_list ap)
{
	sqlite3_stmt *st;
	int i = 1;
	if (sqlite3_prepare_v2(db->h, sql, -1, &st, NULL) != SQLITE_OK) {
		fail(db->h, "prepare", err, errlen);
		return NULL;
	}
	for (const char *f = fmt; *f; f++, i++) {
		if (*f == 't')
			bind_text(st, i, va_arg(ap, const char *));
		else if (*f == 'd')
			bind_num(st, i, va_arg(ap, double));
		else
			sqlite3_bind_int64(st, i, va_arg(ap, long long));
	}
	return st;
}

/* Run a statement that returns no rows. */
static int run(struct psd_db *db, const char *sql, char *err, size_t errlen, const char *fmt, ...)
{
	sqlite3_stmt *st;
	va_list ap;
	int rc;
	va_start(ap, fmt);
	st = prepare(db, sql, err, errlen, fmt, ap);
	va_end(ap);
	if (!st)
		return -1;
	rc = sqlite3_step(st);
	sqlite3_finalize(st);
	return rc == SQLITE_DONE || rc == SQLITE_ROW ? 0 : fail(db->h, "write", err, errlen);
}

/* A query: the statement ready to step, or NULL with a message in err. */
static sqlite3_stmt *query(struct psd_db *db, char *err, size_t errlen, const char *sql, const char *fmt, ...)
{
	sqlite3_stmt *st;
	va_list ap;
	va_start(ap, fmt);
	st = prepare(db, sql, err, errlen, fmt, ap);
	va_end(ap);
	return st;
}

/* ---- dates ------------------------------------------------------------------ */

void psd_db_set_epoch(struct psd_db *db, double epoch0)
{
	db->epoch0 = epoch0;
}

/* The local "YYYY-MM-DD HH:MM:SS" of a UTC time (out at least 20 bytes);
 * "" when utc is not finite. */
static void local_time(double utc, char *out, size_t n)
{
	psd_time_local_text(utc, PSD_TIME_SECOND, out, n);
}

/* The UTC and local text of clock time t for this database. */
static double utc_of(const struct psd_db *db, double t, char local[32])
{
	double u = isfinite(db->epoch0) && isfinite(t) ? db->epoch0 + t : NAN;
	local_time(u, local, 32);
	return u;
}

static const char *or_null(const char *s)
{
	return s && *s ? s : NULL;
}

double psd_db_last_utc(struct psd_db *db)
{
	char err[256];
	sqlite3_stmt *st = query(db, err, sizeof err, "SELECT max(utc) FROM samples", "");
	double v = NAN;
	if (!st)
		return NAN;
	if (sqlite3_step(st) == SQLITE_ROW)
		v = col_num(st, 0);
	sqlite3_finalize(st);
	return v;
}

int psd_db_event(struct psd_db *db, double t, const char *zone, const char *kind, const char *text, char *err,
                 size_t errlen)
{
	char local[32];
	double u = utc_of(db, t, local);
	return run(db, "INSERT INTO events(t, utc, local, zone, kind, text) VALUES(?, ?, ?, ?, ?, ?)", err, errlen,
	           "ddtttt", t, u, or_null(local), zone, kind, text);
}

/* ---- acceptance -------------------------------------------------------------- */

int psd_db_zone_consts_set(struct psd_db *db, const char *zone, double target_lux, double elec_task_lux,
                           double delay, char *err, size_t errlen)
{
	return run(db, "INSERT OR REPLACE INTO zone_consts(zone, utc, target_lux, elec_task_lux, delay)"
	           " VALUES(?, ?, ?, ?, ?)", err, errlen, "tdddd", zone, floor(psd_time_wall()), target_lux,
	           elec_task_lux, delay);
}

int psd_db_zone_occupancy_set(struct psd_db *db, const char *zone, double hold, double vacant_level, char *err,
                              size_t errlen)
{
	return run(db, "UPDATE zone_consts SET vacancy_hold = ?, vacant_level = ? WHERE zone = ?", err, errlen, "ddt",
	           hold, vacant_level, zone);
}

int psd_db_zone_occupancy_get(struct psd_db *db, const char *zone, double *hold, double *vacant_level)
{
	char err[256];
	sqlite3_stmt *st;
	int rc;
	if (!has_column(db, "zone_consts", "vacancy_hold"))
		return 1;   /* a file from before schema 7, opened to read */
	if (!(st = query(db, err, sizeof err, "SELECT vacancy_hold, vacant_level FROM zone_consts WHERE zone = ?"
	                 " AND vacancy_hold IS NOT NULL", "t", zone)))
		return -1;
	rc = sqlite3_step(st);
	if (rc == SQLITE_ROW) {
		*hold = col_num(st, 0);
		*vacant_level = col_num(st, 1);
	}
	sqlite3_finalize(st);
	return rc == SQLITE_ROW ? 0 : rc == SQLITE_DONE ? 1 : -1;
}

int psd_db_zone_consts_get(struct psd_db *db, const char *zone, double *target_lux, double *elec_task_lux,
                           double *delay)
{
	char err[256];
	sqlite3_stmt *st = query(db, err, sizeof err, "SELECT target_lux, elec_task_lux, delay FROM zone_consts"
	                         " WHERE zone = ?", "t", zone);
	int rc;
	if (!st)
		return -1;
	rc = sqlite3_step(st);
	if (rc == SQLITE_ROW) {
		*target_lux = col_num(st, 0);
		*elec_task_lux = col_num(st, 1);
		*delay = col_num(st, 2);
	}
	sqlite3_finalize(st);
	return rc == SQLITE_ROW ? 0 : rc == SQLITE_DONE ? 1 : -1;
}

int psd_db_accept_add(struct psd_db *db, const char *zone, double utc, const char *test, const char *verdict,
                      double value, double limit, long samples, const char *measured, char *err, size_t errlen)
{
	char local[32];
	local_time(utc, local, sizeof local);
	return run(db, "INSERT INTO acceptance_tests(zone, utc, local, test, verdict, value, limit_value, samples, measured)"
	           " VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?)", err, errlen, "tdtttddit", zone, utc, or_null(local), test,
	           verdict, value, limit, (long long)samples, measured);
}

int psd_db_accept_results(struct psd_db *db, const char *zone, psd_db_accept_fn fn, void *user, char *err,
                          size_t errlen)
{
	sqlite3_stmt *st = query(db, err, errlen, "SELECT zone, local, test, verdict, measured, utc, value, limit_value,"
	                         " samples FROM acceptance_tests WHERE zone = ? ORDER BY id", "t", zone);
	int rc;
	if (!st)
		return -1;
	while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
		struct psd_db_accept a = { col_text(st, 0), col_text(st, 1), col_text(st, 2), col_text(st, 3),
		                           col_text(st, 4), col_num(st, 5), col_num(st, 6), col_num(st, 7),
		                           (long)sqlite3_column_int64(st, 8) };
		fn(user, &a);
	}
	sqlite3_finalize(st);
	return rc == SQLITE_DONE ? 0 : fail(db->h, "read", err, errlen);
}

/* ---- the sample log -------------------------------------------------------- */

void psd_db_set_batch(struct psd_db *db, int batch)
{
	db->batch = batch > 0 ? batch : 1;
}

int psd_db_insert(struct psd_db *db, const struct psd_sample *s, char *err, size_t errlen)
{
	char local[32];
	double u = isfinite(s->utc) ? s->utc : utc_of(db, s->t, local);
	int rc;
	bind_num(db->ins, 1, s->t);
	bind_num(db->ins, 2, s->tod_s);
	bind_num(db->ins, 3, s->sensor_v);
	bind_num(db->ins, 4, s->output);
	bind_num(db->ins, 5, s->est_task_lux);
	bind_num(db->ins, 6, s->task_lux);
	bind_num(db->ins, 7, s->daylight_v);
	bind_num(db->ins, 8, s->daylight_lux);
	bind_text(db->ins, 9, s->condition);
	bind_num(db->ins, 10, s->ratio);
	bind_text(db->ins, 11, s->fault);
	bind_text(db->ins, 12, s->zone);
	if (!isfinite(u)) {   /* no clock date given: the wall clock at logging */
		u = psd_time_wall();
	}
	local_time(u, local, sizeof local);
	bind_num(db->ins, 13, u);   /* the clock's time (engine.c: its day + t) */
	bind_text(db->ins, 14, or_null(local));
	if (s->occupied >= 0)
		sqlite3_bind_int(db->ins, 15, s->occupied != 0);
	else
		sqlite3_bind_null(db->ins, 15);
	bind_num(db->ins, 16, s->true_task_lux);
	rc = sqlite3_step(db->ins);
	sqlite3_reset(db->ins);
	return rc == SQLITE_DONE ? 0 : fail(db->h, "insert", err, errlen);
}

int psd_db_begin(struct psd_db *db, char *err, size_t errlen)
{
	if (sqlite3_exec(db->h, "BEGIN IMMEDIATE", NULL, NULL, NULL) != SQLITE_OK)
		return fail(db->h, "begin", err, errlen);
	return 0;
}

int psd_db_end(struct psd_db *db, int commit, char *err, size_t errlen)
{
	if (commit)
		return sqlite3_exec(db->h, "COMMIT", NULL, NULL, NULL) == SQLITE_OK ? 0 : fail(db->h, "commit", err, errlen);
	/* a failed statement may have rolled the transaction back already */
	if (!sqlite3_get_autocommit(db->h))
		sqlite3_exec(db->h, "ROLLBACK", NULL, NULL, NULL);
	return 0;
}

int psd_db_add(struct psd_db *db, const struct psd_sample *s, char *err, size_t errlen)
{
	if (db->pending > 0 && sqlite3_get_autocommit(db->h)) {
		/* SQLite rolled the open batch back (a full disk, an I/O error) */
		psd_errbuf(err, errlen, "insert: %d samples of the open transaction were rolled back", db->pending);
		db->pending = 0;
		return -1;
	}
	if (db->pending == 0 && sqlite3_exec(db->h, "BEGIN", NULL, NULL, NULL) != SQLITE_OK)
		return fail(db->h, "begin", err, errlen);
	if (psd_db_insert(db, s, err, errlen) != 0) {
		if (db->pending == 0)
			psd_db_end(db, 0, NULL, 0);
		else if (sqlite3_get_autocommit(db->h))
			db->pending = 0;
		return -1;
	}
	if (++db->pending >= db->batch)
		return psd_db_commit(db, err, errlen);
	return 0;
}

int psd_db_commit(struct psd_db *db, char *err, size_t errlen)
{
	int n = db->pending;
	if (n == 0)
		return 0;
	db->pending = 0;
	if (sqlite3_get_autocommit(db->h))
		return psd_errbuf(err, errlen, "commit: %d samples of the open transaction were rolled back", n);
	if (psd_db_end(db, 1, err, errlen) != 0) {
		psd_db_end(db, 0, NULL, 0);
		return -1;
	}
	return 0;
}

/* 1 when table has column (a read-only file may predate it). */
static int has_column(struct psd_db *db, const char *table, const char *column)
{
	sqlite3_stmt *st;
	char sql[128];
	int yes = 0;
	snprintf(sql, sizeof sql, "SELECT * FROM \"%s\" LIMIT 0", table);
	if (sqlite3_prepare_v2(db->h, sql, -1, &st, NULL) != SQLITE_OK)
		return 0;
	for (int i = 0; i < sqlite3_column_count(st); i++)
		yes |= strcmp(sqlite3_column_name(st, i), column) == 0;
	sqlite3_finalize(st);
	return yes;
}


static void row_sample(sqlite3_stmt *st, struct psd_sample *s)
{
	*s = (struct psd_sample){
		col_num(st, 0), col_num(st, 1), col_num(st, 2), col_num(st, 3), col_num(st, 4), col_num(st, 5),
		col_num(st, 6), col_num(st, 7), col_text(st, 8), col_num(st, 9), col_text(st, 10), col_text(st, 11),
		col_num(st, 12), col_text(st, 13),
		sqlite3_column_type(st, 14) == SQLITE_NULL ? -1 : sqlite3_column_int(st, 14), col_num(st, 15),
	};
}

long long psd_db_zone_count(struct psd_db *db, const char *zone, char *err, size_t errlen)
{
	sqlite3_stmt *st = query(db, err, errlen, "SELECT count(*) FROM samples WHERE zone = ? OR zone IS NULL", "t",
	                         zone);
	long long n = -1;
	if (!st)
		return -1;
	if (sqlite3_step(st) == SQLITE_ROW)
		n = sqlite3_column_int64(st, 0);
	else
		fail(db->h, "count", err, errlen);
	sqlite3_finalize(st);
	return n;
}

int psd_db_zone_samples(struct psd_db *db, const char *zone, psd_db_sample_fn fn, void *user, char *err,
                        size_t errlen)
{
	char sql[256];
	sqlite3_stmt *st;
	int rc;
	snprintf(sql, sizeof sql, "SELECT %s FROM samples WHERE zone = ? OR zone IS NULL ORDER BY rowid",
	         read_columns(db));
	if (!(st = query(db, err, errlen, sql, "t", zone)))
		return -1;
	while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
		struct psd_sample s;
		row_sample(st, &s);
		fn(user, &s);
	}
	sqlite3_finalize(st);
	return rc == SQLITE_DONE ? 0 : fail(db->h, "read", err, errlen);
}

static void csv_row(void *user, const struct psd_sample *s)
{
	FILE *fp = user;
	const double num[] = { s->t, s->tod_s, s->sensor_v, s->output, s->est_task_lux, s->task_lux, s->daylight_v,
	                       s->daylight_lux };
	for (size_t i = 0; i < sizeof num / sizeof num[0]; i++) {
		psd_csv_num(fp, num[i]);
		fputc(',', fp);
	}
	psd_csv_text(fp, s->condition);
	fputc(',', fp);
	psd_csv_num(fp, s->ratio);
	fputc(',', fp);
	psd_csv_text(fp, s->fault);
	fputc(',', fp);
	psd_csv_text(fp, s->zone);
	fputc('\n', fp);
}

int psd_db_export_csv(const char *path, void *out, char *err, size_t errlen)
{
	struct psd_db *db = psd_db_open_readonly(path, err, errlen);
	char sql[256];
	sqlite3_stmt *st;
	int rc;
	if (!db)
		return -1;
	snprintf(sql, sizeof sql, "SELECT %s FROM samples ORDER BY rowid", read_columns(db));
	if (!(st = query(db, err, errlen, sql, ""))) {
		psd_db_close(db);
		return -1;
	}
	/* the old form, kept as it was (psensctl export has the dates) */
	fputs("t,tod_s,sensor_v,output,est_task_lux,task_lux,daylight_v,daylight_lux,condition,ratio,fault,zone\n",
	      (FILE *)out);
	while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
		struct psd_sample s;
		row_sample(st, &s);
		csv_row(out, &s);
	}
	if (rc != SQLITE_DONE)
		fail(db->h, path, err, errlen);
	sqlite3_finalize(st);
	psd_db_close(db);
	return rc == SQLITE_DONE ? 0 : -1;
}

/* ---- calibration records --------------------------------------------------- */

static int cal_fail(struct psd_db *db, const char *what, char *err, size_t errlen)
{
	return psd_errbuf(err, errlen, "calibration log: %s: %s", what, sqlite3_errmsg(db->h));
}

long long psd_db_cal_begin(struct psd_db *db, const char *zone, const char *kind, double started,
                           const char *config_sha256, const char *scene_sha256, char *err, size_t errlen)
{
	char local[32];
	double u = utc_of(db, started, local);
	if (run(db, "INSERT INTO cal_sessions(zone, kind, state, started, config_sha256, scene_sha256, started_utc,"
	            " started_local) VALUES(?, ?, 'running', ?, ?, ?, ?, ?)", err, errlen, "ttdttdt", zone, kind,
	        started, config_sha256, scene_sha256, u, or_null(local)) != 0)
		return cal_fail(db, "begin", err, errlen);
	return (long long)sqlite3_last_insert_rowid(db->h);
}

int psd_db_cal_sample(struct psd_db *db, long long id, int seq, double t, double level, double volts,
                      double volts_se, double lux, const char *source, char *err, size_t errlen)
{
	char local[32];
	double u = utc_of(db, t, local);
	if (run(db, "INSERT OR REPLACE INTO cal_samples(session, seq, t, level, volts, volts_se, lux, source, utc,"
	            " local) VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?)", err, errlen, "iidddddtdt", id, (long long)seq, t,
	        level, volts, volts_se, lux, source, u, or_null(local)) != 0)
		return cal_fail(db, "sample", err, errlen);
	return 0;
}

int psd_db_cal_end(struct psd_db *db, long long id, const char *state, double ended, const char *results,
                   const char *note, char *err, size_t errlen)
{
	char local[32];
	double u = utc_of(db, ended, local);
	if (run(db, "UPDATE cal_sessions SET state = ?, ended = ?, results = ?, note = ?, ended_utc = ?,"
	            " ended_local = ? WHERE id = ?", err, errlen, "tdttdti", state, ended, results, note, u,
	        or_null(local), id) != 0)
		return cal_fail(db, "end", err, errlen);
	return 0;
}

int psd_db_cal_accept(struct psd_db *db, long long id, char *err, size_t errlen)
{
	if (sqlite3_exec(db->h, "SAVEPOINT accept", NULL, NULL, NULL) != SQLITE_OK)
		return cal_fail(db, "begin", err, errlen);
	if (run(db, "UPDATE cal_sessions SET state = 'superseded' WHERE state = 'accepted' AND"
	            " (zone, kind) = (SELECT zone, kind FROM cal_sessions WHERE id = ?)", err, errlen, "i", id) != 0 ||
	    run(db, "UPDATE cal_sessions SET state = 'accepted' WHERE id = ? AND state = 'done'", err, errlen, "i",
	        id) != 0) {
		cal_fail(db, "accept", err, errlen);
		sqlite3_exec(db->h, "ROLLBACK TO accept; RELEASE accept", NULL, NULL, NULL);
		return -1;
	}
	return sqlite3_exec(db->h, "RELEASE accept", NULL, NULL, NULL) == SQLITE_OK ? 0
	                                                                           : cal_fail(db, "commit", err, errlen);
}

int psd_db_cal_running(struct psd_db *db, const char *zone, long long *id, char *kind, size_t kindlen,
                       double *started)
{
	char err[256];
	sqlite3_stmt *st = query(db, err, sizeof err, "SELECT id, kind, started FROM cal_sessions WHERE zone = ? AND"
	                         " state = 'running' ORDER BY id DESC LIMIT 1", "t", zone);
	int rc;
	if (!st)
		return -1;
	rc = sqlite3_step(st);
	if (rc == SQLITE_ROW) {
		*id = sqlite3_column_int64(st, 0);
		snprintf(kind, kindlen, "%s", col_text(st, 1) ? col_text(st, 1) : "");
		*started = sqlite3_column_double(st, 2);
	}
	sqlite3_finalize(st);
	return rc == SQLITE_ROW ? 0 : rc == SQLITE_DONE ? 1 : -1;
}

int psd_db_cal_samples(struct psd_db *db, long long id, psd_db_cal_sample_fn fn, void *user)
{
	char err[256];
	sqlite3_stmt *st = query(db, err, sizeof err, "SELECT t, level, volts, volts_se, lux FROM cal_samples"
	                         " WHERE session = ? ORDER BY seq", "i", id);
	int rc;
	if (!st)
		return -1;
	while ((rc = sqlite3_step(st)) == SQLITE_ROW)
		fn(user, col_num(st, 0), col_num(st, 1), col_num(st, 2), col_num(st, 3), col_num(st, 4));
	sqlite3_finalize(st);
	return rc == SQLITE_DONE ? 0 : -1;
}

char *psd_db_cal_accepted(struct psd_db *db, const char *zone, const char *kind, long long *id)
{
	char err[256], *out = NULL;
	sqlite3_stmt *st = query(db, err, sizeof err, "SELECT id, results FROM cal_sessions WHERE zone = ? AND"
	                         " kind = ? AND state = 'accepted' ORDER BY id DESC LIMIT 1", "tt", zone, kind);
	if (!st)
		return NULL;
	if (sqlite3_step(st) == SQLITE_ROW && col_text(st, 1)) {
		*id = sqlite3_column_int64(st, 0);
		out = strdup(col_text(st, 1));
	}
	sqlite3_finalize(st);
	return out;
}

int psd_db_cal_sessions(struct psd_db *db, const char *zone, psd_db_cal_session_fn fn, void *user, char *err,
                        size_t errlen)
{
	int dated = has_column(db, "cal_sessions", "started_utc");
	sqlite3_stmt *st = query(db, err, errlen, dated
	                         ? "SELECT id, zone, kind, state, started, ended, results, note,"
	                           " started_utc, ended_utc, started_local, ended_local"
	                           " FROM cal_sessions WHERE zone = ? ORDER BY id"
	                         : "SELECT id, zone, kind, state, started, ended, results, note, NULL, NULL, NULL, NULL"
	                           " FROM cal_sessions WHERE zone = ? ORDER BY id", "t", zone);
	int rc;
	if (!st)
		return -1;
	while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
		struct psd_db_cal_session s = {
			sqlite3_column_int64(st, 0), col_text(st, 1), col_text(st, 2), col_text(st, 3),
			col_num(st, 4), col_num(st, 5), col_text(st, 6), col_text(st, 7),
			col_num(st, 8), col_num(st, 9), col_text(st, 10), col_text(st, 11),
		};
		fn(user, &s);
	}
	sqlite3_finalize(st);
	return rc == SQLITE_DONE ? 0 : fail(db->h, "read", err, errlen);
}

int psd_db_run_starts(struct psd_db *db, void (*fn)(void *user, double utc), void *user, char *err, size_t errlen)
{
	sqlite3_stmt *st;
	int rc;
	if (!has_column(db, "events", "utc"))
		return 0;   /* a file from before schema 5 recorded no start */
	if (!(st = query(db, err, errlen, "SELECT utc FROM events WHERE kind = 'start' AND utc IS NOT NULL"
	                 " ORDER BY utc", "")))
		return -1;
	while ((rc = sqlite3_step(st)) == SQLITE_ROW)
		fn(user, sqlite3_column_double(st, 0));
	sqlite3_finalize(st);
	return rc == SQLITE_DONE ? 0 : fail(db->h, "read", err, errlen);
}

int psd_db_select(const char *path, const char *zone, double since, double until, long last,
                  psd_db_sample_fn fn, void *user, char *err, size_t errlen)
{
	struct psd_db *db = psd_db_open_readonly(path, err, errlen);
	char sql[512];
	sqlite3_stmt *st;
	int rc;
	if (!db)
		return -1;
	/* the last ones: the newest `last` rows, given back oldest first */
	const char *utc = has_utc(db) ? "utc" : "NULL";   /* an older log: no sample has a time */
	snprintf(sql, sizeof sql,
	         "SELECT %s FROM (SELECT rowid AS r, * FROM samples"
	         " WHERE (?1 IS NULL OR zone = ?1 OR zone IS NULL) AND (?2 IS NULL OR %s >= ?2)"
	         " AND (?3 IS NULL OR %s <= ?3) ORDER BY rowid DESC LIMIT ?4) ORDER BY r",
	         read_columns(db), utc, utc);
	if (!(st = query(db, err, errlen, sql, "tddi", zone, since, until, last > 0 ? (long long)last : -1LL))) {
		psd_db_close(db);
		return -1;
	}
	while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
		struct psd_sample s;
		row_sample(st, &s);
		fn(user, &s);
	}
	if (rc != SQLITE_DONE)
		fail(db->h, path, err, errlen);
	sqlite3_finalize(st);
	psd_db_close(db);
	return rc == SQLITE_DONE ? 0 : -1;
}

/* ---- the report's readers (psensctl report) --------------------------------- */

static int table_exists(struct psd_db *db, const char *table)
{
	sqlite3_stmt *st;
	int yes;
	if (sqlite3_prepare_v2(db->h, "SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = ?", -1, &st,
	                       NULL) != SQLITE_OK)
		return -1;
	sqlite3_bind_text(st, 1, table, -1, SQLITE_STATIC);
	yes = sqlite3_step(st) == SQLITE_ROW;
	sqlite3_finalize(st);
	return yes;
}

int psd_db_zones(struct psd_db *db, psd_db_name_fn fn, void *user, char *err, size_t errlen)
{
	int cal = table_exists(db, "cal_sessions");
	sqlite3_stmt *st;
	int rc;
	if (cal < 0)
		return fail(db->h, "read", err, errlen);
	st = query(db, err, errlen, cal ? "SELECT zone FROM samples WHERE zone IS NOT NULL UNION "
	                                  "SELECT zone FROM cal_sessions ORDER BY 1"
	                                : "SELECT DISTINCT zone FROM samples WHERE zone IS NOT NULL ORDER BY 1", "");
	if (!st)
		return -1;
	while ((rc = sqlite3_step(st)) == SQLITE_ROW)
		if (col_text(st, 0))
			fn(user, col_text(st, 0));
	sqlite3_finalize(st);
	return rc == SQLITE_DONE ? 0 : fail(db->h, "read", err, errlen);
}

int psd_db_cal_hashes(struct psd_db *db, const char *zone, char config_sha256[65], char scene_sha256[65])
{
	sqlite3_stmt *st;
	char ignored[128];
	int found = 0;
	config_sha256[0] = scene_sha256[0] = 0;
	if (table_exists(db, "cal_sessions") != 1)
		return 0;
	st = query(db, ignored, sizeof ignored, "SELECT config_sha256, scene_sha256 FROM cal_sessions"
	           " WHERE zone = ? AND config_sha256 IS NOT NULL ORDER BY id DESC LIMIT 1", "t", zone);
	if (!st)
		return -1;
	if (sqlite3_step(st) == SQLITE_ROW) {
		snprintf(config_sha256, 65, "%s", col_text(st, 0) ? col_text(st, 0) : "");
		snprintf(scene_sha256, 65, "%s", col_text(st, 1) ? col_text(st, 1) : "");
		found = 1;
	}
	sqlite3_finalize(st);
	return found;
}

int psd_db_zone_simulated(struct psd_db *db, const char *zone, char *what, size_t n)
{
	sqlite3_stmt *st;
	char ignored[128];
	int found = 0;
	what[0] = 0;
	if (table_exists(db, "events") != 1)
		return 0;
	st = query(db, ignored, sizeof ignored, "SELECT text FROM events WHERE zone = ? AND kind = 'simulated'"
	           " ORDER BY rowid DESC LIMIT 1", "t", zone);
	if (!st)
		return -1;
	if (sqlite3_step(st) == SQLITE_ROW) {
		snprintf(what, n, "%s", col_text(st, 0) ? col_text(st, 0) : "");
		found = 1;
	}
	sqlite3_finalize(st);
	return found;
}

/* ---- the MQTT publisher --------------------------------------------------------- */

int psd_db_samples_after(struct psd_db *db, long long after, int limit, psd_db_sample_row_fn fn, void *user, char *err,
                         size_t errlen)
{
	char sql[320];
	sqlite3_stmt *st;
	int rc, n = 0;
	snprintf(sql, sizeof sql, "SELECT %s, rowid FROM samples WHERE rowid > ? ORDER BY rowid LIMIT ?",
	         sample_columns);
	if (!(st = query(db, err, errlen, sql, "ii", after, (long long)limit)))
		return -1;
	while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
		struct psd_sample s;
		row_sample(st, &s);
		fn(user, sqlite3_column_int64(st, SAMPLE_NCOLUMNS), s.utc, &s);
		n++;
	}
	sqlite3_finalize(st);
	return rc == SQLITE_DONE ? n : fail(db->h, "read", err, errlen);
}

long long psd_db_last_id(struct psd_db *db)
{
	char err[256];
	sqlite3_stmt *st = query(db, err, sizeof err, "SELECT coalesce(max(rowid), 0) FROM samples", "");
	long long id = -1;
	if (!st)
		return -1;
	if (sqlite3_step(st) == SQLITE_ROW)
		id = sqlite3_column_int64(st, 0);
	sqlite3_finalize(st);
	return id;
}

long long psd_db_mqtt_cursor(struct psd_db *db, const char *site)
{
	char err[256];
	sqlite3_stmt *st = query(db, err, sizeof err, "SELECT sample FROM mqtt_cursor WHERE site = ?", "t", site);
	long long id = -1;
	int rc;
	if (!st)
		return -1;
	rc = sqlite3_step(st);
	if (rc == SQLITE_ROW)
		id = sqlite3_column_int64(st, 0);
	else if (rc == SQLITE_DONE)
		id = 0;
	sqlite3_finalize(st);
	return id;
}

int psd_db_mqtt_set_cursor(struct psd_db *db, const char *site, long long id, char *err, size_t errlen)
{
	return run(db, "INSERT OR REPLACE INTO mqtt_cursor(site, sample) VALUES(?, ?)", err, errlen, "ti", site, id);
}

int psd_db_mqtt_announced(struct psd_db *db, const char *site, psd_db_name_fn fn, void *user)
{
	char err[256];
	sqlite3_stmt *st = query(db, err, sizeof err, "SELECT zone FROM mqtt_announced WHERE site = ? ORDER BY zone",
	                         "t", site);
	int rc;
	if (!st)
		return -1;
	while ((rc = sqlite3_step(st)) == SQLITE_ROW)
		fn(user, col_text(st, 0));
	sqlite3_finalize(st);
	return rc == SQLITE_DONE ? 0 : -1;
}

int psd_db_mqtt_announce(struct psd_db *db, const char *site, const char *zone, int add, char *err, size_t errlen)
{
	if (add)
		return run(db, "INSERT OR IGNORE INTO mqtt_announced(site, zone) VALUES(?, ?)", err, errlen, "tt", site,
		           zone);
	return run(db, "DELETE FROM mqtt_announced WHERE site = ? AND zone = ?", err, errlen, "tt", site, zone);
}
