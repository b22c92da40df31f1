/* Content-keyed cache of integration results: the key is a SHA-256 (nettle)
 * of every input's bytes and every option, so a rerun recomputes exactly what
 * changed.  One small text file per entry under the cache directory. */
#ifndef PS_CACHE_H
#define PS_CACHE_H

#include <stddef.h>

#include "err.h"

/* hex SHA-256 of a file's bytes (65 bytes with the NUL). */
int ps_hash_file(const char *path, char hex[65], struct ps_err *e);
/* hex SHA-256 of a string. */
void ps_hash_string(const char *s, char hex[65]);

/* Look up n doubles under key; 1 found, 0 absent (or unreadable). */
int ps_cache_get(const char *dir, const char *key, double *v, int n);
/* The same for an entry's text in memory (len bytes). */
int ps_cache_parse(const char *text, size_t len, const char *key, double *v, int n);
/* Store them (atomically: write then rename); -1 on error, which callers may
 * ignore (a cache that cannot be written only costs time). */
int ps_cache_put(const char *dir, const char *key, const double *v, int n, struct ps_err *e);

#endif
