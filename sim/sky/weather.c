/* SPDX-License-Identifier: ISC */
#include "weather.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "epw.h"
#include "fileio.h"
#include "series.h"
#include "wea.h"

void ps_weather_free(struct ps_weather *w)
{
	if (!w)
		return;
	free(w->step);
	w->step = NULL;
	w->n = w->cap = 0;
}

int ps_weather_parse(struct ps_weather *w, const char *text, size_t len, const char *name,
                     unsigned flags, struct ps_err *e)
{
	size_t skip = 0;
	int rc;
	ps_series_init(w, name);
	if (!text && len)
		return ps_err_set(e, PS_EINVAL, "%s: no data", w->name);
	/* a UTF-8 byte order mark is not part of the first line */
	if (len >= 3 && (unsigned char)text[0] == 0xEF && (unsigned char)text[1] == 0xBB &&
	    (unsigned char)text[2] == 0xBF)
		skip = 3;
	if (len - skip >= 6 && strncasecmp(text + skip, "place", 5) == 0 &&
	    (text[skip + 5] == ' ' || text[skip + 5] == '\t' || text[skip + 5] == '\r' ||
	     text[skip + 5] == '\n'))
		rc = ps_wea_parse(w, text + skip, len - skip, e);
	else if (len - skip >= 9 && strncasecmp(text + skip, "LOCATION,", 9) == 0)
		rc = ps_epw_parse(w, text + skip, len - skip, flags, e);
	else
		return ps_err_set(e, PS_EFORMAT,
		                  "%s:1: not a weather file: a .wea starts with 'place', an .epw with "
		                  "'LOCATION,'",
		                  w->name);
	if (rc == 0)
		rc = ps_series_finish(w, e);
	if (rc != 0)
		ps_weather_free(w);
	return rc;
}

int ps_weather_read(struct ps_weather *w, const char *path, unsigned flags, struct ps_err *e)
{
	uint8_t *data;
	size_t len;
	int rc;
	ps_series_init(w, path);
	if (ps_fileio_read(path, PS_WX_MAX_FILE, &data, &len, e) != 0)
		return -1;
	rc = ps_weather_parse(w, (const char *)data, len, path, flags, e);
	free(data);
	return rc;
}
