/* SPDX-License-Identifier: ISC */
#include "canvas.h"
#include "replace.h"

#include <errno.h>
#include <setjmp.h>
#include <stdlib.h>
#include <string.h>

#include <fontconfig/fontconfig.h>
#include <png.h>

int ps_canvas_init(struct ps_canvas *c, int width, int height, const uint8_t rgb[3],
                   struct ps_err *e)
{
	memset(c, 0, sizeof *c);
	/* 4 bytes a pixel: at most 2^27 pixels (512 MiB) */
	if (width < 1 || height < 1 || width > 32768 || height > 32768 ||
	    (long long)width * height > (1LL << 27))
		return ps_err_set(e, PS_ERANGE, "canvas of %d x %d pixels: 1 to 32768 a side and at most "
		                  "%lld pixels (a smaller zoom?)", width, height, 1LL << 27);
	c->surf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height);
	if (cairo_surface_status(c->surf) != CAIRO_STATUS_SUCCESS) {
		cairo_surface_destroy(c->surf);
		c->surf = NULL;
		return ps_err_set(e, PS_ENOMEM, "canvas of %d x %d pixels: %s", width, height,
		                  cairo_status_to_string(CAIRO_STATUS_NO_MEMORY));
	}
	c->cr = cairo_create(c->surf);
	c->width = width;
	c->height = height;
	c->encoding = PS_PNG_SRGB;
	c->gamma = 2.2;
	cairo_set_source_rgb(c->cr, rgb[0] / 255.0, rgb[1] / 255.0, rgb[2] / 255.0);
	cairo_paint(c->cr);
	return 0;
}

void ps_canvas_free(struct ps_canvas *c)
{
	if (c->cr)
		cairo_destroy(c->cr);
	if (c->surf)
		cairo_surface_destroy(c->surf);
	memset(c, 0, sizeof *c);
}

void ps_canvas_shutdown(void)
{
	cairo_debug_reset_static_data();
	FcFini();
}

void ps_canvas_begin(struct ps_canvas *c)
{
	cairo_surface_flush(c->surf);
}

void ps_canvas_end(struct ps_canvas *c)
{
	cairo_surface_mark_dirty(c->surf);
}

void ps_canvas_set(struct ps_canvas *c, int x, int y, int zoom, const uint8_t rgb[3])
{
	unsigned char *data = cairo_image_surface_get_data(c->surf);
	int stride = cairo_image_surface_get_stride(c->surf);
	uint32_t px = (uint32_t)rgb[0] << 16 | (uint32_t)rgb[1] << 8 | rgb[2];
	for (int j = y; j < y + zoom; j++) {
		if (j < 0 || j >= c->height)
			continue;
		for (int i = x; i < x + zoom; i++)
			if (i >= 0 && i < c->width)
				memcpy(data + (size_t)j * (size_t)stride + 4 * (size_t)i, &px, 4);
	}
}

void ps_canvas_text_chunk(struct ps_canvas *c, const char *key, const char *value)
{
	if (c->ntext >= 8)
		return;
	snprintf(c->text[c->ntext][0], sizeof c->text[0][0], "%.79s", key);
	snprintf(c->text[c->ntext][1], sizeof c->text[0][1], "%s", value);
	c->ntext++;
}

void ps_canvas_label(struct ps_canvas *c, double x, double y, double size, int align,
                     const double rgb[3], int halo, const char *text)
{
	cairo_t *cr = c->cr;
	cairo_text_extents_t ext;
	double x0;
	cairo_save(cr);
	cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
	cairo_set_font_size(cr, size);
	cairo_text_extents(cr, text, &ext);
	x0 = align < 0 ? x : align == 0 ? x - ext.x_advance / 2 : x - ext.x_advance;
	/* centre the ink vertically on y */
	cairo_move_to(cr, x0, y - (ext.y_bearing + ext.height / 2));
	cairo_text_path(cr, text);
	if (halo) {
		cairo_set_source_rgba(cr, 0, 0, 0, 0.75);
		cairo_set_line_width(cr, size / 4);
		cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
		cairo_stroke_preserve(cr);
	}
	cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
	cairo_fill(cr);
	cairo_restore(cr);
}

