/* SPDX-License-Identifier: ISC */
#include "placeout.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "canvas.h"
#include "falsecolor.h"
#include "json.h"
#include "lum.h"
#include "marks.h"
#include "placerun.h"
#include "placeset.h"
#include "placeyear.h"
#include "tonemap.h"
#include "version.h"

/* a sensor as -s gave it, each file by its base name (cone.sen@blue.txt) */
static void short_sensor(const char *spec, char *out, size_t n)
{
	const char *at = strrchr(spec, '@'), *a = spec, *b = at ? at + 1 : NULL;
	size_t la = at ? (size_t)(at - spec) : strlen(spec);
	for (const char *q = spec; q < spec + la; q++)
		if (*q == '/')
			a = q + 1;
	la -= (size_t)(a - spec);
	if (b && strrchr(b, '/'))
		b = strrchr(b, '/') + 1;
	snprintf(out, n, "%.*s%s%s", (int)la, a, b ? "@" : "", b ? b : "");
}

void psd_placeout_table(const struct search *s, size_t rows)
{
	printf("%4s %-8s %6s %-24s %-20s %8s %8s %8s %9s %8s %7s %7s %6s %s\n", "rank", "pose", "rot", "sensor", "law",
	       "energy%", "kWh", "below_h", "def_klxh", "over_h", "chg/h", "sprd%", "days%", "front");
	for (size_t i = 0; i < rows && i < s->nc; i++) {
		const struct combo *k = &s->c[i];
		char sname[64];
		short_sensor(s->o->sens[k->sens], sname, sizeof sname);
		if (k->fail) {
			printf("%4zu %-8s %6.1f %-24.24s %-20s  (the year did not run)\n", i + 1, s->poses[k->pose].id,
			       psd_placerun_rot_deg(s, k->rot), sname, psd_control_algorithm_names[s->o->laws[k->law]]);
			continue;
		}
		printf("%4zu %-8s %6.1f %-24.24s %-20s %8.2f %8.1f %8.1f %9.2f %8.1f %7.3f %7.1f %6.1f %s\n", i + 1,
		       s->poses[k->pose].id, psd_placerun_rot_deg(s, k->rot), sname, psd_control_algorithm_names[s->o->laws[k->law]],
		       100 * k->a.energy_h / k->a.occ_h, k->a.kwh, k->a.below_h, k->deficit_lxh / 1000, k->over_h,
		       k->a.changes_per_h, k->spread_max, k->days > 0 ? 100 * k->days_pass / k->days : NAN,
		       k->pareto ? "*" : "");
	}
}

static json_object *combo_json(const struct search *s, const struct combo *k, size_t rank)
{
	json_object *o = json_object_new_object(), *sp = json_object_new_object();
	static const char *const cls[] = { "clear", "intermediate", "overcast" };
	json_object_object_add(o, "rank", json_object_new_int64((int64_t)rank));
	psd_json_str(o, "pose", s->poses[k->pose].id);
	psd_json_str(o, "view", s->poses[k->pose].view_text);
	psd_json_num(o, "rotation", psd_placerun_rot_deg(s, k->rot));
	psd_json_str(o, "sensor", s->o->sens[k->sens]);
	psd_json_str(o, "law", psd_control_algorithm_names[s->o->laws[k->law]]);
	psd_json_num(o, "occupied_h", k->a.occ_h);
	psd_json_num(o, "energy_pct", 100 * k->a.energy_h / k->a.occ_h);
	psd_json_num(o, "energy_h", k->a.energy_h);
	psd_json_num(o, "light_h", k->a.light_h);
	psd_json_num(o, "kwh", k->a.kwh);
	psd_json_num(o, "savings_pct", 100 * k->a.savings);
	psd_json_num(o, "below90_h", k->a.below_h);
	psd_json_num(o, "deficit_lxh", k->deficit_lxh);
	psd_json_num(o, "overdim_h", k->a.overdim_h);
	psd_json_num(o, "over_h", k->over_h);
	psd_json_num(o, "changes_per_h", k->a.changes_per_h);
	for (int c = 0; c < PS_SKY_NCLASS; c++)
		psd_json_num(sp, cls[c], k->spread[c]);
	json_object_object_add(o, "ratio_spread_pct", sp);
	psd_json_num(o, "days_passing_pct", k->days > 0 ? 100 * k->days_pass / k->days : NAN);
	json_object_object_add(o, "pareto", json_object_new_boolean(k->pareto));
	if (k->exact) {
		psd_json_num(o, "exact_sensor_err_pct", k->exact_sensor_err);
		psd_json_num(o, "exact_energy_err_pts", k->exact_energy_err);
	}
	return o;
}

