/* SPDX-License-Identifier: ISC */
/* Radiance view options (-vt? -vp -vd -vu -vh -vv -vs -vl -vo -va) and the
 * fisheye projections psens integrates over. */
#ifndef PS_VIEW_H
#define PS_VIEW_H

#include <stddef.h>

#include "err.h"

enum ps_view_type {
	PS_VT_PERSP = 'v', PS_VT_PARALLEL = 'l', PS_VT_ANGULAR = 'a', PS_VT_HEMI = 'h',
	PS_VT_CYL = 'c', PS_VT_SOLID = 's', PS_VT_STEREO = 'r'
};

struct ps_view {
	int type;           /* enum ps_view_type */
	double vp[3], vd[3], vu[3];
	double vh, vv;      /* degrees */
	double vs, vl;      /* view shift and lift, in picture widths and heights */
	double vo, va;      /* fore and aft clipping (kept, unused) */
};

/* Radiance's default view: -vtv -vp 0 0 0 -vd 0 1 0 -vu 0 0 1 -vh 45 -vv 45. */
void ps_view_default(struct ps_view *v);
/* The fisheye psens assumes for a picture without a view: -vta -vh 180 -vv 180. */
void ps_view_default_fisheye(struct ps_view *v);
/* Apply the view options in text onto v, in order (later ones override
 * earlier ones, as in Radiance).  Words that are not -v options are skipped
 * with their arguments left alone (an rpict command line parses).  where
 * names the source for messages ("pic.hdr: VIEW"). */
int ps_view_parse(struct ps_view *v, const char *text, const char *where, struct ps_err *e);
/* Check that v is a fisheye psens can integrate (-vta up to 360 degrees,
 * -vth up to 180), with usable vectors. */
int ps_view_check_fisheye(const struct ps_view *v, const char *where, struct ps_err *e);
/* Write v as Radiance options. */
void ps_view_format(const struct ps_view *v, char *buf, size_t len);

#endif
