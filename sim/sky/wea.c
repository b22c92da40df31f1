/* SPDX-License-Identifier: ISC */
#include "wea.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "series.h"

enum { WEA_LINE_MAX = 1024, WEA_FIELDS = 5 };

/* "keyword value" on one line: the value's text (trimmed) in *val, *n. */
static int keyword(const char *line, const char *key, const char **val, size_t *n)
{
	size_t k = strlen(key);
	const char *p = line + strspn(line, " \t");
	if (strncasecmp(p, key, k) != 0 || (p[k] && p[k] != ' ' && p[k] != '\t'))
		return -1;
	p += k;
	p += strspn(p, " \t");
	*val = p;
	*n = strlen(p);
	while (*n && (p[*n - 1] == ' ' || p[*n - 1] == '\t'))
		(*n)--;
	return 0;
}

static int header_number(struct ps_weather *w, struct ps_series_lines *l, char *buf,
                         const char *key, const char *what, double *out, struct ps_err *e)
{
	const char *v;
	size_t n;
	int rc = ps_series_line(l, buf, WEA_LINE_MAX, w->name, e);
	if (rc < 0)
		return -1;
	if (rc == 0)
		return ps_err_set(e, PS_EFORMAT, "%s:%d: the header ends before '%s %s'", w->name,
		                  l->line + 1, key, what);
	if (keyword(buf, key, &v, &n) != 0)
		return ps_err_set(e, PS_EFORMAT, "%s:%d: expected '%s %s'", w->name, l->line, key, what);
	if (memchr(v, ' ', n) || memchr(v, '\t', n))
		return ps_err_set(e, PS_EFORMAT, "%s:%d: '%s' takes one value", w->name, l->line, key);
	return ps_series_number(v, n, out, w->name, l->line, key, e);
}

static int whole(double x)
{
	return x == floor(x) && fabs(x) < 1e6;
}

int ps_wea_parse(struct ps_weather *w, const char *text, size_t len, struct ps_err *e)
{
	struct ps_series_lines l = { text, text + len, 0 };
	char buf[WEA_LINE_MAX];
	const char *v;
	size_t n;
	double lon_west, tz_west, units;
	int rc;
	w->format = PS_WX_WEA;
	w->per_hour = 1;
	/* place: the rest of the line */
	if (ps_series_line(&l, buf, sizeof buf, w->name, e) <= 0)
		return l.line ? -1 : ps_err_set(e, PS_EFORMAT, "%s:1: empty file", w->name);
	if (keyword(buf, "place", &v, &n) != 0)
		return ps_err_set(e, PS_EFORMAT, "%s:%d: expected 'place <name>'", w->name, l.line);
	if (n >= sizeof w->site.name)
		n = sizeof w->site.name - 1;
	memcpy(w->site.name, v, n);
	w->site.name[n] = '\0';
	if (n == 0)
		return ps_err_set(e, PS_EFORMAT, "%s:%d: the header names no site (empty place)", w->name,
		                  l.line);
	if (header_number(w, &l, buf, "latitude", "<degrees north>", &w->site.lat, e) != 0 ||
	    header_number(w, &l, buf, "longitude", "<degrees west>", &lon_west, e) != 0 ||
	    header_number(w, &l, buf, "time_zone", "<degrees west>", &tz_west, e) != 0 ||
	    header_number(w, &l, buf, "site_elevation", "<metres>", &w->site.elevation, e) != 0)
		return -1;
	w->site.lon = -lon_west;
	w->site.tz = -tz_west / 15.0;
	{
		static const int lines[5] = { 1, 2, 3, 4, 5 };
		if (ps_series_check_site(w, lines, e) != 0)
			return -1;
	}
	if (header_number(w, &l, buf, "weather_data_file_units", "<1|2|3>", &units, e) != 0)
		return -1;
	if (units != 1 && units != 2 && units != 3)
		return ps_err_set(e, PS_ERANGE,
		                  "%s:%d: weather_data_file_units %g is not 1 (direct normal and diffuse "
		                  "horizontal irradiance), 2 (direct horizontal and diffuse horizontal "
		                  "irradiance) or 3 (direct normal and diffuse horizontal illuminance)",
		                  w->name, l.line, units);
	w->units = (int)units;
	while ((rc = ps_series_line(&l, buf, sizeof buf, w->name, e)) > 0) {
		static const char *const what[WEA_FIELDS] = { "month", "day", "hour", "direct",
		                                              "diffuse" };
		const char *tok[WEA_FIELDS + 1];
		size_t tlen[WEA_FIELDS + 1];
		double x[WEA_FIELDS];
		int nf = 0;
		const char *p = buf;
		for (;;) {
			p += strspn(p, " \t");
			if (!*p)
				break;
			if (nf <= WEA_FIELDS) {
				tok[nf] = p;
				tlen[nf] = strcspn(p, " \t");
			}
			nf++;
			p += strcspn(p, " \t");
		}
		if (nf == 0)
			continue;   /* blank line */
		if (nf != WEA_FIELDS)
			return ps_err_set(e, PS_EFORMAT,
			                  "%s:%d: %d fields, expected %d (month day hour direct diffuse)",
			                  w->name, l.line, nf, WEA_FIELDS);
		for (int k = 0; k < WEA_FIELDS; k++)
			if (ps_series_number(tok[k], tlen[k], &x[k], w->name, l.line, what[k], e) != 0)
				return -1;
		if (!whole(x[0]) || !whole(x[1]))
			return ps_err_set(e, PS_EFORMAT, "%s:%d: month and day must be whole numbers (%g %g)",
			                  w->name, l.line, x[0], x[1]);
		if (ps_series_push(w, (int)x[0], (int)x[1], x[2], x[3], x[4], PS_WX_DEW_DEFAULT,
		                   l.line, e) != 0)
			return -1;
	}
	return rc;
}
