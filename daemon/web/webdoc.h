/* SPDX-License-Identifier: ISC */
/* The documents the web console serves, made as psensctl and psensd make
 * them, into memory: the commissioning record (psensctl report's
 * psd_report_write, a PDF) and a zone's year (psensd -Y -P's picture, a
 * PNG).  Each is drawn into a private temporary directory, read back and
 * removed.  They fill cairo's and fontconfig's caches: the caller frees
 * them (ps_canvas_shutdown) when nothing draws any more. */
#ifndef PSD_WEBDOC_H
#define PSD_WEBDOC_H

#include <stddef.h>

#include "engine.h"

/* 0 with the document in *buf (malloc'd) and *len; PSD_WEBDOC_NONE when
 * there is nothing to draw (no such zone, no database, no year), -1 when
 * drawing failed; err says why either way. */
enum { PSD_WEBDOC_NONE = -2 };

/* The record of zone (NULL: every zone) from e's log and configuration. */
int psd_webdoc_record(const struct psd_engine *e, const char *zone, unsigned char **buf, size_t *len, char *err,
                      size_t n);
/* The zone's year in its results' weather, with its constants in force. */
int psd_webdoc_year(const struct psd_engine *e, const char *zone, unsigned char **buf, size_t *len, char *err,
                    size_t n);

#endif
