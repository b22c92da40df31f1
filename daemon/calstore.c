#include "calstore.h"

#include <math.h>
#include <stdarg.h>
#include <sqlite3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int fail(sqlite3 *h, const char *what, char *err, size_t errlen)
{
	snprintf(err, errlen, "calibration log: %s: %s", what, sqlite3_errmsg(h));
	return -1;
}

int psd_calstore_init(sqlite3 *h, char *err, size_t errlen)
{
	static const char schema[] =
		"CREATE TABLE IF NOT EXISTS cal_sessions("
		" id INTEGER PRIMARY KEY, zone TEXT NOT NULL, kind TEXT NOT NULL, state TEXT NOT NULL,"
		" started REAL, ended REAL, config_sha256 TEXT, scene_sha256 TEXT, results TEXT, note TEXT);"
		"CREATE TABLE IF NOT EXISTS cal_samples("
		" session INTEGER NOT NULL REFERENCES cal_sessions(id), seq INTEGER NOT NULL, t REAL,"
		" level REAL, volts REAL, volts_se REAL, lux REAL, source TEXT, PRIMARY KEY(session, seq));"
		"INSERT OR IGNORE INTO meta VALUES('cal_schema', '1');";
	char *msg = NULL;
	if (sqlite3_exec(h, schema, NULL, NULL, &msg) != SQLITE_OK) {
		snprintf(err, errlen, "calibration log: %s", msg ? msg : "schema");
		sqlite3_free(msg);
		return -1;
	}
	return 0;
}

static void bind_num(sqlite3_stmt *st, int i, double v)
{
	if (isfinite(v))
		sqlite3_bind_double(st, i, v);
	else
		sqlite3_bind_null(st, i);
}

/* Prepare sql, bind by the letters of fmt (t text, d double, i int64),
 * step once. */
static int run(sqlite3 *h, const char *sql, char *err, size_t errlen, const char *fmt, ...)
{
	sqlite3_stmt *st;
	va_list ap;
	int rc, i = 1;
	if (sqlite3_prepare_v2(h, sql, -1, &st, NULL) != SQLITE_OK)
		return fail(h, "prepare", err, errlen);
	va_start(ap, fmt);
	for (const char *f = fmt; *f; f++, i++) {
		if (*f == 't') {
			const char *s = va_arg(ap, const char *);
			if (s)
				sqlite3_bind_text(st, i, s, -1, SQLITE_TRANSIENT);
			else
				sqlite3_bind_null(st, i);
		} else if (*f == 'd') {
			bind_num(st, i, va_arg(ap, double));
		} else {
			sqlite3_bind_int64(st, i, va_arg(ap, long long));
		}
	}
	va_end(ap);
	rc = sqlite3_step(st);
	sqlite3_finalize(st);
	return rc == SQLITE_DONE || rc == SQLITE_ROW ? 0 : fail(h, "write", err, errlen);
}

long long psd_calstore_begin(sqlite3 *h, const char *zone, const char *kind, double started,
                             const char *config_sha256, const char *scene_sha256, char *err, size_t errlen)
{
	if (run(h, "INSERT INTO cal_sessions(zone, kind, state, started, config_sha256, scene_sha256)"
	           " VALUES(?, ?, 'running', ?, ?, ?)", err, errlen, "ttdtt", zone, kind, started, config_sha256,
	        scene_sha256) != 0)
		return -1;
	return (long long)sqlite3_last_insert_rowid(h);
}

int psd_calstore_sample(sqlite3 *h, long long id, int seq, double t, double level, double volts, double volts_se,
                        double lux, const char *source, char *err, size_t errlen)
{
	return run(h, "INSERT OR REPLACE INTO cal_samples VALUES(?, ?, ?, ?, ?, ?, ?, ?)", err, errlen, "iidddddt", id, (long long)seq, t, level, volts, volts_se, lux, source);
}

