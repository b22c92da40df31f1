#include "db.h"

#include <math.h>
#include <sqlite3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { DB_BATCH = 60 };

struct psd_db {
	sqlite3 *h;
	sqlite3_stmt *ins;
	int pending;          /* samples in the open transaction */
	int batch;
	unsigned long committed;
};

void psd_db_set_batch(struct psd_db *db, int batch)
{
	db->batch = batch > 0 ? batch : 1;
}

struct sqlite3 *psd_db_sqlite(struct psd_db *db)
{
	return db->h;
}

unsigned long psd_db_committed(const struct psd_db *db)
{
	return db->committed;
}

static int fail(sqlite3 *h, const char *what, char *err, size_t errlen)
{
	snprintf(err, errlen, "%s: %s", what, h ? sqlite3_errmsg(h) : "out of memory");
	return -1;
}

static const char schema[] =
	"PRAGMA journal_mode=WAL;"
	"PRAGMA synchronous=NORMAL;"
	"CREATE TABLE IF NOT EXISTS meta(key TEXT PRIMARY KEY, value TEXT);"
	"INSERT OR IGNORE INTO meta VALUES('schema', '1');"
	"CREATE TABLE IF NOT EXISTS samples("
	" t REAL NOT NULL, tod_s REAL, sensor_v REAL, output REAL, est_task_lux REAL,"
	" task_lux REAL, daylight_v REAL, daylight_lux REAL, condition TEXT, ratio REAL, fault TEXT);"
	"CREATE INDEX IF NOT EXISTS samples_t ON samples(t);";

/* Schema 2 names the zone of each sample (several zones share one log). */
static int migrate(sqlite3 *h)
{
	sqlite3_stmt *st;
	int has_zone = 0;
	if (sqlite3_prepare_v2(h, "PRAGMA table_info(samples)", -1, &st, NULL) != SQLITE_OK)
		return -1;
	while (sqlite3_step(st) == SQLITE_ROW)
		has_zone |= strcmp((const char *)sqlite3_column_text(st, 1), "zone") == 0;
	sqlite3_finalize(st);
	if (has_zone)
		return 0;
	return sqlite3_exec(h, "BEGIN; ALTER TABLE samples ADD COLUMN zone TEXT;"
	                       " UPDATE meta SET value = '2' WHERE key = 'schema'; COMMIT;",
	                    NULL, NULL, NULL) == SQLITE_OK ? 0 : -1;
}

struct psd_db *psd_db_open(const char *path, char *err, size_t errlen)
{
	struct psd_db *db = calloc(1, sizeof *db);
	char *msg = NULL;
	if (!db) {
		snprintf(err, errlen, "%s: out of memory", path);
		return NULL;
	}
	if (sqlite3_open_v2(path, &db->h, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, NULL) != SQLITE_OK) {
		fail(db->h, path, err, errlen);
		goto bad;
	}
	sqlite3_busy_timeout(db->h, 2000);   /* readers (psensctl export) may hold it briefly */
	if (sqlite3_exec(db->h, schema, NULL, NULL, &msg) != SQLITE_OK) {
		snprintf(err, errlen, "%s: %s", path, msg ? msg : "schema");
		sqlite3_free(msg);
		goto bad;
	}
	if (migrate(db->h) != 0) {
		fail(db->h, path, err, errlen);
		goto bad;
	}
	db->batch = DB_BATCH;
	if (sqlite3_prepare_v2(db->h,
	                       "INSERT INTO samples(t, tod_s, sensor_v, output, est_task_lux, task_lux,"
	                       " daylight_v, daylight_lux, condition, ratio, fault, zone)"
	                       " VALUES(?,?,?,?,?,?,?,?,?,?,?,?)", -1, &db->ins,
	                       NULL) != SQLITE_OK) {
		fail(db->h, path, err, errlen);
		goto bad;
	}
	return db;
bad:
	sqlite3_close(db->h);
	free(db);
	return NULL;
}

static void bind_num(sqlite3_stmt *st, int i, double v)
{
	if (isnan(v))
		sqlite3_bind_null(st, i);
	else
		sqlite3_bind_double(st, i, v);
}

