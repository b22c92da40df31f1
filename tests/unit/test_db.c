/* SPDX-License-Identifier: ISC */
/* The database's schema and its migrations: files written by earlier
 * psensd versions (made here with the statements those versions ran) are
 * brought forward in place with every row kept; a newer file is refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <sqlite3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

#include "db.h"

static char path[64];

static int setup(void **state)
{
	int fd;
	(void)state;
	snprintf(path, sizeof path, "/tmp/test_db.XXXXXX");
	fd = mkstemp(path);
	if (fd < 0)
		return -1;
	close(fd);
	unlink(path);
	return 0;
}

static int teardown(void **state)
{
	char wal[80];
	(void)state;
	unlink(path);
	snprintf(wal, sizeof wal, "%s-wal", path);
	unlink(wal);
	snprintf(wal, sizeof wal, "%s-shm", path);
	unlink(wal);
	return 0;
}

static void exec(const char *sql)
{
	sqlite3 *h;
	assert_int_equal(sqlite3_open(path, &h), SQLITE_OK);
	assert_int_equal(sqlite3_exec(h, sql, NULL, NULL, NULL), SQLITE_OK);
	sqlite3_close(h);
}

static long long scalar(const char *sql)
{
	sqlite3 *h;
	sqlite3_stmt *st;
	long long v = -1;
	assert_int_equal(sqlite3_open(path, &h), SQLITE_OK);
	assert_int_equal(sqlite3_prepare_v2(h, sql, -1, &st, NULL), SQLITE_OK);
	if (sqlite3_step(st) == SQLITE_ROW)
		v = sqlite3_column_int64(st, 0);
	sqlite3_finalize(st);
	sqlite3_close(h);
	return v;
}

/* What version 1 wrote: the sample log without zones. */
static const char v1[] =
	"CREATE TABLE meta(key TEXT PRIMARY KEY, value TEXT);"
	"INSERT INTO meta VALUES('schema', '1');"
	"CREATE TABLE samples(t REAL NOT NULL, tod_s REAL, sensor_v REAL, output REAL, est_task_lux REAL,"
	" task_lux REAL, daylight_v REAL, daylight_lux REAL, condition TEXT, ratio REAL, fault TEXT);"
	"CREATE INDEX samples_t ON samples(t);"
	"INSERT INTO samples VALUES(21600, 21600, 0.5, 1, 600, NULL, 0.1, 47, 'daylight_mean', 236, NULL);"
	"INSERT INTO samples VALUES(21660, 21660, 0.0, 1, NULL, NULL, NULL, NULL, 'daylight_mean', 236, 'open');";

static void from_version_1(void **state)
{
	char err[256];
	struct psd_db *db;
	(void)state;
	exec(v1);
	db = psd_db_open(path, err, sizeof err);
	assert_non_null(db);
	assert_int_equal(psd_db_schema(db), PSD_DB_SCHEMA);
	/* the old rows, with no zone, belong to every zone's report */
	assert_int_equal(psd_db_zone_count(db, "office", err, sizeof err), 2);
	assert_true(psd_db_cal_begin(db, "office", "night", 0, "", "", err, sizeof err) > 0);
	psd_db_close(db);
	assert_int_equal(scalar("SELECT count(*) FROM samples"), 2);
	assert_int_equal(scalar("SELECT count(*) FROM samples WHERE zone IS NULL AND fault = 'open'"), 1);
	assert_int_equal(scalar("SELECT value FROM meta WHERE key = 'schema'"), PSD_DB_SCHEMA);
	assert_int_equal(scalar("SELECT count(*) FROM cal_sessions"), 1);
}

/* What version 2 wrote: zones, and the calibration tables made apart
 * (meta 'cal_schema' 1) with a session on record. */
