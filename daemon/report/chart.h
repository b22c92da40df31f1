/* SPDX-License-Identifier: ISC */
/* Axes for the report's charts: round ticks (1, 2 or 5 x 10^n for numbers;
 * 5, 10, 15, 30 minutes or 1, 2, 3, 6, 12, 24 hours for times of day) and
 * their labels.  Pure arithmetic, no drawing: daemon/report/report.c draws. */
#ifndef PSD_CHART_H
#define PSD_CHART_H

#include <stddef.h>

enum { PSD_TICKS_MAX = 64 };

struct psd_ticks {
	double v[PSD_TICKS_MAX];  /* the ticks, ascending, all within [lo, hi] */
	int n;
	double step;              /* between ticks (seconds for times) */
	int decimals;             /* numbers: digits after the point a label needs */
};

/* Round ticks within [lo, hi]: the smallest step of 1, 2 or 5 x 10^n that
 * gives at most max ticks (max >= 2).  -1 (EINVAL) when lo, hi are not
 * finite or hi < lo. */
int psd_chart_ticks_num(double lo, double hi, int max, struct psd_ticks *t);
/* The same for seconds (times of day): whole 5, 10, 15, 30 minutes or
 * 1, 2, 3, 6, 12 or 24 hours. */
int psd_chart_ticks_time(double lo, double hi, int max, struct psd_ticks *t);
/* A range [lo, hi] widened to the round ticks just outside it, so the
 * first and last tick sit on the axis ends (numbers). */
void psd_chart_ticks_round_range(double *lo, double *hi, int max);
/* A tick's label: numbers with t->decimals digits ("0.5", "1500"); times
 * as hh:mm of the day (seconds modulo 24 h). */
void psd_chart_tick_num_label(const struct psd_ticks *t, double v, char *buf, size_t n);
void psd_chart_tick_time_label(double seconds, char *buf, size_t n);

#endif
