#include "log.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <syslog.h>

/* The whole state, reset by log_init (tests call it again). */
static struct {
	int foreground;
	int level;
	const char *ident;
} log_state = { 1, PSD_LOG_INFO, "psensd" };

void log_init(int foreground, int level, const char *ident)
{
	log_state.foreground = foreground;
	log_state.level = level;
	log_state.ident = ident ? ident : "psensd";
	if (!foreground)
		openlog(log_state.ident, LOG_PID | LOG_NDELAY, LOG_DAEMON);
}

__attribute__((format(printf, 4, 0)))
static void vlog(int level, int prio, const char *errtext, const char *fmt, va_list ap)
{
	char msg[1024];
	int saved = errno;
	if (level > log_state.level) {
		errno = saved;
		return;
	}
	vsnprintf(msg, sizeof msg, fmt, ap);
	if (log_state.foreground)
		fprintf(stderr, "%s: %s%s%s\n", log_state.ident, msg, errtext ? ": " : "",
		        errtext ? errtext : "");
	else
		syslog(prio, "%s%s%s", msg, errtext ? ": " : "", errtext ? errtext : "");
	errno = saved;
}

void log_warnx(const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vlog(PSD_LOG_WARN, LOG_WARNING, NULL, fmt, ap);
	va_end(ap);
}

void log_warn(const char *fmt, ...)
{
	va_list ap;
	const char *e = strerror(errno);
	va_start(ap, fmt);
	vlog(PSD_LOG_WARN, LOG_WARNING, e, fmt, ap);
	va_end(ap);
}

void log_info(const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vlog(PSD_LOG_INFO, LOG_INFO, NULL, fmt, ap);
	va_end(ap);
}

void log_debug(const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vlog(PSD_LOG_DEBUG, LOG_DEBUG, NULL, fmt, ap);
	va_end(ap);
}