int psd_placeout_json(const struct search *s, FILE *fp, double seconds)
{
	json_object *root = json_object_new_object(), *arr = json_object_new_array();
	psd_json_str(root, "candidates", s->o->cands ? s->o->cands : s->o->ceiling);
	psd_json_str(root, "grid", s->o->grid);
	psd_json_str(root, "statistic", s->o->stat);
	psd_json_str(root, "weather", s->o->weather);
	psd_json_num(root, "target_lux", s->zc->ctl.target_lux);
	psd_json_num(root, "grid_electric_lux", s->elec_task);
	psd_json_num(root, "period_s", s->ao.period);
	psd_json_num(root, "seconds", seconds);
	{
		/* the sensors as given, with the colour weights applied */
		json_object *sa = json_object_new_array();
		for (int k = 0; k < s->o->nsens; k++) {
			json_object *so = json_object_new_object(), *w = json_object_new_array();
			psd_json_str(so, "sensor", s->o->sens[k]);
			for (int c = 0; c < 3; c++)
				json_object_array_add(w, json_object_new_double(s->o->coef[k][c]));
			json_object_object_add(so, "rgb", w);
			json_object_array_add(sa, so);
		}
		json_object_object_add(root, "sensors", sa);
	}
	for (size_t i = 0; i < s->nc; i++)
		json_object_array_add(arr, combo_json(s, &s->c[i], i + 1));
	json_object_object_add(root, "combinations", arr);
	fprintf(fp, "%s\n", psd_json_text(root, 17));
	json_object_put(root);
	return ferror(fp) ? -1 : 0;
}

/* month and day of day-of-year doy (from 1) */
static void month_day(int doy, int leap, int *m, int *d)
{
	static const int md[12] = { 31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31 };
	int i = 0;
	while (i < 11 && doy > md[i] + (i == 1 && leap)) {
		doy -= md[i] + (i == 1 && leap);
		i++;
	}
	*m = i + 1;
	*d = doy;
}

/* The winner's year again, hour by hour: the schedule, the CSV, the
 * results and the zone section. */
