/* SPDX-License-Identifier: ISC */
/* Fuzz the reader of psscene's text cache entries (sim/cache.c) from memory: a cache
 * directory is a file system anyone may have written to. */
#include <stddef.h>
#include <stdint.h>

#include "cache.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	double v[8];
	static const char key[] = "sensor=builtin:cosine view=-vta -vh 180 -vv 180 size=256x256";
	(void)ps_cache_parse((const char *)data, size, key, v, 8);
	return 0;
}
