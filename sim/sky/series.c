/* SPDX-License-Identifier: ISC */
/* A weather series built step by step (series.h): what the .wea and .epw
 * readers share. */
#include "series.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const int month_days[12] = { 31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31 };

void ps_series_init(struct ps_weather *w, const char *name)
{
	memset(w, 0, sizeof *w);
	snprintf(w->name, sizeof w->name, "%s", name ? name : "(weather)");
	w->per_hour = 1;
}

int ps_series_line(struct ps_series_lines *l, char *buf, size_t size, const char *name,
                   struct ps_err *e)
{
	const char *nl;
	size_t n;
	if (l->p >= l->end)
		return 0;
	nl = memchr(l->p, '\n', (size_t)(l->end - l->p));
	n = nl ? (size_t)(nl - l->p) : (size_t)(l->end - l->p);
	l->line++;
	if (n + 1 > size)
		return ps_err_set(e, PS_EFORMAT, "%s:%d: line longer than %zu bytes", name, l->line,
		                  size - 1);
	if (memchr(l->p, '\0', n))
		return ps_err_set(e, PS_EFORMAT, "%s:%d: NUL byte in the line", name, l->line);
	memcpy(buf, l->p, n);
	buf[n] = '\0';
	if (n && buf[n - 1] == '\r')
		buf[n - 1] = '\0';
	l->p += n + (nl ? 1 : 0);
	return 1;
}

int ps_series_number(const char *tok, size_t n, double *out, const char *name, int line,
                     const char *what, struct ps_err *e)
{
	char buf[64], *end;
	double x;
	while (n && (*tok == ' ' || *tok == '\t')) {
		tok++;
		n--;
	}
	while (n && (tok[n - 1] == ' ' || tok[n - 1] == '\t'))
		n--;
	if (n == 0)
		return ps_err_set(e, PS_EFORMAT, "%s:%d: %s is empty", name, line, what);
	if (n >= sizeof buf)
		return ps_err_set(e, PS_EFORMAT, "%s:%d: %s '%.20s...' is not a number", name, line, what,
		                  tok);
	memcpy(buf, tok, n);
	buf[n] = '\0';
	errno = 0;
	x = strtod(buf, &end);
	if (end == buf || *end)
		return ps_err_set(e, PS_EFORMAT, "%s:%d: %s '%s' is not a number", name, line, what, buf);
	if (!isfinite(x) || errno == ERANGE)
		return ps_err_set(e, PS_ERANGE, "%s:%d: %s '%s' is not a finite number", name, line, what,
		                  buf);
	*out = x;
	return 0;
}

int ps_series_check_site(const struct ps_weather *w, const int line[5], struct ps_err *e)
{
	const struct ps_site *s = &w->site;
	const char *p = s->name + strspn(s->name, " \t");
	if (!*p)
		return ps_err_set(e, PS_EFORMAT, "%s:%d: the header names no site", w->name, line[0]);
	if (!(s->lat >= -90.0 && s->lat <= 90.0))
		return ps_err_set(e, PS_ERANGE, "%s:%d: latitude %g is not -90 to 90 degrees", w->name,
		                  line[1], s->lat);
	if (!(s->lon >= -180.0 && s->lon <= 180.0))
		return ps_err_set(e, PS_ERANGE, "%s:%d: longitude %g is not -180 to 180 degrees", w->name,
		                  line[2], w->format == PS_WX_WEA ? -s->lon : s->lon);
	if (!(s->tz >= -12.0 && s->tz <= 14.0))
		return ps_err_set(e, PS_ERANGE, "%s:%d: time zone %g is not %s", w->name, line[3],
		                  w->format == PS_WX_WEA ? -15.0 * s->tz : s->tz,
		                  w->format == PS_WX_WEA ? "-180 to 180 degrees west" : "-12 to 14 hours");
	if (!(s->elevation >= -1000.0 && s->elevation <= 9999.9))
		return ps_err_set(e, PS_ERANGE, "%s:%d: elevation %g m is not -1000 to 9999.9", w->name,
		                  line[4], s->elevation);
	return 0;
}

