/* SPDX-License-Identifier: ISC */
/* The [prometheus] section of psensd.conf (psensd.conf(5)): the textfile
 * node-exporter's textfile collector reads, and how often it is written.
 * Read and judged with the rest of the file (every error as file:line).  A
 * file with no [prometheus] section leaves textfile NULL: nothing written. */
#ifndef PSD_PROMCONF_H
#define PSD_PROMCONF_H

#include "conf.h"

struct psd_prom_conf {
	char *textfile;   /* textfile: the point model's .prom file, NULL: none */
	double interval;  /* interval: seconds between its writes */
};

/* Read [prometheus] of c into p (errors go to c). */
void psd_promconf_load(struct psd_prom_conf *p, struct ps_conf *c);
void psd_promconf_free(struct psd_prom_conf *p);

#endif
