/* SPDX-License-Identifier: ISC */
/* Replacing a file durably: the new contents go to a temporary beside the
 * file (same directory, so the rename is atomic), which is fsync'd, renamed
 * over the file, and the directory fsync'd.  After a power cut a reader
 * finds the old file or the whole new one, never an empty or partial one.
 * Every failure is reported with its errno (in ps_err and in errno); on any
 * failure before the rename the temporary is removed and the old file is
 * untouched. */
#ifndef PS_REPLACE_H
#define PS_REPLACE_H

#include <stdio.h>
#include <sys/types.h>

#include "err.h"

/* The system calls the helper makes: a seam so that a test can record
 * their order and make each one fail. */
struct ps_replace_ops {
	int (*open)(const char *path, int flags, mode_t mode);
	ssize_t (*write)(int fd, const void *buf, size_t n);
	int (*fsync)(int fd);
	int (*close)(int fd);
	int (*rename)(const char *from, const char *to);
	int (*unlink)(const char *path);
};

/* Put len bytes of buf in place of path (created with mode, less the
 * umask): 0, or -1 with *e and errno.  The _ops forms make their calls
 * through ops; the others through the system's. */
int ps_replace_file(const char *path, mode_t mode, const void *buf, size_t len, struct ps_err *e);
int ps_replace_file_ops(const struct ps_replace_ops *ops, const char *path, mode_t mode, const void *buf,
                        size_t len, struct ps_err *e);

/* Put the finished, closed file tmp (beside path) in place of path: fsync
 * tmp, rename, fsync the directory.  For a temporary another program or a
 * mapping wrote.  On a failure before the rename tmp is removed. */
int ps_replace_install(const char *tmp, const char *path, struct ps_err *e);
int ps_replace_install_ops(const struct ps_replace_ops *ops, const char *tmp, const char *path, struct ps_err *e);

/* A writer that prints with stdio: its text collects in memory and is put
 * in place by ps_replace_mem_commit, which frees it whatever happens. */
struct ps_replace_mem {
	FILE *fp;
	char *buf;
	size_t len;
};
/* the stream to print to, or NULL with *e */
FILE *ps_replace_mem_open(struct ps_replace_mem *m, struct ps_err *e);
int ps_replace_mem_commit(struct ps_replace_mem *m, const char *path, mode_t mode, struct ps_err *e);
/* give up: nothing is written */
void ps_replace_mem_abort(struct ps_replace_mem *m);

#endif