int psd_placeout_exports(const struct search *s, const struct combo *k0, char *err, size_t errlen)
{
	const struct opts *o = s->o;
	struct combo k = *k0;
	struct watch w;
	static double power[8784], level[8784], steps[8784];
	int days;
	if (!o->schedule && !o->csv && !o->results_out && !o->zone_out)
		return 0;
	memset(&w, 0, sizeof w);
	memset(power, 0, sizeof power);
	memset(level, 0, sizeof level);
	memset(steps, 0, sizeof steps);
	w.hour_power = power;
	w.hour_level = level;
	w.hour_steps = steps;
	if (psd_placerun_row(s, &k, 1, psd_placerun_row_of(s, &k), psd_placerun_elec_of(s, &k), &w) != 0)
		return snprintf(err, errlen, "the chosen combination's year did not run"), -1;
	days = k.a.days;
	if (o->schedule || o->csv) {
		for (int pass = 0; pass < 2; pass++) {
			const char *path = pass ? o->csv : o->schedule;
			FILE *fp;
			if (!path)
				continue;
			fp = fopen(path, "w");
			if (!fp)
				return snprintf(err, errlen, "%s: %s", path, strerror(errno)), -1;
			if (!pass)
				fprintf(fp, "lighting_power_fraction\n");
			else
				fprintf(fp, "month,day,hour_ending,light_output,power_fraction\n");
			for (int hr = 0; hr < days * 24; hr++) {
				double pw = steps[hr] > 0 ? power[hr] / steps[hr] : 0, lv = steps[hr] > 0 ? level[hr] / steps[hr] : 0;
				if (!pass)
					fprintf(fp, "%.6f\n", pw);
				else {
					int m, d;
					month_day(hr / 24 + 1, days == 366, &m, &d);
					fprintf(fp, "%d,%d,%d,%.6f,%.6f\n", m, d, hr % 24 + 1, lv, pw);
				}
			}
			if (fclose(fp) != 0)
				return snprintf(err, errlen, "%s: %s", path, strerror(errno)), -1;
		}
	}
	if (o->results_out) {
		struct ps_results r;
		struct ps_err e;
		double ss;
		if (psd_placeyear_results(s, psd_placerun_row_of(s, &k), psd_placerun_elec_of(s, &k), &s->sens[k.sens], &r, &ss) != 0)
			return snprintf(err, errlen, "out of memory"), -1;
		if (ps_results_write(&r, o->results_out, &e) != 0) {
			psd_placeyear_release(&r);
			return snprintf(err, errlen, "%s", e.msg), -1;
		}
		psd_placeyear_release(&r);
	}
	if (o->zone_out) {
		FILE *fp = fopen(o->zone_out, "w");
		const struct psd_control *c = &s->zc->ctl;
		if (!fp)
			return snprintf(err, errlen, "%s: %s", o->zone_out, strerror(errno)), -1;
		fprintf(fp, "; psplace's choice for zone %s: pose %s (%s), the sensor %s turned %g degrees\n"
		            "; about its axis; over the year: %.1f %% energy, %.1f h below 90 %% of the target.\n"
		            "; Merge into the zone's section of psensd.conf (its points stay as they are).\n"
		            "[zone %s]\nalgorithm = %s\ntarget_lux = %g\nmin_level = %g\n",
		        s->zc->name, s->poses[k.pose].id, s->poses[k.pose].view_text, o->sens[k.sens],
		        psd_placerun_rot_deg(s, k.rot), 100 * k.a.energy_h / k.a.occ_h, k.a.below_h, s->zc->name,
		        psd_control_algorithm_names[o->laws[k.law]], c->target_lux, c->min_level);
		if (o->results_out)
			fprintf(fp, "results = %s\n", o->results_out);
		if (fclose(fp) != 0)
			return snprintf(err, errlen, "%s: %s", o->zone_out, strerror(errno)), -1;
	}
	return 0;
}

/* ---- the plan ------------------------------------------------------ */

/* The room's plan seen from above (x across, y up the picture): each pose
 * a disc coloured by its best combination's energy (blue least, red most,
 * grey when none stays within the under-lighting allowed), its aim's
 * horizontal part an arrow, the winner ringed. */
