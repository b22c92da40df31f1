/* SPDX-License-Identifier: ISC */
#include "marks.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "contour.h"

#define DEG (M_PI / 180.0)

void ps_marks_place_init(struct ps_marks_place *p, const struct ps_view *v, int width, int height, double ox,
                         double oy, double zoom)
{
	ps_fisheye_init(&p->f, v, width, height);
	p->ox = ox;
	p->oy = oy;
	p->zoom = zoom;
}

/* Canvas position of the direction (theta, phi), radians (phi the sensor
 * azimuth: 0 up, growing to the left). */
static void place_point(const struct ps_marks_place *p, double theta, double phi, double *x, double *y)
{
	double rho = ps_fisheye_rho(&p->f, theta), a = phi + M_PI / 2;
	double u = rho * cos(a), v = rho * sin(a);
	*x = p->ox + p->zoom * p->f.width * (u - p->f.u0) / p->f.su;
	*y = p->oy + p->zoom * p->f.height * (1.0 - (v - p->f.v0) / p->f.sv);
}

/* Direction at a canvas position; -1 outside the field. */
static int ps_marks_place_dir(const struct ps_marks_place *p, double x, double y, double *theta, double *phi)
{
	double u = ps_fisheye_u(&p->f, (x - p->ox) / p->zoom);
	double v = ps_fisheye_v(&p->f, p->f.height - (y - p->oy) / p->zoom);
	double rho = hypot(u, v);
	if (rho > 1.0)
		return -1;
	*theta = ps_fisheye_theta(&p->f, rho);
	*phi = atan2(v, u) - M_PI / 2;
	return 0;
}

double *ps_marks_place_sensitivity(const struct ps_marks_place *p, const struct ps_sensor *s,
                                   double rotation_deg, int *nx, int *ny)
{
	int w = (int)lround(p->zoom * p->f.width) + 1, h = (int)lround(p->zoom * p->f.height) + 1;
	double *val = malloc((size_t)w * (size_t)h * sizeof *val);
	double top = s->max_value > 0 ? s->max_value : 1.0;
	if (!val)
		return NULL;
	for (int j = 0; j < h; j++)
		for (int i = 0; i < w; i++) {
			double theta, phi;
			val[(size_t)j * (size_t)w + (size_t)i] =
			        ps_marks_place_dir(p, p->ox + i, p->oy + j, &theta, &phi) == 0
			                ? ps_sensor_value(s, theta, phi - rotation_deg * DEG) / top
			                : NAN;
		}
	*nx = w;
	*ny = h;
	return val;
}

/* polyline along a ring of constant theta, clipped to the picture */
static void ring(cairo_t *cr, const struct ps_marks_place *p, double theta)
{
	int started = 0;
	for (int k = 0; k <= 360; k++) {
		double x, y;
		place_point(p, theta, k * DEG, &x, &y);
		if (started)
			cairo_line_to(cr, x, y);
		else
			cairo_move_to(cr, x, y);
		started = 1;
	}
}

static void stroke_haloed(cairo_t *cr, double width, double alpha)
{
	cairo_set_source_rgba(cr, 0, 0, 0, 0.55 * alpha);
	cairo_set_line_width(cr, width + 1.5);
	cairo_stroke_preserve(cr);
	cairo_set_source_rgba(cr, 1, 1, 1, alpha);
	cairo_set_line_width(cr, width);
	cairo_stroke(cr);
}

