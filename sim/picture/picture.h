/* SPDX-License-Identifier: ISC */
/* Radiance pictures (.hdr, .pic): reading and writing.
 *
 * A picture is kept as the 4-byte RGBE (or XYZE) pixels the file stores, in
 * Radiance's standard orientation (-Y N +X M: row 0 is the top scanline, x
 * grows to the right), whatever orientation the file used.  Decoding a pixel
 * to radiance is exact and done on demand in double: a mantissa m with
 * exponent e reads as (m + 0.5) * 2^(e - 136), as Radiance's colr_color()
 * does, then divided by the header's EXPOSURE (and COLORCORR) products.
 * Keeping 4 bytes a pixel lets 4096 x 4096 pictures fit in 64 MiB and keeps
 * radiances from 2^-136 to 2^119 without float underflow. */
#ifndef PS_PICTURE_H
#define PS_PICTURE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "err.h"

enum ps_picture_format { PS_PIC_RGBE = 0, PS_PIC_XYZE = 1 };

struct ps_picture {
	int width;                 /* pixels per row in standard orientation */
	int height;                /* rows */
	uint8_t *pix;              /* width * height * 4 bytes, row-major, row 0 = top */
	int format;                /* enum ps_picture_format */
	double exposure[3];        /* product of all EXPOSURE= and COLORCORR= lines, per channel */
	double pixaspect;          /* product of PIXASPECT= lines (1 if none) */
	int has_primaries;
	double primaries[8];       /* PRIMARIES= rx ry gx gy bx by wx wy */
	char *view;                /* all VIEW= options in order, joined by spaces (NULL if none) */
	char *header;              /* the whole header text as read (for writing it back) */
	int orientation;           /* the file's resolution-string orientation flags (see picture.c) */
};

/* Read a picture file.  On error returns -1 with e->msg naming the file and the
 * header line or byte offset.  Never allocates more than the file can justify. */
int ps_picture_read(struct ps_picture *pic, const char *path, struct ps_err *e);
/* Read from memory (name is used in messages). */
int ps_picture_read_mem(struct ps_picture *pic, const uint8_t *data, size_t len,
                        const char *name, struct ps_err *e);
void ps_picture_free(struct ps_picture *pic);

/* ---- row by row, without keeping the pixels ----
 * ps_picture_head_mem reads the header and resolution (pic->pix stays NULL;
 * free pic with ps_picture_free) and says where the scanlines start.  For a
 * picture in standard orientation (ps_picture_is_standard: -Y H +X W, scanline s
 * is row s), ps_picture_scanline_starts finds where each of the height
 * scanlines starts in one pass that checks them without decoding pixels,
 * and ps_picture_scan_rows decodes rows y0..y1-1 from off (a scanline start)
 * one at a time into a buffer of width RGBE pixels and calls row(ctx, y,
 * pixels); want (may be NULL: all) names the rows to decode, the others are
 * only checked.  A row callback's non-zero return stops the scan and is
 * returned.  Errors name the file and byte as ps_picture_read_mem's do. */
int ps_picture_head_mem(struct ps_picture *pic, const uint8_t *data, size_t len, const char *name,
                        size_t *data_off, struct ps_err *e);
int ps_picture_is_standard(const struct ps_picture *pic);
int ps_picture_scanline_starts(const struct ps_picture *pic, const uint8_t *data, size_t len,
                               const char *name, size_t off, size_t *starts, struct ps_err *e);
int ps_picture_scan_rows(const struct ps_picture *pic, const uint8_t *data, size_t len,
                         const char *name, size_t off, int y0, int y1, const uint8_t *want,
                         int (*row)(void *ctx, int y, const uint8_t *rgbe), void *ctx,
                         struct ps_err *e);

/* Radiance of pixel (x, y) in standard orientation, in the picture's own
 * colour space (RGB or XYZ), exposure divided out. */
void ps_picture_get(const struct ps_picture *pic, int x, int y, double out[3]);

/* The 256-entry table of 2^(e-136) that decoding uses (e = 0 means black). */
extern const double ps_picture_rgbe_scale[256];

/* Encode one colour as RGBE the way Radiance's setcolr() does. */
void ps_picture_rgbe_encode(const double rgb[3], uint8_t out[4]);
/* Decode one RGBE pixel exactly as Radiance does ((m + 0.5) * 2^(e-136)). */
void ps_picture_rgbe_decode(const uint8_t in[4], double rgb[3]);

/* Write a picture that Radiance reads: "#?RADIANCE", extra header lines
 * (may be NULL; each must end in a newline), VIEW= (if view non-NULL),
 * FORMAT=32-bit_rle_rgbe, "-Y H +X W", new-style run-length scanlines.
 * rgb is width * height * 3 doubles, row 0 = top. */
int ps_picture_write(const char *path, int width, int height, const double *rgb,
                     const char *view, const char *extra_header, struct ps_err *e);
/* Same onto an open stream (path is for messages). */
int ps_picture_write_fp(FILE *fp, const char *path, int width, int height, const double *rgb,
                        const char *view, const char *extra_header, struct ps_err *e);

#endif