/* libpng reports errors by longjmp: keep the message for ps_err. */
struct png_ctx {
	jmp_buf jmp;
	char msg[200];
};

static void png_fail(png_structp png, png_const_charp msg)
{
	struct png_ctx *ctx = png_get_error_ptr(png);
	snprintf(ctx->msg, sizeof ctx->msg, "%s", msg);
	longjmp(ctx->jmp, 1);
}

static void png_warn(png_structp png, png_const_charp msg)
{
	(void)png;
	(void)msg;
}

int ps_canvas_write_png(struct ps_canvas *c, FILE *fp, const char *path, struct ps_err *e)
{
	struct png_ctx ctx;
	png_structp png;
	png_infop info = NULL;
	png_bytep volatile row = NULL;
	png_text text[8];
	const unsigned char *data;
	int stride;
	ctx.msg[0] = '\0';
	png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &ctx, png_fail, png_warn);
	if (!png || !(info = png_create_info_struct(png))) {
		png_destroy_write_struct(&png, NULL);
		return ps_err_set(e, PS_ENOMEM, "%s: out of memory for the PNG writer", path);
	}
	if (setjmp(ctx.jmp)) {
		png_destroy_write_struct(&png, &info);
		free(row);
		if (ferror(fp))
			return ps_err_sys(e, "%s: writing the PNG", path);
		return ps_err_set(e, PS_EIO, "%s: writing the PNG: %s", path, ctx.msg);
	}
	row = malloc(3 * (size_t)c->width);
	if (!row)
		png_error(png, "out of memory");
	png_init_io(png, fp);
	png_set_IHDR(png, info, (png_uint_32)c->width, (png_uint_32)c->height, 8, PNG_COLOR_TYPE_RGB,
	             PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
	if (c->encoding == PS_PNG_SRGB)
		png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
	else
		png_set_gAMA(png, info, 1.0 / c->gamma);
	for (int i = 0; i < c->ntext; i++) {
		memset(&text[i], 0, sizeof text[i]);
		text[i].compression = PNG_TEXT_COMPRESSION_NONE;
		text[i].key = c->text[i][0];
		text[i].text = c->text[i][1];
	}
	if (c->ntext)
		png_set_text(png, info, text, c->ntext);
	png_set_compression_level(png, 9);
	png_write_info(png, info);
	cairo_surface_flush(c->surf);
	data = cairo_image_surface_get_data(c->surf);
	stride = cairo_image_surface_get_stride(c->surf);
	for (int y = 0; y < c->height; y++) {
		const unsigned char *src = data + (size_t)y * (size_t)stride;
		for (int x = 0; x < c->width; x++) {
			uint32_t px;
			memcpy(&px, src + 4 * (size_t)x, 4);
			row[3 * x] = (png_byte)(px >> 16);
			row[3 * x + 1] = (png_byte)(px >> 8);
			row[3 * x + 2] = (png_byte)px;
		}
		png_write_row(png, row);
	}
	png_write_end(png, info);
	png_destroy_write_struct(&png, &info);
	free(row);
	if (fflush(fp) != 0 || ferror(fp))
		return ps_err_sys(e, "%s: writing the PNG", path);
	return 0;
}

int ps_canvas_save_png(struct ps_canvas *c, const char *path, struct ps_err *e)
{
	/* written beside and renamed: a failed write leaves an older file whole */
	struct ps_replace_mem m;
	FILE *fp;
	if (!(fp = ps_replace_mem_open(&m, e)))
		return -1;
	/* errors name the file asked for: the copy beside it is ours, not the user's */
	if (ps_canvas_write_png(c, fp, path, e) != 0) {
		ps_replace_mem_abort(&m);
		return -1;
	}
	return ps_replace_mem_commit(&m, path, 0644, e);
}
