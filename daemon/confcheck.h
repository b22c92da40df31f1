/* SPDX-License-Identifier: ISC */
/* Checks of a loaded configuration beyond single keys (daemon/confcheck.c):
 * two-key ranges and the files it names, every error added to
 * cf->conf.errors with its line.  psd_config_load runs them. */
#ifndef PSD_CONFCHECK_H
#define PSD_CONFCHECK_H

#include "config.h"

/* Ranges that involve two keys. */
void psd_confcheck_ranges(struct psd_config *cf);
/* The scene, the results and replays: present and parsed (a driver's
 * replay is resolved against the file's directory).  Only for a file:
 * psd_config_load_string leaves them unopened. */
void psd_confcheck_files(struct psd_config *cf);

/* The directories of the files psensd writes (database, socket, textfile):
 * judged by -n and a reload.  Not at a start, where opening the file itself
 * fails and the lights go to the safe level with the cause logged. */
void psd_confcheck_outputs(struct psd_config *cf);

#endif
