/* SPDX-License-Identifier: ISC */
#ifdef PS_WITH_QRENCODE
#include <qrencode.h>
#endif
#include "report.h"

#include <cairo-pdf.h>
#include <cairo-svg.h>
#include <cairo.h>
#include <errno.h>
#include <json-c/json.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "accept.h"
#include "cache.h"
#include "chart.h"
#include "db.h"
#include "errbuf.h"
#include "replace.h"
#include "results.h"
#include "sum.h"
#include "time.h"

/* A4 in points; PNG pages at 1.5 px per point (108 dpi). */
#define PAGE_W 595.28
#define PAGE_H 841.89
#define MARGIN 40.0
#define PNG_SCALE 1.5
#define FONT "DejaVu Sans"
#define FOOT_Y (PAGE_H - 22)

enum { MAXPTS = 1200, MAXSESS = 200, MAXACC = 60, MAXCOL = 10, MAXPAGES = 64 };

static const double BLACK[3] = { 0, 0, 0 }, GREY[3] = { 0.35, 0.35, 0.35 }, BLUE[3] = { 0.12, 0.31, 0.61 },
                    GREEN[3] = { 0.17, 0.48, 0.17 }, ORANGE[3] = { 0.88, 0.48, 0 }, RED[3] = { 0.75, 0.22, 0.17 },
                    PURPLE[3] = { 0.45, 0.2, 0.6 };

/* ---- one zone's data ----------------------------------------------------- */

struct session {
	long long id;
	char kind[16], state[16], result[200], design[64];
	double started, ended;
	char local0[20], local1[20];      /* local stamps (schema 5), "" when not recorded */
	int judged, pass;
};

struct zone {
	char name[48];
	int ci;                          /* index in the config, -1 when none */
	/* plotted points, thinned evenly */
	double *t, *v, *lux, *est, *out, *energy;
	unsigned char *fault, *vacant;   /* vacant: the occupancy input said so */
	int n;
	/* over every sample */
	long long total, seen;
	double tmin, tmax, vmax, luxmax, energy_h, fault_s, prev_t;
	double utc0;              /* UTC of clock 0 of the first dated run (NAN: none yet) */
	char local0[20], local1[20];     /* local date and time of the first and last sample ("" undated) */
	struct ps_sum esum;              /* energy */
	/* occupancy (schema 7): the hours occupied and vacant, and the energy
	 * the vacancies saved (full-load h): the daylight control's level,
	 * from the logged daylight estimate and the zone's constants on
	 * record, less the output; the last sample's for the interval after it */
	int has_occ, prev_occ;
	double occ_s, vac_s, saved_h, prev_out, prev_dl, target, elec;
	long long nmeas;                 /* task meter readings */
	struct psd_accept_result verif;  /* accept-test's verification (verif.test NULL: none) */
	char verif_why[160];             /* why there is none */
	char simulated[160];             /* what simulates its devices, "" when real */
	struct session sess[MAXSESS];
	int nsess, checks, fails, verdict;
	char config_sha[65], scene_sha[65];
	/* the latest psensctl accept-test run, one row a test */
	struct {
		char local[20], test[40], verdict[16], measured[400];
	} acc[MAXACC];
	int nacc, nruns;
	double acc_utc;                  /* when the last run was stored */
	int acc_state;                   /* enum accept_state of the last run */
	int scene_k;                     /* its scene in doc.scene[] */
};

/* A zone's last acceptance run, as the verdict and the cover read it. */
enum accept_state { ACC_NONE, ACC_INCOMPLETE, ACC_FAILED, ACC_PASSED };

/* A record's time on the report's axis: its clock time, or, for rows that
 * carry their UTC (schema 4), the seconds since clock 0 of the first dated
 * run, so that runs on later days follow it instead of drawing over it. */
static double rec_t(struct zone *z, double t, double utc)
{
	if (!isfinite(utc))
		return t;
	if (!isfinite(z->utc0))
		z->utc0 = utc - t;
	return utc - z->utc0;
}

static void add_sample(void *user, const struct psd_sample *row)
{
	struct zone *z = user;
	struct psd_sample sample = *row, *s = &sample;
	long long step = z->total / MAXPTS + 1;
	double dt;
	sample.t = rec_t(z, row->t, row->utc);
	if (row->local && strlen(row->local) >= 16) {
		if (!z->local0[0])
			snprintf(z->local0, sizeof z->local0, "%.19s", row->local);
		snprintf(z->local1, sizeof z->local1, "%.19s", row->local);
	}
	dt = z->seen > 0 ? s->t - z->prev_t : 0;
	/* energy: output times time (a gap longer than an hour is not counted) */
	if (dt > 0 && dt <= 3600 && isfinite(s->output))
		ps_sum_add(&z->esum, s->output * dt / 3600);
	if (dt > 0 && dt <= 3600 && s->fault)
		z->fault_s += dt;
	if (dt > 0 && dt <= 3600 && z->prev_occ >= 0) {
		double want = (z->target - z->prev_dl) / z->elec;
		*(z->prev_occ ? &z->occ_s : &z->vac_s) += dt;
		want = want < 0 ? 0 : want > 1 ? 1 : want;
		if (!z->prev_occ && isfinite(want) && want > z->prev_out)
			z->saved_h += (want - z->prev_out) * dt / 3600;
	}
	z->has_occ |= s->occupied >= 0;
	z->prev_occ = s->occupied;
	z->prev_out = s->output;
	z->prev_dl = s->daylight_lux;
	z->nmeas += isfinite(s->task_lux);
	z->prev_t = s->t;
	if (s->t < z->tmin)
		z->tmin = s->t;
	if (s->t > z->tmax)
		z->tmax = s->t;
	if (z->seen++ % step == 0 && z->n < MAXPTS) {
		int i = z->n++;
		z->t[i] = s->t;
		z->v[i] = s->sensor_v;
		z->lux[i] = s->task_lux;
		z->est[i] = s->est_task_lux;
		z->out[i] = isfinite(s->output) ? 100 * s->output : NAN;
		z->energy[i] = ps_sum_get(&z->esum);
		z->fault[i] = s->fault != NULL;
		z->vacant[i] = s->occupied == 0;
		if (isfinite(s->sensor_v) && s->sensor_v > z->vmax)
			z->vmax = s->sensor_v;
		if (isfinite(s->task_lux) && s->task_lux > z->luxmax)
			z->luxmax = s->task_lux;
		if (isfinite(s->est_task_lux) && s->est_task_lux > z->luxmax)
			z->luxmax = s->est_task_lux;
	}
}

static double jnum(json_object *o, const char *k)
{
	json_object *v;
	return o && json_object_object_get_ex(o, k, &v) && v ? json_object_get_double(v) : NAN;
}

struct sess_ctx {
	struct zone *z;
	double tol;
};

static void add_session(void *user, const struct psd_db_cal_session *row)
{
	struct sess_ctx *c = user;
	struct zone *z = c->z;
	struct session *s;
	json_object *o, *cond;
	double e = NAN;
	if (z->nsess >= MAXSESS)
		return;
	s = &z->sess[z->nsess++];
	memset(s, 0, sizeof *s);
	s->id = row->id;
	snprintf(s->kind, sizeof s->kind, "%s", row->kind ? row->kind : "?");
	snprintf(s->state, sizeof s->state, "%s", row->state ? row->state : "?");
	s->started = rec_t(c->z, row->started, row->started_utc);
	snprintf(s->local0, sizeof s->local0, "%.16s", row->started_local ? row->started_local : "");
	snprintf(s->local1, sizeof s->local1, "%.16s", row->ended_local ? row->ended_local : "");
	s->ended = rec_t(c->z, row->ended, row->ended_utc);
	o = row->results ? json_tokener_parse(row->results) : NULL;
	if (o && strcmp(s->kind, "night") == 0) {
		e = jnum(o, "electric_lux_error_pct");
		snprintf(s->result, sizeof s->result, "offset %.4f V, %.4f V at full (se %.4f), R\xc2\xb2 %.6f, "
		         "worst residual %.2f %%", jnum(o, "offset"), jnum(o, "gain"), jnum(o, "gain_se"), jnum(o, "r2"),
		         jnum(o, "max_resid_pct"));
		if (isfinite(e))
			snprintf(s->design, sizeof s->design, "electric lux %+.1f %%", e);
	} else if (o) {
		e = jnum(o, "error_pct");
		snprintf(s->result, sizeof s->result, "%.2f lux/V (se %.2f, n %.0f) vs simulated %.2f (%s)",
		         jnum(o, "ratio"), jnum(o, "ratio_se"), jnum(o, "samples"), jnum(o, "sim_ratio"),
		         json_object_object_get_ex(o, "condition", &cond) ? json_object_get_string(cond) : "?");
		if (isfinite(e))
			snprintf(s->design, sizeof s->design, "ratio %+.1f %%", e);
	} else if (row->note) {
		snprintf(s->result, sizeof s->result, "%s", row->note);
	}
	if (isfinite(e)) {
		s->judged = 1;
		s->pass = fabs(e) <= c->tol;
		snprintf(s->design + strlen(s->design), sizeof s->design - strlen(s->design), s->pass ? ": pass" : ": FAIL");
		if (strcmp(s->state, "accepted") == 0 || strcmp(s->state, "done") == 0) {
			z->checks++;
			z->fails += !s->pass;
		}
	}
	json_object_put(o);
}

/* psensctl accept-test stores one row per test, dated alike (a run's rows
 * within a second); rows come oldest first, so the last run is what stays. */
static void add_accept_run(void *user, const struct psd_db_accept *a)
{
	struct zone *z = user;
	double u = isfinite(a->utc) ? a->utc : 0;
	if (z->nruns == 0 || u > z->acc_utc + 1) {
		z->acc_utc = u;
		z->nacc = 0;
		z->nruns++;
	}
	if (z->nacc < MAXACC) {
		snprintf(z->acc[z->nacc].local, sizeof z->acc[0].local, "%.16s", a->local ? a->local : "");
		snprintf(z->acc[z->nacc].test, sizeof z->acc[0].test, "%s", a->test ? a->test : "?");
		snprintf(z->acc[z->nacc].verdict, sizeof z->acc[0].verdict, "%s", a->verdict ? a->verdict : "?");
		snprintf(z->acc[z->nacc].measured, sizeof z->acc[0].measured, "%s", a->measured ? a->measured : "");
		z->nacc++;
	}
}

