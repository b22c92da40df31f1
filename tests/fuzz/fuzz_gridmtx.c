/* SPDX-License-Identifier: ISC */
/* Fuzz the work-plane grid's readers (gridmtx.h) from memory: the Radiance
 * matrix (header, ascii and binary data) and the electric irradiance lines;
 * the first byte chooses which, the rest is the file. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "gridmtx.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct ps_err e;
	if (size < 1)
		return 0;
	if (data[0] & 1) {
		struct ps_gridmtx m;
		if (ps_gridmtx_parse(&m, data + 1, size - 1, "fuzz.mtx", &e) == 0)
			ps_gridmtx_free(&m);
	} else {
		double lux[64];
		ps_gridmtx_elec_parse((const char *)data + 1, size - 1, "fuzz.dat", 1 + data[0] % 63, lux, &e);
	}
	return 0;
}
