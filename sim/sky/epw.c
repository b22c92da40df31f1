/* SPDX-License-Identifier: ISC */
#include "epw.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "series.h"

enum { EPW_LINE_MAX = 65536 };

/* Split a line at commas: up to max fields (start and length); returns the
 * number of fields in the line (may exceed max). */
static int split(const char *line, const char **f, size_t *n, int max)
{
	int k = 0;
	const char *p = line;
	for (;;) {
		size_t len = strcspn(p, ",");
		if (k < max) {
			f[k] = p;
			n[k] = len;
		}
		k++;
		if (p[len] != ',')
			return k;
		p += len + 1;
	}
}

static int whole(double x, double lo, double hi)
{
	return x == floor(x) && x >= lo && x <= hi;
}

/* Header lines 2 to 7: each starts with its keyword. */
static const char *const header_keys[6] = {
	"DESIGN CONDITIONS", "TYPICAL/EXTREME PERIODS", "GROUND TEMPERATURES",
	"HOLIDAYS/DAYLIGHT SAVING", "COMMENTS 1", "COMMENTS 2"
};

static int parse_location(struct ps_weather *w, const char *line, struct ps_err *e)
{
	const char *f[11];
	size_t n[11];
	double v[4];
	int nf = split(line, f, n, 11);
	static const char *const what[4] = { "latitude", "longitude", "time zone", "elevation" };
	static const int lines[5] = { 1, 1, 1, 1, 1 };
	size_t cn, kn;
	if (nf != 10)
		return ps_err_set(e, PS_EFORMAT,
		                  "%s:1: LOCATION has %d fields, expected 10 (LOCATION, city, state, "
		                  "country, source, WMO, latitude, longitude, time zone, elevation)",
		                  w->name, nf);
	for (int k = 0; k < 4; k++)
		if (ps_series_number(f[6 + k], n[6 + k], &v[k], w->name, 1, what[k], e) != 0)
			return -1;
	/* the site: "city, country" */
	cn = n[1];
	while (cn && (f[1][cn - 1] == ' ' || f[1][cn - 1] == '\t'))
		cn--;
	kn = n[3];
	if (cn >= 100)
		cn = 100;
	if (kn >= 20)
		kn = 20;
	snprintf(w->site.name, sizeof w->site.name, "%.*s%s%.*s", (int)cn, f[1], cn && kn ? ", " : "",
	         cn ? (int)kn : 0, f[3]);
	w->site.lat = v[0];
	w->site.lon = v[1];
	w->site.tz = v[2];
	w->site.elevation = v[3];
	if (cn == 0)
		return ps_err_set(e, PS_EFORMAT, "%s:1: the header names no site (empty city)", w->name);
	return ps_series_check_site(w, lines, e);
}

static int parse_periods(struct ps_weather *w, const char *line, int lineno, struct ps_err *e)
{
	const char *f[4];
	size_t n[4];
	double count, per;
	int nf = split(line, f, n, 4);
	if (nf < 4)
		return ps_err_set(e, PS_EFORMAT, "%s:%d: DATA PERIODS needs the count and the records "
		                  "per hour", w->name, lineno);
	if (ps_series_number(f[1], n[1], &count, w->name, lineno, "number of data periods", e) != 0 ||
	    ps_series_number(f[2], n[2], &per, w->name, lineno, "records per hour", e) != 0)
		return -1;
	if (!whole(count, 1, 1000))
		return ps_err_set(e, PS_ERANGE, "%s:%d: number of data periods %g is not 1 or more",
		                  w->name, lineno, count);
	if (!whole(per, 1, 60) || 60 % (int)per != 0)
		return ps_err_set(e, PS_ERANGE, "%s:%d: records per hour %g does not divide 60", w->name,
		                  lineno, per);
	w->per_hour = (int)per;
	return 0;
}

