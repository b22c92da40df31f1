/* SPDX-License-Identifier: ISC */
#include "picdraw.h"

#include <math.h>

void ps_picdraw_tone(struct ps_canvas *c, const struct ps_picture *pic, const struct ps_tonemap *t,
                     int ox, int oy, int zoom)
{
	ps_canvas_begin(c);
	for (int row = 0; row < pic->height; row++)
		for (int x = 0; x < pic->width; x++) {
			double rgb[3];
			uint8_t out[3];
			ps_lum_rgb(&t->lum, pic, x, row, rgb);
			ps_tonemap_rgb(t, rgb, out);
			ps_canvas_set(c, ox + zoom * x, oy + zoom * row, zoom, out);
		}
	ps_canvas_end(c);
}

void ps_picdraw_grey(struct ps_canvas *c, const struct ps_picture *pic, const struct ps_tonemap *t,
                     int ox, int oy, int zoom, double dim)
{
	ps_canvas_begin(c);
	for (int row = 0; row < pic->height; row++)
		for (int x = 0; x < pic->width; x++) {
			double rgb[3], y;
			uint8_t out[3];
			ps_lum_rgb(&t->lum, pic, x, row, rgb);
			y = ps_lum_y(&t->lum, rgb);
			rgb[0] = rgb[1] = rgb[2] = y;
			ps_tonemap_rgb(t, rgb, out);
			out[0] = out[1] = out[2] = (uint8_t)floor(out[1] * dim + 0.5);
			ps_canvas_set(c, ox + zoom * x, oy + zoom * row, zoom, out);
		}
	ps_canvas_end(c);
}

void ps_picdraw_false(struct ps_canvas *c, const struct ps_picture *pic, const struct ps_lum *l,
                      const struct ps_falsecolor_scale *s, int ox, int oy, int zoom)
{
	ps_canvas_begin(c);
	for (int row = 0; row < pic->height; row++)
		for (int x = 0; x < pic->width; x++) {
			double rgb[3];
			uint8_t out[3];
			ps_lum_rgb(l, pic, x, row, rgb);
			ps_falsecolor_rgb8(ps_falsecolor_scale_fraction(s, PS_LUM_EFFICACY * ps_lum_y(l, rgb)), out);
			ps_canvas_set(c, ox + zoom * x, oy + zoom * row, zoom, out);
		}
	ps_canvas_end(c);
}

double ps_picdraw_max_cdm2(const struct ps_picture *pic, const struct ps_lum *l)
{
	double top = 0;
	for (int row = 0; row < pic->height; row++)
		for (int x = 0; x < pic->width; x++) {
			double rgb[3], y;
			ps_lum_rgb(l, pic, x, row, rgb);
			y = ps_lum_y(l, rgb);
			if (y > top)
				top = y;
		}
	return PS_LUM_EFFICACY * top;
}
