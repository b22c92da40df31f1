/* SPDX-License-Identifier: ISC */
#include "falsecolor.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "tonemap.h"

static const double anchor_at[8] = { 0.0, 0.15, 0.30, 0.45, 0.60, 0.75, 0.88, 1.0 };
static const double anchor_rgb[8][3] = {
	{ 0.05, 0.03, 0.22 },   /* deep navy */
	{ 0.16, 0.10, 0.55 },   /* indigo */
	{ 0.10, 0.35, 0.80 },   /* blue */
	{ 0.05, 0.62, 0.68 },   /* teal */
	{ 0.35, 0.78, 0.30 },   /* green */
	{ 0.85, 0.80, 0.15 },   /* yellow */
	{ 0.98, 0.55, 0.10 },   /* orange */
	{ 0.90, 0.12, 0.10 },   /* red */
};

double ps_falsecolor_scale_fraction(const struct ps_falsecolor_scale *s, double value)
{
	if (!s->log)
		return value / s->max;
	if (!(value > 0))
		return -1.0;
	return log10(value / s->max) / s->decades + 1.0;
}

void ps_falsecolor_rgb8(double f, uint8_t out[3])
{
	int k = 0;
	double t;
	if (f > 1.0) {
		out[0] = out[1] = out[2] = 255;
		return;
	}
	if (!(f > 0.0))
		f = 0.0;
	while (k < 6 && f > anchor_at[k + 1])
		k++;
	t = (f - anchor_at[k]) / (anchor_at[k + 1] - anchor_at[k]);
	for (int c = 0; c < 3; c++)
		out[c] = ps_tonemap_byte(anchor_rgb[k][c] + t * (anchor_rgb[k + 1][c] - anchor_rgb[k][c]));
}

double ps_falsecolor_nice_ceil(double v)
{
	double p = pow(10.0, floor(log10(v)));
	static const double steps[] = { 1, 1.5, 2, 2.5, 3, 4, 5, 6, 8, 10 };
	for (int i = 0; i < 10; i++)
		if (steps[i] * p >= v * (1 - 1e-12))
			return steps[i] * p;
	return 10 * p;
}

int ps_falsecolor_scale_ticks(const struct ps_falsecolor_scale *s, double *ticks, int max)
{
	int n = 0;
	if (s->log) {
		for (int k = s->decades; k >= 0 && n < max; k--)
			ticks[n++] = s->max / pow(10.0, k);
		return n;
	}
	{
		double step = ps_falsecolor_nice_ceil(s->max / 6.0);
		for (int k = 0; k * step <= s->max * (1 + 1e-9) && n < max; k++)
			ticks[n++] = k * step;
	}
	return n;
}

/* A value as a short label ("0.5", "250", "12000"). */
static void ps_falsecolor_label(double v, char *buf, int len)
{
	if (v == 0)
		snprintf(buf, (size_t)len, "0");
	else if (fabs(v) >= 1e7 || fabs(v) < 1e-3)
		snprintf(buf, (size_t)len, "%.2g", v);
	else if (fabs(v) >= 100)
		snprintf(buf, (size_t)len, "%.0f", v);
	else
		snprintf(buf, (size_t)len, "%.3g", v);
}

void ps_falsecolor_legend_layout(struct ps_falsecolor_legend *l, int sx, int sy, int sw, int sh)
{
	(void)sw;
	l->font = sh > 400 ? 13.0 : sh > 200 ? 11.0 : 9.0;
	l->above = 1;
	l->x = sx + 8;
	l->width = (int)(l->font * 1.6);
	l->top = sy + (int)(4.6 * l->font);
	l->bottom = sy + sh - (int)(1.2 * l->font);
	if (l->bottom < l->top + 10)
		l->bottom = l->top + 10;
}

int ps_falsecolor_legend_row(const struct ps_falsecolor_legend *l, double f)
{
	double h = l->bottom - l->top;
	int row = (int)floor(l->bottom - f * h);
	if (row < l->top)
		row = l->top;
	if (row > l->bottom - 1)
		row = l->bottom - 1;
	return row;
}

void ps_falsecolor_legend_draw(struct ps_canvas *c, const struct ps_falsecolor_legend *l, const struct ps_falsecolor_scale *s,
                               const char *title)
{
	double h = l->bottom - l->top, ticks[16], fg[3] = { 0.92, 0.92, 0.92 };
	int nt = ps_falsecolor_scale_ticks(s, ticks, 16);
	uint8_t white[3] = { 255, 255, 255 };
	cairo_t *cr = c->cr;
	ps_canvas_label(c, l->x - 2, l->top - 3.6 * l->font, l->font, -1, fg, 0, title);
	ps_canvas_begin(c);
	for (int row = l->top; row < l->bottom; row++) {
		uint8_t rgb[3];
		ps_falsecolor_rgb8((l->bottom - (row + 0.5)) / h, rgb);
		for (int x = l->x; x < l->x + l->width; x++)
			ps_canvas_set(c, x, row, 1, rgb);
	}
	/* above the scale: white */
	for (int row = l->top - (int)(2.0 * l->font); l->above && row < l->top - (int)(0.9 * l->font); row++)
		for (int x = l->x; x < l->x + l->width; x++)
			ps_canvas_set(c, x, row, 1, white);
	ps_canvas_end(c);
	if (l->above)
		ps_canvas_label(c, l->x + l->width + 4, l->top - 1.45 * l->font, l->font * 0.9, -1, fg, 0,
		                "above");
	cairo_save(cr);
	cairo_set_line_width(cr, 1.0);
	cairo_set_source_rgb(cr, fg[0], fg[1], fg[2]);
	for (int i = 0; i < nt; i++) {
		char lab[32];
		double y = l->bottom - ps_falsecolor_scale_fraction(s, ticks[i]) * h;
		y = floor(y) + 0.5;
		cairo_move_to(cr, l->x + l->width - 4, y);
		cairo_line_to(cr, l->x + l->width + 3, y);
		cairo_stroke(cr);
		ps_falsecolor_label(ticks[i], lab, sizeof lab);
		ps_canvas_label(c, l->x + l->width + 5, y, l->font, -1, fg, 0, lab);
	}
	cairo_restore(cr);
}
