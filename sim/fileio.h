/* SPDX-License-Identifier: ISC */
/* Reading a whole input file into memory, with a size limit. */
#ifndef PS_FILEIO_H
#define PS_FILEIO_H

#include <stddef.h>
#include <stdint.h>

#include "err.h"

/* Read path into a malloc'd buffer (NUL-terminated, not counted in *len).
 * Files larger than max bytes are refused. */
int ps_fileio_read(const char *path, size_t max, uint8_t **data, size_t *len, struct ps_err *e);

/* A whole input file in memory: a regular file read in one piece of its
 * size (no growing buffer), anything else (a pipe) as ps_fileio_read does.
 * Release it with ps_fileio_unmap. */
struct ps_fileio_map {
	const uint8_t *data;
	size_t len;
	uint8_t *buf;   /* owned */
};
int ps_fileio_map(const char *path, size_t max, struct ps_fileio_map *m, struct ps_err *e);
void ps_fileio_unmap(struct ps_fileio_map *m);

#endif