static void from_version_2(void **state)
{
	char err[256];
	struct psd_db *db;
	struct psd_sample s = { 30000, 30000, 1.2, 0.5, 510, NAN, 0.9, 212, "daylight_mean", 236, NULL, "office",
	                        NAN, NULL, -1, NAN };
	(void)state;
	exec(v1);
	exec("ALTER TABLE samples ADD COLUMN zone TEXT; UPDATE meta SET value = '2' WHERE key = 'schema';"
	     "CREATE TABLE cal_sessions(id INTEGER PRIMARY KEY, zone TEXT NOT NULL, kind TEXT NOT NULL,"
	     " state TEXT NOT NULL, started REAL, ended REAL, config_sha256 TEXT, scene_sha256 TEXT, results TEXT,"
	     " note TEXT);"
	     "CREATE TABLE cal_samples(session INTEGER NOT NULL REFERENCES cal_sessions(id), seq INTEGER NOT NULL,"
	     " t REAL, level REAL, volts REAL, volts_se REAL, lux REAL, source TEXT, PRIMARY KEY(session, seq));"
	     "INSERT INTO meta VALUES('cal_schema', '1');"
	     "INSERT INTO cal_sessions VALUES(7, 'office', 'night', 'accepted', 75600, 77000, 'a', 'b',"
	     " '{\"offset\":0.05}', NULL);"
	     "INSERT INTO cal_samples VALUES(7, 0, 75900, 1, 0.597, 0.0005, NULL, 'settled');");
	db = psd_db_open(path, err, sizeof err);
	assert_non_null(db);
	assert_int_equal(psd_db_schema(db), PSD_DB_SCHEMA);
	{
		long long id = 0;
		char *json = psd_db_cal_accepted(db, "office", "night", &id);
		assert_non_null(json);
		assert_int_equal(id, 7);
		assert_string_equal(json, "{\"offset\":0.05}");
		free(json);
	}
	/* and it goes on logging */
	assert_int_equal(psd_db_add(db, &s, err, sizeof err), 0);
	assert_int_equal(psd_db_commit(db, err, sizeof err), 0);
	psd_db_close(db);
	assert_int_equal(scalar("SELECT count(*) FROM samples"), 3);
	assert_int_equal(scalar("SELECT count(*) FROM samples WHERE zone = 'office'"), 1);
	assert_int_equal(scalar("SELECT count(*) FROM cal_samples WHERE session = 7"), 1);
}

/* What version 3 wrote (no dates): samples of two zones, a
 * session and its samples.  Version 4 keeps every row and value, leaves
 * the dates of old rows unknown (NULL, never made up), and dates what is
 * logged after it: UTC = the epoch of clock 0 + t, and the local text. */
static void from_version_3(void **state)
{
	char err[256];
	struct psd_db *db;
	struct psd_sample s = { 36000, 36000, 1.0, 0.4, 505, 498, 0.8, 200, "daylight_mean", 236, NULL, "office",
	                        NAN, NULL, -1, NAN };
	const double epoch0 = 1773792000;   /* 2026-03-18 00:00 UTC */
	(void)state;
	exec(v1);
	exec("ALTER TABLE samples ADD COLUMN zone TEXT; UPDATE meta SET value = '3' WHERE key = 'schema';"
	     "UPDATE samples SET zone = 'office';"
	     "INSERT INTO samples VALUES(21600, 21600, 0.6, 1, 610, 600, 0.1, 47, 'daylight_mean', 236, NULL, 'hall');"
	     "CREATE TABLE cal_sessions(id INTEGER PRIMARY KEY, zone TEXT NOT NULL, kind TEXT NOT NULL,"
	     " state TEXT NOT NULL, started REAL, ended REAL, config_sha256 TEXT, scene_sha256 TEXT, results TEXT,"
	     " note TEXT);"
	     "CREATE TABLE cal_samples(session INTEGER NOT NULL REFERENCES cal_sessions(id), seq INTEGER NOT NULL,"
	     " t REAL, level REAL, volts REAL, volts_se REAL, lux REAL, source TEXT, PRIMARY KEY(session, seq));"
	     "INSERT INTO cal_sessions VALUES(3, 'office', 'night', 'accepted', 75600, 77000, 'a', 'b',"
	     " '{\"offset\":0.05}', NULL);"
	     "INSERT INTO cal_samples VALUES(3, 0, 75900, 1, 0.597, 0.0005, NULL, 'settled');"
	     "INSERT INTO cal_samples VALUES(3, 1, 76200, 0.75, 0.458, 0.0006, NULL, 'settled');");
	assert_int_equal(scalar("SELECT count(*) FROM samples"), 3);
	db = psd_db_open(path, err, sizeof err);
	assert_non_null(db);
	assert_int_equal(psd_db_schema(db), PSD_DB_SCHEMA);
	assert_true(PSD_DB_SCHEMA >= 4);
	assert_true(isnan(psd_db_last_utc(db)));   /* old rows: no date on record */
	psd_db_set_epoch(db, epoch0);
	assert_int_equal(psd_db_add(db, &s, err, sizeof err), 0);
	assert_int_equal(psd_db_commit(db, err, sizeof err), 0);
	assert_int_equal(psd_db_event(db, 43200, "office", "fault", "sensor reads 0.000 V", err, sizeof err), 0);
	assert_true(psd_db_last_utc(db) == epoch0 + 36000);
	psd_db_close(db);
	/* every old row and value kept */
	assert_int_equal(scalar("SELECT count(*) FROM samples"), 4);
	assert_int_equal(scalar("SELECT count(*) FROM samples WHERE utc IS NULL AND local IS NULL"), 3);
	assert_int_equal(scalar("SELECT count(*) FROM samples WHERE zone = 'office' AND fault = 'open' AND t = 21660"), 1);
	assert_int_equal(scalar("SELECT count(*) FROM samples WHERE zone = 'hall' AND est_task_lux = 610"), 1);
	assert_int_equal(scalar("SELECT count(*) FROM cal_sessions WHERE id = 3 AND state = 'accepted' AND"
	                        " started = 75600 AND started_utc IS NULL"), 1);
	assert_int_equal(scalar("SELECT count(*) FROM cal_samples WHERE session = 3 AND utc IS NULL"), 2);
	assert_int_equal(scalar("SELECT sum(volts * 1000) FROM cal_samples"), 597 + 458);
	/* the new row: its UTC, and its local text is that UTC's local time */
	assert_int_equal(scalar("SELECT utc FROM samples WHERE t = 36000"), 1773792000 + 36000);
	assert_int_equal(scalar("SELECT local = strftime('%Y-%m-%d %H:%M:%S', utc, 'unixepoch', 'localtime')"
	                        " FROM samples WHERE t = 36000"), 1);
	assert_int_equal(scalar("SELECT count(*) FROM events WHERE kind = 'fault' AND utc = 1773792000 + 43200"), 1);
	assert_int_equal(scalar("SELECT value FROM meta WHERE key = 'schema'"), PSD_DB_SCHEMA);
}

