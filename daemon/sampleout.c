/* SPDX-License-Identifier: ISC */
/* The sample log as CSV, JSON or a table: see sampleout.h. */
#include "sampleout.h"

#include <json-c/json.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "csv.h"
#include "json.h"
#include "time.h"

int psd_sampleout_time_parse(const char *s, double *utc)
{
	struct tm tm;
	int y, mo, d, h = 0, mi = 0, sec = 0, n = 0;
	char *end;
	double v = strtod(s, &end);
	time_t t;
	if (end != s && !*end && strchr(s, '-') == NULL) {   /* Unix seconds, years 1970 to 5138 */
		if (!(v >= 0 && v <= 1e11))
			return -1;
		*utc = v;
		return 0;
	}
	if (sscanf(s, "%4d-%2d-%2d%n", &y, &mo, &d, &n) != 3 || y < 1970 || y > 5000)
		return -1;
	s += n;
	if (*s == 'T' || *s == ' ') {
		n = psd_time_hhmm_scan(s + 1, &h, &mi);
		if (n < 0)
			return -1;
		s += 1 + n;
		if (*s == ':') {
			n = 0;
			if (sscanf(s + 1, "%2d%n", &sec, &n) != 1)
				return -1;
			s += 1 + n;
		}
	}
	if ((*s && strcmp(s, "Z") != 0) || mo < 1 || mo > 12 || d < 1 || d > 31 || h > 23 || mi > 59 || sec > 60 ||
	    h < 0 || mi < 0 || sec < 0)
		return -1;
	memset(&tm, 0, sizeof tm);
	tm.tm_year = y - 1900;
	tm.tm_mon = mo - 1;
	tm.tm_mday = d;
	tm.tm_hour = h;
	tm.tm_min = mi;
	tm.tm_sec = sec;
	tm.tm_isdst = -1;
	t = *s == 'Z' ? timegm(&tm) : mktime(&tm);
	if (t == (time_t)-1)
		return -1;
	*utc = (double)t;
	return 0;
}

void psd_sampleout_time_iso(double utc, char out[32])
{
	/* to the nearest second; NAN and the out of range are "-" */
	if (!isfinite(utc) || psd_time_local_text(floor(utc + 0.5), PSD_TIME_ISO, out, 32) != 0)
		snprintf(out, 32, "-");
}

/* each number's unit in its name (output a fraction, as logged: psensctl
 * log prints it in %); the clock's own seconds are not repeated beside
 * utc_s and tod_s; task_lux is a task meter's (measured), the simulated
 * room's true task illuminance its own column (empty in a real room), and
 * occupied 1 or 0 (empty: the zone has no occupancy input) */
static const char csv_header[] = "zone,time_local,utc_s,tod_s,sensor_v,output_fraction,est_task_lux,task_lux,"
                                 "daylight_v,daylight_lux,condition,ratio_lux_per_unit,fault,occupied,"
                                 "simulated_true_task_lux";

void psd_sampleout_begin(struct psd_sampleout *o, FILE *fp, int format)
{
	o->fp = fp;
	o->format = format;
	o->rows = 0;
	o->headed = 0;
}

/* The header goes out with the first row or at the end: a log that cannot be
 * read prints its error alone, no header above it. */
static void head(struct psd_sampleout *o)
{
	if (o->headed)
		return;
	o->headed = 1;
	if (o->format == PSD_OUT_CSV)
		fprintf(o->fp, "%s\n", csv_header);
	else if (o->format == PSD_OUT_JSON)
		fputs("[", o->fp);
	else
		fprintf(o->fp, "%-19s %-10s %7s %9s %9s %9s %9s %4s  %s\n", "time", "zone", "output", "sensor_v",
		        "est_lux", "task_lux", "true_lux", "occ", "fault");
}

static const char *cell(char *buf, size_t n, int prec, double v)
{
	if (isfinite(v))
		snprintf(buf, n, "%.*f", prec, v);
	else
		snprintf(buf, n, "-");
	return buf;
}

void psd_sampleout_row(void *user, const struct psd_sample *s)
{
	struct psd_sampleout *o = user;
	char iso[32], a[32], b[32], c[32], d[32], e[32];
	const double num[] = { s->utc, s->tod_s, s->sensor_v, s->output, s->est_task_lux, s->task_lux,
	                       s->daylight_v, s->daylight_lux };
	psd_sampleout_time_iso(s->utc, iso);
	head(o);
	if (o->format == PSD_OUT_CSV) {
		psd_csv_text(o->fp, s->zone);
		fprintf(o->fp, ",%s,", isfinite(s->utc) ? iso : "");
		for (size_t i = 0; i < sizeof num / sizeof num[0]; i++) {
			psd_csv_num(o->fp, num[i]);
			fputc(',', o->fp);
		}
		psd_csv_text(o->fp, s->condition);
		fputc(',', o->fp);
		psd_csv_num(o->fp, s->ratio);
		fputc(',', o->fp);
		psd_csv_text(o->fp, s->fault);
		fputs(s->occupied < 0 ? ",," : s->occupied ? ",1," : ",0,", o->fp);
		psd_csv_num(o->fp, s->true_task_lux);
		fputc('\n', o->fp);
	} else if (o->format == PSD_OUT_JSON) {
		json_object *j = json_object_new_object();
		psd_json_str(j, "zone", s->zone);
		psd_json_str(j, "time", isfinite(s->utc) ? iso : NULL);
		psd_json_num(j, "utc", s->utc);
		psd_json_num(j, "t", s->t);
		psd_json_num(j, "tod_s", s->tod_s);
		psd_json_num(j, "sensor_v", s->sensor_v);
		psd_json_num(j, "output", s->output);
		psd_json_num(j, "est_task_lux", s->est_task_lux);
		psd_json_num(j, "task_lux", s->task_lux);
		psd_json_num(j, "daylight_v", s->daylight_v);
		psd_json_num(j, "daylight_lux", s->daylight_lux);
		psd_json_str(j, "condition", s->condition);
		psd_json_num(j, "ratio", s->ratio);
		psd_json_str(j, "fault", s->fault);
		json_object_object_add(j, "occupied", s->occupied < 0 ? NULL : json_object_new_boolean(s->occupied));
		psd_json_num(j, "simulated_true_task_lux", s->true_task_lux);
		fprintf(o->fp, "%s\n  %s", o->rows ? "," : "", psd_json_text(j, 15));
		json_object_put(j);
	} else {
		if (!isfinite(s->utc)) {   /* a log from before schema 4: the clock's time of day */
			long t = (long)floor(s->tod_s + 0.5);
			snprintf(iso, sizeof iso, "%02ld:%02ld:%02ld", t / 3600 % 24, t / 60 % 60, t % 60);
		}
		fprintf(o->fp, "%-19s %-10s %6s%% %9s %9s %9s %9s %4s  %s\n", iso, s->zone ? s->zone : "-",
		        cell(a, sizeof a, 1, 100 * s->output), cell(b, sizeof b, 4, s->sensor_v),
		        cell(c, sizeof c, 1, s->est_task_lux), cell(d, sizeof d, 1, s->task_lux),
		        cell(e, sizeof e, 1, s->true_task_lux), s->occupied < 0 ? "-" : s->occupied ? "yes" : "no",
		        s->fault ? s->fault : "");
	}
	o->rows++;
}

int psd_sampleout_end(struct psd_sampleout *o)
{
	head(o);
	if (o->format == PSD_OUT_JSON)
		fputs(o->rows ? "\n]\n" : "]\n", o->fp);
	return fflush(o->fp) == 0 && !ferror(o->fp) ? 0 : -1;
}
