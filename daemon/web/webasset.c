/* SPDX-License-Identifier: ISC */
#include "webasset.h"

#include <string.h>

/* generated (genassets.sh): static const unsigned char arrays and
 * static const struct psd_webasset assets[] */
#include "webassets.inc"

const struct psd_webasset *psd_webasset_find(const char *path)
{
	for (size_t i = 0; i < sizeof assets / sizeof assets[0]; i++)
		if (strcmp(assets[i].path, path) == 0)
			return &assets[i];
	return NULL;
}
