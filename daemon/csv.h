/* SPDX-License-Identifier: ISC */
/* The daemon's one CSV writer (RFC 4180), one field per call: the sample
 * log's exports.  A number is written with the fewest significant digits
 * (15 to 17) that read back (strtod) as the same double; a number that is
 * not finite is an empty field, never "nan" or "inf".  A text holding a
 * comma, a double quote, CR or LF is quoted, its quotes doubled; NULL is an
 * empty field. */
#ifndef PSD_CSV_H
#define PSD_CSV_H

#include <stddef.h>
#include <stdio.h>

/* v as the field's text in out (at least 32 bytes): "" when not finite */
void psd_csv_num_text(double v, char out[32]);
void psd_csv_num(FILE *fp, double v);
void psd_csv_text(FILE *fp, const char *t);

#endif