static const char *month_name(int m)
{
	static const char *const names[12] = { "January", "February", "March", "April", "May",
	                                       "June", "July", "August", "September", "October",
	                                       "November", "December" };
	return names[m - 1];
}

int ps_series_push(struct ps_weather *w, int month, int day, double hour, double dir,
                   double dif, double dew, int line, struct ps_err *e)
{
	struct ps_wx_step *s;
	int dirphot = w->units == PS_WX_ILLUM;
	if (month < 1 || month > 12)
		return ps_err_set(e, PS_ERANGE, "%s:%d: month %d is not 1 to 12", w->name, line, month);
	if (day < 1 || day > month_days[month - 1])
		return ps_err_set(e, PS_ERANGE, "%s:%d: day %d is not in %s (1 to %d)", w->name, line, day,
		                  month_name(month), month_days[month - 1]);
	if (!(hour >= 0.0 && hour <= 24.0))
		return ps_err_set(e, PS_ERANGE, "%s:%d: hour %g is not 0 to 24", w->name, line, hour);
	if (dir < 0)
		return ps_err_set(e, PS_ERANGE, "%s:%d: negative direct %s %g", w->name, line,
		                  dirphot ? "illuminance" : "irradiance", dir);
	if (dif < 0)
		return ps_err_set(e, PS_ERANGE, "%s:%d: negative diffuse %s %g", w->name, line,
		                  dirphot ? "illuminance" : "irradiance", dif);
	if (w->n > 0) {
		const struct ps_wx_step *p = &w->step[w->n - 1];
		if (month < p->month || (month == p->month && day < p->day) ||
		    (month == p->month && day == p->day && hour <= p->hour))
			return ps_err_set(e, PS_EFORMAT,
			                  "%s:%d: %d/%d %g h does not come after %d/%d %g h (line %d): "
			                  "times must increase",
			                  w->name, line, month, day, hour, p->month, p->day, p->hour, p->line);
	}
	if (w->n >= PS_WX_MAX_STEPS)
		return ps_err_set(e, PS_ERANGE, "%s:%d: more than %d time steps", w->name, line,
		                  PS_WX_MAX_STEPS);
	if (w->n == w->cap) {
		size_t cap = w->cap ? 2 * w->cap : 64;
		struct ps_wx_step *ns = realloc(w->step, cap * sizeof *ns);
		if (!ns)
			return ps_err_set(e, PS_ENOMEM, "%s:%d: out of memory", w->name, line);
		w->step = ns;
		w->cap = cap;
	}
	s = &w->step[w->n++];
	memset(s, 0, sizeof *s);
	s->month = month;
	s->day = day;
	s->hour = hour;
	s->dir = dir;
	s->dif = dif;
	s->dew = dew;
	s->line = line;
	return 0;
}

int ps_series_finish(struct ps_weather *w, struct ps_err *e)
{
	double hist[2] = { NAN, NAN }, last = PS_WX_DEW_DEFAULT;
	if (w->n == 0)
		return ps_err_set(e, PS_EFORMAT, "%s: no data lines after the header", w->name);
	w->leap = 0;
	for (size_t i = 0; i < w->n; i++)
		if (w->step[i].month == 2 && w->step[i].day == 29)
			w->leap = 1;
	w->dew_missing = 0;
	for (size_t i = 0; i < w->n; i++) {
		struct ps_wx_step *s = &w->step[i];
		s->doy = ps_sun_day_of_year(s->month, s->day, w->leap);
		if (w->format == PS_WX_WEA) {
			s->dew = PS_WX_DEW_DEFAULT;
			s->dew_given = 0;
		} else if (isnan(s->dew)) {
			/* missing: keep the last value, restart the mean */
			s->dew = last;
			s->dew_given = 0;
			hist[0] = hist[1] = NAN;
			w->dew_missing++;
		} else {
			double d = s->dew;
			if (isnan(hist[0]))
				hist[0] = hist[1] = d;
			last = s->dew = (hist[0] + hist[1] + d) / 3.0;
			s->dew_given = 1;
			hist[0] = hist[1];
			hist[1] = d;
		}
		ps_sun_position(&w->site, s->doy, s->hour, &s->sun);
	}
	return 0;
}
