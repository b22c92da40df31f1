/* SPDX-License-Identifier: ISC */
/* The commissioning record as a document: its text boxes never overlap and
 * its pages are filled, on a database like the example's (two simulated
 * days of a zone with a fault, night and day sessions with the longest
 * results the report prints, an aborted session with its reason, a second
 * zone never calibrated); the old report's overlap is caught by the same
 * check; a misspelled zone is an error naming the zones and writes no file. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cairo.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <cmocka.h>
#include <sqlite3.h>

#include "canvas.h"
#include "db.h"
#include "report.h"
#include "textbox.h"

static char dir[64], dbpath[96];

static void make_db(void)
{
	char err[256];
	struct psd_db *db = psd_db_open(dbpath, err, sizeof err);
	long long id;
	assert_non_null(db);
	/* dated as psensd dates them (clock 0 = 2026-03-18 00:00 UTC): a row
	 * with no date would be stamped with the wall clock (db.h) */
	psd_db_set_epoch(db, 1773792000.0);
	for (int day = 0; day < 2; day++)
		for (double tod = 6 * 3600; tod < 20 * 3600; tod += 60) {
			double t = day * 86400 + tod, sun = fmax(0, sin(M_PI * (tod - 6 * 3600) / (13 * 3600)));
			int fault = day == 0 && tod >= 12 * 3600 && tod < 12 * 3600 + 1200;
			for (int z = 0; z < 2; z++) {
				struct psd_sample s = { t, tod, fault ? 0 : 0.05 + 3 * sun, fault ? 1 : fmax(0.1, 1 - 2 * sun),
					                fault ? NAN : 500 + 1500 * sun, 505 + 1490 * sun, 3 * sun, 1500 * sun,
					                "clear", 470, fault ? "sensor reads 0.000 V" : NULL,
					                z ? "corridor" : "office", NAN, NULL, -1, NAN };
				assert_int_equal(psd_db_add(db, &s, err, sizeof err), 0);
			}
		}
	assert_int_equal(psd_db_commit(db, err, sizeof err), 0);
	id = psd_db_cal_begin(db, "office", "night", 2 * 3600, "a1b2", "c3d4", err, sizeof err);
	assert_true(id > 0);
	assert_int_equal(psd_db_cal_end(db, id, "done", 3 * 3600,
	                                "{\"offset\":0.0490,\"gain\":0.5486,\"gain_se\":0.0001,\"r2\":0.999999,"
	                                "\"max_resid_pct\":0.20,\"electric_lux_error_pct\":1.2}", NULL, err, sizeof err),
	                 0);
	assert_int_equal(psd_db_cal_accept(db, id, err, sizeof err), 0);
	id = psd_db_cal_begin(db, "office", "day", 10 * 3600, "a1b2", "c3d4", err, sizeof err);
	assert_int_equal(psd_db_cal_end(db, id, "done", 10.5 * 3600,
	                                "{\"ratio\":472.91,\"ratio_se\":0.52,\"samples\":12,\"sim_ratio\":471.14,"
	                                "\"condition\":\"clear sky, sun in view of the window\",\"error_pct\":0.4}",
	                                NULL, err, sizeof err), 0);
	assert_int_equal(psd_db_cal_accept(db, id, err, sizeof err), 0);
	id = psd_db_cal_begin(db, "office", "night", 12 * 3600, "a1b2", "c3d4", err, sizeof err);
	assert_int_equal(psd_db_cal_end(db, id, "aborted", 12 * 3600 + 60, NULL,
	                                "fault: sensor reads 0.000 V, outside 0.01 to 9.9 V; the lights went to the "
	                                "safe level and the session was abandoned", err, sizeof err), 0);
	psd_db_close(db);
	/* acceptance tests, in a table of their own (the report shows any such
	 * table's columns, the zone's rows only) */
	{
		sqlite3 *h;
		assert_int_equal(sqlite3_open(dbpath, &h), SQLITE_OK);
		/* the table is psensd's own since schema 5 (psensctl accept-test) */
		assert_int_equal(sqlite3_exec(h, "INSERT INTO acceptance_tests(zone, test, measured, verdict) VALUES"
		                                 "('office', 'daylight 150 % of design', 'lights at 10 % power', 'PASS'),"
		                                 "('corridor', 'little daylight', 'task 96 % of target', 'PASS');",
		                              NULL, NULL, NULL), SQLITE_OK);
		sqlite3_close(h);
	}
}