int psd_placeout_plan(const struct search *s, const char *path, char *err, size_t errlen)
{
	static const uint8_t white[3] = { 255, 255, 255 };
	static const double ink[3] = { 0, 0, 0 };
	const int W = 640, H = 560, top = 50, side = 60;
	double x0 = 1e30, x1 = -1e30, y0 = 1e30, y1 = -1e30, emin = 1e30, emax = -1e30, scale;
	double *best = calloc((size_t)s->nposes, sizeof *best);
	int *have = calloc((size_t)s->nposes, sizeof *have);
	struct ps_canvas cv;
	struct ps_err e;
	char buf[160];
	if (!best || !have) {
		free(best);
		free(have);
		return snprintf(err, errlen, "out of memory"), -1;
	}
	for (size_t i = 0; i < s->nc; i++) {
		const struct combo *k = &s->c[i];
		if (k->fail || have[k->pose])
			continue;
		have[k->pose] = k->a.below_h <= s->o->max_below ? 1 : 2;
		best[k->pose] = 100 * k->a.energy_h / k->a.occ_h;
		if (have[k->pose] == 1) {
			emin = fmin(emin, best[k->pose]);
			emax = fmax(emax, best[k->pose]);
		}
	}
	for (int i = 0; i < s->nposes; i++) {
		x0 = fmin(x0, s->poses[i].view.vp[0]);
		x1 = fmax(x1, s->poses[i].view.vp[0]);
		y0 = fmin(y0, s->poses[i].view.vp[1]);
		y1 = fmax(y1, s->poses[i].view.vp[1]);
	}
	x0 -= 0.6, x1 += 0.6, y0 -= 0.6, y1 += 0.6;
	scale = fmin((W - 2 * side) / (x1 - x0), (H - top - side) / (y1 - y0));
	if (ps_canvas_init(&cv, W, H, white, &e) != 0) {
		free(best);
		free(have);
		return snprintf(err, errlen, "%s", e.msg), -1;
	}
	{
		cairo_t *cr = cv.cr;
		double px0 = side, py0 = top + (y1 - y0) * scale;
		cairo_set_source_rgb(cr, 0.4, 0.4, 0.4);
		cairo_set_line_width(cr, 1.0);
		cairo_rectangle(cr, px0, top, (x1 - x0) * scale, (y1 - y0) * scale);
		cairo_stroke(cr);
		for (int i = 0; i < s->nposes; i++) {
			const struct ps_view *v = &s->poses[i].view;
			double px = px0 + (v->vp[0] - x0) * scale, py = py0 - (v->vp[1] - y0) * scale, r = 16;
			double hx = v->vd[0], hy = v->vd[1], hl = sqrt(hx * hx + hy * hy);
			uint8_t rgb[3] = { 170, 170, 170 };
			if (have[i] == 1)
				ps_falsecolor_rgb8(emax > emin ? (best[i] - emin) / (emax - emin) : 0.0, rgb);
			/* tilted poses sit beside the ones at the same point */
			if (hl > 1e-6) {
				px += 3.2 * r * hx / hl;
				py -= 3.2 * r * hy / hl;
			}
			cairo_set_source_rgb(cr, rgb[0] / 255.0, rgb[1] / 255.0, rgb[2] / 255.0);
			cairo_arc(cr, px, py, r, 0, 2 * M_PI);
			cairo_fill_preserve(cr);
			cairo_set_source_rgb(cr, 0, 0, 0);
			cairo_set_line_width(cr, s->nc && s->c[0].pose == i ? 4.0 : 1.0);
			cairo_stroke(cr);
			if (hl > 1e-6) {
				cairo_set_line_width(cr, 2.0);
				cairo_move_to(cr, px, py);
				cairo_line_to(cr, px + 1.5 * r * hx / hl, py - 1.5 * r * hy / hl);
				cairo_stroke(cr);
			}
			snprintf(buf, sizeof buf, "%s %s", s->poses[i].id, have[i] ? "" : "(no year)");
			if (have[i])
				snprintf(buf, sizeof buf, "%s %.1f%%", s->poses[i].id, best[i]);
			ps_canvas_label(&cv, px, py + r + 9, 10, 0, ink, 0, buf);
		}
	}
	ps_canvas_label(&cv, 10, 16, 13, -1, ink, 0, "psplace: candidate poses, plan (x across, y up; metres)");
	snprintf(buf, sizeof buf, "colour: the pose's best energy, blue %.1f %% to red %.1f %%; grey: under-lit; ringed: the best",
	         emin < 1e29 ? emin : 0.0, emax > -1e29 ? emax : 0.0);
	ps_canvas_label(&cv, 10, 34, 10, -1, ink, 0, buf);
	snprintf(buf, sizeof buf, "x %.2f to %.2f m, y %.2f to %.2f m", x0, x1, y0, y1);
	ps_canvas_label(&cv, 10, H - 14, 10, -1, ink, 0, buf);
	free(best);
	free(have);
	if (ps_canvas_save_png(&cv, path, &e) != 0) {
		ps_canvas_free(&cv);
		return snprintf(err, errlen, "%s", e.msg), -1;
	}
	ps_canvas_free(&cv);
	ps_canvas_shutdown();
	return 0;
}


/* ---- the best pose's sensitivity over its fisheye ------------------- */