/* What version 6 wrote: every table to the acceptance tests, samples
 * with dates but neither occupancy nor truth. */
static const char v6[] =
	"CREATE TABLE meta(key TEXT PRIMARY KEY, value TEXT);"
	"INSERT INTO meta VALUES('schema', '6');"
	"CREATE TABLE samples(t REAL NOT NULL, tod_s REAL, sensor_v REAL, output REAL, est_task_lux REAL,"
	" task_lux REAL, daylight_v REAL, daylight_lux REAL, condition TEXT, ratio REAL, fault TEXT, zone TEXT,"
	" utc REAL, local TEXT);"
	"CREATE INDEX samples_t ON samples(t); CREATE INDEX samples_utc ON samples(utc);"
	"CREATE TABLE cal_sessions(id INTEGER PRIMARY KEY, zone TEXT NOT NULL, kind TEXT NOT NULL,"
	" state TEXT NOT NULL, started REAL, ended REAL, config_sha256 TEXT, scene_sha256 TEXT, results TEXT,"
	" note TEXT, started_utc REAL, started_local TEXT, ended_utc REAL, ended_local TEXT);"
	"CREATE TABLE cal_samples(session INTEGER NOT NULL REFERENCES cal_sessions(id), seq INTEGER NOT NULL,"
	" t REAL, level REAL, volts REAL, volts_se REAL, lux REAL, source TEXT, utc REAL, local TEXT,"
	" PRIMARY KEY(session, seq));"
	"CREATE TABLE events(t REAL, utc REAL, local TEXT, zone TEXT, kind TEXT NOT NULL, text TEXT);"
	"CREATE TABLE mqtt_cursor(site TEXT PRIMARY KEY, sample INTEGER NOT NULL);"
	"CREATE TABLE mqtt_announced(site TEXT NOT NULL, zone TEXT NOT NULL, PRIMARY KEY(site, zone));"
	"CREATE TABLE zone_consts(zone TEXT PRIMARY KEY, utc REAL, target_lux REAL, elec_task_lux REAL, delay REAL);"
	"CREATE TABLE acceptance_tests(id INTEGER PRIMARY KEY, zone TEXT NOT NULL, local TEXT, test TEXT NOT NULL,"
	" verdict TEXT NOT NULL, value REAL, limit_value REAL, samples INTEGER, measured TEXT, utc REAL);"
	"INSERT INTO samples VALUES(30000, 30000, 1.2, 0.5, 510, 498, 0.9, 212, 'daylight_mean', 236, NULL,"
	" 'office', 1773822000, '2026-03-18 08:20:00');"
	"INSERT INTO samples VALUES(30060, 30060, 1.3, 0.4, 520, 505, 1.0, 236, 'daylight_mean', 236, NULL,"
	" 'office', 1773822060, '2026-03-18 08:21:00');"
	"INSERT INTO zone_consts VALUES('office', 1773822000, 500, 1265.4, 300);";