static int setup(void **state)
{
	(void)state;
	snprintf(dir, sizeof dir, "/tmp/test_report.XXXXXX");
	if (!mkdtemp(dir))
		return -1;
	snprintf(dbpath, sizeof dbpath, "%s/psensd.db", dir);
	make_db();
	return 0;
}

static int teardown(void **state)
{
	char cmd[160];
	(void)state;
	snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
	return system(cmd) == 0 ? 0 : -1;
}

/* The old SVG report's sessions row: the result at x 350 and the verdict at
 * x 730, both 12 px DejaVu Sans, measured with cairo as the SVG viewer
 * would set them: the result runs into the verdict. */
static void old_overlap_is_caught(void **state)
{
	cairo_surface_t *s = cairo_image_surface_create(CAIRO_FORMAT_RGB24, 10, 10);
	cairo_t *cr = cairo_create(s);
	struct psd_textboxes r = { 0 };
	cairo_text_extents_t a, b;
	size_t i, j;
	static const char res[] = "offset 0.0490 V, 0.5486 V at full (se 0.0001), R2 0.999999, worst residual 0.20 %";
	static const char des[] = "electric lux +1.2 % pass";
	(void)state;
	cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
	cairo_set_font_size(cr, 12);
	cairo_text_extents(cr, res, &a);
	cairo_text_extents(cr, des, &b);
	assert_int_equal(psd_textbox_add(&r, 1, 350, 500 - 11, 350 + a.x_advance, 503, res), 0);
	assert_int_equal(psd_textbox_add(&r, 1, 730, 500 - 11, 730 + b.x_advance, 503, des), 0);
	assert_int_equal(psd_textbox_overlap(&r, 0.5, &i, &j), 1);
	/* the same two a row apart do not overlap */
	r.box[1].y0 += 18;
	r.box[1].y1 += 18;
	assert_int_equal(psd_textbox_overlap(&r, 0.5, &i, &j), 0);
	psd_textbox_free(&r);
	cairo_destroy(cr);
	cairo_surface_destroy(s);
}

