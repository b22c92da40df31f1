/* SPDX-License-Identifier: ISC */
/* The commissioning record (psensctl report): a document drawn with cairo
 * from the database (and, when given, the configuration): a cover with the
 * site, zones, sensors, scene, the configuration's SHA-256, dates, verdicts
 * and a sign-off block; per zone, charts of sensor volts, estimated and
 * measured task lux against the target, dimming level and energy, with
 * faults and calibration sessions shaded and day boundaries marked; tables
 * of the calibration sessions and of acceptance tests when the database has
 * them.  PDF (A4 pages), PNG or SVG (the pages one under the other).
 * Every text drawn records its box (textbox.h). */
#ifndef PSD_REPORT_H
#define PSD_REPORT_H

#include <stddef.h>
#include <stdio.h>
#include <time.h>

#include "config.h"
#include "textbox.h"

enum psd_report_format { PSD_REPORT_PDF = 0, PSD_REPORT_PNG, PSD_REPORT_SVG };

struct psd_report_opts {
	const char *dbpath;
	const char *zone;               /* NULL: every zone */
	const char *config_path;        /* NULL: none (no target line, no config hash) */
	const struct psd_config *cf;    /* that file, loaded; NULL with config_path NULL */
	const char *site;               /* NULL: not named */
	double tolerance_pct;           /* a result within this of the design passes */
	int format;                     /* enum psd_report_format */
	int page;                       /* PNG, SVG: 0 every page, n: page n only */
	time_t written;                 /* the date printed (UTC) */
};

struct psd_report_out {
	int verdict;                    /* 1 PASS, -1 FAIL, 0 nothing judged */
	int nzones;
	struct {
		char name[48];
		/* 1 PASS (calibrated and acceptance-tested), -1 FAIL, 0 not
		 * calibrated, 2 calibrated but not (fully) acceptance-tested */
		int verdict;
	} zone[PSD_MAX_ZONES];
	int pages;
	struct psd_textboxes boxes;     /* every text drawn (free with psd_report_out_free) */
};

/* The format a file name's extension asks for (.pdf .png .svg), -1 if none. */
int psd_report_format_of(const char *path);
/* Draw the document into path through a temporary file in its directory renamed
 * over it only when complete: a failure leaves no file (and an older one
 * untouched).  path NULL: standard output.  Both zero *r first:
 * psd_report_out_free(r) is right after any return. */
int psd_report_write(const struct psd_report_opts *o, const char *path, struct psd_report_out *r, char *err,
                     size_t n);
void psd_report_out_free(struct psd_report_out *r);

#endif