struct rows {
	int n, occupied[4];
	double est[4], truth[4];
};

static void take_row(void *user, const struct psd_sample *s)
{
	struct rows *r = user;
	if (r->n < 4) {
		r->occupied[r->n] = s->occupied;
		r->est[r->n] = s->est_task_lux;
		r->truth[r->n] = s->true_task_lux;
	}
	r->n++;
}

/* Version 6 to 7: a reader of the old file sees no occupancy and no truth
 * (-1, NAN); opened to write, the file gains both columns, every row and
 * value kept with NULL in them, and the rows logged after carry them. */
static void from_version_6(void **state)
{
	char err[256];
	struct psd_db *db;
	struct rows r = { 0 };
	struct psd_sample s = { 30120, 30120, 1.4, 0, 515, 510, 1.1, 260, "daylight_mean", 236, NULL, "office",
	                        1773822120, NULL, 0, 512.5 };
	double target, elec, delay;
	(void)state;
	exec(v6);
	db = psd_db_open_readonly(path, err, sizeof err);
	assert_non_null(db);
	assert_int_equal(psd_db_zone_samples(db, "office", take_row, &r, err, sizeof err), 0);
	psd_db_close(db);
	assert_int_equal(r.n, 2);
	assert_int_equal(r.occupied[0], -1);
	assert_true(isnan(r.truth[1]));
	assert_int_equal(scalar("SELECT value FROM meta WHERE key = 'schema'"), 6);   /* a reader migrates nothing */
	db = psd_db_open(path, err, sizeof err);
	assert_non_null(db);
	assert_int_equal(psd_db_schema(db), 7);
	assert_int_equal(psd_db_add(db, &s, err, sizeof err), 0);
	s.t = s.tod_s = 30180;
	s.utc += 60;
	s.occupied = -1;
	s.true_task_lux = NAN;
	assert_int_equal(psd_db_add(db, &s, err, sizeof err), 0);
	assert_int_equal(psd_db_commit(db, err, sizeof err), 0);
	assert_int_equal(psd_db_zone_consts_get(db, "office", &target, &elec, &delay), 0);
	assert_true(target == 500 && elec == 1265.4 && delay == 300);
	r.n = 0;
	assert_int_equal(psd_db_zone_samples(db, "office", take_row, &r, err, sizeof err), 0);
	psd_db_close(db);
	assert_int_equal(r.n, 4);
	assert_true(r.est[0] == 510 && r.est[1] == 520);
	assert_int_equal(r.occupied[1], -1);
	assert_int_equal(r.occupied[2], 0);
	assert_true(r.truth[2] == 512.5);
	assert_int_equal(r.occupied[3], -1);
	assert_true(isnan(r.truth[3]));
	assert_int_equal(scalar("SELECT count(*) FROM samples"), 4);
	assert_int_equal(scalar("SELECT count(*) FROM samples WHERE occupied IS NULL AND true_task_lux IS NULL"), 3);
	assert_int_equal(scalar("SELECT count(*) FROM samples WHERE local = '2026-03-18 08:21:00' AND output = 0.4"), 1);
	assert_int_equal(scalar("SELECT value FROM meta WHERE key = 'schema'"), 7);
}

/* A file from a newer psensd is not touched. */
/* What version 4 wrote (MQTT: samples.utc, the cursor and the zones
 * announced), and a development file of 4 that had the dates of 5
 * already (samples.local): both come forward, an existing column kept,
 * every row and the MQTT cursor with them. */