static void no_overlap_pages_filled(void **state)
{
	struct psd_report_opts o = { .dbpath = dbpath, .site = "Validation office, Lab 2", .tolerance_pct = 25,
		                     .format = PSD_REPORT_PDF, .written = 1790000000 };
	struct psd_report_out r;
	char err[512], out[128];
	size_t i, j;
	struct stat st;
	(void)state;
	snprintf(out, sizeof out, "%s/report.pdf", dir);
	if (psd_report_write(&o, out, &r, err, sizeof err) != 0)
		fail_msg("%s", err);
	assert_int_equal(stat(out, &st), 0);
	assert_true(st.st_size > 10000);
	/* cover, office, corridor */
	assert_int_equal(r.pages, 3);
	assert_int_equal(r.nzones, 2);
	assert_string_equal(r.zone[0].name, "corridor");
	assert_int_equal(r.zone[0].verdict, 0);
	assert_string_equal(r.zone[1].name, "office");
	assert_int_equal(r.zone[1].verdict, 1);
	assert_true(r.boxes.n > 100);
	if (psd_textbox_overlap(&r.boxes, 0.01, &i, &j))
		fail_msg("page %d: '%s' (%.1f,%.1f-%.1f,%.1f) overlaps '%s' (%.1f,%.1f-%.1f,%.1f)", r.boxes.box[i].page,
		         r.boxes.box[i].text, r.boxes.box[i].x0, r.boxes.box[i].y0, r.boxes.box[i].x1, r.boxes.box[i].y1,
		         r.boxes.box[j].text, r.boxes.box[j].x0, r.boxes.box[j].y0, r.boxes.box[j].x1, r.boxes.box[j].y1);
	/* every text inside the page, and every page's text reaching its foot */
	for (size_t k = 0; k < r.boxes.n; k++) {
		assert_true(r.boxes.box[k].x0 >= 0 && r.boxes.box[k].x1 <= 595.28);
		assert_true(r.boxes.box[k].y0 >= 0 && r.boxes.box[k].y1 <= 841.89);
	}
	/* no empty band: between the texts (tick labels included) no vertical
	 * gap of 15 % of the page (the cover without its chart of every zone's
	 * output had 27 %) */
	for (int p = 1; p <= r.pages; p++) {
		double reach = 0, worst = 0;
		int first = 1;
		for (;;) {
			/* the next box down by its top edge, footer excluded */
			const struct psd_textbox *next = NULL;
			for (size_t k = 0; k < r.boxes.n; k++) {
				const struct psd_textbox *b = &r.boxes.box[k];
				if (b->page == p && b->y0 < 800 && (first || b->y0 > reach) && (!next || b->y0 < next->y0))
					next = b;
			}
			if (!next)
				break;
			if (!first && next->y0 - reach > worst)
				worst = next->y0 - reach;
			/* everything starting above this box's bottom is within reach */
			reach = next->y1;
			for (size_t k = 0; k < r.boxes.n; k++)
				if (r.boxes.box[k].page == p && r.boxes.box[k].y0 < 800 && r.boxes.box[k].y0 <= reach)
					reach = fmax(reach, r.boxes.box[k].y1);
			first = 0;
		}
		if (!(worst < 0.15 * 841.89))
			fail_msg("page %d: an empty band of %.0f pt", p, worst);
	}
	/* the page's content (not its footer, from y 800) reaches 85 % down */
	for (int p = 1; p <= r.pages; p++) {
		double bottom = 0;
		for (size_t k = 0; k < r.boxes.n; k++)
			if (r.boxes.box[k].page == p && r.boxes.box[k].y0 < 800)
				bottom = fmax(bottom, r.boxes.box[k].y1);
		if (!(bottom > 0.85 * 841.89))
			fail_msg("page %d: content ends at %.0f of 842 pt", p, bottom);
	}
	/* the second day's midnight marked with its date (the samples are
	 * dated) on the zone pages' charts (four charts each) and the cover's */
	{
		int days = 0, y, m, dd, k0;
		for (size_t k = 0; k < r.boxes.n; k++) {
			const char *t = r.boxes.box[k].text;
			k0 = 0;
			days += strlen(t) == 10 && sscanf(t, "%4d-%2d-%2d%n", &y, &m, &dd, &k0) == 3 && k0 == 10;
			assert_null(strstr(t, "day 2"));
		}
		assert_int_equal(days, 1 + 4 + 4);
	}
	/* the acceptance tests: each zone's row on its own page (corridor is page 2) */
	{
		int seen = 0;
		for (size_t k = 0; k < r.boxes.n; k++) {
			if (strcmp(r.boxes.box[k].text, "lights at 10 % power") == 0)
				seen += r.boxes.box[k].page == 3 ? 1 : 100;
			if (strcmp(r.boxes.box[k].text, "task 96 % of target") == 0)
				seen += r.boxes.box[k].page == 2 ? 10 : 100;
		}
		assert_int_equal(seen, 11);
	}
	psd_report_out_free(&r);
	/* one zone, strict: the same sessions fail */
	o.zone = "office";
	o.tolerance_pct = 0.1;
	o.format = PSD_REPORT_PNG;
	snprintf(out, sizeof out, "%s/report.png", dir);
	assert_int_equal(psd_report_write(&o, out, &r, err, sizeof err), 0);
	assert_int_equal(r.nzones, 1);
	assert_int_equal(r.verdict, -1);
	assert_int_equal(psd_textbox_overlap(&r.boxes, 0.01, &i, &j), 0);
	psd_report_out_free(&r);
	/* SVG, page 2 alone: drawn straight onto the SVG surface, the same boxes */
	o.format = PSD_REPORT_SVG;
	o.page = 2;
	snprintf(out, sizeof out, "%s/report.svg", dir);
	assert_int_equal(psd_report_write(&o, out, &r, err, sizeof err), 0);
	assert_int_equal(r.pages, 2);
	assert_int_equal(psd_textbox_overlap(&r.boxes, 0.01, &i, &j), 0);
	assert_int_equal(stat(out, &st), 0);
	assert_true(st.st_size > 10000);
	psd_report_out_free(&r);
}

/* With the configuration: the sensor, the target line in the legend, the
 * simulated date, and the file's SHA-256 on the cover (its value is
 * checked against sha256sum in tests/system/265-report.sh). */
