/* SPDX-License-Identifier: ISC */
/* Fuzz the .epw reader from memory, and the sky of every step it accepts. */
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "patches.h"
#include "series.h"
#include "sky.h"
#include "epw.h"
#include "weather.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct ps_weather w;
	struct ps_err e;
	/* always through the .epw reader, whatever the first line says */
	ps_series_init(&w, "fuzz.epw");
	if (ps_epw_parse(&w, (const char *)data, size, (size & 1) ? PS_WX_EPW_ILLUM : 0, &e) == 0 && ps_series_finish(&w, &e) == 0) {
		struct ps_patches P;
		struct ps_sky_opt o;
		double v[3 * 146];
		ps_sky_opt_default(&o);
		if (ps_patches_init(&P, 1, &e) == 0) {
			for (size_t i = 0; i < w.n && i < 64; i++) {
				struct ps_sky s;
				if (ps_sky_step(&s, &w, i, &o, &e) == 0)
					ps_sky_vector(&s, &P, PS_SKY_ALL, v);
			}
			ps_patches_free(&P);
		}
	}
	ps_weather_free(&w);
	return 0;
}
