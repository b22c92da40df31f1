/* SPDX-License-Identifier: ISC */
/* The results kept up to date with the scene (daemon/refresh.c). */
#ifndef PSD_REFRESH_H
#define PSD_REFRESH_H

struct psd_config;

/* Recompute the results with psscene when they are missing or older than
 * the scene (daemon/refresh.c).  -1 after logging why. */
int psd_refresh_results(const struct psd_config *cf, const char *self);

#endif
