/* The commissioning report (psensctl report): an SVG page from the
 * database: the zone's sensor volts and task lux over time, its calibration
 * sessions, and PASS or FAIL against the design prediction. */
#ifndef PSD_REPORT_H
#define PSD_REPORT_H

#include <stddef.h>
#include <stdio.h>

/* verdict: 1 pass, -1 fail, 0 nothing to judge.  -1 with a message. */
int psd_report_svg(const char *dbpath, const char *zone, double tolerance_pct, FILE *fp, int *verdict, char *err,
                   size_t n);

#endif
