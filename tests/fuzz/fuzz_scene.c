/* SPDX-License-Identifier: ISC */
/* Fuzz the scene-file reader from memory (ps_scene_read shares everything
 * but the fopen); the results reader has its own target, fuzz_results. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct ps_scene s;
	struct ps_err e;
	char *text = malloc(size + 1);
	if (!text)
		return 0;
	memcpy(text, data, size);
	text[size] = '\0';
	if (ps_scene_parse(&s, text, "fuzz.scene", &e) == 0)
		ps_scene_free(&s);
	free(text);
	return 0;
}
