/* Fuzz the scene-file and results-file readers, from memory (the file
 * readers share everything but the fopen with these). */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "results.h"
#include "scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct ps_scene s;
	struct ps_results r;
	struct ps_err e;
	char *text = malloc(size + 1);
	if (!text)
		return 0;
	memcpy(text, data, size);
	text[size] = '\0';
	if (ps_scene_parse(&s, text, "fuzz.scene", &e) == 0)
		ps_scene_free(&s);
	if (ps_results_parse(&r, text, "fuzz.results", &e) == 0)
		ps_results_free(&r);
	free(text);
	return 0;
}
