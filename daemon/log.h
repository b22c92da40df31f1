/* SPDX-License-Identifier: ISC */
/* The daemon's one logging module (OpenBSD shape): stderr in the
 * foreground, syslog otherwise; errno is preserved.
 *
 * Priorities: psd_log_err/psd_log_errx (LOG_ERR) for what needs a person: a
 * configuration refused at start or at SIGHUP, a failure to reach the safe
 * level, a start that fails; psd_log_warnx (LOG_WARNING) for faults
 * the daemon handles by itself; psd_log_info; psd_log_debug.  When stderr is the
 * journal (systemd sets JOURNAL_STREAM to its device and inode), each line
 * carries its priority as sd-daemon(3)'s "<N>" prefix instead of the
 * program's name, so `journalctl -p err` finds the errors. */
#ifndef PSD_LOG_H
#define PSD_LOG_H

enum { PSD_LOG_WARN = 0, PSD_LOG_INFO = 1, PSD_LOG_DEBUG = 2 };

/* foreground: stderr; else syslog.  level: the most verbose to print. */
void psd_log_init(int foreground, int level, const char *ident);
void psd_log_errx(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
void psd_log_err(const char *fmt, ...) __attribute__((format(printf, 1, 2)));     /* appends strerror(errno) */
void psd_log_warnx(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
void psd_log_info(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
void psd_log_debug(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

#endif