/* The last run's state from its rows: failed when a test failed, passed
 * when every test ran and passed, incomplete otherwise. */
static int accept_state(const struct zone *z)
{
	int pass = 0, fail = 0, other = 0;
	for (int i = 0; i < z->nacc; i++) {
		if (strcmp(z->acc[i].verdict, "PASS") == 0)
			pass++;
		else if (strcmp(z->acc[i].verdict, "FAIL") == 0)
			fail++;
		else
			other++;
	}
	return z->nacc == 0 ? ACC_NONE : fail ? ACC_FAILED : pass && !other ? ACC_PASSED : ACC_INCOMPLETE;
}

static int zone_alloc(struct zone *z)
{
	double *p = calloc((size_t)MAXPTS * 6, sizeof *p);
	z->fault = calloc(2 * MAXPTS, 1);
	z->vacant = z->fault ? z->fault + MAXPTS : NULL;
	if (!p || !z->fault) {
		free(p);
		free(z->fault);
		return -1;
	}
	z->t = p;
	z->v = p + MAXPTS;
	z->lux = p + 2 * MAXPTS;
	z->est = p + 3 * MAXPTS;
	z->out = p + 4 * MAXPTS;
	z->energy = p + 5 * MAXPTS;
	return 0;
}

static void zone_free(struct zone *z)
{
	free(z->t);
	free(z->fault);
	z->t = NULL;
	z->fault = NULL;
}

static int load_zone(struct psd_db *db, struct zone *z, double tol, char *err, size_t n)
{
	struct sess_ctx c = { z, tol };
	char ignored[256];
	z->tmin = INFINITY;
	z->utc0 = NAN;
	z->tmax = -INFINITY;
	z->prev_occ = -1;
	if (psd_db_zone_consts_get(db, z->name, &z->target, &z->elec, &(double){ 0 }) != 0 || !(z->elec > 0))
		z->target = z->elec = NAN;   /* no savings can be estimated */
	if ((z->total = psd_db_zone_count(db, z->name, err, n)) < 0)
		return -1;
	if (psd_db_zone_samples(db, z->name, add_sample, z, err, n) != 0)
		return -1;
	z->energy_h = ps_sum_get(&z->esum);
	/* an older database has no sessions table: then none are shown */
	psd_db_cal_sessions(db, z->name, add_session, &c, ignored, sizeof ignored);
	psd_db_cal_hashes(db, z->name, z->config_sha, z->scene_sha);
	psd_db_accept_results(db, z->name, add_accept_run, z, ignored, sizeof ignored);
	if (psd_db_zone_simulated(db, z->name, z->simulated, sizeof z->simulated) != 1)
		z->simulated[0] = 0;
	/* the estimate against the meter, judged as accept-test judges it */
	if (psd_accept_verification(db, z->name, &z->verif, z->verif_why, sizeof z->verif_why) != 0)
		z->verif.test = NULL;
	/* calibrated within the tolerance is not yet a zone that works: PASS
	 * needs the acceptance tests too (psensctl accept-test), all run and
	 * passed; a failed calibration or test fails the zone */
	z->acc_state = accept_state(z);
	if (z->fails || z->acc_state == ACC_FAILED)
		z->verdict = -1;
	else if (z->checks == 0)
		z->verdict = 0;
	else
		z->verdict = z->acc_state == ACC_PASSED ? 1 : 2;
	return 0;
}

/* ---- the document ---------------------------------------------------------- */

struct doc {
	const struct psd_report_opts *o;
	struct zone *zones;
	int nzones;
	int simulated;                   /* a zone's devices are simulated: the record says so */
	char config_sha[65];
	/* every zone's samples dated (schema 5): times shown as local dates;
	 * the first zone's first date is its axis's day floor(t0 / 86400) */
	int dated;
	int y0, m0, d0;
	double t0;
	/* the simulations the zones run on: the scene shown (its results file
	 * when it names none), the results read, the scene's SHA-256 */
	struct {
		const char *path, *results;
		char sha[65];
	} scene[PSD_MAX_ZONES];
	int nscenes;
	cairo_t *cr;                     /* the current page */
	int page, pages;                 /* pages: from the first pass, for "page n of N" */
	struct psd_textboxes *boxes;
	cairo_surface_t *rec[MAXPAGES];  /* every page, recorded */
	int nrec;
	int failed;
	int mono;                        /* text in DejaVu Sans Mono (hashes) */
	/* SVG: pages first..last drawn straight onto this surface (cairo 1.16's
	 * SVG surface leaks a recording surface painted onto it) */
	cairo_surface_t *direct;
	int first, last;
	double gap;
};

static void set_rgb(cairo_t *cr, const double c[3])
{
	cairo_set_source_rgb(cr, c[0], c[1], c[2]);
}

