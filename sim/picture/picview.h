/* SPDX-License-Identifier: ISC */
/* The fisheye view of a picture, as psens takes it: its VIEW= lines (and
 * rpict command lines) on top of Radiance's default view, or -vta -vh 180
 * -vv 180 when it has none; checked to be a fisheye psens integrates. */
#ifndef PS_PICVIEW_H
#define PS_PICVIEW_H

#include "err.h"
#include "picture.h"
#include "view.h"

/* path names the picture in messages; *assumed (may be NULL) is set to 1
 * when the picture had no view and the default fisheye was taken. */
int ps_picview_fisheye(const struct ps_picture *pic, const char *path, struct ps_view *v,
                       int *assumed, struct ps_err *e);

#endif
