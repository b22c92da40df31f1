/* The commissioning report: one SVG page a person reads without a terminal,
 * from the database alone (psensd need not run).  Sensor volts, measured and
 * estimated task lux over time with the faults shaded, the calibration
 * sessions with their results, and a verdict against the design prediction. */
#include "report.h"

#include <json-c/json.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "clock.h"
#include "db.h"

enum { MAXPTS = 2000, W = 960, H = 1100, PX = 80, PY = 110, PW = 800, PH = 340 };

struct series {
	double t[MAXPTS], v[MAXPTS], lux[MAXPTS], est[MAXPTS];
	int fault[MAXPTS];
	int n;
	double tmin, tmax, vmax, luxmax;
};

static void esc(FILE *fp, const char *s)
{
	for (; s && *s; s++) {
		switch (*s) {
		case '&': fputs("&amp;", fp); break;
		case '<': fputs("&lt;", fp); break;
		case '>': fputs("&gt;", fp); break;
		case '"': fputs("&quot;", fp); break;
		default:
			if ((unsigned char)*s >= 0x20)
				fputc(*s, fp);
		}
	}
}

/* Every sample of the zone, thinned evenly to at most MAXPTS. */
struct thin {
	struct series *s;
	long long i, step;
};

static void add_point(void *user, const struct psd_sample *row)
{
	struct thin *th = user;
	struct series *s = th->s;
	if (th->i++ % th->step || s->n >= MAXPTS)
		return;
	s->t[s->n] = row->t;
	s->v[s->n] = row->sensor_v;
	s->lux[s->n] = row->task_lux;
	s->est[s->n] = row->est_task_lux;
	s->fault[s->n] = row->fault != NULL;
	if (s->t[s->n] < s->tmin)
		s->tmin = s->t[s->n];
	if (s->t[s->n] > s->tmax)
		s->tmax = s->t[s->n];
	if (s->v[s->n] > s->vmax)
		s->vmax = s->v[s->n];
	if (s->lux[s->n] > s->luxmax)
		s->luxmax = s->lux[s->n];
	if (s->est[s->n] > s->luxmax)
		s->luxmax = s->est[s->n];
	s->n++;
}

static int load_series(struct psd_db *db, const char *zone, struct series *s, char *err, size_t n)
{
	long long total = psd_db_zone_count(db, zone, err, n);
	struct thin th = { s, 0, 0 };
	if (total < 0)
		return -1;
	th.step = total / MAXPTS + 1;
	memset(s, 0, sizeof *s);
	s->tmin = INFINITY;
	s->tmax = -INFINITY;
	return psd_db_zone_samples(db, zone, add_point, &th, err, n);
}

static double xof(const struct series *s, double t)
{
	return PX + (s->tmax > s->tmin ? (t - s->tmin) / (s->tmax - s->tmin) : 0.5) * PW;
}

static void polyline(FILE *fp, const struct series *s, const double *y, double ymax, const char *style)
{
	int open = 0;
	for (int i = 0; i < s->n; i++) {
		if (!isfinite(y[i])) {
			if (open)
				fputs("\"/>\n", fp);
			open = 0;
			continue;
		}
		if (!open)
			fprintf(fp, "<polyline %s points=\"", style);
		open = 1;
		fprintf(fp, "%.1f,%.1f ", xof(s, s->t[i]), PY + PH - (ymax > 0 ? y[i] / ymax : 0) * PH);
	}
	if (open)
		fputs("\"/>\n", fp);
}

