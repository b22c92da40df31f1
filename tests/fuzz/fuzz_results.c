/* SPDX-License-Identifier: ISC */
/* Fuzz the results-file reader (psscene's output, psensd's input) from
 * memory: the conditions, the summaries it recomputes, the year's hours. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "results.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct ps_results r;
	struct ps_err e;
	char *text = malloc(size + 1);
	if (!text)
		return 0;
	memcpy(text, data, size);
	text[size] = '\0';
	if (ps_results_parse(&r, text, "fuzz.results", &e) == 0)
		ps_results_free(&r);
	free(text);
	return 0;
}
