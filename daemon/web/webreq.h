/* SPDX-License-Identifier: ISC */
/* What the web console's requests carry, parsed: form fields
 * (application/x-www-form-urlencoded), a cookie, and the control request
 * line a page asks psensd to run.  The line is the control socket's own
 * (psensctl(1)); it is judged here only for what the console may ask and
 * for its form, and then by psd_cmdtab_request like any other. */
#ifndef PSD_WEBREQ_H
#define PSD_WEBREQ_H

#include <stddef.h>

/* The value of key in a form body, decoded (%XX, '+'), into out.  0, or -1
 * when absent, too long or badly encoded. */
int psd_webreq_form(const char *body, const char *key, char *out, size_t n);
/* The value of cookie name in a Cookie: header into out.  0 or -1. */
int psd_webreq_cookie(const char *header, const char *name, char *out, size_t n);
/* 0 when line is a request the console may send: printable ASCII, shorter
 * than the control socket's line, its first word one of ping, help, status,
 * ratios, target, override, release, calibrate, accept-test (the command
 * table's console rows, cmdtab.h).  -1 with why. */
int psd_webreq_line_ok(const char *line, char *err, size_t errlen);

#endif
