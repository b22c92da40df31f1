/* SPDX-License-Identifier: ISC */
/* A Radiance picture's pixels on a canvas: tone mapped, or in false colour
 * of luminance.  Each picture pixel becomes a zoom x zoom block with its
 * top-left corner at (ox + zoom x, oy + zoom row), standard orientation. */
#ifndef PS_PICDRAW_H
#define PS_PICDRAW_H

#include "canvas.h"
#include "falsecolor.h"
#include "picture.h"
#include "tonemap.h"

void ps_picdraw_tone(struct ps_canvas *c, const struct ps_picture *pic, const struct ps_tonemap *t,
                     int ox, int oy, int zoom);
/* dim in 0..1 scales the display values down (a background under marks). */
void ps_picdraw_grey(struct ps_canvas *c, const struct ps_picture *pic, const struct ps_tonemap *t,
                     int ox, int oy, int zoom, double dim);
/* Luminance in cd/m2 on the scale s. */
void ps_picdraw_false(struct ps_canvas *c, const struct ps_picture *pic, const struct ps_lum *l,
                      const struct ps_falsecolor_scale *s, int ox, int oy, int zoom);
/* The largest luminance of a picture, cd/m2. */
double ps_picdraw_max_cdm2(const struct ps_picture *pic, const struct ps_lum *l);

#endif
