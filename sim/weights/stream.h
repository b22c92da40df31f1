/* SPDX-License-Identifier: ISC */
/* Integration fused with decoding: a picture in memory is decoded row by
 * row into one scanline buffer and each row integrated at once, so its
 * pixels are never stored; rows the weights do not reach are checked but
 * not decoded; with several threads, one pass finds where every scanline
 * starts and bands of rows are decoded and integrated in parallel.  The
 * result is ps_integrate's bit for bit (each row is summed in the same
 * order, and the rows are merged in the same order).  Pictures not in
 * standard orientation are decoded whole and given to ps_integrate. */
#ifndef PS_STREAM_H
#define PS_STREAM_H

#include <stddef.h>
#include <stdint.h>

#include "err.h"
#include "integrate.h"
#include "picture.h"
#include "weights.h"

/* head: from ps_picture_head_mem on the same data, with off where its
 * scanlines start.  nthreads <= 1: this thread only. */
int ps_stream_integrate(const struct ps_weights *w, const struct ps_picture *head,
                        const uint8_t *data, size_t len, size_t off, const char *name,
                        const double coef[3], int nthreads, struct ps_response *r,
                        struct ps_err *e);

/* The same for several weight maps of the picture's size (several sensors)
 * with one decoding: rs[k] for ws[k], each ps_stream_integrate's alone bit for
 * bit (every map's rows are summed and merged as they would be alone). */
int ps_stream_integrate_multi(const struct ps_weights *const *ws, int nmaps,
                              const struct ps_picture *head, const uint8_t *data, size_t len,
                              size_t off, const char *name, const double coef[3], int nthreads,
                              struct ps_response *rs, struct ps_err *e);

#endif