static void plot(FILE *fp, const struct series *s)
{
	double vmax = s->vmax > 0 ? s->vmax * 1.1 : 1, lmax = s->luxmax > 0 ? s->luxmax * 1.1 : 1;
	fprintf(fp, "<rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\" fill=\"#fafafa\" stroke=\"#888\"/>\n", PX, PY,
	        PW, PH);
	/* faults: the lights were at the safe level */
	for (int i = 0; i < s->n; i++)
		if (s->fault[i]) {
			double x0 = xof(s, s->t[i]), x1 = i + 1 < s->n ? xof(s, s->t[i + 1]) : x0 + 1;
			fprintf(fp, "<rect x=\"%.1f\" y=\"%d\" width=\"%.1f\" height=\"%d\" fill=\"#f4c7c3\"/>\n", x0, PY,
			        fmax(x1 - x0, 1), PH);
		}
	for (int k = 0; k <= 4; k++) {
		double y = PY + PH - k * PH / 4.0;
		char t[8];
		fprintf(fp, "<line x1=\"%d\" y1=\"%.1f\" x2=\"%d\" y2=\"%.1f\" stroke=\"#ddd\"/>\n", PX, y, PX + PW, y);
		fprintf(fp, "<text x=\"%d\" y=\"%.1f\" font-size=\"11\" text-anchor=\"end\" fill=\"#1f4e9c\">%.3g</text>\n",
		        PX - 6, y + 4, vmax * k / 4);
		fprintf(fp, "<text x=\"%d\" y=\"%.1f\" font-size=\"11\" fill=\"#2b7a2b\">%.0f</text>\n", PX + PW + 6,
		        y + 4, lmax * k / 4);
		psd_clock_hhmm(s->tmin + (s->tmax - s->tmin) * k / 4, t);
		fprintf(fp, "<text x=\"%.1f\" y=\"%d\" font-size=\"11\" text-anchor=\"middle\">%s</text>\n",
		        PX + PW * k / 4.0, PY + PH + 16, t);
	}
	polyline(fp, s, s->v, vmax, "fill=\"none\" stroke=\"#1f4e9c\" stroke-width=\"1.5\"");
	polyline(fp, s, s->lux, lmax, "fill=\"none\" stroke=\"#2b7a2b\" stroke-width=\"1.5\"");
	polyline(fp, s, s->est, lmax, "fill=\"none\" stroke=\"#e07b00\" stroke-width=\"1.5\" stroke-dasharray=\"5,3\"");
	fprintf(fp, "<text x=\"%d\" y=\"%d\" font-size=\"12\"><tspan fill=\"#1f4e9c\">sensor volts (left)</tspan>"
	            "  <tspan fill=\"#2b7a2b\">measured task lux (right)</tspan>  <tspan fill=\"#e07b00\">task lux"
	            " estimated from the simulated ratio (right)</tspan>  <tspan fill=\"#c0392b\">shaded: fault, lights at"
	            " the safe level</tspan></text>\n", PX, PY - 10);
}

static double jnum(json_object *o, const char *k)
{
	json_object *v;
	return o && json_object_object_get_ex(o, k, &v) && v ? json_object_get_double(v) : NAN;
}

/* One row of the sessions' table; the verdict counts the sessions in force
 * or awaiting acceptance. */
struct table {
	FILE *fp;
	int y, checks, fails;
	double tolerance_pct;
};

static void session_row(void *user, const struct psd_db_cal_session *row)
{
	struct table *t = user;
	FILE *fp = t->fp;
	json_object *o;
	char result[256] = "", design[128] = "", t0[8];
	int judged = 0, pass = 1;
	if (t->y >= H - 80)
		return;
	o = row->results ? json_tokener_parse(row->results) : NULL;
	t->y += 18;
	psd_clock_hhmm(row->started, t0);
	if (o && strcmp(row->kind, "night") == 0) {
		double e = jnum(o, "electric_lux_error_pct");
		snprintf(result, sizeof result, "offset %.4f V, %.4f V at full (se %.4f), R2 %.6f, worst residual "
		         "%.2f %%", jnum(o, "offset"), jnum(o, "gain"), jnum(o, "gain_se"), jnum(o, "r2"),
		         jnum(o, "max_resid_pct"));
		if (isfinite(e)) {
			judged = 1;
			pass = fabs(e) <= t->tolerance_pct;
			snprintf(design, sizeof design, "electric lux %+.1f %%", e);
		}
	} else if (o) {
		double e = jnum(o, "error_pct");
		json_object *c;
		snprintf(result, sizeof result, "%.2f lux/V (se %.2f, n %.0f) vs simulated %.2f (%s)",
		         jnum(o, "ratio"), jnum(o, "ratio_se"), jnum(o, "samples"), jnum(o, "sim_ratio"),
		         json_object_object_get_ex(o, "condition", &c) ? json_object_get_string(c) : "?");
		if (isfinite(e)) {
			judged = 1;
			pass = fabs(e) <= t->tolerance_pct;
			snprintf(design, sizeof design, "ratio %+.1f %%", e);
		}
	} else if (row->note) {
		snprintf(result, sizeof result, "%s", row->note);
	}
	if (judged && (strcmp(row->state, "accepted") == 0 || strcmp(row->state, "done") == 0)) {
		t->checks++;
		t->fails += !pass;
	}
	fprintf(fp, "<text x=\"%d\" y=\"%d\" font-size=\"12\"><tspan x=\"%d\">%lld</tspan><tspan x=\"%d\">",
	        PX, t->y, PX, row->id, PX + 60);
	esc(fp, row->kind);
	fprintf(fp, "</tspan><tspan x=\"%d\">", PX + 120);
	esc(fp, row->state);
	fprintf(fp, "</tspan><tspan x=\"%d\">%s</tspan><tspan x=\"%d\">", PX + 210, t0, PX + 270);
	esc(fp, result);
	fprintf(fp, "</tspan><tspan x=\"%d\" fill=\"%s\">", PX + 650, !judged ? "#555" : pass ? "#2b7a2b" : "#c0392b");
	esc(fp, design);
	fprintf(fp, "%s</tspan></text>\n", judged ? (pass ? " pass" : " FAIL") : "");
	json_object_put(o);
}

