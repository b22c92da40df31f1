/* SPDX-License-Identifier: ISC */
/* An index of string keys to their positions in an array the caller owns:
 * open addressing (FNV-1a, linear probing), grown to keep it at most half
 * full, so that adding n keys and finding one costs O(1) each on average.
 * The config reader uses it so that a section of thousands of keys (a
 * results file's [year_hours]) loads in linear time: a linear search per
 * key made the load quadratic.  The index keeps the key pointers, not
 * copies: each key must outlive the index. */
#ifndef PS_KEYIDX_H
#define PS_KEYIDX_H

#include <stddef.h>

struct ps_keyidx_slot {
	const char *key;     /* NULL: empty */
	size_t pos;
};

struct ps_keyidx {
	struct ps_keyidx_slot *slot;
	size_t cap;          /* a power of two, or 0 before the first add */
	size_t n;
};

/* Record key at pos (key not yet in x): 0, or -1 with errno ENOMEM (x is
 * unchanged). */
int ps_keyidx_add(struct ps_keyidx *x, const char *key, size_t pos);
/* 1 and *pos when key is in x, else 0. */
int ps_keyidx_find(const struct ps_keyidx *x, const char *key, size_t *pos);
void ps_keyidx_free(struct ps_keyidx *x);

#endif
