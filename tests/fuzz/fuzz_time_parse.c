/* SPDX-License-Identifier: ISC */
/* Fuzz psensctl export's time arguments (daemon/sampleout.c): ISO 8601
 * date-times and Unix seconds; a parsed time formats back without harm. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "sampleout.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	char *text = malloc(size + 1), iso[32];
	double t;
	if (!text)
		return 0;
	memcpy(text, data, size);
	text[size] = '\0';
	if (psd_sampleout_time_parse(text, &t) == 0)
		psd_sampleout_time_iso(t, iso);
	free(text);
	return 0;
}
