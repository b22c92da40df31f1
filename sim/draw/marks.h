/* SPDX-License-Identifier: ISC */
/* Where a fisheye picture sits on a canvas, and the marks that say how to
 * read it: polar-angle rings (30, 60, 90 ... degrees from the view
 * direction), azimuth ticks every 30 degrees labelled at 0 (the picture's up),
 * 90 (left: azimuth grows to the left, as psens and the sensor tables count
 * it), 180 and 270, and an arrow for the sensor's own azimuth 0 after its
 * rotation. */
#ifndef PS_MARKS_H
#define PS_MARKS_H

#include "canvas.h"
#include "fisheye.h"
#include "sensor.h"

struct ps_marks_place {
	struct ps_fisheye f;
	double ox, oy;   /* canvas position of the picture's top-left corner */
	double zoom;     /* canvas pixels per picture pixel */
};

void ps_marks_place_init(struct ps_marks_place *p, const struct ps_view *v, int width, int height, double ox,
                         double oy, double zoom);

/* The sensor's sensitivity, as a fraction of its largest table value, at every
 * canvas pixel corner over the picture (the sensor looks along the view
 * direction, its azimuth 0 turned by rotation_deg towards growing azimuth):
 * a grid of (zoom W + 1) x (zoom H + 1) samples, NaN outside the field.
 * Free with free(); NULL when out of memory. */
double *ps_marks_place_sensitivity(const struct ps_marks_place *p, const struct ps_sensor *s,
                                   double rotation_deg, int *nx, int *ny);

/* Contours of a sensitivity grid (ps_marks_place_sensitivity's) at
 * levels[0 .. n-1] percent of its peak, in colour rgb, 2 px wide, each
 * labelled "L %" at text size font where it crosses azimuth 320 degrees. */
void ps_marks_contours(struct ps_canvas *c, const struct ps_marks_place *p, const double *grid, int nx, int ny,
                       const double *levels, int n, const double rgb[3], double font);

enum { PS_MARK_RINGS = 1, PS_MARK_AZIMUTH = 2, PS_MARK_SENSOR = 4 };
/* Draw the marks chosen (PS_MARK_*) at text size font. */
void ps_marks_draw(struct ps_canvas *c, const struct ps_marks_place *p, int which, double rotation_deg,
                   double font);

#endif
