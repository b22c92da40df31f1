/* SPDX-License-Identifier: ISC */
/* Fuzz the weight cache's readers: a whole entry file (sim/cache.c's
 * header checks: size, magic, key, checksum) and a weight-map payload
 * (sim/weights/wcache.c), which is parsed directly too since the fuzzer rarely
 * forges a checksum.  Every accepted map is walked in full. */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cache.h"
#include "wcache.h"
#include "weights.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void walk(const void *payload, size_t len)
{
	struct ps_weights w;
	struct ps_err e;
	int32_t wh[3] = { 16, 16, 0 };
	volatile double sum = 0;
	double *copy;
	if (len >= 16)
		memcpy(wh, (const uint8_t *)payload + 4, sizeof wh);
	if (wh[0] <= 0 || wh[1] <= 0 || wh[0] > 8192 || wh[1] > 8192)
		return;
	/* aligned as a map is */
	copy = malloc(len / 8 * 8 + 8);
	if (!copy)
		return;
	memcpy(copy, payload, len);
	if (ps_wcache_from_payload(&w, copy, len, wh[0], wh[1], wh[2], "fuzz", &e) == 0) {
		for (size_t i = 0; i < w.nruns; i++)
			for (int k = 0; k < w.runs[i].n; k++)
				sum += ps_weights_run_at(&w, &w.runs[i], k);   /* compact maps: palindromes */
		if (sum != sum)   /* NaN weights are the payload's business, not a fault */
			sum = 0;
		w.w = NULL;   /* the copy's, freed below */
		ps_weights_free(&w);
	}
	free(copy);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	static const char digits[] = "0123456789abcdef";
	char hex[65];
	struct ps_err e;
	memset(hex, '0', 64);
	hex[64] = '\0';
	if (size >= 48)   /* the key the entry says it is, so the later checks run */
		for (int i = 0; i < 32; i++) {
			hex[2 * i] = digits[data[16 + i] >> 4];
			hex[2 * i + 1] = digits[data[16 + i] & 15];
		}
	if (ps_cache_blob_check(data, size, hex, "fuzz", &e) == 0)
		walk(data + PS_CACHE_BLOB_HEADER, size - PS_CACHE_BLOB_HEADER);
	walk(data, size);
	return 0;
}
