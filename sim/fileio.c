/* SPDX-License-Identifier: ISC */
#include "fileio.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

int ps_fileio_read(const char *path, size_t max, uint8_t **data, size_t *len, struct ps_err *e)
{
	FILE *fp = fopen(path, "rb");
	uint8_t *buf = NULL;
	size_t n = 0, cap = 0;
	*data = NULL;
	*len = 0;
	if (!fp)
		return ps_err_sys(e, "%s", path);
	for (;;) {
		size_t got;
		if (n + 1 >= cap) {
			size_t ncap = cap ? cap * 2 : 65536;
			uint8_t *nb;
			if (cap > max) {
				fclose(fp);
				free(buf);
				return ps_err_set(e, PS_ERANGE, "%s: larger than %zu bytes", path, max);
			}
			nb = realloc(buf, ncap);
			if (!nb) {
				fclose(fp);
				free(buf);
				return ps_err_set(e, PS_ENOMEM, "%s: out of memory", path);
			}
			buf = nb;
			cap = ncap;
		}
		got = fread(buf + n, 1, cap - n - 1, fp);
		n += got;
		if (got == 0)
			break;
	}
	if (ferror(fp)) {
		int rc = ps_err_sys(e, "%s: read error", path);
		fclose(fp);
		free(buf);
		return rc;
	}
	fclose(fp);
	if (n > max) {
		free(buf);
		return ps_err_set(e, PS_ERANGE, "%s: larger than %zu bytes", path, max);
	}
	buf[n] = '\0';
	*data = buf;
	*len = n;
	return 0;
}

int ps_fileio_map(const char *path, size_t max, struct ps_fileio_map *m, struct ps_err *e)
{
	struct stat st;
	int fd;
	memset(m, 0, sizeof *m);
	fd = open(path, O_RDONLY | O_CLOEXEC);
	if (fd < 0)
		return ps_err_sys(e, "%s", path);
	/* a regular file is read in one piece of its size (not mapped: a file
	 * cut short by another process meanwhile must not end in SIGBUS) */
	if (fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0) {
		size_t want = (size_t)st.st_size, got = 0;
		if ((uint64_t)st.st_size > max) {
			close(fd);
			return ps_err_set(e, PS_ERANGE, "%s: larger than %zu bytes", path, max);
		}
		m->buf = malloc(want + 1);
		if (!m->buf) {
			close(fd);
			return ps_err_set(e, PS_ENOMEM, "%s: out of memory for %zu bytes", path, want);
		}
		while (got < want) {
			ssize_t k = read(fd, m->buf + got, want - got);
			if (k < 0 && errno == EINTR)
				continue;
			if (k < 0) {
				int rc = ps_err_sys(e, "%s: read error", path);
				close(fd);
				ps_fileio_unmap(m);
				return rc;
			}
			if (k == 0)
				break;   /* shorter than it was: what is there */
			got += (size_t)k;
		}
		close(fd);
		m->buf[got] = '\0';
		m->data = m->buf;
		m->len = got;
		return 0;
	}
	close(fd);
	if (ps_fileio_read(path, max, &m->buf, &m->len, e) != 0)
		return -1;
	m->data = m->buf;
	return 0;
}

void ps_fileio_unmap(struct ps_fileio_map *m)
{
	free(m->buf);
	memset(m, 0, sizeof *m);
}
