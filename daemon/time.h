/* SPDX-License-Identifier: ISC */
/* The daemon's time: the clocks it reads, the one HH:MM rule, and the
 * dates it writes (ISO 8601 in UTC or local time, and the shorter forms the
 * summaries use).
 *
 * HH:MM rule: one or two digits of hour, a colon, two digits of minute,
 * nothing else; 00:00 to 23:59.  "7:05" is 07:05; "24:00", "24:30", "7:5",
 * " 7:05" and "07:05 " are refused.  A time of day is an instant within the
 * day, and midnight is 00:00 of the next one. */
#ifndef PSD_TIME_H
#define PSD_TIME_H

#include <stddef.h>
#include <time.h>

/* CLOCK_MONOTONIC in seconds: for intervals and deadlines, never a date. */
double psd_time_mono(void);
/* CLOCK_REALTIME in Unix seconds (UTC): the date now. */
double psd_time_wall(void);
/* CLOCK_THREAD_CPUTIME_ID in seconds: the CPU time the calling thread has
 * used (what a turn of the loop cost, apart from waiting). */
double psd_time_thread_cpu(void);

/* The local broken-down time of Unix seconds utc (psd_time_wall() for
 * today): 0, or -1 when utc is not a time localtime_r can take. */
int psd_time_local(double utc, struct tm *tm);

/* The HH:MM at the start of s (the rule above; what follows is not
 * looked at): the characters it takes (4 or 5) and *h, *m; -1 if none. */
int psd_time_hhmm_scan(const char *s, int *h, int *m);
/* s is exactly one HH:MM (the rule above): 0 and *seconds after midnight,
 * -1 else. */
int psd_time_hhmm(const char *s, double *seconds);

/* The forms of a date, for psd_time_utc_text and psd_time_local_text. */
enum psd_time_form {
	PSD_TIME_DATE,     /* 2026-03-18 */
	PSD_TIME_MINUTE,   /* 2026-03-18 12:05 */
	PSD_TIME_SECOND,   /* 2026-03-18 12:05:30 */
	PSD_TIME_ISO,      /* 2026-03-18T12:05:30 (UTC: with Z) */
	PSD_TIME_ISO_MS,   /* 2026-03-18T12:05:30.250 (UTC: with Z); ms truncated */
};

/* Unix seconds utc as text in UTC (ISO forms end in Z) or in local time
 * (TZ), seconds truncated (a caller that rounds adds 0.5 first): 0, or -1
 * with out empty when utc is not finite, more than 1e11 s from 1970, or
 * the text does not fit in n. */
int psd_time_utc_text(double utc, int form, char *out, size_t n);
int psd_time_local_text(double utc, int form, char *out, size_t n);

#endif
