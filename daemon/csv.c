/* SPDX-License-Identifier: ISC */
/* The daemon's one CSV writer: see csv.h. */
#include "csv.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void psd_csv_num_text(double v, char out[32])
{
	out[0] = 0;
	if (!isfinite(v))
		return;
	/* 17 significant digits always read back; fewer often do, and read
	 * better (0.3, not 0.29999999999999999) */
	for (int digits = 15; digits <= 17; digits++) {
		snprintf(out, 32, "%.*g", digits, v);
		if (strtod(out, NULL) == v)
			return;
	}
}

void psd_csv_num(FILE *fp, double v)
{
	char buf[32];
	psd_csv_num_text(v, buf);
	fputs(buf, fp);
}

void psd_csv_text(FILE *fp, const char *t)
{
	if (!t)
		return;
	if (!strpbrk(t, ",\"\r\n")) {
		fputs(t, fp);
		return;
	}
	fputc('"', fp);
	for (; *t; t++) {
		if (*t == '"')
			fputc('"', fp);
		fputc(*t, fp);
	}
	fputc('"', fp);
}