static void font(struct doc *d, double size, int bold)
{
	cairo_select_font_face(d->cr, d->mono ? FONT " Mono" : FONT, CAIRO_FONT_SLANT_NORMAL,
	                       bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
	cairo_set_font_size(d->cr, size);
}

static double width_of(struct doc *d, const char *s)
{
	cairo_text_extents_t te;
	cairo_text_extents(d->cr, s, &te);
	return te.x_advance;
}

static void record(struct doc *d, double x0, double y0, double x1, double y1, const char *s)
{
	if (psd_textbox_add(d->boxes, d->page, x0, y0, x1, y1, s) != 0)
		d->failed = 1;
}

/* Text with its baseline at y: align -1 left of x, 0 centred, 1 right.  Its
 * width is returned. */
static double text(struct doc *d, double x, double y, double size, int bold, int align, const double rgb[3],
                   const char *s)
{
	cairo_font_extents_t fe;
	double w;
	font(d, size, bold);
	cairo_font_extents(d->cr, &fe);
	w = width_of(d, s);
	x -= align < 0 ? 0 : align == 0 ? w / 2 : w;
	set_rgb(d->cr, rgb);
	cairo_move_to(d->cr, x, y);
	cairo_show_text(d->cr, s);
	record(d, x, y - fe.ascent, x + w, y + fe.descent, s);
	return w;
}

/* Text made to fit maxw: smaller type down to min, then cut with an
 * ellipsis.  Left aligned. */
static double text_fit(struct doc *d, double x, double y, double maxw, double size, double min, int bold,
                       const double rgb[3], const char *s)
{
	char buf[512];
	size_t len;
	for (; size > min; size -= 0.25) {
		font(d, size, bold);
		if (width_of(d, s) <= maxw)
			return text(d, x, y, size, bold, -1, rgb, s);
	}
	font(d, min, bold);
	snprintf(buf, sizeof buf, "%s", s);
	len = strlen(buf);
	while (len > 0) {
		/* cut at a character boundary, then add the ellipsis */
		do
			len--;
		while (len > 0 && ((unsigned char)buf[len] & 0xc0) == 0x80);
		snprintf(buf + len, sizeof buf - len, "\xe2\x80\xa6");
		if (width_of(d, buf) <= maxw)
			break;
		buf[len] = 0;
	}
	return text(d, x, y, min, bold, -1, rgb, buf);
}

/* Words wrapped to maxw from baseline y; the baseline after the last line. */
static double paragraph(struct doc *d, double x, double y, double maxw, double size, double lead,
                        const double rgb[3], const char *s)
{
	char line[640] = "", word[128];
	font(d, size, 0);
	while (*s) {
		size_t k = strcspn(s, " ");
		char trial[800];
		size_t len;
		snprintf(word, sizeof word, "%.*s", (int)(k < sizeof word - 1 ? k : sizeof word - 1), s);
		s += k;
		s += strspn(s, " ");
		snprintf(trial, sizeof trial, "%s%s%s", line, *line ? " " : "", word);
		font(d, size, 0);
		if (*line && width_of(d, trial) > maxw) {
			text(d, x, y, size, 0, -1, rgb, line);
			y += lead;
			snprintf(line, sizeof line, "%s", word);
		} else {
			len = strlen(trial) < sizeof line - 1 ? strlen(trial) : sizeof line - 1;
			memcpy(line, trial, len);
			line[len] = 0;
		}
	}
	if (*line) {
		text(d, x, y, size, 0, -1, rgb, line);
		y += lead;
	}
	return y;
}

/* Text turned a quarter to the left, centred on (x, y): a y axis title. */
static void text_up(struct doc *d, double x, double y, double size, const double rgb[3], const char *s)
{
	cairo_font_extents_t fe;
	double w;
	font(d, size, 0);
	cairo_font_extents(d->cr, &fe);
	w = width_of(d, s);
	cairo_save(d->cr);
	set_rgb(d->cr, rgb);
	cairo_move_to(d->cr, x, y + w / 2);
	cairo_rotate(d->cr, -M_PI / 2);
	cairo_show_text(d->cr, s);
	cairo_restore(d->cr);
	record(d, x - fe.ascent, y - w / 2, x + fe.descent, y + w / 2, s);
}

static void hline(struct doc *d, double x0, double x1, double y, double lw, const double rgb[3])
{
	set_rgb(d->cr, rgb);
	cairo_set_line_width(d->cr, lw);
	cairo_move_to(d->cr, x0, y);
	cairo_line_to(d->cr, x1, y);
	cairo_stroke(d->cr);
}

static const char *verdict_word(int v)
{
	return v == 1 ? "PASS" : v == 2 ? "NOT TESTED" : v < 0 ? "FAIL" : "NOT CALIBRATED";
}

static const double *verdict_rgb(int v)
{
	return v == 1 ? GREEN : v < 0 ? RED : GREY;
}

static void begin_page(struct doc *d)
{
	cairo_rectangle_t ext = { 0, 0, PAGE_W, PAGE_H };
	if (d->nrec >= MAXPAGES) {
		d->failed = 1;
		d->cr = NULL;
		return;
	}
	d->rec[d->nrec] = cairo_recording_surface_create(CAIRO_CONTENT_COLOR_ALPHA, &ext);
	d->nrec++;
	d->page++;
	if (d->direct && d->page - 1 >= d->first && d->page - 1 <= d->last) {
		d->cr = cairo_create(d->direct);
		cairo_translate(d->cr, 0, (d->page - 1 - d->first) * (PAGE_H + d->gap));
		cairo_rectangle(d->cr, 0, 0, PAGE_W, PAGE_H);
		cairo_clip(d->cr);
	} else {
		d->cr = cairo_create(d->rec[d->nrec - 1]);
	}
	cairo_set_source_rgb(d->cr, 1, 1, 1);
	cairo_paint(d->cr);
}

static void end_page(struct doc *d, const char *what)
{
	char foot[200];
	const char *site = d->o->site ? d->o->site : "site not named";
	snprintf(foot, sizeof foot, "psensd %s record \xc2\xb7 %s \xc2\xb7 %s",
	         d->simulated ? "SIMULATED" : "commissioning", site, what);
	if (d->simulated)   /* every page says what it is, in its corner */
		text(d, PAGE_W - MARGIN, MARGIN - 12, 9, 1, 1, RED, "SIMULATED \xe2\x80\x94 not a building's record");
	hline(d, MARGIN, PAGE_W - MARGIN, FOOT_Y - 10, 0.4, GREY);
	text_fit(d, MARGIN, FOOT_Y, PAGE_W - 2 * MARGIN - 80, 7, 5.5, 0, GREY, foot);
	if (d->pages > 0)
		snprintf(foot, sizeof foot, "page %d of %d", d->page, d->pages);
	else
		snprintf(foot, sizeof foot, "page %d", d->page);
	text(d, PAGE_W - MARGIN, FOOT_Y, 7, 0, 1, GREY, foot);
	if (cairo_status(d->cr) != CAIRO_STATUS_SUCCESS)
		d->failed = 1;
	cairo_destroy(d->cr);
	d->cr = NULL;
}

/* "day 1 06:00" for a time on psensd's clock (seconds from local midnight of
 * its first day). */
static void when(double t, char *buf, size_t n)
{
	char hm[16];
	if (!isfinite(t)) {
		snprintf(buf, n, "-");
		return;
	}
	psd_chart_tick_time_label(t, hm, sizeof hm);
	snprintf(buf, n, "day %d %s", (int)floor(t / 86400) + 1, hm);
}

/* The local date of the axis's day containing t (dated records), as
 * YYYY-MM-DD, else "day N". */
static void day_label(const struct doc *d, double t, char *buf, size_t n)
{
	struct tm tm = { 0 };
	time_t u;
	if (!d->dated) {
		snprintf(buf, n, "day %d", (int)floor(t / 86400) + 1);
		return;
	}
	tm.tm_year = d->y0 - 1900;
	tm.tm_mon = d->m0 - 1;
	tm.tm_mday = d->d0 + (int)(floor(t / 86400) - floor(d->t0 / 86400));
	tm.tm_hour = 12;
	u = timegm(&tm);   /* normalises the day of the month */
	psd_time_utc_text((double)u, PSD_TIME_DATE, buf, n);
}

/* A zone's first or last sample for the tables: "2026-03-18 06:01" from
 * its local stamp, else on psensd's clock. */
static void when_z(const struct zone *z, int last, char *buf, size_t n)
{
	const char *l = last ? z->local1 : z->local0;
	if (l[0])
		snprintf(buf, n, "%.16s", l);
	else
		when(last ? z->tmax : z->tmin, buf, n);
}

static const struct psd_zone_conf *zconf(const struct doc *d, const struct zone *z)
{
	return d->o->cf && z->ci >= 0 ? &d->o->cf->zone[z->ci] : NULL;
}

static void sensor_text(const struct doc *d, const struct zone *z, char *buf, size_t n, int compact)
{
	const struct psd_zone_conf *zc = zconf(d, z);
	if (zc && zc->sensor >= 0) {
		const struct psd_point_conf *p = &d->o->cf->pt[zc->sensor];
		const struct psd_device_conf *dev = &d->o->cf->dev[p->device];
		char kind[96];
		/* a virtual room reads as one: psvirt's Modbus device is marked in the config */
		snprintf(kind, sizeof kind, "%s%s%s", dev->drv ? dev->drv->name : "?",
		         dev->simulated[0] ? ", virtual: " : "", dev->simulated);
		if (compact)
			snprintf(buf, n, "%s (%s)", p->name, kind);
		else
			snprintf(buf, n, "point %s, device %s (%s)", p->name, dev->name, kind);
	} else {
		snprintf(buf, n, "(no configuration given)");
	}
}

static int overall(const struct doc *d)
{
	int fail = 0, pass = 0;
	for (int i = 0; i < d->nzones; i++) {
		fail |= d->zones[i].verdict < 0;
		pass += d->zones[i].verdict == 1;
	}
	return fail ? -1 : pass == d->nzones && pass > 0 ? 1 : 0;
}

/* ---- the cover --------------------------------------------------------------- */

struct chart {
	double x0, y0, x1, y1;           /* the plot area */
	double tlo, thi, ylo, yhi;
	double blo, bhi;                 /* a long gap with no samples (psensd not running),
	                                    drawn BREAK_W wide; blo >= bhi: none */
};

enum { BREAK_W = 14 };

struct legend {
	const char *label;
	const double *rgb;
	int kind;                        /* 0 line, 1 dashed line, 2 shade */
	double alpha;
};



static void frame(struct doc *d, const struct chart *c, const struct zone *z, const char *title, const char *ytitle,
                  const struct legend *lg, int nlg, int xtitle);
static void line(struct doc *d, const struct chart *c, const struct zone *z, const double *y, const double rgb[3],
                 double lw, int dashed);
static void find_break(const struct zone *z, struct chart *c);

static void overview(struct doc *d, double top, double bottom, double tmin, double tmax)
{
	static const double *const pal[] = { PURPLE, GREEN, ORANGE, BLUE, RED, BLACK };
	struct chart c = { MARGIN + 34, top, PAGE_W - MARGIN - 4, bottom, tmin, tmax > tmin ? tmax : tmin + 3600, 0,
		           100, 0, 0 };
	struct legend lg[PSD_MAX_ZONES] = { { 0 } };
	int n = d->nzones < 6 ? d->nzones : 6;
	for (int i = 0; i < n; i++)
		lg[i] = (struct legend){ d->zones[i].name, pal[i], 0, 1 };
	/* the first zone's long gap, when no other zone has a sample in it */
	if (n > 0) {
		find_break(&d->zones[0], &c);
		for (int i = 1; i < n && c.bhi > c.blo; i++)
			for (int k = 0; k < d->zones[i].n; k++)
				if (d->zones[i].t[k] > c.blo && d->zones[i].t[k] < c.bhi) {
					c.blo = c.bhi = 0;
					break;
				}
	}
	frame(d, &c, NULL, "Light output, every zone", "light output (%)", lg, n, 1);
	/* zones often share an output (the same room and target): each drawn
	 * thinner than the one before, so a line under another shows as its
	 * border instead of vanishing */
	for (int i = 0; i < n; i++)
		line(d, &c, &d->zones[i], d->zones[i].out, pal[i], 1.1 + 1.4 * (n - 1 - i), 0);
}

static double keyval(struct doc *d, double y, const char *key, const char *val, int mono)
{
	text(d, MARGIN, y, 8.5, 1, -1, BLACK, key);
	d->mono = mono && strspn(val, "0123456789abcdef") >= 16;   /* a hash, not a remark */
	text_fit(d, MARGIN + 120, y, PAGE_W - 2 * MARGIN - 120, 8.5, 6, 0, BLACK, val);
	d->mono = 0;
	return y + 13;
}

/* The configuration's hash: the one read now, else the one the last
 * calibration recorded. */
static double cover_config_sha(struct doc *d, double y)
{
	char buf[512];
	if (d->config_sha[0])
		return keyval(d, y, "Configuration SHA-256", d->config_sha, 1);
	if (d->nzones && d->zones[0].config_sha[0]) {
		snprintf(buf, sizeof buf, "%s (at the last calibration)", d->zones[0].config_sha);
		return keyval(d, y, "Configuration SHA-256", buf, 1);
	}
	return keyval(d, y, "Configuration SHA-256", "(unknown)", 0);
}

/* The scene and its hash; zones on their own simulations: each scene, its
 * zones, its hash. */
static double cover_scenes(struct doc *d, double y)
{
	char buf[512];
	if (d->nscenes > 1) {
		for (int k = 0; k < d->nscenes; k++) {
			snprintf(buf, sizeof buf, "%s (", d->scene[k].path);
			for (int i = 0; i < d->nzones; i++)
				if (d->zones[i].scene_k == k)
					snprintf(buf + strlen(buf), sizeof buf - strlen(buf), "%s%s",
					         buf[strlen(buf) - 1] == '(' ? "zone " : ", ", d->zones[i].name);
			snprintf(buf + strlen(buf), sizeof buf - strlen(buf), ")");
			y = keyval(d, y, "Scene", buf, 0);
			y = keyval(d, y, "Scene SHA-256", d->scene[k].sha[0] ? d->scene[k].sha : "(unknown: results not read)",
			           1);
		}
	} else {
		const char *sha = d->nscenes && d->scene[0].sha[0] ? d->scene[0].sha : NULL;
		y = keyval(d, y, "Scene", d->nscenes ? d->scene[0].path : "(see the configuration)", 0);
		y = keyval(d, y, "Scene SHA-256", sha ? sha : d->nzones && d->zones[0].scene_sha[0] ?
		           d->zones[0].scene_sha : "(unknown: no results file read, no calibration recorded it)", 1);
	}
	return y;
}

/* The records' span, tmin to tmax (ISO local stamps when dated). */
static double cover_records(struct doc *d, double y, double tmin, double tmax)
{
	const struct psd_report_opts *o = d->o;
	char buf[512], a[64], b[64];
	when(tmin, a, sizeof a);
	when(tmax, b, sizeof b);
	if (d->dated) {
		/* ISO stamps: the smallest first and the largest last */
		const char *f = NULL, *l = NULL;
		for (int i = 0; i < d->nzones; i++) {
			if (!f || strcmp(d->zones[i].local0, f) < 0)
				f = d->zones[i].local0;
			if (!l || strcmp(d->zones[i].local1, l) > 0)
				l = d->zones[i].local1;
		}
		snprintf(a, sizeof a, "%.16s", f);
		snprintf(b, sizeof b, "%.16s", l);
	}
	if (isfinite(tmin))
		snprintf(buf, sizeof buf, "%s to %s (%.1f h%s)%s%s", a, b, (tmax - tmin) / 3600,
		         d->dated ? ", local time" : "", o->cf && o->cf->date[0] ? ", the room's day " : "",
		         o->cf && o->cf->date[0] ? o->cf->date : "");
	else
		snprintf(buf, sizeof buf, "no samples");
	return keyval(d, y, d->simulated ? "Simulated records" : "Records", buf, 0);
}

/* The facts of the record, one per line: site, zones, configuration,
 * scene, database, the records' span, when the report was written. */
static double cover_facts(struct doc *d, double y, double tmin, double tmax)
{
	const struct psd_report_opts *o = d->o;
	char buf[512], a[64], wr[128];
	y = keyval(d, y, "Site", o->site ? o->site : "(not named: psensctl report --site)", 0);
	buf[0] = 0;
	for (int i = 0; i < d->nzones; i++)
		snprintf(buf + strlen(buf), sizeof buf - strlen(buf), "%s%s", i ? ", " : "", d->zones[i].name);
	y = keyval(d, y, "Zones", buf, 0);
	y = keyval(d, y, "Configuration", o->config_path ? o->config_path : "(not given: psensctl report -c FILE)", 0);
	y = cover_config_sha(d, y);
	y = cover_scenes(d, y);
	y = keyval(d, y, "Database", o->dbpath, 0);
	y = cover_records(d, y, tmin, tmax);
	psd_time_utc_text((double)o->written, PSD_TIME_MINUTE, a, sizeof a);
	snprintf(wr, sizeof wr, "%.40s UTC%s", a, d->simulated ? " (the real date; the records' dates are simulated)" : "");
	return keyval(d, y, "Report written", wr, 0);
}

/* Column c of zone z's row in the cover's table, into buf. */
static void zone_cell(struct doc *d, struct zone *z, int c, char *buf, size_t n)
{
	const struct psd_zone_conf *zc = zconf(d, z);
	char a[64], b[64];
	switch (c) {
	case 0: snprintf(buf, n, "%s", z->name); break;
	case 1: sensor_text(d, z, buf, n, 1); break;
	case 2:
		if (zc)
			snprintf(buf, n, "%.0f lx", zc->ctl.target_lux);
		else
			snprintf(buf, n, "-");
		break;
	case 3: snprintf(buf, n, "%lld", z->total); break;
	case 4:
		when_z(z, 0, a, sizeof a);
		when_z(z, 1, b, sizeof b);
		if (z->local0[0]) /* 03-18 06:01 to 20:58 */
			snprintf(buf, n, "%s to %s", a + 5, b + (strncmp(a, b, 10) == 0 ? 11 : 5));
		else
			snprintf(buf, n, "%s to %s", a, b + (strncmp(a, b, 5) == 0 ? 6 : 0));
		break;
	case 5: snprintf(buf, n, "%.0f min", z->fault_s / 60); break;
	case 6: snprintf(buf, n, "%.2f flh", z->energy_h); break;
	case 7:
		if (!z->has_occ)
			snprintf(buf, n, "-");
		else if (isfinite(z->elec))
			snprintf(buf, n, "%.1f/%.1f h, %.2f flh", z->occ_s / 3600, z->vac_s / 3600, z->saved_h);
		else
			snprintf(buf, n, "%.1f/%.1f h", z->occ_s / 3600, z->vac_s / 3600);
		break;
	default: snprintf(buf, n, "%s", verdict_word(z->verdict)); break;
	}
}

/* The zones' table, then what its columns mean. */
static double cover_zones(struct doc *d, double y)
{
	static const double cols[] = { 0, 55, 145, 180, 220, 305, 340, 382, 452 };
	static const char *const head[] = { "zone", "sensor", "target", "samples", "recorded", "faults",
	                                    "energy", "occupied/vacant", "verdict" };
	char buf[512];
	text(d, MARGIN, y, 12, 1, -1, BLACK, "Zones");
	y += 16;
	for (int c = 0; c < 9; c++)
		text(d, MARGIN + cols[c], y, 7.5, 1, -1, BLACK, head[c]);
	hline(d, MARGIN, PAGE_W - MARGIN, y + 3, 0.5, BLACK);
	y += 13;
	for (int i = 0; i < d->nzones; i++) {
		struct zone *z = &d->zones[i];
		for (int c = 0; c < 9; c++) {
			double colw = (c < 8 ? cols[c + 1] : PAGE_W - 2 * MARGIN) - cols[c] - 6;
			zone_cell(d, z, c, buf, sizeof buf);
			text_fit(d, MARGIN + cols[c], y, colw, 7.5, 5.5, c == 8, c == 8 ? verdict_rgb(z->verdict) : BLACK,
			         buf);
		}
		y += 12;
	}
	y += 4;
	y = paragraph(d, MARGIN, y, PAGE_W - 2 * MARGIN, 7, 9, GREY,
	              d->dated ? "target: the task illuminance the zone holds; recorded: first and last sample (local "
	              "date and time); faults: time at the safe level; energy: lighting energy in full-load hours "
	              "(hours at full output; power taken as proportional to the output); occupied/vacant: the "
	              "hours the occupancy input said so, and the energy the vacancies saved (the daylight "
	              "control's level from the logged daylight estimate, less the output; - no input)." :
	              "target: the task illuminance the zone holds; recorded: first and last sample (day 1 is the "
	              "day psensd started); faults: time at the safe level; energy: lighting energy in full-load "
	              "hours (hours at full output; power taken as proportional to the output); occupied/vacant: "
	              "the hours the occupancy input said so, and the energy the vacancies saved (the daylight "
	              "control's level from the logged daylight estimate, less the output; - no input).");
	return y;
}

/* The verdict (v: overall's), then its reason and how it is reached. */
static double cover_verdict(struct doc *d, double y, int v, int checks, int fails)
{
	char buf[512];
	int tested = 0, accepted = 0;
	text(d, MARGIN, y + 12, 26, 1, -1, verdict_rgb(v), v == 0 && checks ? "INCOMPLETE" : verdict_word(v));
	y += 30;
	for (int i = 0; i < d->nzones; i++) {
		accepted += d->zones[i].acc_state == ACC_PASSED;
		tested += d->zones[i].acc_state != ACC_NONE;
	}
	snprintf(buf, sizeof buf, "%d of %d calibration results within %g %% of the design prediction (the "
	         "simulated ratios); %d of %d zone%s acceptance-tested, %d accepted.", checks - fails, checks,
	         d->o->tolerance_pct, tested, d->nzones, d->nzones == 1 ? "" : "s", accepted);
	y = paragraph(d, MARGIN, y, PAGE_W - 2 * MARGIN, 9, 12, BLACK, buf);
	y += 6;
	y = paragraph(d, MARGIN, y, PAGE_W - 2 * MARGIN, 8, 11, GREY,
	              "A night session fits the sensor's offset and its response to the electric light; a day session "
	              "measures the ratio of task illuminance to the sensor's daylight signal against the simulated "
	              "ratio. The acceptance tests (psensctl accept-test) judge the zone from its log: the estimate "
	              "against the task meter over a verification window, and the functional tests of California "
	              "Title 24 NA7.6.1 and IECC C408.3. PASS: every session within the tolerance and the last "
	              "acceptance run passed every test; NOT TESTED: calibrated, not acceptance-tested. The pages "
	              "that follow show each zone's signals with faults and sessions shaded, and its sessions.");
	return y;
}

/* The sign-off, at the foot of the page. */
/* Where the sign-off begins: the simulated record's statement is shorter. */
static double sign_off_top(const struct doc *d)
{
	return d->simulated ? FOOT_Y - 76 : FOOT_Y - 172;
}

static void sign_off(struct doc *d)
{
	double y = sign_off_top(d);
	if (d->simulated) {
		char buf[900], zones[600];
		zones[0] = 0;
		for (int i = 0; i < d->nzones; i++)
			if (d->zones[i].simulated[0])
				snprintf(zones + strlen(zones), sizeof zones - strlen(zones), "%szone %s: %s",
				         zones[0] ? "; " : "", d->zones[i].name, d->zones[i].simulated);
		hline(d, MARGIN, PAGE_W - MARGIN, y - 16, 0.8, RED);
		text(d, MARGIN, y, 12, 1, -1, RED, "SIMULATED: no sign-off");
		y += 15;
		snprintf(buf, sizeof buf, "This record was made from simulated devices (%s). It shows how psensd "
		         "controls a simulated room, with simulated dates; it is not the commissioning of a building "
		         "and cannot be signed off as one.", zones);
		paragraph(d, MARGIN, y, PAGE_W - 2 * MARGIN, 8, 11, BLACK, buf);
		return;
	}
	hline(d, MARGIN, PAGE_W - MARGIN, y - 16, 0.8, BLACK);
	text(d, MARGIN, y, 12, 1, -1, BLACK, "Sign-off");
	y += 15;
	y = paragraph(d, MARGIN, y, PAGE_W - 2 * MARGIN, 8, 11, BLACK,
	              "We have reviewed this record and accept the calibration and the functional performance of "
	              "the zones listed above, subject to the verdicts shown.");
	y += 10;
	for (int c = 0; c < 2; c++) {
		double x = MARGIN + c * (PAGE_W - 2 * MARGIN) / 2, yy = y;
		static const char *const who[] = { "Commissioning agent", "Building owner or representative" };
		static const char *const lines[] = { "Name", "Signature", "Date" };
		text(d, x, yy, 9, 1, -1, BLACK, who[c]);
		yy += 26;
		for (int k = 0; k < 3; k++, yy += 28) {
			text(d, x, yy, 8, 0, -1, GREY, lines[k]);
			hline(d, x + 52, x + (PAGE_W - 2 * MARGIN) / 2 - 18, yy + 1, 0.6, BLACK);
		}
	}
}

static void cover(struct doc *d)
{
	double y = MARGIN + 22, tmin = INFINITY, tmax = -INFINITY;
	int v = overall(d), checks = 0, fails = 0;
	begin_page(d);
	if (!d->cr)
		return;
	text(d, MARGIN, y, 20, 1, -1, d->simulated ? RED : BLACK,
	     d->simulated ? "SIMULATED commissioning record" : "Commissioning record");
	y += 18;
	text(d, MARGIN, y, 10.5, 0, -1, GREY, "Daylight-linked lighting control (psensd): sensor calibration and performance");
	y += 26;
	for (int i = 0; i < d->nzones; i++) {
		tmin = fmin(tmin, d->zones[i].tmin);
		tmax = fmax(tmax, d->zones[i].tmax);
		checks += d->zones[i].checks;
		fails += d->zones[i].fails;
	}
	y = cover_facts(d, y, tmin, tmax);
	y += 14;
	y = cover_zones(d, y);
	y += 16;
	y = cover_verdict(d, y, v, checks, fails);
	/* every zone's light output over the record: fills the page to the sign-off */
	if (sign_off_top(d) - 44 - (y + 30) >= 60 && isfinite(tmin))
		overview(d, y + 30, sign_off_top(d) - 44, tmin, tmax);
	sign_off(d);
	end_page(d, "cover");
}

/* ---- a zone's charts --------------------------------------------------------- */

static double cx(const struct chart *c, double t)
{
	double span, w;
	if (!(c->bhi > c->blo))
		return c->x0 + (c->thi > c->tlo ? (t - c->tlo) / (c->thi - c->tlo) : 0.5) * (c->x1 - c->x0);
	/* the time on either side of the break shares the width less the break's */
	span = (c->thi - c->tlo) - (c->bhi - c->blo);
	w = c->x1 - c->x0 - BREAK_W;
	if (t <= c->blo)
		return c->x0 + (t - c->tlo) / span * w;
	if (t >= c->bhi)
		return c->x0 + (c->blo - c->tlo + t - c->bhi) / span * w + BREAK_W;
	return c->x0 + (c->blo - c->tlo) / span * w + BREAK_W / 2.0;
}

/* The longest gap between plotted points, when it is more than 3 h and a
 * quarter of the span: the charts leave it out (a night psensd did not run
 * would otherwise take half of each chart). */
static void find_break(const struct zone *z, struct chart *c)
{
	double best = 0;
	c->blo = c->bhi = 0;
	for (int i = 1; i < z->n; i++)
		if (z->t[i] - z->t[i - 1] > best) {
			best = z->t[i] - z->t[i - 1];
			c->blo = z->t[i - 1];
			c->bhi = z->t[i];
		}
	if (!(best > 3 * 3600 && best > 0.25 * (c->thi - c->tlo)))
		c->blo = c->bhi = 0;
}

static double cy(const struct chart *c, double v)
{
	return c->y1 - (c->yhi > c->ylo ? (v - c->ylo) / (c->yhi - c->ylo) : 0) * (c->y1 - c->y0);
}

static void line(struct doc *d, const struct chart *c, const struct zone *z, const double *y, const double rgb[3],
                 double lw, int dashed)
{
	int open = 0;
	/* a gap much longer than the points' spacing (psensd not running) is
	 * left blank, not bridged by a straight line */
	double gap = z->n > 1 ? fmax(1800, 5 * (z->tmax - z->tmin) / (z->n - 1)) : INFINITY;
	cairo_save(d->cr);
	cairo_rectangle(d->cr, c->x0, c->y0, c->x1 - c->x0, c->y1 - c->y0);
	cairo_clip(d->cr);
	for (int i = 0; i < z->n; i++) {
		/* a gap (NaN) or time going back (a second run appended) breaks the line */
		if (!isfinite(y[i]) || (i > 0 && (z->t[i] < z->t[i - 1] || z->t[i] - z->t[i - 1] > gap))) {
			open = 0;
			if (!isfinite(y[i]))
				continue;
		}
		if (open)
			cairo_line_to(d->cr, cx(c, z->t[i]), cy(c, y[i]));
		else
			cairo_move_to(d->cr, cx(c, z->t[i]), cy(c, y[i]));
		open = 1;
	}
	set_rgb(d->cr, rgb);
	cairo_set_line_width(d->cr, lw);
	if (dashed) {
		static const double dash[] = { 4, 2.5 };
		cairo_set_dash(d->cr, dash, 2, 0);
	}
	cairo_set_line_join(d->cr, CAIRO_LINE_JOIN_ROUND);
	cairo_stroke(d->cr);
	cairo_restore(d->cr);
}

/* The chart's frame, shading, ticks, axis titles and legend; xtitle only
 * under the last chart. */
static void frame(struct doc *d, const struct chart *c, const struct zone *z, const char *title, const char *ytitle,
                  const struct legend *lg, int nlg, int xtitle)
{
	struct psd_ticks tt, yt;
	char lab[32];
	double x, lw, avail, size = 7;
	int midnights = 0;
	/* shading: faults (red), calibration sessions (blue) */
	if (!z)
		goto unshaded;
	cairo_save(d->cr);
	cairo_rectangle(d->cr, c->x0, c->y0, c->x1 - c->x0, c->y1 - c->y0);
	cairo_clip(d->cr);
	for (int i = 0; i < z->n; i++)
		if (z->fault[i]) {
			double a = cx(c, z->t[i]), b = i + 1 < z->n && z->t[i + 1] > z->t[i] ? cx(c, z->t[i + 1]) : a + 1;
			cairo_rectangle(d->cr, a, c->y0, fmax(b - a, 0.8), c->y1 - c->y0);
		}
	cairo_set_source_rgba(d->cr, RED[0], RED[1], RED[2], 0.22);
	cairo_fill(d->cr);
	for (int i = 0; i < z->n; i++)
		if (z->vacant[i]) {
			double a = cx(c, z->t[i]), b = i + 1 < z->n && z->t[i + 1] > z->t[i] ? cx(c, z->t[i + 1]) : a + 1;
			cairo_rectangle(d->cr, a, c->y0, fmax(b - a, 0.8), c->y1 - c->y0);
		}
	cairo_set_source_rgba(d->cr, GREY[0], GREY[1], GREY[2], 0.14);
	cairo_fill(d->cr);
	for (int i = 0; i < z->nsess; i++) {
		double a = z->sess[i].started, b = isfinite(z->sess[i].ended) ? z->sess[i].ended : z->tmax;
		if (!isfinite(a))
			continue;
		cairo_rectangle(d->cr, cx(c, a), c->y0, fmax(cx(c, b) - cx(c, a), 1.2), c->y1 - c->y0);
	}
	cairo_set_source_rgba(d->cr, BLUE[0], BLUE[1], BLUE[2], 0.16);
	cairo_fill(d->cr);
	cairo_restore(d->cr);
unshaded:
	/* grid and y ticks */
	if (psd_chart_ticks_num(c->ylo, c->yhi, 6, &yt) == 0)
		for (int i = 0; i < yt.n; i++) {
			double y = cy(c, yt.v[i]);
			hline(d, c->x0, c->x1, y, 0.3, (const double[3]){ 0.85, 0.85, 0.85 });
			psd_chart_tick_num_label(&yt, yt.v[i], lab, sizeof lab);
			text(d, c->x0 - 3, y + 2.5, 6.5, 0, 1, BLACK, lab);
		}
	/* time ticks: on each side of a break, for its own span */
	for (int seg = 0; seg < (c->bhi > c->blo ? 2 : 1); seg++) {
		double lo = c->bhi > c->blo && seg ? c->bhi : c->tlo, hi = c->bhi > c->blo && !seg ? c->blo : c->thi;
		int room = (int)((cx(c, hi) - cx(c, lo)) / 45);
		if (hi <= lo || psd_chart_ticks_time(lo, hi, room > 1 ? room : 2, &tt) != 0)
			continue;
		for (int i = 0; i < tt.n; i++) {
			x = cx(c, tt.v[i]);
			set_rgb(d->cr, GREY);
			cairo_set_line_width(d->cr, 0.5);
			cairo_move_to(d->cr, x, c->y1);
			cairo_line_to(d->cr, x, c->y1 + 3);
			cairo_stroke(d->cr);
			psd_chart_tick_time_label(tt.v[i], lab, sizeof lab);
			text(d, x, c->y1 + 12, 6.5, 0, 0, BLACK, lab);
		}
	}
	if (c->bhi > c->blo) {   /* the break: a gap in the frame's foot, two slants */
		x = cx(c, (c->blo + c->bhi) / 2);
		cairo_save(d->cr);
		set_rgb(d->cr, GREY);
		cairo_set_line_width(d->cr, 0.8);
		for (int k = -1; k <= 1; k += 2) {
			cairo_move_to(d->cr, x + k * 3 - 2, c->y1 + 4);
			cairo_line_to(d->cr, x + k * 3 + 2, c->y1 - 4);
		}
		cairo_stroke(d->cr);
		cairo_restore(d->cr);
	}
	/* day boundaries */
	for (double day = ceil(c->tlo / 86400) * 86400; day <= c->thi; day += 86400) {
		if (day <= c->tlo)
			continue;
		midnights++;
		x = cx(c, day);
		cairo_save(d->cr);
		set_rgb(d->cr, BLACK);
		cairo_set_line_width(d->cr, 0.8);
		cairo_set_dash(d->cr, (const double[2]){ 2, 2 }, 2, 0);
		cairo_move_to(d->cr, x, c->y0);
		cairo_line_to(d->cr, x, c->y1);
		cairo_stroke(d->cr);
		cairo_restore(d->cr);
		day_label(d, day, lab, sizeof lab);
		text(d, x + 2, c->y0 + 7, 6, 0, -1, BLACK, lab);
	}
	/* the frame */
	cairo_set_line_width(d->cr, 0.6);
	set_rgb(d->cr, GREY);
	cairo_rectangle(d->cr, c->x0, c->y0, c->x1 - c->x0, c->y1 - c->y0);
	cairo_stroke(d->cr);
	text_up(d, MARGIN + 6, (c->y0 + c->y1) / 2, 7, BLACK, ytitle);
	if (xtitle)
		/* the dashed line is explained only where there is one */
		text(d, (c->x0 + c->x1) / 2, c->y1 + 22.5, 7, 0, 0, BLACK, !d->dated ? "local time of day (hh:mm); day 1 "
		     "is the day psensd started" : midnights ? "local time of day (hh:mm); a dashed line is midnight, "
		     "with the new date" : "local time of day (hh:mm)");
	/* title and legend above the plot */
	lw = text(d, c->x0, c->y0 - 4, 8.5, 1, -1, BLACK, title);
	x = c->x0 + lw + 12;
	avail = c->x1 - x;
	for (;;) {
		double need = 0;
		font(d, size, 0);
		for (int i = 0; i < nlg; i++)
			need += 16 + width_of(d, lg[i].label) + 8;
		if (need <= avail || size <= 5)
			break;
		size -= 0.25;
	}
	for (int i = 0; i < nlg; i++) {
		double ly = c->y0 - 6.5;
		if (lg[i].kind == 2) {
			cairo_rectangle(d->cr, x, ly - 3, 12, 6);
			cairo_set_source_rgba(d->cr, lg[i].rgb[0], lg[i].rgb[1], lg[i].rgb[2], lg[i].alpha);
			cairo_fill(d->cr);
		} else {
			cairo_save(d->cr);
			if (lg[i].kind == 1)
				cairo_set_dash(d->cr, (const double[2]){ 3, 2 }, 2, 0);
			hline(d, x, x + 12, ly, 1.4, lg[i].rgb);
			cairo_restore(d->cr);
		}
		x += 16;
		x += text_fit(d, x, c->y0 - 4, fmax(c->x1 - x, 10), size, 5, 0, BLACK, lg[i].label) + 8;
	}
}

static void charts(struct doc *d, const struct zone *z, double top, double bottom)
{
	const struct psd_zone_conf *zc = zconf(d, z);
	double target = zc ? zc->ctl.target_lux : NAN;
	double gap = 30, h = (bottom - top - 3 * gap - 12) / 4;
	double tlo = z->tmin, thi = z->tmax > z->tmin ? z->tmax : z->tmin + 3600;
	struct chart c = { MARGIN + 34, top, PAGE_W - MARGIN - 4, top + h, tlo, thi, 0, 1, 0, 0 };
	double *tl = NULL;
	find_break(z, &c);
	const struct legend fault = { "fault (safe level)", RED, 2, 0.22 }, cal = { "calibration", BLUE, 2, 0.16 },
	                    vacant = { "vacant", GREY, 2, 0.14 };
	/* sensor volts */
	c.ylo = 0;
	c.yhi = z->vmax > 0 ? z->vmax : 1;
	psd_chart_ticks_round_range(&c.ylo, &c.yhi, 6);
	{
		struct legend lg[4] = { { "sensor signal", BLUE, 0, 1 } };
		int k = 1;
		if (z->fault_s > 0)
			lg[k++] = fault;
		if (z->nsess)
			lg[k++] = cal;
		if (z->vac_s > 0)
			lg[k++] = vacant;
		frame(d, &c, z, "Sensor", "sensor signal (V)", lg, k, 0);
	}
	line(d, &c, z, z->v, BLUE, 1.1, 0);
	/* task lux */
	c.y0 += h + gap;
	c.y1 += h + gap;
	c.ylo = 0;
	c.yhi = fmax(z->luxmax, isfinite(target) ? target * 1.1 : 0);
	if (!(c.yhi > 0))
		c.yhi = 100;
	psd_chart_ticks_round_range(&c.ylo, &c.yhi, 6);
	{
		struct legend lg[6] = { { "estimated", ORANGE, 1, 1 } };
		int k = 1;
		if (z->nmeas)
			lg[k++] = (struct legend){ "measured", GREEN, 0, 1 };
		if (isfinite(target))
			lg[k++] = (struct legend){ "target", RED, 1, 1 };
		if (z->fault_s > 0)
			lg[k++] = fault;
		if (z->nsess)
			lg[k++] = cal;
		if (z->vac_s > 0)
			lg[k++] = vacant;
		frame(d, &c, z, "Task illuminance", "task illuminance (lx)", lg, k, 0);
	}
	line(d, &c, z, z->lux, GREEN, 1.1, 0);
	line(d, &c, z, z->est, ORANGE, 1.1, 1);
	if (isfinite(target) && (tl = malloc((size_t)z->n * sizeof *tl))) {
		for (int i = 0; i < z->n; i++)
			tl[i] = target;
		line(d, &c, z, tl, RED, 0.9, 1);
		free(tl);
	}
	/* dimming level */
	c.y0 += h + gap;
	c.y1 += h + gap;
	c.ylo = 0;
	c.yhi = 100;
	{
		struct legend lg[4] = { { "light output", PURPLE, 0, 1 } };
		int k = 1;
		if (z->fault_s > 0)
			lg[k++] = fault;
		if (z->nsess)
			lg[k++] = cal;
		if (z->vac_s > 0)
			lg[k++] = vacant;
		frame(d, &c, z, "Dimming level", "light output (%)", lg, k, 0);
	}
	line(d, &c, z, z->out, PURPLE, 1.1, 0);
	/* energy */
	c.y0 += h + gap;
	c.y1 += h + gap;
	c.ylo = 0;
	c.yhi = z->energy_h > 0 ? z->energy_h : 1;
	psd_chart_ticks_round_range(&c.ylo, &c.yhi, 6);
	{
		char lab[96];
		snprintf(lab, sizeof lab, "lighting energy to date, %.2f full-load h in all", z->energy_h);
		const struct legend lg[] = { { lab, BLACK, 0, 1 } };
		frame(d, &c, z, "Energy", "energy (full-load h)", lg, 1, 1);
	}
	line(d, &c, z, z->energy, BLACK, 1.1, 0);
}

/* ---- tables ------------------------------------------------------------------ */

enum { ROW_H = 11 };

static double table_head(struct doc *d, double y, const char *title, const double *cols, const char *const *head,
                         int ncol)
{
	text(d, MARGIN, y, 10, 1, -1, BLACK, title);
	y += 14;
	for (int c = 0; c < ncol; c++) {
		double w = (c + 1 < ncol ? cols[c + 1] : PAGE_W - 2 * MARGIN) - cols[c] - 4;
		text_fit(d, MARGIN + cols[c], y, w, 7, 5, 1, BLACK, head[c]);
	}
	hline(d, MARGIN, PAGE_W - MARGIN, y + 3, 0.5, BLACK);
	return y + ROW_H + 1;
}

static const double SCOLS[] = { 0, 18, 46, 98, 152, 206, 420 };

/* A session's result in at most two lines of the result column: 1 or 2. */
static int result_lines(struct doc *d, const char *s, char *l1, char *l2, size_t n)
{
	double maxw = SCOLS[6] - SCOLS[5] - 4;
	snprintf(l1, n, "%s", s);
	l2[0] = 0;
	font(d, 7, 0);
	if (width_of(d, l1) <= maxw)
		return 1;
	/* the longest first line that fits, broken after a space */
	for (size_t k = strlen(l1); k > 0; k--)
		if (s[k] == ' ') {
			l1[k] = 0;
			if (width_of(d, l1) <= maxw) {
				snprintf(l2, n, "%s", s + k + 1);
				return 2;
			}
		}
	snprintf(l1, n, "%s", s);
	return 1;
}

static double session_row(struct doc *d, double y, const struct session *s)
{
	char buf[64], a[32], l1[200], l2[200];
	int lines = result_lines(d, s->result[0] ? s->result : "-", l1, l2, sizeof l1);
	const char *cells[7];
	snprintf(buf, sizeof buf, "%lld", s->id);
	cells[0] = buf;
	cells[1] = s->kind;
	cells[2] = s->state;
	if (s->local0[0])
		snprintf(a, sizeof a, "%s", s->local0 + 5);   /* 03-18 09:58 */
	else
		when(s->started, a, sizeof a);
	cells[3] = a;
	for (int c = 0; c < 4; c++)
		text_fit(d, MARGIN + SCOLS[c], y, SCOLS[c + 1] - SCOLS[c] - 4, 7, 5, 0, BLACK, cells[c]);
	if (s->local1[0])
		snprintf(a, sizeof a, "%s", s->local1 + 5);
	else
		when(s->ended, a, sizeof a);
	text_fit(d, MARGIN + SCOLS[4], y, SCOLS[5] - SCOLS[4] - 4, 7, 5, 0, BLACK, a);
	text_fit(d, MARGIN + SCOLS[5], y, SCOLS[6] - SCOLS[5] - 4, 7, 5, 0, BLACK, l1);
	if (lines > 1)
		text_fit(d, MARGIN + SCOLS[5] + 6, y + ROW_H - 1.5, SCOLS[6] - SCOLS[5] - 10, 7, 5, 0, BLACK, l2);
	text_fit(d, MARGIN + SCOLS[6], y, PAGE_W - 2 * MARGIN - SCOLS[6], 7, 5, s->judged && !s->pass,
	         !s->judged ? GREY : s->pass ? GREEN : RED, s->design[0] ? s->design : "not judged");
	return y + lines * ROW_H - (lines > 1 ? 1.5 : 0);
}

/* One test of the acceptance run: its name, its verdict, and what it
 * measured wrapped over the rest of the line (up to four lines). */
enum { ACOL_VERDICT = 80, ACOL_MEASURED = 140 };

static double acc_row(struct doc *d, double y, const struct zone *z, int r)
{
	const char *v = z->acc[r].verdict;
	const double *rgb = strcmp(v, "PASS") == 0 ? GREEN : strcmp(v, "FAIL") == 0 ? RED : GREY;
	double end;
	text_fit(d, MARGIN, y, ACOL_VERDICT - 4, 7, 5, 0, BLACK, z->acc[r].test);
	text_fit(d, MARGIN + ACOL_VERDICT, y, ACOL_MEASURED - ACOL_VERDICT - 4, 7, 5, 1, rgb, v);
	end = paragraph(d, MARGIN + ACOL_MEASURED, y, PAGE_W - 2 * MARGIN - ACOL_MEASURED, 6.5, 8.5, BLACK,
	                z->acc[r].measured[0] ? z->acc[r].measured : "-");
	return fmax(y + ROW_H, end + 2.5);
}

/* With [web] url: a QR code of the link that opens the zone in the web
 * console (URL#zone=NAME), size pt square, its top right corner at x, y.
 * The size it took (0: none, or built without libqrencode). */
static double zone_qr(struct doc *d, const struct zone *z, double x, double y, double size)
{
#ifdef PS_WITH_QRENCODE
	const char *url = d->o->cf ? d->o->cf->web.url : "";
	char link[512];
	size_t k;
	QRcode *q;
	double m;
	if (!url[0] || !d->cr)
		return 0;
	k = (size_t)snprintf(link, sizeof link, "%s%s#zone=", url, url[strlen(url) - 1] == '/' ? "" : "/");
	for (const char *p = z->name; *p && k + 4 < sizeof link; p++)   /* the name, percent-encoded */
		k += (size_t)(strchr("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-._~", *p) ?
		              snprintf(link + k, sizeof link - k, "%c", *p) :
		              snprintf(link + k, sizeof link - k, "%%%02X", (unsigned char)*p));
	if (!(q = QRcode_encodeString(link, 0, QR_ECLEVEL_M, QR_MODE_8, 1)))
		return 0;
	m = size / (q->width + 8);   /* and the quiet zone of four modules each side */
	cairo_set_source_rgb(d->cr, 1, 1, 1);
	cairo_rectangle(d->cr, x - size, y, size, size);
	cairo_fill(d->cr);
	set_rgb(d->cr, BLACK);
	for (int r = 0; r < q->width; r++)
		for (int c = 0; c < q->width; c++)
			if (q->data[r * q->width + c] & 1)
				cairo_rectangle(d->cr, x - size + (c + 4) * m, y + (r + 4) * m, m, m);
	cairo_fill(d->cr);
	QRcode_free(q);
	return size;
#else
	(void)d;
	(void)z;
	(void)x;
	(void)y;
	(void)size;
	return 0;
#endif
}

static void zone_pages(struct doc *d, const struct zone *z)
{
	static const char *const shead[] = { "#", "kind", "state", "started", "ended", "result",
	                                      "against the design" };
	char buf[768], sensor[160], a[32], b[32], what[80], lo[96];
	const struct psd_zone_conf *zc = zconf(d, z);
	double y, bottom = FOOT_Y - 16, charts_min = 4 * 92 + 3 * 30 + 12;
	int row = 0, acc = 0, nlines = 0;
	double tables_h, top = MARGIN + 52, room = bottom - top - charts_min - 24, qr;
	char l1[200], l2[200];
	snprintf(what, sizeof what, "zone %s", z->name);
	begin_page(d);
	if (!d->cr)
		return;
	for (int i = 0; i < z->nsess; i++)
		nlines += result_lines(d, z->sess[i].result[0] ? z->sess[i].result : "-", l1, l2, sizeof l1);
	tables_h = 12 + 26 + (nlines ? nlines : 1) * ROW_H + (z->nacc ? 36 + z->nacc * 4 * 8.5 : 0);
	snprintf(buf, sizeof buf, "Zone %s", z->name);
	text_fit(d, MARGIN, MARGIN + 14, PAGE_W - 2 * MARGIN - 170, 16, 9, 1, BLACK, buf);
	text(d, PAGE_W - MARGIN, MARGIN + 14, 16, 1, 1, verdict_rgb(z->verdict), verdict_word(z->verdict));
	if ((qr = zone_qr(d, z, PAGE_W - MARGIN, MARGIN + 20, 64)) > 0) {
		top += qr - 30;   /* the charts start below it, the tables keep their room */
		room -= qr - 30;
	}
	sensor_text(d, z, sensor, sizeof sensor, 0);
	when_z(z, 0, a, sizeof a);
	when_z(z, 1, b, sizeof b);
	if (zc)
		snprintf(buf, sizeof buf, "sensor %s; target %.0f lx; %lld samples, %s to %s", sensor, zc->ctl.target_lux,
		         z->total, a, b);
	else
		snprintf(buf, sizeof buf, "%lld samples, %s to %s", z->total, a, b);
	if (z->has_occ) {
		size_t k = strlen(buf);
		snprintf(buf + k, sizeof buf - k, "; occupied %.2f h, vacant %.2f h", z->occ_s / 3600, z->vac_s / 3600);
		k = strlen(buf);
		if (isfinite(z->elec))
			snprintf(buf + k, sizeof buf - k, ", the vacancies saved %.2f full-load h", z->saved_h);
	}
	text_fit(d, MARGIN, MARGIN + 29, PAGE_W - 2 * MARGIN - (qr > 0 ? qr + 8 : 0), 8, 5.5, 0, GREY, buf);
	if (z->verif.test && z->verif.verdict != PSD_ACCEPT_NOT_TESTED)
		snprintf(lo, sizeof lo, "%ld in sessions or %g s after one left out",
		         z->verif.left_out, z->verif.settle_s);
	if (z->verif.test && z->verif.verdict != PSD_ACCEPT_NOT_TESTED)
		snprintf(buf, sizeof buf, "verification (as accept-test): rms %.2f %% over %ld samples (%s), %s; "
		         "%d of %d calibration results within %g %%; faults %.0f min; energy %.2f full-load h",
		         z->verif.value, z->verif.samples, lo, psd_accept_verdict_names[z->verif.verdict + 1],
		         z->checks - z->fails, z->checks, d->o->tolerance_pct, z->fault_s / 60, z->energy_h);
	else
		snprintf(buf, sizeof buf, "verification: %s; %d of %d calibration results within %g %%; "
		         "faults %.0f min; energy %.2f full-load h", z->verif.test ? z->verif.measured : z->verif_why,
		         z->checks - z->fails, z->checks, d->o->tolerance_pct, z->fault_s / 60, z->energy_h);
	text_fit(d, MARGIN, MARGIN + 40, PAGE_W - 2 * MARGIN - (qr > 0 ? qr + 8 : 0), 8, 5.5, 0, GREY, buf);
	/* the tables take what they need from the bottom (up to what leaves the
	 * charts their least height); the charts fill the rest */
	if (tables_h > room)
		tables_h = room;
	if (z->n)
		charts(d, z, top + 10, bottom - tables_h - 10);
	else
		text(d, MARGIN, top + 30, 12, 0, -1, GREY, "no samples for this zone");
	y = bottom - tables_h + 12;
	for (;;) {
		if (row < z->nsess || (row == 0 && !z->nsess)) {
			y = table_head(d, y, row ? "Calibration sessions (continued)" : "Calibration sessions", SCOLS, shead, 7);
			if (!z->nsess) {
				text(d, MARGIN, y, 7, 0, -1, GREY, "no calibration session recorded");
				y += ROW_H;
			}
			for (; row < z->nsess; row++) {
				int lines = result_lines(d, z->sess[row].result[0] ? z->sess[row].result : "-", l1, l2,
				                         sizeof l1);
				if (y + (lines - 1) * ROW_H > bottom)
					break;
				y = session_row(d, y, &z->sess[row]);
			}
		}
		if (row >= z->nsess && z->nacc && acc < z->nacc && y + 40 <= bottom) {
			static const double acols[] = { 0, ACOL_VERDICT, ACOL_MEASURED };
			static const char *const ahead[] = { "test", "verdict", "what it measured" };
			char title[160];
			snprintf(title, sizeof title, "Acceptance tests%s%s%s%s", acc ? " (continued)" : "",
			         z->acc[0].local[0] ? ", run " : "", z->acc[0].local,
			         z->nruns > 1 ? " (the last run; earlier runs are in the database)" : "");
			y = table_head(d, y + 10, title, acols, ahead, 3);
			for (; acc < z->nacc && y + 4 * 8.5 <= bottom; acc++)
				y = acc_row(d, y, z, acc);
		}
		if (row >= z->nsess && acc >= z->nacc)
			break;
		end_page(d, what);
		begin_page(d);
		if (!d->cr)
			return;
		y = MARGIN + 14;
	}
	end_page(d, what);
}

/* ---- zones, output ------------------------------------------------------------ */

struct names {
	char name[PSD_MAX_ZONES * 4][48];
	int n;
};

static void add_name(void *user, const char *name)
{
	struct names *nm = user;
	if (nm->n < (int)(sizeof nm->name / sizeof nm->name[0]))
		snprintf(nm->name[nm->n++], sizeof nm->name[0], "%s", name);
}

int psd_report_format_of(const char *path)
{
	const char *dot = path ? strrchr(path, '.') : NULL;
	if (!dot)
		return -1;
	return strcasecmp(dot, ".pdf") == 0 ? PSD_REPORT_PDF : strcasecmp(dot, ".png") == 0 ? PSD_REPORT_PNG :
	       strcasecmp(dot, ".svg") == 0 ? PSD_REPORT_SVG : -1;
}

/* Which zones: the one asked for (an error naming the zones there are when
 * the database does not know it), or every zone. */
static int pick_zones(const struct psd_report_opts *o, struct psd_db *db, struct doc *d, char *err, size_t n)
{
	static struct names nm;
	char list[512] = "";
	nm.n = 0;
	if (psd_db_zones(db, add_name, &nm, err, n) != 0)
		return -1;
	/* zones of the configuration with nothing recorded yet still appear */
	if (o->cf)
		for (size_t i = 0; i < o->cf->nzone; i++) {
			int have = 0;
			for (int k = 0; k < nm.n; k++)
				have |= strcmp(nm.name[k], o->cf->zone[i].name) == 0;
			if (!have)
				add_name(&nm, o->cf->zone[i].name);
		}
	for (int k = 0; k < nm.n; k++)
		snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", k ? ", " : "", nm.name[k]);
	if (o->zone) {
		int found = 0;
		for (int k = 0; k < nm.n; k++)
			found |= strcmp(nm.name[k], o->zone) == 0;
		/* a log written before samples named their zone: its samples are
		 * every zone's (psd_db_zone_samples), so any name is taken */
		if (!found && nm.n == 0 && psd_db_zone_count(db, "", err, n) > 0)
			found = 1;
		if (!found)
			return psd_errbuf(err, n, "%s: no zone '%s' (zones: %s)", o->dbpath, o->zone,
			                nm.n ? list : "none recorded");
		nm.n = 1;
		snprintf(nm.name[0], sizeof nm.name[0], "%s", o->zone);
	}
	if (nm.n <= 0)
		return psd_errbuf(err, n, "%s: no zone recorded (%s)", o->dbpath, psd_db_zone_count(db, "", err, n) > 0 ?
		                "its samples name none: give the zone" : "no samples, no sessions");
	if (nm.n > PSD_MAX_ZONES)
		nm.n = PSD_MAX_ZONES;
	d->zones = calloc((size_t)nm.n, sizeof *d->zones);
	if (!d->zones)
		return psd_errbuf(err, n, "out of memory");
	for (int k = 0; k < nm.n; k++) {
		struct zone *z = &d->zones[d->nzones++];
		snprintf(z->name, sizeof z->name, "%s", nm.name[k]);
		z->ci = o->cf ? psd_config_zone(o->cf, z->name) : -1;
		if (zone_alloc(z) != 0)
			return psd_errbuf(err, n, "out of memory");
	}
	return 0;
}

static void layout(struct doc *d)
{
	d->page = 0;
	cover(d);
	for (int i = 0; i < d->nzones && !d->failed; i++)
		zone_pages(d, &d->zones[i]);
}

static void drop_pages(struct doc *d)
{
	for (int i = 0; i < d->nrec; i++)
		cairo_surface_destroy(d->rec[i]);
	d->nrec = 0;
}

static cairo_status_t to_file(void *closure, const unsigned char *data, unsigned int len)
{
	return fwrite(data, 1, len, closure) == len ? CAIRO_STATUS_SUCCESS : CAIRO_STATUS_WRITE_ERROR;
}

static int emit(struct doc *d, FILE *fp, char *err, size_t n)
{
	const struct psd_report_opts *o = d->o;
	cairo_surface_t *s;
	cairo_t *cr;
	cairo_status_t st;
	int first = 0, last = d->nrec - 1;
	double scale = o->format == PSD_REPORT_PNG ? PNG_SCALE : 1, gap = 12;
	if (o->format != PSD_REPORT_PDF && o->page > 0) {
		if (o->page > d->nrec)
			return psd_errbuf(err, n, "page %d: the report has %d pages", o->page, d->nrec);
		first = last = o->page - 1;
	}
	if (o->format == PSD_REPORT_PDF) {
		s = cairo_pdf_surface_create_for_stream(to_file, fp, PAGE_W, PAGE_H);
		cairo_pdf_surface_set_metadata(s, CAIRO_PDF_METADATA_TITLE, "psensd commissioning record");
		cairo_pdf_surface_set_metadata(s, CAIRO_PDF_METADATA_CREATOR, "psensctl report");
		if (o->site)
			cairo_pdf_surface_set_metadata(s, CAIRO_PDF_METADATA_SUBJECT, o->site);
		{
			char iso[32];
			psd_time_utc_text((double)o->written, PSD_TIME_ISO, iso, sizeof iso);
			cairo_pdf_surface_set_metadata(s, CAIRO_PDF_METADATA_CREATE_DATE, iso);
		}
	} else {
		int pages = last - first + 1;
		double w = PAGE_W * scale, h = (PAGE_H * pages + gap * (pages - 1)) * scale;
		s = o->format == PSD_REPORT_PNG ? cairo_image_surface_create(CAIRO_FORMAT_RGB24, (int)ceil(w), (int)ceil(h))
		                                : cairo_svg_surface_create_for_stream(to_file, fp, w, h);
	}
	cr = cairo_create(s);
	if (o->format != PSD_REPORT_PDF) {
		cairo_set_source_rgb(cr, 0.6, 0.6, 0.6);
		cairo_paint(cr);
	}
	if (o->format == PSD_REPORT_SVG) {
		/* drawn again, straight onto the SVG surface (same layout, same boxes) */
		drop_pages(d);
		psd_textbox_free(d->boxes);
		d->direct = s;
		d->first = first;
		d->last = last;
		d->gap = gap;
		layout(d);
		d->direct = NULL;
		first = 0;
		last = -1;
	}
	for (int i = first; i <= last; i++) {
		cairo_save(cr);
		if (o->format != PSD_REPORT_PDF) {
			cairo_scale(cr, scale, scale);
			cairo_translate(cr, 0, (i - first) * (PAGE_H + gap));
		}
		cairo_set_source_surface(cr, d->rec[i], 0, 0);
		cairo_paint(cr);
		cairo_restore(cr);
		if (o->format == PSD_REPORT_PDF)
			cairo_show_page(cr);
	}
	st = cairo_status(cr);
	cairo_destroy(cr);
	if (st == CAIRO_STATUS_SUCCESS && o->format == PSD_REPORT_PNG)
		st = cairo_surface_write_to_png_stream(s, to_file, fp);
	cairo_surface_finish(s);
	if (st == CAIRO_STATUS_SUCCESS)
		st = cairo_surface_status(s);
	cairo_surface_destroy(s);
	if (st != CAIRO_STATUS_SUCCESS || ferror(fp))
		return psd_errbuf(err, n, "writing the report: %s", ferror(fp) ? strerror(errno) : cairo_status_to_string(st));
	return 0;
}

/* Draw the document to fp.  -1 with a message (a zone the database does not
 * know is named with the zones it does know). */
static int render(const struct psd_report_opts *o, FILE *fp, struct psd_report_out *r, char *err, size_t n)
{
	struct psd_db *db;
	struct doc d = { 0 };
	int rc = -1;
	memset(r, 0, sizeof *r);
	d.o = o;
	d.boxes = &r->boxes;
	if (!(db = psd_db_open_readonly(o->dbpath, err, n)))
		return -1;
	if (pick_zones(o, db, &d, err, n) != 0)
		goto out;
	for (int i = 0; i < d.nzones; i++)
		if (load_zone(db, &d.zones[i], o->tolerance_pct, err, n) != 0)
			goto out;
	for (int i = 0; i < d.nzones; i++) {
		struct zone *z = &d.zones[i];
		int k = o->cf ? psd_config_zone(o->cf, z->name) : -1;
		const char *sim = k >= 0 ? psd_config_zone_simulated(o->cf, &o->cf->zone[k]) : NULL;
		if (!z->simulated[0] && sim)
			snprintf(z->simulated, sizeof z->simulated, "the zone's devices are simulated (%s)", sim);
		d.simulated |= z->simulated[0] != 0;
	}
	d.dated = d.nzones > 0;
	for (int i = 0; i < d.nzones; i++)
		d.dated &= d.zones[i].local0[0] != 0 || d.zones[i].total == 0;
	for (int i = 0; d.dated && i < d.nzones; i++)
		if (d.zones[i].local0[0] && sscanf(d.zones[i].local0, "%d-%d-%d", &d.y0, &d.m0, &d.d0) == 3) {
			d.t0 = d.zones[i].tmin;
			break;
		}
	if (o->config_path) {
		struct ps_err pe = { 0 };
		if (ps_cache_hash_file(o->config_path, d.config_sha, &pe) != 0)
			d.config_sha[0] = 0;   /* the cover then says it is unknown */
	}
	/* each simulation the zones run on, read once: its scene (or, with no
	 * scene named, its results file) and the SHA-256 psscene gave the scene
	 * and every input it names */
	for (int i = 0; o->cf && i < d.nzones; i++) {
		const struct psd_zone_conf *zc = zconf(&d, &d.zones[i]);
		const char *res_path = zc ? psd_config_zone_results(o->cf, zc) : NULL;
		int k = 0;
		if (!res_path)
			continue;
		while (k < d.nscenes && strcmp(d.scene[k].results, res_path) != 0)
			k++;
		if (k == d.nscenes) {
			struct ps_results res = { 0 };
			struct ps_err pe = { 0 };
			const char *sc = psd_config_zone_scene(o->cf, zc);
			d.scene[k].results = res_path;
			d.scene[k].path = sc ? sc : res_path;
			if (ps_results_read(&res, res_path, &pe) == 0 && res.scene_hash)
				snprintf(d.scene[k].sha, sizeof d.scene[k].sha, "%s", res.scene_hash);
			ps_results_free(&res);
			d.nscenes++;
		}
		d.zones[i].scene_k = k;
	}
	/* twice: the first pass counts the pages for "page n of N" */
	layout(&d);
	d.pages = d.nrec;
	drop_pages(&d);
	psd_textbox_free(&r->boxes);
	d.failed = 0;
	layout(&d);
	if (d.failed) {
		psd_errbuf(err, n, "drawing the report failed (more than %d pages, or out of memory)", MAXPAGES);
		goto out;
	}
	if (emit(&d, fp, err, n) != 0)
		goto out;
	r->pages = d.nrec;
	r->verdict = overall(&d);
	r->nzones = d.nzones;
	for (int i = 0; i < d.nzones; i++) {
		snprintf(r->zone[i].name, sizeof r->zone[i].name, "%s", d.zones[i].name);
		r->zone[i].verdict = d.zones[i].verdict;
	}
	rc = 0;
out:
	drop_pages(&d);
	for (int i = 0; i < d.nzones; i++)
		zone_free(&d.zones[i]);
	free(d.zones);
	psd_db_close(db);
	return rc;
}

int psd_report_write(const struct psd_report_opts *o, const char *path, struct psd_report_out *r, char *err,
                     size_t n)
{
	struct ps_replace_mem m;
	struct ps_err e;
	FILE *fp;
	memset(r, 0, sizeof *r);   /* freeable whatever fails */
	if (!path)
		return render(o, stdout, r, err, n) == 0 && fflush(stdout) == 0 ? 0 : -1;
	if (!(fp = ps_replace_mem_open(&m, &e)))
		return psd_errbuf(err, n, "%s: %s", path, e.msg);
	if (render(o, fp, r, err, n) != 0) {
		ps_replace_mem_abort(&m);
		return -1;
	}
	/* 0666 less the umask: the report reads as it would have been created by fopen */
	if (ps_replace_mem_commit(&m, path, 0666, &e) != 0)
		return psd_errbuf(err, n, "%s", e.msg);
	return 0;
}

void psd_report_out_free(struct psd_report_out *r)
{
	psd_textbox_free(&r->boxes);
}