int psd_report_svg(const char *dbpath, const char *zone, double tolerance_pct, FILE *fp, int *verdict, char *err,
                   size_t n)
{
	struct psd_db *db;
	static struct series s;
	struct table t = { fp, PY + PH + 60, 0, 0, tolerance_pct };
	time_t now = time(NULL);
	char when[64], ignored[256];
	struct tm tm;
	*verdict = 0;
	if (!(db = psd_db_open_readonly(dbpath, err, n)))
		return -1;
	if (load_series(db, zone, &s, err, n) != 0) {
		psd_db_close(db);
		return -1;
	}
	localtime_r(&now, &tm);
	strftime(when, sizeof when, "%Y-%m-%d %H:%M", &tm);
	fprintf(fp, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
	            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\" "
	            "font-family=\"DejaVu Sans, Helvetica, Arial, sans-serif\">\n"
	            "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n", W, H, W, H);
	fputs("<text x=\"80\" y=\"40\" font-size=\"22\" font-weight=\"bold\">psensd commissioning report: zone ", fp);
	esc(fp, zone);
	fputs("</text>\n<text x=\"80\" y=\"64\" font-size=\"12\" fill=\"#555\">", fp);
	esc(fp, dbpath);
	fprintf(fp, ", %d samples shown, written %s</text>\n", s.n, when);
	if (s.n)
		plot(fp, &s);
	else
		fprintf(fp, "<text x=\"%d\" y=\"%d\" font-size=\"14\">no samples for this zone</text>\n", PX, PY + 40);
	/* the sessions */
	fprintf(fp, "<text x=\"%d\" y=\"%d\" font-size=\"16\" font-weight=\"bold\">Calibration sessions</text>\n", PX, t.y);
	t.y += 22;
	fprintf(fp, "<text x=\"%d\" y=\"%d\" font-size=\"12\" font-weight=\"bold\">"
	            "<tspan x=\"%d\">session</tspan><tspan x=\"%d\">kind</tspan><tspan x=\"%d\">state</tspan>"
	            "<tspan x=\"%d\">started</tspan><tspan x=\"%d\">result</tspan><tspan x=\"%d\">against design</tspan>"
	            "</text>\n", PX, t.y, PX, PX + 60, PX + 120, PX + 210, PX + 270, PX + 650);
	psd_db_cal_sessions(db, zone, session_row, &t, ignored, sizeof ignored);   /* none recorded: none shown */
	psd_db_close(db);
	t.y += 50;
	*verdict = t.checks == 0 ? 0 : t.fails ? -1 : 1;
	fprintf(fp, "<text x=\"%d\" y=\"%d\" font-size=\"28\" font-weight=\"bold\" fill=\"%s\">%s</text>\n", PX, t.y,
	        *verdict > 0 ? "#2b7a2b" : *verdict < 0 ? "#c0392b" : "#555",
	        *verdict > 0 ? "PASS" : *verdict < 0 ? "FAIL" : "NOT CALIBRATED");
	fprintf(fp, "<text x=\"%d\" y=\"%d\" font-size=\"12\" fill=\"#555\">%d of %d results within %.0f %% of the "
	            "design prediction (the simulated ratios)</text>\n</svg>\n", PX + 200, t.y - 6, t.checks - t.fails, t.checks,
	        tolerance_pct);
	return ferror(fp) ? -1 : 0;
}