int psd_db_add(struct psd_db *db, const struct psd_sample *s, char *err, size_t errlen)
{
	if (db->pending == 0 && sqlite3_exec(db->h, "BEGIN", NULL, NULL, NULL) != SQLITE_OK)
		return fail(db->h, "begin", err, errlen);
	bind_num(db->ins, 1, s->t);
	bind_num(db->ins, 2, s->tod_s);
	bind_num(db->ins, 3, s->sensor_v);
	bind_num(db->ins, 4, s->output);
	bind_num(db->ins, 5, s->est_task_lux);
	bind_num(db->ins, 6, s->task_lux);
	bind_num(db->ins, 7, s->daylight_v);
	bind_num(db->ins, 8, s->daylight_lux);
	if (s->condition)
		sqlite3_bind_text(db->ins, 9, s->condition, -1, SQLITE_TRANSIENT);
	else
		sqlite3_bind_null(db->ins, 9);
	bind_num(db->ins, 10, s->ratio);
	if (s->fault)
		sqlite3_bind_text(db->ins, 11, s->fault, -1, SQLITE_TRANSIENT);
	else
		sqlite3_bind_null(db->ins, 11);
	if (s->zone)
		sqlite3_bind_text(db->ins, 12, s->zone, -1, SQLITE_TRANSIENT);
	else
		sqlite3_bind_null(db->ins, 12);
	if (sqlite3_step(db->ins) != SQLITE_DONE) {
		sqlite3_reset(db->ins);
		return fail(db->h, "insert", err, errlen);
	}
	sqlite3_reset(db->ins);
	if (++db->pending >= db->batch)
		return psd_db_commit(db, err, errlen);
	return 0;
}

int psd_db_commit(struct psd_db *db, char *err, size_t errlen)
{
	if (db->pending == 0)
		return 0;
	if (sqlite3_exec(db->h, "COMMIT", NULL, NULL, NULL) != SQLITE_OK)
		return fail(db->h, "commit", err, errlen);
	db->committed += (unsigned long)db->pending;
	db->pending = 0;
	return 0;
}

void psd_db_close(struct psd_db *db)
{
	char err[256];
	if (!db)
		return;
	psd_db_commit(db, err, sizeof err);
	sqlite3_finalize(db->ins);
	sqlite3_close(db->h);
	free(db);
}

static void csv_num(FILE *fp, sqlite3_stmt *st, int col)
{
	if (sqlite3_column_type(st, col) != SQLITE_NULL)
		fprintf(fp, "%.10g", sqlite3_column_double(st, col));
}

static void csv_text(FILE *fp, sqlite3_stmt *st, int col)
{
	const unsigned char *t = sqlite3_column_text(st, col);
	if (!t)
		return;
	if (strpbrk((const char *)t, ",\"\n")) {
		fputc('"', fp);
		for (; *t; t++) {
			if (*t == '"')
				fputc('"', fp);
			fputc(*t, fp);
		}
		fputc('"', fp);
	} else {
		fputs((const char *)t, fp);
	}
}

int psd_db_export_csv(const char *path, void *out, char *err, size_t errlen)
{
	FILE *fp = out;
	sqlite3 *h = NULL;
	sqlite3_stmt *st = NULL;
	int rc;
	if (sqlite3_open_v2(path, &h, SQLITE_OPEN_READONLY, NULL) != SQLITE_OK) {
		fail(h, path, err, errlen);
		sqlite3_close(h);
		return -1;
	}
	sqlite3_busy_timeout(h, 2000);
	if (sqlite3_prepare_v2(h, "SELECT t, tod_s, sensor_v, output, est_task_lux, task_lux, daylight_v,"
	                          " daylight_lux, condition, ratio, fault, zone FROM samples ORDER BY rowid",
	                       -1, &st, NULL) != SQLITE_OK) {
		fail(h, path, err, errlen);
		sqlite3_close(h);
		return -1;
	}
	fputs("t,tod_s,sensor_v,output,est_task_lux,task_lux,daylight_v,daylight_lux,condition,ratio,fault,zone\n", fp);
	while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
		for (int c = 0; c < 12; c++) {
			if (c)
				fputc(',', fp);
			if (c == 8 || c >= 10)
				csv_text(fp, st, c);
			else
				csv_num(fp, st, c);
		}
		fputc('\n', fp);
	}
	if (rc != SQLITE_DONE)
		fail(h, path, err, errlen);
	sqlite3_finalize(st);
	sqlite3_close(h);
	return rc == SQLITE_DONE ? 0 : -1;
}
