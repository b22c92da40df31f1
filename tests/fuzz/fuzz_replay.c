/* SPDX-License-Identifier: ISC */
/* Fuzz the replay-file reader (the CSV psensctl exports). */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include "replay.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct ps_room_daypoint *d;
	size_t n;
	char err[256];
	if (ps_replay_parse((const char *)data, size, "fuzz.csv", 0.5, 200, &d, &n, err, sizeof err) == 0)
		free(d);
	return 0;
}
