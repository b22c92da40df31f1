/* Reading a whole input file into memory, with a size limit. */
#ifndef PS_FILE_H
#define PS_FILE_H

#include <stddef.h>
#include <stdint.h>

#include "err.h"

/* Read path into a malloc'd buffer (NUL-terminated, not counted in *len).
 * Files larger than max bytes are refused. */
int ps_read_file(const char *path, size_t max, uint8_t **data, size_t *len, struct ps_err *e);

#endif
