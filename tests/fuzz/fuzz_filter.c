/* SPDX-License-Identifier: ISC */
/* Fuzz the colour-filter reader, and the analysis of what it accepts.
 *
 * The analysis integrates the filter against the CIE tables on their 1 nm
 * grid (some 70 integrals, about 0.5 ms under the sanitizers) whatever the
 * input, so running it on every accepted input held the target to about
 * 1 500 executions a second.  It runs on one accepted input in 16, chosen by
 * a hash of the input (so a crash reproduces): the parser gets the
 * executions, and the analysis still runs on a sixteenth of the filters the
 * fuzzer finds, its branches feeding the coverage like any other code. */
#include <stddef.h>
#include <stdint.h>

#include "filter.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct ps_filter f;
	struct ps_filter_report r;
	struct ps_err e;
	uint32_t h = 2166136261u;   /* FNV-1a */
	for (size_t i = 0; i < size; i++)
		h = (h ^ data[i]) * 16777619u;
	if (ps_filter_parse(&f, (const char *)data, size, "fuzz.txt", PS_FILTER_PERCENT_AUTO, &e) == 0) {
		if ((h & 15) == 0)
			(void)ps_filter_analyse(&f, "A", &r, &e);
		ps_filter_free(&f);
	}
	return 0;
}