static void with_config(void **state)
{
	static const char conf[] = "[psensd]\nresults = ofb.results\nperiod = 60\n[simulate]\ndate = 03-18\n"
	                           "[device room]\ndriver = loopback\n[zone office]\ndevice = room\n"
	                           "target_lux = 450\n";
	struct psd_config *cf = calloc(1, sizeof *cf);
	struct psd_report_out r;
	char err[512], out[128], cpath[128];
	int target = 0, sensor = 0, date = 0, sha = 0;
	FILE *fp;
	(void)state;
	assert_non_null(cf);
	snprintf(cpath, sizeof cpath, "%s/psensd.conf", dir);
	fp = fopen(cpath, "w");
	assert_non_null(fp);
	fputs(conf, fp);
	fclose(fp);
	if (psd_config_load_keys(cf, cpath) != 0)
		fail_msg("%s", cf->conf.nerrors ? cf->conf.errors[0] : "config");
	{
		struct psd_report_opts o = { .dbpath = dbpath, .zone = "office", .config_path = cpath, .cf = cf,
			                     .tolerance_pct = 25, .format = PSD_REPORT_PDF, .written = 1790000000 };
		snprintf(out, sizeof out, "%s/conf.pdf", dir);
		assert_int_equal(psd_report_write(&o, out, &r, err, sizeof err), 0);
	}
	for (size_t k = 0; k < r.boxes.n; k++) {
		const char *t = r.boxes.box[k].text;
		target += strcmp(t, "target") == 0 && r.boxes.box[k].page == 2;   /* the legend, not the cover's column */
		sensor += strstr(t, "room.sensor") != NULL;
		date += strstr(t, "the room's day 03-18") != NULL;
		sha += strlen(t) >= 47 && strspn(t, "0123456789abcdef") >= 47;
	}
	assert_int_equal(target, 1);
	assert_true(sensor >= 2);
	assert_int_equal(date, 1);
	assert_int_equal(sha, 1);
	psd_report_out_free(&r);
	psd_config_free(cf);
	free(cf);
}

static void misspelled_zone(void **state)
{
	struct psd_report_opts o = { .dbpath = dbpath, .zone = "ofice", .tolerance_pct = 25,
		                     .format = PSD_REPORT_PDF, .written = 1790000000 };
	struct psd_report_out r;
	char err[512], out[128];
	struct stat st;
	(void)state;
	snprintf(out, sizeof out, "%s/wrong.pdf", dir);
	assert_int_equal(psd_report_write(&o, out, &r, err, sizeof err), -1);
	psd_report_out_free(&r);
	assert_non_null(strstr(err, "'ofice'"));
	assert_non_null(strstr(err, "zones: corridor, office"));
	assert_int_equal(stat(out, &st), -1);
	/* nor a temporary file left behind */
	snprintf(out, sizeof out, "rm '%s'/.wrong.pdf.* 2>/dev/null", dir);
	assert_int_not_equal(system(out), 0);
}

/* A log from before samples named their zone (schema 2, zone NULL): any
 * zone asked for is shown with those samples, as the old report did. */
static void unnamed_samples(void **state)
{
	char err[512], out[128], path2[128];
	struct psd_report_out r;
	sqlite3 *h;
	(void)state;
	snprintf(path2, sizeof path2, "%s/old.db", dir);
	assert_int_equal(sqlite3_open(path2, &h), SQLITE_OK);
	assert_int_equal(sqlite3_exec(h, "CREATE TABLE samples(t REAL NOT NULL, tod_s REAL, sensor_v REAL, output REAL,"
	                                 " est_task_lux REAL, task_lux REAL, daylight_v REAL, daylight_lux REAL,"
	                                 " condition TEXT, ratio REAL, fault TEXT, zone TEXT);"
	                                 "INSERT INTO samples(t, tod_s, sensor_v, output) VALUES (21600, 21600, 0.5, 0.4),"
	                                 " (21660, 21660, 0.6, 0.3);", NULL, NULL, NULL), SQLITE_OK);
	sqlite3_close(h);
	{
		struct psd_report_opts o = { .dbpath = path2, .zone = "office", .tolerance_pct = 25,
			                     .format = PSD_REPORT_PDF, .written = 1790000000 };
		snprintf(out, sizeof out, "%s/old.pdf", dir);
		if (psd_report_write(&o, out, &r, err, sizeof err) != 0)
			fail_msg("%s", err);
		assert_int_equal(r.nzones, 1);
		psd_report_out_free(&r);
		/* without a zone: nothing names one */
		o.zone = NULL;
		assert_int_equal(psd_report_write(&o, out, &r, err, sizeof err), -1);
		assert_non_null(strstr(err, "no zone recorded (its samples name none: give the zone)"));
		psd_report_out_free(&r);
	}
}