static void from_version_4(void **state)
{
	static const char *const extra[2] = { "", "ALTER TABLE samples ADD COLUMN local TEXT;"
	                                          "ALTER TABLE cal_samples ADD COLUMN utc REAL;" };
	char err[256];
	(void)state;
	for (int k = 0; k < 2; k++) {
		struct psd_db *db;
		teardown(NULL);
		exec(v1);
		exec("ALTER TABLE samples ADD COLUMN zone TEXT;"
		     "CREATE TABLE cal_sessions(id INTEGER PRIMARY KEY, zone TEXT NOT NULL, kind TEXT NOT NULL,"
		     " state TEXT NOT NULL, started REAL, ended REAL, config_sha256 TEXT, scene_sha256 TEXT,"
		     " results TEXT, note TEXT);"
		     "CREATE TABLE cal_samples(session INTEGER NOT NULL REFERENCES cal_sessions(id), seq INTEGER NOT NULL,"
		     " t REAL, level REAL, volts REAL, volts_se REAL, lux REAL, source TEXT, PRIMARY KEY(session, seq));"
		     "ALTER TABLE samples ADD COLUMN utc REAL;"
		     "CREATE TABLE mqtt_cursor(site TEXT PRIMARY KEY, sample INTEGER NOT NULL);"
		     "CREATE TABLE mqtt_announced(site TEXT NOT NULL, zone TEXT NOT NULL, PRIMARY KEY(site, zone));"
		     "INSERT INTO mqtt_cursor VALUES('b1', 2);"
		     "UPDATE samples SET utc = 1773792000 + t;"
		     "UPDATE meta SET value = '4' WHERE key = 'schema';");
		exec(extra[k]);
		db = psd_db_open(path, err, sizeof err);
		if (!db)
			fail_msg("%s", err);
		assert_int_equal(psd_db_schema(db), PSD_DB_SCHEMA);
		assert_int_equal(psd_db_mqtt_cursor(db, "b1"), 2);
		assert_true(psd_db_last_utc(db) == 1773792000.0 + 21660);
		psd_db_close(db);
		assert_int_equal(scalar("SELECT count(*) FROM samples WHERE utc IS NOT NULL AND local IS NULL"), 2);
		assert_int_equal(scalar("SELECT count(*) FROM events"), 0);
		assert_int_equal(scalar("SELECT count(*) FROM acceptance_tests"), 0);
	}
}

static void newer_refused(void **state)
{
	char err[256];
	(void)state;
	exec("CREATE TABLE meta(key TEXT PRIMARY KEY, value TEXT); INSERT INTO meta VALUES('schema', '99');");
	assert_null(psd_db_open(path, err, sizeof err));
	assert_non_null(strstr(err, "schema version 99 is newer than this psensd's"));
	assert_int_equal(scalar("SELECT value FROM meta WHERE key = 'schema'"), 99);
}

/* A reader (psensctl report, export, log, accept-test) given a file that is
 * not a psensd log names the file and says what it is not, before SQLite's
 * words alone ("no such table: samples") reach the user; the file is left
 * as it was. */
static void reader_names_the_file(void **state)
{
	char err[256];
	FILE *fp;
	(void)state;
	assert_non_null(fp = fopen(path, "w"));
	fputs("zone,time\nnot a database\n", fp);
	fclose(fp);
	assert_null(psd_db_open_readonly(path, err, sizeof err));
	assert_non_null(strstr(err, path));
	assert_non_null(strstr(err, "not a database"));
	assert_int_equal(psd_db_export_csv(path, stdout, err, sizeof err), -1);
	assert_non_null(strstr(err, path));
	unlink(path);

	exec("CREATE TABLE foo(a);");
	assert_null(psd_db_open_readonly(path, err, sizeof err));
	assert_non_null(strstr(err, path));
	assert_non_null(strstr(err, "not a psensd database"));
	assert_int_equal(scalar("SELECT count(*) FROM sqlite_master"), 1);
	unlink(path);

	exec("CREATE TABLE meta(key TEXT PRIMARY KEY, value TEXT); INSERT INTO meta VALUES('schema', '99');"
	     "CREATE TABLE samples(t REAL);");
	assert_null(psd_db_open_readonly(path, err, sizeof err));
	assert_non_null(strstr(err, path));
	assert_non_null(strstr(err, "schema version 99 is newer than this psensd's"));
}

/* A new file is made at the current version; opening it again changes
 * nothing. */
static void new_file(void **state)
{
	char err[256];
	struct psd_db *db;
	(void)state;
	for (int i = 0; i < 2; i++) {
		db = psd_db_open(path, err, sizeof err);
		assert_non_null(db);
		assert_int_equal(psd_db_schema(db), PSD_DB_SCHEMA);
		psd_db_close(db);
	}
	assert_int_equal(scalar("SELECT count(*) FROM meta"), 1);
	db = psd_db_open_readonly(path, err, sizeof err);
	assert_non_null(db);
	assert_int_equal(psd_db_schema(db), PSD_DB_SCHEMA);
	psd_db_close(db);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test_setup_teardown(from_version_1, setup, teardown),
		cmocka_unit_test_setup_teardown(from_version_2, setup, teardown),
		cmocka_unit_test_setup_teardown(from_version_3, setup, teardown),
		cmocka_unit_test_setup_teardown(from_version_4, setup, teardown),
		cmocka_unit_test_setup_teardown(from_version_6, setup, teardown),
		cmocka_unit_test_setup_teardown(newer_refused, setup, teardown),
		cmocka_unit_test_setup_teardown(new_file, setup, teardown),
		cmocka_unit_test_setup_teardown(reader_names_the_file, setup, teardown),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