void ps_marks_draw(struct ps_canvas *c, const struct ps_marks_place *p, int which, double rotation_deg,
                   double font)
{
	cairo_t *cr = c->cr;
	double white[3] = { 1, 1, 1 }, yellow[3] = { 1.0, 0.9, 0.3 };
	double field = p->f.theta_field, pw = p->zoom * p->f.width, ph = p->zoom * p->f.height;
	double edge = fmin(field, M_PI / 2);   /* the horizon, or the field's edge */
	cairo_save(cr);
	cairo_rectangle(cr, p->ox, p->oy, pw, ph);
	cairo_clip(cr);
	if (which & PS_MARK_RINGS) {
		for (int t = 30; t < 180 && t * DEG <= field + 1e-9; t += 30) {
			ring(cr, p, t * DEG);
			stroke_haloed(cr, t == 90 ? 1.2 : 0.8, 0.7);
		}
	}
	if (which & PS_MARK_AZIMUTH) {
		for (int a = 0; a < 360; a += 30) {
			double x0, y0, x1, y1;
			place_point(p, edge - 6 * DEG, a * DEG, &x0, &y0);
			place_point(p, edge, a * DEG, &x1, &y1);
			cairo_move_to(cr, x0, y0);
			cairo_line_to(cr, x1, y1);
			stroke_haloed(cr, a % 90 ? 1.0 : 2.0, 0.9);
		}
	}
	if (which & PS_MARK_SENSOR) {
		double x0, y0, x1, y1, ang, r = rotation_deg * DEG, hl = 0.9 * font;
		place_point(p, 0, 0, &x0, &y0);
		place_point(p, fmin(edge, 60 * DEG), r, &x1, &y1);
		ang = atan2(y1 - y0, x1 - x0);
		cairo_move_to(cr, x0, y0);
		cairo_line_to(cr, x1, y1);
		cairo_move_to(cr, x1 + hl * cos(ang + 2.6), y1 + hl * sin(ang + 2.6));
		cairo_line_to(cr, x1, y1);
		cairo_line_to(cr, x1 + hl * cos(ang - 2.6), y1 + hl * sin(ang - 2.6));
		cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
		cairo_set_source_rgba(cr, 0, 0, 0, 0.6);
		cairo_set_line_width(cr, 3.5);
		cairo_stroke_preserve(cr);
		cairo_set_source_rgb(cr, yellow[0], yellow[1], yellow[2]);
		cairo_set_line_width(cr, 2.0);
		cairo_stroke(cr);
		{
			char lab[64];
			double lx = x1 + 1.3 * font * cos(ang), ly = y1 + 1.3 * font * sin(ang);
			snprintf(lab, sizeof lab, "sensor 0\xc2\xb0");
			ps_canvas_label(c, lx, ly, font, 0, yellow, 1, lab);
		}
	}
	if (which & PS_MARK_RINGS) {
		/* ring labels along azimuth 225 (lower right), inside the picture */
		for (int t = 30; t < 180 && t * DEG <= field + 1e-9; t += 30) {
			char lab[16];
			double x, y;
			place_point(p, t * DEG, 225 * DEG, &x, &y);
			if (x < p->ox + font || x > p->ox + pw - font || y < p->oy + font || y > p->oy + ph - font)
				continue;
			snprintf(lab, sizeof lab, "%d\xc2\xb0", t);
			ps_canvas_label(c, x, y, 0.85 * font, 0, white, 1, lab);
		}
	}
	cairo_restore(cr);
	if (which & PS_MARK_AZIMUTH) {
		/* azimuth labels just outside the horizon ring; may fall in the margin */
		static const char *const name[4] = { "0\xc2\xb0 up", "90\xc2\xb0", "180\xc2\xb0", "270\xc2\xb0" };
		for (int k = 0; k < 4; k++) {
			double xc, yc, xe, ye, dx, dy, d;
			place_point(p, 0, 0, &xc, &yc);
			place_point(p, edge, k * M_PI / 2, &xe, &ye);
			dx = xe - xc;
			dy = ye - yc;
			d = hypot(dx, dy);
			if (d <= 0)
				continue;
			/* beyond the ring: above or below by one line, beside by a gap */
			d = 0.9 * font / d;
			if (k % 2)
				ps_canvas_label(c, xe + dx * 0.4 * font / hypot(dx, dy), ye, font,
				                k == 1 ? 1 : -1, white, 1, name[k]);
			else
				ps_canvas_label(c, xe + dx * d, ye + dy * d, font, 0, white, 1, name[k]);
		}
	}
}

void ps_marks_contours(struct ps_canvas *c, const struct ps_marks_place *p, const double *grid, int nx, int ny,
                       const double *levels, int n, const double rgb[3], double font)
{
	/* a target far out along azimuth 320: each contour's label goes where
	 * the contour crosses that direction */
	double xc, yc, xe, ye, lx, ly;
	place_point(p, 0, 0, &xc, &yc);
	place_point(p, M_PI / 2, 320 * M_PI / 180, &xe, &ye);
	lx = xc + 4 * (xe - xc);
	ly = yc + 4 * (ye - yc);
	for (int k = 0; k < n; k++) {
		char lab[32];
		snprintf(lab, sizeof lab, "%g %%", levels[k]);
		struct ps_contour_style st = { .ox = p->ox, .oy = p->oy, .step = 1.0, .rgb = rgb,
		                               .width = 2.0, .label = lab, .font = font, .lx = lx, .ly = ly };
		ps_contour_draw(c, grid, nx, ny, levels[k] / 100.0, &st);
	}
}