/* PASS needs the acceptance tests: a zone calibrated within the tolerance
 * with no accept-test run is NOT TESTED (2); its run passing every test
 * makes it PASS (1); a later run with one test failed makes it FAIL (-1),
 * though the calibration still agrees with the design. */
static void pass_needs_acceptance(void **state)
{
	char err[512], out[160], path[128];
	struct psd_report_opts o = { .dbpath = path, .tolerance_pct = 25, .format = PSD_REPORT_SVG,
		                     .written = 1790000000 };
	struct psd_report_out r;
	struct psd_db *db;
	long long id;
	static const char *const tests[] = { "verification", "full daylight", "low daylight", "cycling" };
	(void)state;
	snprintf(path, sizeof path, "%s/accept.db", dir);
	snprintf(out, sizeof out, "%s/accept.svg", dir);
	db = psd_db_open(path, err, sizeof err);
	assert_non_null(db);
	psd_db_set_epoch(db, 1773792000.0);
	for (double t = 6 * 3600; t < 8 * 3600; t += 600) {
		struct psd_sample s = { t, t, 1, 0.5, 600, 600, 0.5, 100, "clear", 470, NULL, "hall", NAN, NULL, -1, NAN };
		assert_int_equal(psd_db_add(db, &s, err, sizeof err), 0);
	}
	id = psd_db_cal_begin(db, "hall", "day", 7 * 3600, "a1", "b2", err, sizeof err);
	assert_int_equal(psd_db_cal_end(db, id, "done", 7.5 * 3600, "{\"ratio\":470,\"ratio_se\":1,\"samples\":5,"
	                                "\"sim_ratio\":471,\"condition\":\"clear\",\"error_pct\":-0.2}", NULL, err,
	                                sizeof err), 0);
	assert_int_equal(psd_db_cal_accept(db, id, err, sizeof err), 0);
	psd_db_commit(db, err, sizeof err);
	assert_int_equal(psd_report_write(&o, out, &r, err, sizeof err), 0);
	assert_int_equal(r.zone[0].verdict, 2);
	assert_int_equal(r.verdict, 0);
	psd_report_out_free(&r);
	for (int k = 0; k < 4; k++)
		assert_int_equal(psd_db_accept_add(db, "hall", 1790000000, tests[k], "PASS", 1, 10, 40, "measured", err,
		                                   sizeof err), 0);
	psd_db_commit(db, err, sizeof err);
	assert_int_equal(psd_report_write(&o, out, &r, err, sizeof err), 0);
	assert_int_equal(r.zone[0].verdict, 1);
	assert_int_equal(r.verdict, 1);
	psd_report_out_free(&r);
	for (int k = 0; k < 4; k++)
		assert_int_equal(psd_db_accept_add(db, "hall", 1790003600, tests[k], k == 1 ? "FAIL" : "PASS", 1, 10, 40,
		                                   "measured", err, sizeof err), 0);
	psd_db_commit(db, err, sizeof err);
	assert_int_equal(psd_report_write(&o, out, &r, err, sizeof err), 0);
	assert_int_equal(r.zone[0].verdict, -1);
	assert_int_equal(r.verdict, -1);
	psd_report_out_free(&r);
	psd_db_close(db);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(old_overlap_is_caught),
		cmocka_unit_test(no_overlap_pages_filled),
		cmocka_unit_test(with_config),
		cmocka_unit_test(misspelled_zone),
		cmocka_unit_test(unnamed_samples),
		cmocka_unit_test(pass_needs_acceptance),
	};
	int rc = cmocka_run_group_tests(tests, setup, teardown);
	ps_canvas_shutdown();   /* cairo's and fontconfig's caches, for leak checkers */
	return rc;
}
