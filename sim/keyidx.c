/* SPDX-License-Identifier: ISC */
#include "keyidx.h"

#include <errno.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static uint64_t hash_key(const char *key)
{
	uint64_t h = 14695981039346656037u;
	for (const unsigned char *p = (const unsigned char *)key; *p; p++) {
		h ^= *p;
		h *= 1099511628211u;
	}
	return h;
}

/* the slot holding key, or the empty slot where it would go */
static size_t probe(const struct ps_keyidx_slot *slot, size_t cap, const char *key)
{
	size_t i = (size_t)hash_key(key) & (cap - 1);
	while (slot[i].key && strcmp(slot[i].key, key) != 0)
		i = (i + 1) & (cap - 1);
	return i;
}

static int grow(struct ps_keyidx *x)
{
	size_t cap = x->cap ? x->cap * 2 : 16;
	struct ps_keyidx_slot *slot;
	if (cap < x->cap || cap > SIZE_MAX / sizeof *slot) {
		errno = ENOMEM;
		return -1;
	}
	slot = calloc(cap, sizeof *slot);
	if (!slot)
		return -1;
	for (size_t i = 0; i < x->cap; i++)
		if (x->slot[i].key)
			slot[probe(slot, cap, x->slot[i].key)] = x->slot[i];
	free(x->slot);
	x->slot = slot;
	x->cap = cap;
	return 0;
}

int ps_keyidx_add(struct ps_keyidx *x, const char *key, size_t pos)
{
	size_t i;
	/* at most half full: short probes, and always an empty slot to end one */
	if ((x->n + 1) * 2 > x->cap && grow(x) != 0)
		return -1;
	i = probe(x->slot, x->cap, key);
	x->slot[i] = (struct ps_keyidx_slot){ .key = key, .pos = pos };
	x->n++;
	return 0;
}

int ps_keyidx_find(const struct ps_keyidx *x, const char *key, size_t *pos)
{
	size_t i;
	if (x->cap == 0)
		return 0;
	i = probe(x->slot, x->cap, key);
	if (!x->slot[i].key)
		return 0;
	*pos = x->slot[i].pos;
	return 1;
}

void ps_keyidx_free(struct ps_keyidx *x)
{
	free(x->slot);
	*x = (struct ps_keyidx){ 0 };
}
