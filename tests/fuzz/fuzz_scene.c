/* Fuzz the scene-file and results-file readers (through a file: both take paths). */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <unistd.h>

#include "results.h"
#include "scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	char path[64];
	FILE *fp;
	struct ps_scene s;
	struct ps_results r;
	struct ps_err e;
	snprintf(path, sizeof path, "/tmp/fuzz_scene.%ld", (long)getpid());
	fp = fopen(path, "wb");
	if (!fp)
		return 0;
	fwrite(data, 1, size, fp);
	fclose(fp);
	if (ps_scene_read(&s, path, &e) == 0)
		ps_scene_free(&s);
	if (ps_results_read(&r, path, &e) == 0)
		ps_results_free(&r);
	unlink(path);
	return 0;
}
