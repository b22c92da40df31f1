/* The daemon's one logging module (OpenBSD shape): stderr in the
 * foreground, syslog otherwise; errno is preserved. */
#ifndef PSD_LOG_H
#define PSD_LOG_H

enum { PSD_LOG_WARN = 0, PSD_LOG_INFO = 1, PSD_LOG_DEBUG = 2 };

/* foreground: stderr; else syslog.  level: the most verbose to print. */
void log_init(int foreground, int level, const char *ident);
void log_warnx(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
void log_warn(const char *fmt, ...) __attribute__((format(printf, 1, 2)));   /* appends strerror(errno) */
void log_info(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
void log_debug(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

#endif