int psd_placeout_fisheye(const struct search *s, const struct combo *k, const char *path, char *err, size_t errlen)
{
	static const uint8_t bg[3] = { 28, 28, 28 };
	static const double fg[3] = { 0.92, 0.92, 0.92 };
	const struct pose *p = &s->poses[k->pose];
	const struct ps_sensor *sens = &s->sens[k->sens];
	double rot = psd_placerun_rot_deg(s, k->rot), font, *grid;
	struct ps_picture pic;
	struct ps_canvas c;
	struct ps_marks_place pl;
	struct ps_tonemap t;
	struct ps_err e;
	char caption[700];
	int w, h, zoom, margin, nx, ny;
	if (psd_placeset_elec_read(s, p, &pic, err, errlen) != 0)
		return -1;
	w = pic.width;
	h = pic.height;
	zoom = (511 + (w > h ? w : h)) / (w > h ? w : h);
	zoom = zoom < 1 ? 1 : zoom > 4 ? 4 : zoom;
	font = h * zoom >= 480 ? 13.0 : 11.0;
	margin = (int)(3.0 * font);
	if (ps_canvas_init(&c, 2 * margin + w * zoom, 3 * margin + h * zoom, bg, &e) != 0) {
		ps_picture_free(&pic);
		return snprintf(err, errlen, "%s", e.msg), -1;
	}
	ps_marks_place_init(&pl, &p->view, w, h, margin, margin, zoom);
	grid = ps_marks_place_sensitivity(&pl, sens, rot, &nx, &ny);
	if (!grid) {
		ps_canvas_free(&c);
		ps_picture_free(&pic);
		return snprintf(err, errlen, "out of memory"), -1;
	}
	/* the picture in grey (its luminance, tone mapped), tinted in false
	 * colour by the sensitivity at each pixel's centre where it is above
	 * 0.5 % of its peak; outside the fisheye the background */
	ps_tonemap_init(&t, &pic, PS_TONE_REINHARD, 0, 2.2, 0);
	ps_canvas_begin(&c);
	for (int row = 0; row < h; row++)
		for (int x = 0; x < w; x++) {
			double th, ph, rgb[3], y, v;
			uint8_t out[3], fc[3];
			size_t at = (size_t)(row * zoom + zoom / 2) * (size_t)nx + (size_t)(x * zoom + zoom / 2);
			if (ps_fisheye_pixel_dir(&pl.f, x, row, &th, &ph) != 0)
				continue;
			ps_lum_rgb(&t.lum, &pic, x, row, rgb);
			y = ps_lum_y(&t.lum, rgb);
			rgb[0] = rgb[1] = rgb[2] = y;
			ps_tonemap_rgb(&t, rgb, out);
			out[0] = out[2] = out[1];
			v = grid[at];
			if (isfinite(v) && v > 0.005) {
				ps_falsecolor_rgb8(v, fc);
				for (int i = 0; i < 3; i++)
					out[i] = (uint8_t)lround(0.4 * out[i] + 0.6 * fc[i]);
			}
			ps_canvas_set(&c, margin + zoom * x, margin + zoom * row, zoom, out);
		}
	ps_canvas_end(&c);
	ps_marks_draw(&c, &pl, PS_MARK_RINGS | PS_MARK_AZIMUTH | PS_MARK_SENSOR, rot, font);
	{
		/* 10, 50 and 90 % of the peak in light blue, as mksens --overlay */
		static const double levels[3] = { 10, 50, 90 }, light_blue[3] = { 0.55, 0.88, 1 };
		ps_marks_contours(&c, &pl, grid, nx, ny, levels, 3, light_blue, font);
	}
	free(grid);
	{
		char name[200];
		short_sensor(s->o->sens[k->sens], name, sizeof name);
		snprintf(caption, sizeof caption, "pose %s, %s turned %g\xc2\xb0, over its electric picture", p->id, name,
		         rot);
	}
	ps_canvas_label(&c, margin, margin + h * zoom + 0.9 * margin, font, -1, fg, 0, caption);
	ps_canvas_label(&c, margin, margin + h * zoom + 1.6 * margin, font, -1, fg, 0,
	                "colour and contours: the sensitivity in % of its peak");
	snprintf(caption, sizeof caption, "%.600s", p->view_text);
	ps_canvas_text_chunk(&c, "Software", "psplace (psensd) " PS_VERSION);
	ps_canvas_text_chunk(&c, "Comment", caption);
	ps_picture_free(&pic);
	if (ps_canvas_save_png(&c, path, &e) != 0) {
		ps_canvas_free(&c);
		return snprintf(err, errlen, "%s", e.msg), -1;
	}
	ps_canvas_free(&c);
	ps_canvas_shutdown();
	return 0;
}
