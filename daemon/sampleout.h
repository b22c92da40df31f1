/* SPDX-License-Identifier: ISC */
/* The sample log for people and programs: time arguments (ISO 8601 local or
 * UTC date-time, or Unix seconds), and rows as CSV, JSON or a table
 * (psensctl log and export). */
#ifndef PSD_SAMPLEOUT_H
#define PSD_SAMPLEOUT_H

#include <stdio.h>

#include "db.h"

/* "2026-03-18T12:05[:SS][Z]" (local time, or UTC with Z; a space for the T),
 * "2026-03-18" (local midnight), or Unix seconds: 0 and *utc, -1 else. */
int psd_sampleout_time_parse(const char *s, double *utc);
/* "2026-03-18T12:05:00" (local), or "-" when utc is not finite */
void psd_sampleout_time_iso(double utc, char out[32]);

enum psd_sampleout_format { PSD_OUT_CSV, PSD_OUT_JSON, PSD_OUT_TABLE };

struct psd_sampleout {
	FILE *fp;
	int format;       /* enum psd_sampleout_format */
	long rows;
	int headed;       /* the header is out */
};

/* Ready to write; the header (CSV, table) or the opening bracket (JSON)
 * goes out with the first row or at psd_sampleout_end, so a caller that
 * fails before any row and skips the end prints nothing on fp. */
void psd_sampleout_begin(struct psd_sampleout *o, FILE *fp, int format);
/* One sample: a psd_db_sample_fn (user is the psd_sampleout). */
void psd_sampleout_row(void *user, const struct psd_sample *s);
/* The header if no row came, the closing bracket (JSON); 0, or -1 on a write error. */
int psd_sampleout_end(struct psd_sampleout *o);

#endif
