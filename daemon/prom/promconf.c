/* SPDX-License-Identifier: ISC */
#include "promconf.h"

#include <stdlib.h>

void psd_promconf_load(struct psd_prom_conf *p, struct ps_conf *c)
{
	struct ps_conf_section *s = ps_conf_section(c, "prometheus");
	p->textfile = ps_conf_path(c, s, "textfile");
	ps_conf_double(c, s, "interval", 15, 1, 3600, &p->interval);
	if (s && !p->textfile)
		ps_conf_error(c, s->line, "[prometheus] needs 'textfile' (the .prom file node-exporter's textfile "
		              "collector reads)");
}

void psd_promconf_free(struct psd_prom_conf *p)
{
	free(p->textfile);
	p->textfile = NULL;
}
