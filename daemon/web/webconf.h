/* SPDX-License-Identifier: ISC */
/* The [web] section of psensd.conf (psensd.conf(5) [web], doc/console.md):
 * where the on-site console listens, its password's hash, how long a login
 * lasts, its public address.  Read and judged with the rest of the file
 * (every error as file:line), in a build with or without the console.  A
 * file with no [web] section leaves `enabled` 0: psensd serves nothing. */
#ifndef PSD_WEBCONF_H
#define PSD_WEBCONF_H

#include "conf.h"
#include "webpass.h"

struct psd_web_conf {
	int enabled;                  /* a [web] section is there */
	int line;                     /* its line */
	char addr[64];                /* bind's IPv4 address */
	long port;                    /* bind's TCP port */
	char hash[PSD_WEBPASS_LINE];  /* password_file's first line (webpass.h) */
	double session;               /* s a login lasts, default 12 h */
	double update;                /* s between two live updates, default 1 */
	char url[256];                /* the console's public base URL, "" none (the record's QR codes) */
};

/* Read [web] of c into w (errors go to c).  The password file must be
 * readable by psensd, by no one else, and hold a hash line. */
void psd_webconf_load(struct psd_web_conf *w, struct ps_conf *c);

#endif