int psd_calstore_end(sqlite3 *h, long long id, const char *state, double ended, const char *results,
                     const char *note, char *err, size_t errlen)
{
	return run(h, "UPDATE cal_sessions SET state = ?, ended = ?, results = ?, note = ? WHERE id = ?", err, errlen,
	           "tdtti", state, ended, results, note, id);
}

int psd_calstore_accept(sqlite3 *h, long long id, char *err, size_t errlen)
{
	if (sqlite3_exec(h, "SAVEPOINT accept", NULL, NULL, NULL) != SQLITE_OK)
		return fail(h, "begin", err, errlen);
	if (run(h, "UPDATE cal_sessions SET state = 'superseded' WHERE state = 'accepted' AND"
	           " (zone, kind) = (SELECT zone, kind FROM cal_sessions WHERE id = ?)", err, errlen, "i", id) != 0 ||
	    run(h, "UPDATE cal_sessions SET state = 'accepted' WHERE id = ? AND state = 'done'", err, errlen, "i",
	        id) != 0) {
		sqlite3_exec(h, "ROLLBACK TO accept; RELEASE accept", NULL, NULL, NULL);
		return -1;
	}
	return sqlite3_exec(h, "RELEASE accept", NULL, NULL, NULL) == SQLITE_OK ? 0 : fail(h, "commit", err, errlen);
}

int psd_calstore_running(sqlite3 *h, const char *zone, long long *id, char *kind, size_t kindlen, double *started)
{
	sqlite3_stmt *st;
	int rc;
	if (sqlite3_prepare_v2(h, "SELECT id, kind, started FROM cal_sessions WHERE zone = ? AND state = 'running'"
	                          " ORDER BY id DESC LIMIT 1", -1, &st, NULL) != SQLITE_OK)
		return -1;
	sqlite3_bind_text(st, 1, zone, -1, SQLITE_TRANSIENT);
	rc = sqlite3_step(st);
	if (rc == SQLITE_ROW) {
		*id = sqlite3_column_int64(st, 0);
		snprintf(kind, kindlen, "%s", (const char *)sqlite3_column_text(st, 1));
		*started = sqlite3_column_double(st, 2);
	}
	sqlite3_finalize(st);
	return rc == SQLITE_ROW ? 0 : rc == SQLITE_DONE ? 1 : -1;
}

static double col(sqlite3_stmt *st, int i)
{
	return sqlite3_column_type(st, i) == SQLITE_NULL ? NAN : sqlite3_column_double(st, i);
}

int psd_calstore_samples(sqlite3 *h, long long id, psd_calstore_sample_fn fn, void *user)
{
	sqlite3_stmt *st;
	int rc;
	if (sqlite3_prepare_v2(h, "SELECT t, level, volts, volts_se, lux FROM cal_samples WHERE session = ?"
	                          " ORDER BY seq", -1, &st, NULL) != SQLITE_OK)
		return -1;
	sqlite3_bind_int64(st, 1, id);
	while ((rc = sqlite3_step(st)) == SQLITE_ROW)
		fn(user, col(st, 0), col(st, 1), col(st, 2), col(st, 3), col(st, 4));
	sqlite3_finalize(st);
	return rc == SQLITE_DONE ? 0 : -1;
}

char *psd_calstore_accepted(sqlite3 *h, const char *zone, const char *kind, long long *id)
{
	sqlite3_stmt *st;
	char *out = NULL;
	if (sqlite3_prepare_v2(h, "SELECT id, results FROM cal_sessions WHERE zone = ? AND kind = ? AND"
	                          " state = 'accepted' ORDER BY id DESC LIMIT 1", -1, &st, NULL) != SQLITE_OK)
		return NULL;
	sqlite3_bind_text(st, 1, zone, -1, SQLITE_TRANSIENT);
	sqlite3_bind_text(st, 2, kind, -1, SQLITE_TRANSIENT);
	if (sqlite3_step(st) == SQLITE_ROW && sqlite3_column_text(st, 1)) {
		*id = sqlite3_column_int64(st, 0);
		out = strdup((const char *)sqlite3_column_text(st, 1));
	}
	sqlite3_finalize(st);
	return out;
}
