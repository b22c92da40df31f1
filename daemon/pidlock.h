/* SPDX-License-Identifier: ISC */
/* An exclusive lock with its holder's pid: a file next to what it guards
 * (the control socket, the database), locked with flock(2) for as long as
 * the daemon runs.  The kernel drops the lock when the process ends, even
 * by SIGKILL, so a lock file left behind never blocks the next start; a
 * second daemon finds the lock taken and reads who holds it. */
#ifndef PSD_PIDLOCK_H
#define PSD_PIDLOCK_H

#include <stddef.h>
#include <sys/types.h>

/* Lock path (created 0644 if missing) and write our pid into it.  Returns
 * the open descriptor (keep it; close it to release), or -1: errno
 * EWOULDBLOCK when another process holds it (its pid in *holder, 0 when it
 * wrote none yet), anything else when the file cannot be opened. */
int psd_pidlock_take(const char *path, pid_t *holder);
/* Release: close the descriptor (the file stays; see above). */
void psd_pidlock_release(int fd);

#endif
