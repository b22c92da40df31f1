/* SPDX-License-Identifier: ISC */
#include "log.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <syslog.h>

/* The whole state, reset by psd_log_init (tests call it again). */
static struct {
	int foreground;
	int journal;          /* stderr is the journal: "<N>" priority prefixes */
	int level;
	const char *ident;
} log_state = { 1, 0, PSD_LOG_INFO, "psensd" };

/* systemd connects stderr to the journal and says so in JOURNAL_STREAM
 * ("device:inode" of the stream); stderr redirected elsewhere is not it. */
static int stderr_is_journal(void)
{
	const char *v = getenv("JOURNAL_STREAM");
	unsigned long long dev, ino;
	struct stat st;
	int n = 0;
	if (!v || sscanf(v, "%llu:%llu%n", &dev, &ino, &n) != 2 || v[n] || fstat(2, &st) != 0)
		return 0;
	return (unsigned long long)st.st_dev == dev && (unsigned long long)st.st_ino == ino;
}

void psd_log_init(int foreground, int level, const char *ident)
{
	log_state.foreground = foreground;
	log_state.journal = foreground && stderr_is_journal();
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
	if (log_state.journal)
		fprintf(stderr, "<%d>%s%s%s\n", prio, msg, errtext ? ": " : "", errtext ? errtext : "");
	else if (log_state.foreground)
		fprintf(stderr, "%s: %s%s%s\n", log_state.ident, msg, errtext ? ": " : "", errtext ? errtext : "");
	else
		syslog(prio, "%s%s%s", msg, errtext ? ": " : "", errtext ? errtext : "");
	errno = saved;
}

#define LOG_FN(name, level, prio, with_errno)                                  \
	void name(const char *fmt, ...)                                        \
	{                                                                      \
		va_list ap;                                                    \
		const char *e = with_errno ? strerror(errno) : NULL;           \
		va_start(ap, fmt);                                             \
		vlog(level, prio, e, fmt, ap);                                 \
		va_end(ap);                                                    \
	}

LOG_FN(psd_log_errx, PSD_LOG_WARN, LOG_ERR, 0)
LOG_FN(psd_log_err, PSD_LOG_WARN, LOG_ERR, 1)
LOG_FN(psd_log_warnx, PSD_LOG_WARN, LOG_WARNING, 0)
LOG_FN(psd_log_info, PSD_LOG_INFO, LOG_INFO, 0)
LOG_FN(psd_log_debug, PSD_LOG_DEBUG, LOG_DEBUG, 0)
