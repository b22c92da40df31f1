/* SPDX-License-Identifier: ISC */
/* The console's pages (daemon/web/assets/: HTML, CSS, JavaScript; no
 * framework, nothing from elsewhere), built into psensd by
 * daemon/web/genassets.sh, so an installed psensd serves them as built. */
#ifndef PSD_WEBASSET_H
#define PSD_WEBASSET_H

#include <stddef.h>

struct psd_webasset {
	const char *path;   /* "/index.html" */
	const char *type;   /* its Content-Type */
	const unsigned char *data;
	size_t len;
};

/* The asset at path, NULL when none. */
const struct psd_webasset *psd_webasset_find(const char *path);

#endif
