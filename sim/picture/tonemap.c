/* SPDX-License-Identifier: ISC */
#include "tonemap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sum.h"

int ps_tonemap_parse(const char *name)
{
	static const char *const names[] = { "linear", "gamma", "srgb", "reinhard" };
	for (int i = 0; i < 4; i++)
		if (strcmp(name, names[i]) == 0)
			return i;
	return -1;
}

const char *ps_tonemap_name(int curve)
{
	switch (curve) {
	case PS_TONE_LINEAR: return "linear";
	case PS_TONE_GAMMA: return "gamma";
	case PS_TONE_SRGB: return "srgb";
	case PS_TONE_REINHARD: return "reinhard";
	default: return "?";
	}
}

int ps_tonemap_exposure_parse(const char *text, double *mult)
{
	char *end;
	double v;
	if (strcmp(text, "auto") == 0)
		return 1;
	v = strtod(text, &end);
	if (end == text || *end || !isfinite(v))
		return -1;
	if (text[0] == '+' || text[0] == '-') {
		if (fabs(v) > 100)
			return -1;
		v = exp2(v);
	}
	if (!(v > 0) || !isfinite(v))
		return -1;
	*mult = v;
	return 0;
}

void ps_tonemap_stats(const struct ps_picture *pic, const struct ps_lum *l, double *logavg,
                      double *ymax)
{
	struct ps_sum s;
	size_t n = 0;
	double top = 0;
	ps_sum_init(&s);
	for (int row = 0; row < pic->height; row++)
		for (int x = 0; x < pic->width; x++) {
			double rgb[3], y;
			ps_lum_rgb(l, pic, x, row, rgb);
			y = ps_lum_y(l, rgb);
			if (!(y > 0))
				continue;
			ps_sum_add(&s, log(y));
			n++;
			if (y > top)
				top = y;
		}
	*logavg = n ? exp(ps_sum_get(&s) / (double)n) : 0.0;
	*ymax = top;
}

void ps_tonemap_init(struct ps_tonemap *t, const struct ps_picture *pic, int curve,
                     double exposure, double gamma, double white)
{
	double logavg = 0, ymax = 0;
	memset(t, 0, sizeof *t);
	ps_lum_init(&t->lum, pic);
	t->curve = curve;
	t->gamma = gamma > 0 ? gamma : 2.2;
	if (exposure <= 0 || white <= 0)
		ps_tonemap_stats(pic, &t->lum, &logavg, &ymax);
	t->exposure = exposure > 0 ? exposure : logavg > 0 ? PS_TONE_KEY / logavg : 1.0;
	t->white = (white > 0 ? white : ymax) * t->exposure;
	if (!(t->white > 0))
		t->white = 1.0;
}

double ps_tonemap_srgb_encode(double v)
{
	if (!(v > 0))
		return 0.0;
	if (v >= 1)
		return 1.0;
	return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1 / 2.4) - 0.055;
}

uint8_t ps_tonemap_byte(double v)
{
	if (!(v > 0))
		return 0;
	if (v >= 1)
		return 255;
	return (uint8_t)floor(255.0 * v + 0.5);
}

void ps_tonemap_rgb(const struct ps_tonemap *t, const double rgb[3], uint8_t out[3])
{
	double x[3], scale = t->exposure;
	if (t->curve == PS_TONE_REINHARD) {
		double l = t->exposure * ps_lum_y(&t->lum, rgb);
		double ld = l * (1 + l / (t->white * t->white)) / (1 + l);
		scale = l > 0 ? t->exposure * ld / l : 0.0;
	}
	for (int c = 0; c < 3; c++) {
		x[c] = scale * rgb[c];
		x[c] = x[c] > 0 ? (x[c] < 1 ? x[c] : 1.0) : 0.0;
		switch (t->curve) {
		case PS_TONE_LINEAR: break;
		case PS_TONE_GAMMA: x[c] = pow(x[c], 1 / t->gamma); break;
		default: x[c] = ps_tonemap_srgb_encode(x[c]); break;
		}
		out[c] = ps_tonemap_byte(x[c]);
	}
}
