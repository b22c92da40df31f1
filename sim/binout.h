/* SPDX-License-Identifier: ISC */
/* Binary output (pictures) and terminals: a tool that would write a picture
 * to standard output refuses when that is a terminal, and says how to get
 * the picture instead. */
#ifndef PS_BINOUT_H
#define PS_BINOUT_H

#include "err.h"

/* 0 when writing to path (non-NULL) or to a standard output that is not a
 * terminal; -1 with a message naming the tool's redirect (example, e.g.
 * "mksens cosine.sen > cosine.hdr") and --output otherwise. */
int ps_binout_check(const char *path, const char *example, struct ps_err *e);

#endif
