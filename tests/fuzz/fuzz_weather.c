/* SPDX-License-Identifier: ISC */
/* Fuzz the weather reader as psensd and pssky call it: ps_weather_parse
 * tells .wea from .epw by the first line, with either flag. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include "weather.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct ps_weather w;
	struct ps_err e;
	/* the last byte chooses the flags, the rest is the file */
	unsigned flags = size && (data[size - 1] & 1) ? PS_WX_EPW_ILLUM : 0;
	if (size)
		size--;
	if (ps_weather_parse(&w, (const char *)data, size, "fuzz.wx", flags, &e) == 0)
		ps_weather_free(&w);
	return 0;
}
