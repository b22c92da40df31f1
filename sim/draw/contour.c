/* SPDX-License-Identifier: ISC */
#include "contour.h"

#include <math.h>

/* crossing of the level along an edge from a (value va) to b (value vb) */
static double cross(double va, double vb, double level)
{
	double d = vb - va;
	return d != 0 ? (level - va) / d : 0.5;
}

long ps_contour(const double *val, int nx, int ny, double level, ps_contour_fn fn, void *arg)
{
	long n = 0;
	for (int j = 0; j + 1 < ny; j++)
		for (int i = 0; i + 1 < nx; i++) {
			/* corners: 0 top-left, 1 top-right, 2 bottom-right, 3 bottom-left */
			double v[4] = { val[(size_t)j * (size_t)nx + (size_t)i],
			                val[(size_t)j * (size_t)nx + (size_t)i + 1],
			                val[(size_t)(j + 1) * (size_t)nx + (size_t)i + 1],
			                val[(size_t)(j + 1) * (size_t)nx + (size_t)i] };
			double px[4], py[4];
			int above[4], k, np = 0;
			if (isnan(v[0]) || isnan(v[1]) || isnan(v[2]) || isnan(v[3]))
				continue;
			for (k = 0; k < 4; k++)
				above[k] = v[k] >= level;
			/* edges: 0 top (0-1), 1 right (1-2), 2 bottom (3-2), 3 left (0-3) */
			if (above[0] != above[1]) {
				px[np] = i + cross(v[0], v[1], level); py[np] = j; np++;
			}
			if (above[1] != above[2]) {
				px[np] = i + 1; py[np] = j + cross(v[1], v[2], level); np++;
			}
			if (above[3] != above[2]) {
				px[np] = i + cross(v[3], v[2], level); py[np] = j + 1; np++;
			}
			if (above[0] != above[3]) {
				px[np] = i; py[np] = j + cross(v[0], v[3], level); np++;
			}
			if (np == 2) {
				fn(arg, px[0], py[0], px[1], py[1]);
				n++;
			} else if (np == 4) {
				/* saddle: corners 0 and 2 on one side.  If the centre is on
				 * their side, they connect through it: cut off corners 1 and 3
				 * (join top-right and bottom-left edge pairs); else cut 0 and 2. */
				double centre = 0.25 * (v[0] + v[1] + v[2] + v[3]);
				int joined = (centre >= level) == above[0];
				if (joined) {
					fn(arg, px[0], py[0], px[1], py[1]);   /* top-right: corner 1 */
					fn(arg, px[2], py[2], px[3], py[3]);   /* bottom-left: corner 3 */
				} else {
					fn(arg, px[0], py[0], px[3], py[3]);   /* top-left: corner 0 */
					fn(arg, px[1], py[1], px[2], py[2]);   /* bottom-right: corner 2 */
				}
				n += 2;
			}
		}
	return n;
}

struct draw_ctx {
	cairo_t *cr;
	double ox, oy, step, lx, ly, best, bx, by, angle;
};

static void draw_seg(void *arg, double x0, double y0, double x1, double y1)
{
	struct draw_ctx *d = arg;
	double ax = d->ox + x0 * d->step, ay = d->oy + y0 * d->step;
	double bx = d->ox + x1 * d->step, by = d->oy + y1 * d->step;
	double mx = 0.5 * (ax + bx), my = 0.5 * (ay + by), dist = hypot(mx - d->lx, my - d->ly);
	cairo_move_to(d->cr, ax, ay);
	cairo_line_to(d->cr, bx, by);
	if (dist < d->best) {
		d->best = dist;
		d->bx = mx;
		d->by = my;
	}
}

long ps_contour_draw(struct ps_canvas *c, const double *val, int nx, int ny, double level,
                     const struct ps_contour_style *st)
{
	const double *rgb = st->rgb;
	double width = st->width;
	struct draw_ctx d = { c->cr, st->ox, st->oy, st->step, st->lx, st->ly, INFINITY, 0, 0, 0 };
	long n;
	cairo_save(c->cr);
	cairo_new_path(c->cr);
	n = ps_contour(val, nx, ny, level, draw_seg, &d);
	/* a dark line under the coloured one keeps it visible on light and dark */
	cairo_set_line_cap(c->cr, CAIRO_LINE_CAP_ROUND);
	cairo_set_source_rgba(c->cr, 0, 0, 0, 0.6);
	cairo_set_line_width(c->cr, width + 1.5);
	cairo_stroke_preserve(c->cr);
	cairo_set_source_rgb(c->cr, rgb[0], rgb[1], rgb[2]);
	cairo_set_line_width(c->cr, width);
	cairo_stroke(c->cr);
	cairo_restore(c->cr);
	if (st->label && n > 0)
		ps_canvas_label(c, d.bx, d.by, st->font, 0, rgb, 1, st->label);
	return n;
}
