/* Fuzz the colour-filter reader and the analysis of what it accepts. */
#include <stddef.h>
#include <stdint.h>

#include "spectral.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct ps_filter f;
	struct ps_filter_report r;
	struct ps_err e;
	if (ps_filter_parse(&f, (const char *)data, size, "fuzz.txt", PS_FILTER_PERCENT_AUTO, &e) == 0) {
		(void)ps_filter_analyse(&f, "A", &r, &e);
		ps_filter_free(&f);
	}
	return 0;
}
