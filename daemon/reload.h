/* SPDX-License-Identifier: ISC */
/* A reload (SIGHUP, psensctl reload) of the running daemon's configuration
 * (daemon/reload.c). */
#ifndef PSD_RELOAD_H
#define PSD_RELOAD_H

struct psd_daemon;

/* SIGHUP's work: a new config replaces the running one only when it loads
 * and opens; otherwise the old one keeps running.  0 when replaced. */
int psd_reload(struct psd_daemon *d);
/* The same, with the reasons of a refusal (each "file:line: why" when the
 * configuration names one) in w, for the control socket's reload. */
enum { PSD_RELOAD_WHY_MAX = 16, PSD_RELOAD_WHY_LEN = 400 };
struct psd_reload_why {
	int n;
	char line[PSD_RELOAD_WHY_MAX][PSD_RELOAD_WHY_LEN];
};
int psd_reload_explain(struct psd_daemon *d, struct psd_reload_why *w);

#endif
