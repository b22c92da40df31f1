/* The commissioning report: one SVG page a person reads without a terminal,
 * from the database alone (psensd need not run).  Sensor volts, measured and
 * estimated task lux over time with the faults shaded, the calibration
 * sessions with their results, and a verdict against the design prediction. */
#include "report.h"

#include <json-c/json.h>
#include <math.h>
#include <sqlite3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

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

static double col(sqlite3_stmt *st, int i)
{
	return sqlite3_column_type(st, i) == SQLITE_NULL ? NAN : sqlite3_column_double(st, i);
}

/* Every sample of the zone, thinned evenly to at most MAXPTS. */
static int load_series(sqlite3 *h, const char *zone, struct series *s, char *err, size_t n)
{
	sqlite3_stmt *st;
	long long total = 0, i = 0, step;
	if (sqlite3_prepare_v2(h, "SELECT count(*) FROM samples WHERE zone = ? OR zone IS NULL", -1, &st, NULL) !=
	    SQLITE_OK) {
		snprintf(err, n, "%s", sqlite3_errmsg(h));
		return -1;
	}
	sqlite3_bind_text(st, 1, zone, -1, SQLITE_TRANSIENT);
	if (sqlite3_step(st) == SQLITE_ROW)
		total = sqlite3_column_int64(st, 0);
	sqlite3_finalize(st);
	step = total / MAXPTS + 1;
	if (sqlite3_prepare_v2(h, "SELECT t, sensor_v, task_lux, est_task_lux, fault FROM samples"
	                          " WHERE zone = ? OR zone IS NULL ORDER BY rowid", -1, &st, NULL) != SQLITE_OK) {
		snprintf(err, n, "%s", sqlite3_errmsg(h));
		return -1;
	}
	sqlite3_bind_text(st, 1, zone, -1, SQLITE_TRANSIENT);
	memset(s, 0, sizeof *s);
	s->tmin = INFINITY;
	s->tmax = -INFINITY;
	while (sqlite3_step(st) == SQLITE_ROW) {
		if (i++ % step || s->n >= MAXPTS)
			continue;
		s->t[s->n] = col(st, 0);
		s->v[s->n] = col(st, 1);
		s->lux[s->n] = col(st, 2);
		s->est[s->n] = col(st, 3);
		s->fault[s->n] = sqlite3_column_type(st, 4) != SQLITE_NULL;
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
	sqlite3_finalize(st);
	return 0;
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

static void hhmm(double t, char out[16])
{
	double tod = fmod(t, 86400);
	if (tod < 0)
		tod += 86400;
	snprintf(out, 16, "%02d:%02d", (int)(tod / 3600), (int)fmod(tod / 60, 60));
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
		char t[16];
		fprintf(fp, "<line x1=\"%d\" y1=\"%.1f\" x2=\"%d\" y2=\"%.1f\" stroke=\"#ddd\"/>\n", PX, y, PX + PW, y);
		fprintf(fp, "<text x=\"%d\" y=\"%.1f\" font-size=\"11\" text-anchor=\"end\" fill=\"#1f4e9c\">%.3g</text>\n",
		        PX - 6, y + 4, vmax * k / 4);
		fprintf(fp, "<text x=\"%d\" y=\"%.1f\" font-size=\"11\" fill=\"#2b7a2b\">%.0f</text>\n", PX + PW + 6,
		        y + 4, lmax * k / 4);
		hhmm(s->tmin + (s->tmax - s->tmin) * k / 4, t);
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

int psd_report_svg(const char *dbpath, const char *zone, double tolerance_pct, FILE *fp, int *verdict, char *err,
                   size_t n)
{
	sqlite3 *h = NULL;
	sqlite3_stmt *st = NULL;
	static struct series s;
	int y = PY + PH + 60, checks = 0, fails = 0;
	time_t now = time(NULL);
	char when[64], t0[16];
	struct tm tm;
	*verdict = 0;
	if (sqlite3_open_v2(dbpath, &h, SQLITE_OPEN_READONLY, NULL) != SQLITE_OK) {
		snprintf(err, n, "%s: %s", dbpath, h ? sqlite3_errmsg(h) : "cannot open");
		sqlite3_close(h);
		return -1;
	}
	sqlite3_busy_timeout(h, 2000);
	if (load_series(h, zone, &s, err, n) != 0) {
		sqlite3_close(h);
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
	fprintf(fp, "<text x=\"%d\" y=\"%d\" font-size=\"16\" font-weight=\"bold\">Calibration sessions</text>\n", PX, y);
	y += 22;
	fprintf(fp, "<text x=\"%d\" y=\"%d\" font-size=\"12\" font-weight=\"bold\">"
	            "<tspan x=\"%d\">session</tspan><tspan x=\"%d\">kind</tspan><tspan x=\"%d\">state</tspan>"
	            "<tspan x=\"%d\">started</tspan><tspan x=\"%d\">result</tspan><tspan x=\"%d\">against design</tspan>"
	            "</text>\n", PX, y, PX, PX + 60, PX + 120, PX + 210, PX + 270, PX + 650);
	if (sqlite3_prepare_v2(h, "SELECT id, kind, state, started, results, note FROM cal_sessions WHERE zone = ?"
	                          " ORDER BY id", -1, &st, NULL) == SQLITE_OK) {
		sqlite3_bind_text(st, 1, zone, -1, SQLITE_TRANSIENT);
		while (sqlite3_step(st) == SQLITE_ROW && y < H - 80) {
			const char *kind = (const char *)sqlite3_column_text(st, 1);
			const char *state = (const char *)sqlite3_column_text(st, 2);
			const char *res = (const char *)sqlite3_column_text(st, 4);
			const char *note = (const char *)sqlite3_column_text(st, 5);
			json_object *o = res ? json_tokener_parse(res) : NULL;
			char result[256] = "", design[128] = "";
			int judged = 0, pass = 1;
			y += 18;
			hhmm(col(st, 3), t0);
			if (o && strcmp(kind, "night") == 0) {
				double e = jnum(o, "electric_lux_error_pct");
				snprintf(result, sizeof result, "offset %.4f V, %.4f V at full (se %.4f), R2 %.6f, worst residual "
				         "%.2f %%", jnum(o, "offset"), jnum(o, "gain"), jnum(o, "gain_se"), jnum(o, "r2"),
				         jnum(o, "max_resid_pct"));
				if (isfinite(e)) {
					judged = 1;
					pass = fabs(e) <= tolerance_pct;
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
					pass = fabs(e) <= tolerance_pct;
					snprintf(design, sizeof design, "ratio %+.1f %%", e);
				}
			} else if (note) {
				snprintf(result, sizeof result, "%s", note);
			}
			/* the verdict counts the sessions in force or awaiting acceptance */
			if (judged && (strcmp(state, "accepted") == 0 || strcmp(state, "done") == 0)) {
				checks++;
				fails += !pass;
			}
			fprintf(fp, "<text x=\"%d\" y=\"%d\" font-size=\"12\"><tspan x=\"%d\">%lld</tspan><tspan x=\"%d\">",
			        PX, y, PX, (long long)sqlite3_column_int64(st, 0), PX + 60);
			esc(fp, kind);
			fprintf(fp, "</tspan><tspan x=\"%d\">", PX + 120);
			esc(fp, state);
			fprintf(fp, "</tspan><tspan x=\"%d\">%s</tspan><tspan x=\"%d\">", PX + 210, t0, PX + 270);
			esc(fp, result);
			fprintf(fp, "</tspan><tspan x=\"%d\" fill=\"%s\">", PX + 650, !judged ? "#555" : pass ? "#2b7a2b" : "#c0392b");
			esc(fp, design);
			fprintf(fp, "%s</tspan></text>\n", judged ? (pass ? " pass" : " FAIL") : "");
			json_object_put(o);
		}
		sqlite3_finalize(st);
	}
	y += 50;
	*verdict = checks == 0 ? 0 : fails ? -1 : 1;
	fprintf(fp, "<text x=\"%d\" y=\"%d\" font-size=\"28\" font-weight=\"bold\" fill=\"%s\">%s</text>\n", PX, y,
	        *verdict > 0 ? "#2b7a2b" : *verdict < 0 ? "#c0392b" : "#555",
	        *verdict > 0 ? "PASS" : *verdict < 0 ? "FAIL" : "NOT CALIBRATED");
	fprintf(fp, "<text x=\"%d\" y=\"%d\" font-size=\"12\" fill=\"#555\">%d of %d results within %.0f %% of the "
	            "design prediction (the simulated ratios)</text>\n</svg>\n", PX + 200, y - 6, checks - fails, checks,
	        tolerance_pct);
	sqlite3_close(h);
	return ferror(fp) ? -1 : 0;
}
