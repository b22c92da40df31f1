/* SPDX-License-Identifier: ISC */
/* A picture to look at: an 8-bit RGB raster (a cairo image surface) that the
 * tools fill pixel by pixel, draw marks and text on with cairo, and write as
 * PNG with libpng (with the colour encoding stated in the file and text
 * chunks saying what made it). */
#ifndef PS_CANVAS_H
#define PS_CANVAS_H

#include <stdint.h>
#include <stdio.h>

#include <cairo.h>

#include "err.h"

/* How the PNG's values are encoded (its sRGB or gAMA chunk). */
enum ps_png_encoding { PS_PNG_SRGB = 0, PS_PNG_GAMMA = 1 };

struct ps_canvas {
	int width, height;
	cairo_surface_t *surf;   /* CAIRO_FORMAT_RGB24 */
	cairo_t *cr;
	int encoding;            /* enum ps_png_encoding */
	double gamma;            /* PS_PNG_GAMMA: the display gamma the values are for (1 = linear) */
	char text[8][2][256];    /* tEXt chunks: keyword, value */
	int ntext;
};

/* A canvas of width x height, filled with rgb (0..255). */
int ps_canvas_init(struct ps_canvas *c, int width, int height, const uint8_t rgb[3],
                   struct ps_err *e);
void ps_canvas_free(struct ps_canvas *c);
/* Set a block of zoom x zoom pixels with its top-left corner at (x, y).
 * Bracket a run of these with ps_canvas_begin and ps_canvas_end. */
void ps_canvas_begin(struct ps_canvas *c);
void ps_canvas_set(struct ps_canvas *c, int x, int y, int zoom, const uint8_t rgb[3]);
void ps_canvas_end(struct ps_canvas *c);
/* Add a tEXt chunk (at most 8; longer text is cut). */
void ps_canvas_text_chunk(struct ps_canvas *c, const char *key, const char *value);

/* Text in the project's font (DejaVu Sans, fonts-dejavu-core) at (x, y):
 * align -1 left, 0 centred, 1 right of x; y is the baseline's middle line
 * (text centred vertically on y).  A dark halo keeps it readable on any
 * background when halo is set. */
void ps_canvas_label(struct ps_canvas *c, double x, double y, double size, int align,
                     const double rgb[3], int halo, const char *text);

/* Release cairo's and fontconfig's caches of fonts (process-wide, kept by
 * the libraries between canvases): call once at the end of a program that
 * drew text, after its last canvas is freed, so leak checkers see nothing. */
void ps_canvas_shutdown(void);

/* Write the canvas as an 8-bit RGB PNG. */
int ps_canvas_write_png(struct ps_canvas *c, FILE *fp, const char *path, struct ps_err *e);
int ps_canvas_save_png(struct ps_canvas *c, const char *path, struct ps_err *e);

#endif
