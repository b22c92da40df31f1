/* SPDX-License-Identifier: ISC */
/* Content-keyed cache of integration results: the key is a SHA-256 (nettle)
 * of every input's bytes and every option, so a rerun recomputes exactly what
 * changed.  One small text file per entry under the cache directory. */
#ifndef PS_CACHE_H
#define PS_CACHE_H

#include <stddef.h>

#include "err.h"

/* hex SHA-256 of a file's bytes (65 bytes with the NUL). */
int ps_cache_hash_file(const char *path, char hex[65], struct ps_err *e);
/* hex SHA-256 of a string. */
void ps_cache_hash_string(const char *s, char hex[65]);

/* Look up n doubles under key; 1 found, 0 absent (or unreadable). */
int ps_cache_get(const char *dir, const char *key, double *v, int n);
/* The same for an entry's text in memory (len bytes). */
int ps_cache_parse(const char *text, size_t len, const char *key, double *v, int n);
/* Store them (atomically: write then rename); -1 on error, which callers may
 * ignore (a cache that cannot be written only costs time). */
int ps_cache_put(const char *dir, const char *key, const double *v, int n, struct ps_err *e);

/* ---- binary entries: memory-mapped, checksummed, bounded ------------------
 *
 * A blob is a payload of bytes under a 64-hex key (a SHA-256 of whatever
 * identifies it), kept as DIR/blobs/kk/<62 hex> (kk: the key's first two
 * digits):
 *   bytes 0-7     "PSCBLOB2"
 *   bytes 8-15    payload length, little-endian
 *   bytes 16-47   the key (32 bytes)
 *   bytes 48-55   the payload's 64-bit checksum, little-endian (cache.c:
 *                 four lanes of rotate-multiply over its words, mixed)
 *   bytes 56-127  zero
 *   bytes 128-    the payload (page-aligned in the map: 8-byte aligned)
 * Written to a temporary file in the same directory and renamed into place,
 * so a reader sees a whole entry or none, whatever other processes do; a
 * reader keeps its map even if the entry is evicted meanwhile.  A read
 * checks the size, the magic, the key and the checksum: an entry that fails
 * is removed and reported, never used.  Each hit sets the entry's
 * modification time (the least recently used go first); after a write,
 * entries are evicted oldest first (under an flock on DIR/blobs/.lock) until
 * they hold at most max_bytes (the entry just written stays). */
#define PS_CACHE_BLOB_HEADER 128
#define PS_CACHE_MAX_DEFAULT ((size_t)2 << 30)   /* 2 GiB */

struct ps_cache_blob {
	const void *data;   /* the payload (read-only) */
	size_t len;
	void *map;          /* the whole mapped file */
	size_t maplen;
};

/* 1: found and verified (release it); 0: absent; -1: present but corrupt or
 * unreadable (e says which, naming the file; a corrupt entry is removed). */
int ps_cache_blob_get(const char *dir, const char *hexkey, struct ps_cache_blob *b,
                      struct ps_err *e);
void ps_cache_blob_release(struct ps_cache_blob *b);
/* The checks a read makes, on a whole entry file in memory: 0 when it is a
 * sound entry for hexkey, else -1 with e naming name and the byte. */
int ps_cache_blob_check(const void *file, size_t len, const char *hexkey, const char *name,
                        struct ps_err *e);
/* Store a payload given in pieces (n of them: ptr[i], len[i]).  -1 (e) when
 * the directory cannot be written; callers go on uncached. */
int ps_cache_blob_put(const char *dir, const char *hexkey, int n, const void *const *ptr,
                      const size_t *len, size_t max_bytes, struct ps_err *e);
/* An entry written in place: a temporary file in the entry's directory,
 * its blocks reserved (posix_fallocate: a full disk or a file system
 * without it is an error here, and the caller takes ps_cache_blob_put's
 * route) and mapped shared, so a payload built at o->payload reaches the
 * page cache once.  ps_cache_blob_commit writes the checksum and the
 * header, closes and renames it into place (readers see a whole entry or
 * none) and evicts as ps_cache_blob_put does; ps_cache_blob_abort removes
 * the temporary file.  Either way the mapping (o->map, o->maplen) stays
 * the caller's to unmap, valid after the rename. */
struct ps_cache_blob_out {
	void *map;            /* the whole file */
	size_t maplen;
	void *payload;        /* len bytes, 128 into the map */
	size_t len;
	int fd;
	char hex[65];
	char path[4096], tmp[4200];
};

int ps_cache_blob_create(const char *dir, const char *hexkey, size_t len, struct ps_cache_blob_out *o,
                         struct ps_err *e);
int ps_cache_blob_commit(struct ps_cache_blob_out *o, const char *dir, size_t max_bytes,
                         struct ps_err *e);
void ps_cache_blob_abort(struct ps_cache_blob_out *o);

/* The cache directory psscene and psens share: $XDG_CACHE_HOME/psensd,
 * else $HOME/.cache/psensd (/tmp/.cache/psensd without a HOME). */
void ps_cache_default_dir(char *buf, size_t len);
/* Bytes allowed (PSENSD_CACHE_MAX, with an optional K, M or G suffix; else
 * PS_CACHE_MAX_DEFAULT). */
size_t ps_cache_max_bytes(void);

#endif
