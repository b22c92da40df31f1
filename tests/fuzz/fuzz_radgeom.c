/* SPDX-License-Identifier: ISC */
/* Fuzz the Radiance geometry reader (polygons, !genbox | xform) and trace a
 * few rays through whatever it read. */
#include <stddef.h>
#include <stdint.h>

#include "radgeom.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct ps_radgeom g;
	struct ps_err e;
	static const double org[3] = { 1.85, 2.285, 2.2 };
	static const double dir[4][3] = { { 0, 0, -1 }, { 0, 0, 1 }, { 1, 0.3, -0.2 }, { -0.4, -1, 0.1 } };
	ps_radgeom_init(&g);
	(void)ps_radgeom_parse(&g, (const char *)data, size, "fuzz", &e);
	for (int i = 0; i < 4; i++) {
		double t;
		(void)ps_radgeom_trace(&g, org, dir[i], &t);
	}
	ps_radgeom_free(&g);
	return 0;
}
