/* SPDX-License-Identifier: ISC */
/* A weather series (weather.h) built step by step: what the readers of
 * .wea (wea.c) and .epw (epw.c) files share. */
#ifndef PS_SERIES_H
#define PS_SERIES_H

#include <stddef.h>

#include "err.h"
#include "weather.h"

/* Lines of a text in memory. */
struct ps_series_lines {
	const char *p, *end;
	int line;            /* number of the line last returned */
};
/* Next line (without its newline or CR) into buf; 0 at the end, -1 if longer
 * than the buffer (e names the line). */
int ps_series_line(struct ps_series_lines *l, char *buf, size_t size, const char *name,
                   struct ps_err *e);
/* A whole token as a finite number: 0, or -1 with e naming name:line and what. */
int ps_series_number(const char *tok, size_t n, double *out, const char *name, int line,
                     const char *what, struct ps_err *e);
/* Start an empty series (name copied). */
void ps_series_init(struct ps_weather *w, const char *name);
/* Check a site read from a header: name non-empty, values in range; line[]
 * gives the lines of the name, latitude, longitude, time zone, elevation. */
int ps_series_check_site(const struct ps_weather *w, const int line[5], struct ps_err *e);
/* Append a step after checking its date, time, values and order.  dew may
 * be NAN (missing) for an .epw; a .wea passes its default. */
int ps_series_push(struct ps_weather *w, int month, int day, double hour, double dir,
                   double dif, double dew, int line, struct ps_err *e);
/* After the last step: days of the year, dew-point means, sun positions. */
int ps_series_finish(struct ps_weather *w, struct ps_err *e);

#endif