static int parse_record(struct ps_weather *w, const char *line, int lineno, unsigned flags,
                        struct ps_err *e)
{
	const char *f[PS_EPW_FIELDS];
	size_t n[PS_EPW_FIELDS];
	double year, month, day, hour, minute, dew, dir, dif, t;
	int nf = split(line, f, n, PS_EPW_FIELDS), illum = (flags & PS_WX_EPW_ILLUM) != 0;
	int idir = illum ? 17 : 14, idif = illum ? 18 : 15;
	double missing = illum ? 999900.0 : 9999.0;
	if (nf != PS_EPW_FIELDS)
		return ps_err_set(e, PS_EFORMAT, "%s:%d: %d fields, expected %d", w->name, lineno, nf,
		                  PS_EPW_FIELDS);
	if (ps_series_number(f[0], n[0], &year, w->name, lineno, "year (field 1)", e) != 0 ||
	    ps_series_number(f[1], n[1], &month, w->name, lineno, "month (field 2)", e) != 0 ||
	    ps_series_number(f[2], n[2], &day, w->name, lineno, "day (field 3)", e) != 0 ||
	    ps_series_number(f[3], n[3], &hour, w->name, lineno, "hour (field 4)", e) != 0 ||
	    ps_series_number(f[4], n[4], &minute, w->name, lineno, "minute (field 5)", e) != 0)
		return -1;
	if (!whole(year, -9999, 9999) || !whole(month, 1, 12) || !whole(day, 1, 31))
		return ps_err_set(e, PS_ERANGE, "%s:%d: no date %g/%g/%g (year/month/day, whole numbers)",
		                  w->name, lineno, year, month, day);
	if (!whole(hour, 1, 24) || !whole(minute, 0, 60))
		return ps_err_set(e, PS_ERANGE, "%s:%d: hour %g minute %g: the hour must be 1 to 24 and "
		                  "the minute 0 to 60", w->name, lineno, hour, minute);
	if (w->per_hour == 1) {
		t = hour - 0.5;
	} else {
		if (minute == 0)
			return ps_err_set(e, PS_ERANGE, "%s:%d: minute 0 with %d records an hour: the minute "
			                  "is the end of the interval (1 to 60)", w->name, lineno, w->per_hour);
		t = hour - 1.0 + minute / 60.0 - 0.5 / w->per_hour;
	}
	/* the dew point: empty or 99.9 (and above) is missing */
	if (f[7][strspn(f[7], " \t")] == ',' || n[7] == 0) {
		dew = NAN;
	} else {
		if (ps_series_number(f[7], n[7], &dew, w->name, lineno, "dew point (field 8)", e) != 0)
			return -1;
		if (dew >= 99.9)
			dew = NAN;
		else if (!(dew > -70.0 && dew < 70.0))
			return ps_err_set(e, PS_ERANGE, "%s:%d: dew point %g C is not between -70 and 70",
			                  w->name, lineno, dew);
	}
	if (ps_series_number(f[idir], n[idir], &dir, w->name, lineno,
	                     illum ? "direct normal illuminance (field 18)"
	                            : "direct normal irradiance (field 15)", e) != 0 ||
	    ps_series_number(f[idif], n[idif], &dif, w->name, lineno,
	                     illum ? "diffuse horizontal illuminance (field 19)"
	                            : "diffuse horizontal irradiance (field 16)", e) != 0)
		return -1;
	if (dir >= missing || dif >= missing)
		return ps_err_set(e, PS_EMISSING, "%s:%d: %s %s is missing (%g)", w->name, lineno,
		                  dir >= missing ? "direct normal" : "diffuse horizontal",
		                  illum ? "illuminance" : "irradiance", dir >= missing ? dir : dif);
	return ps_series_push(w, (int)month, (int)day, t, dir, dif, dew, lineno, e);
}

int ps_epw_parse(struct ps_weather *w, const char *text, size_t len, unsigned flags,
                 struct ps_err *e)
{
	struct ps_series_lines l = { text, text + len, 0 };
	char *buf = malloc(EPW_LINE_MAX);
	int rc;
	w->format = PS_WX_EPW;
	w->units = (flags & PS_WX_EPW_ILLUM) ? PS_WX_ILLUM : PS_WX_DN_DH;
	if (!buf)
		return ps_err_set(e, PS_ENOMEM, "%s: out of memory", w->name);
	rc = ps_series_line(&l, buf, EPW_LINE_MAX, w->name, e);
	if (rc == 0)
		rc = ps_err_set(e, PS_EFORMAT, "%s:1: empty file", w->name);
	if (rc > 0)
		rc = parse_location(w, buf, e);
	for (int k = 0; rc == 0 && k < 7; k++) {
		const char *key = k < 6 ? header_keys[k] : "DATA PERIODS";
		rc = ps_series_line(&l, buf, EPW_LINE_MAX, w->name, e);
		if (rc == 0)
			rc = ps_err_set(e, PS_EFORMAT, "%s:%d: the header ends before '%s'", w->name,
			                l.line + 1, key);
		else if (rc > 0 && strncasecmp(buf, key, strlen(key)) != 0)
			rc = ps_err_set(e, PS_EFORMAT, "%s:%d: expected the '%s,' header line", w->name,
			                l.line, key);
		else if (rc > 0)
			rc = k < 6 ? 0 : parse_periods(w, buf, l.line, e);
	}
	while (rc == 0 && (rc = ps_series_line(&l, buf, EPW_LINE_MAX, w->name, e)) > 0) {
		if (buf[strspn(buf, " \t")] == '\0') {
			rc = 0;
			continue;   /* blank line */
		}
		rc = parse_record(w, buf, l.line, flags, e);
	}
	free(buf);
	return rc;
}
