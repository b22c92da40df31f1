/* SPDX-License-Identifier: ISC */
#include "replace.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static int sys_open(const char *path, int flags, mode_t mode)
{
	return open(path, flags, mode);
}

static const struct ps_replace_ops ps_replace_sys = {
	.open = sys_open,
	.write = write,
	.fsync = fsync,
	.close = close,
	.rename = rename,
	.unlink = unlink,
};

/* The temporary's name: beside path, unique in this process and among
 * processes (pid and a counter), so concurrent writers never share one. */
static int tmp_name(const char *path, char *tmp, size_t n, struct ps_err *e)
{
	static unsigned long counter;
	unsigned long k = __atomic_add_fetch(&counter, 1, __ATOMIC_RELAXED);
	if ((size_t)snprintf(tmp, n, "%s.tmp.%ld.%lu", path, (long)getpid(), k) >= n) {
		errno = ENAMETOOLONG;
		return ps_err_sys(e, "%.200s...", path);
	}
	return 0;
}

/* fsync path's directory: what makes the rename itself survive a power cut */
static int sync_dir(const struct ps_replace_ops *ops, const char *path, struct ps_err *e)
{
	char dir[4096];
	const char *slash = strrchr(path, '/');
	int fd;
	if (!slash)
		snprintf(dir, sizeof dir, ".");
	else if ((size_t)snprintf(dir, sizeof dir, "%.*s", slash == path ? 1 : (int)(slash - path), path) >=
	         sizeof dir)
		return ps_err_set(e, PS_EINVAL, "%.200s...: path too long", path);
	if ((fd = ops->open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC, 0)) < 0)
		return ps_err_sys(e, "%s: opening the directory", dir);
	if (ops->fsync(fd) != 0) {
		int rc = ps_err_sys(e, "%s: fsync of the directory", dir);
		ops->close(fd);
		errno = e ? e->sys_errno : errno;
		return rc;
	}
	if (ops->close(fd) != 0)
		return ps_err_sys(e, "%s: closing the directory", dir);
	return 0;
}

/* remove tmp after a failure, keeping the failure's errno */
static int drop(const struct ps_replace_ops *ops, const char *tmp)
{
	int saved = errno;
	ops->unlink(tmp);
	errno = saved;
	return -1;
}

static int sync_close(const struct ps_replace_ops *ops, int fd, const char *tmp, struct ps_err *e)
{
	if (ops->fsync(fd) != 0) {
		ps_err_sys(e, "%s: fsync", tmp);
		ops->close(fd);
		errno = e ? e->sys_errno : errno;
		return -1;
	}
	if (ops->close(fd) != 0)
		return ps_err_sys(e, "%s: closing", tmp);
	return 0;
}

/* the steps every replace ends with: fsync and close the temporary, rename
 * it over path, fsync the directory; tmp removed on a failure before the
 * rename */
static int sync_rename(const struct ps_replace_ops *ops, int fd, const char *tmp, const char *path,
                       struct ps_err *e)
{
	if (sync_close(ops, fd, tmp, e) != 0)
		return drop(ops, tmp);
	if (ops->rename(tmp, path) != 0) {
		ps_err_sys(e, "rename %s to %s", tmp, path);
		return drop(ops, tmp);
	}
	return sync_dir(ops, path, e);
}

int ps_replace_install_ops(const struct ps_replace_ops *ops, const char *tmp, const char *path, struct ps_err *e)
{
	int fd = ops->open(tmp, O_RDONLY | O_CLOEXEC, 0);
	if (fd < 0) {
		ps_err_sys(e, "%s", tmp);
		return drop(ops, tmp);
	}
	return sync_rename(ops, fd, tmp, path, e);
}

int ps_replace_install(const char *tmp, const char *path, struct ps_err *e)
{
	return ps_replace_install_ops(&ps_replace_sys, tmp, path, e);
}

static int write_all(const struct ps_replace_ops *ops, int fd, const char *p, size_t len)
{
	while (len > 0) {
		ssize_t n = ops->write(fd, p, len);
		if (n < 0 && errno == EINTR)
			continue;
		if (n <= 0) {
			if (n == 0)
				errno = EIO;
			return -1;
		}
		p += n;
		len -= (size_t)n;
	}
	return 0;
}

int ps_replace_file_ops(const struct ps_replace_ops *ops, const char *path, mode_t mode, const void *buf,
                        size_t len, struct ps_err *e)
{
	char tmp[4200];
	int fd;
	if (tmp_name(path, tmp, sizeof tmp, e) != 0)
		return -1;
	/* named by the file asked for: its directory is what is missing or shut */
	if ((fd = ops->open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, mode)) < 0)
		return ps_err_sys(e, "%s", path);
	if (write_all(ops, fd, buf, len) != 0) {
		ps_err_sys(e, "%s: writing", tmp);
		ops->close(fd);
		errno = e ? e->sys_errno : errno;
		return drop(ops, tmp);
	}
	return sync_rename(ops, fd, tmp, path, e);
}

int ps_replace_file(const char *path, mode_t mode, const void *buf, size_t len, struct ps_err *e)
{
	return ps_replace_file_ops(&ps_replace_sys, path, mode, buf, len, e);
}

FILE *ps_replace_mem_open(struct ps_replace_mem *m, struct ps_err *e)
{
	m->buf = NULL;
	m->len = 0;
	if (!(m->fp = open_memstream(&m->buf, &m->len)))
		ps_err_sys(e, "open_memstream");
	return m->fp;
}

int ps_replace_mem_commit(struct ps_replace_mem *m, const char *path, mode_t mode, struct ps_err *e)
{
	int rc;
	if (ferror(m->fp)) {
		fclose(m->fp);
		errno = ENOMEM;
		rc = ps_err_sys(e, "%s: writing", path);
	} else if (fclose(m->fp) != 0) {
		rc = ps_err_sys(e, "%s: writing", path);
	} else {
		rc = ps_replace_file(path, mode, m->buf, m->len, e);
	}
	free(m->buf);
	m->fp = NULL;
	m->buf = NULL;
	return rc;
}

void ps_replace_mem_abort(struct ps_replace_mem *m)
{
	fclose(m->fp);
	free(m->buf);
	m->fp = NULL;
	m->buf = NULL;
}
