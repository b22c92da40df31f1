#include "annual.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "canvas.h"
#include "dated.h"
#include "falsecolor.h"
#include "room.h"
#include "roomsetup.h"
#include "sum.h"

#define DAYS 365
#define ROWS 144   /* 10-minute rows */

static double clamp(double x, double lo, double hi)
{
	return x < lo ? lo : x > hi ? hi : x;
}

int psd_annual_run(const struct ps_results *r, const struct psd_control *ctl,
                   const struct psd_annual_opt *o, struct psd_annual *a)
{
	struct ps_room_daypoint day[PSD_DAY_POINTS];
	struct ps_room_params p;
	struct psd_control c = *ctl;
	struct ps_sum em[2], e2[2];
	struct timespec t0, t1;
	int steps_day = (int)floor(86400.0 / o->period + 0.5);
	memset(a, 0, sizeof *a);
	if (!r->have_year || isnan(r->electric_sensor_response) || o->period <= 0)
		return -1;
	clock_gettime(CLOCK_MONOTONIC, &t0);
	for (int k = 0; k < 2; k++) {
		ps_sum_init(&em[k]);
		ps_sum_init(&e2[k]);
	}
	/* a year without light has no ratio: any will do, there is no daylight */
	c.daylight_ratio = r->year.mean_ratio > 0 ? r->year.mean_ratio
	                   : ctl->daylight_ratio > 0 ? ctl->daylight_ratio : 1.0;
	c.elec_sensor = r->electric_sensor_response;
	c.elec_task_lux = r->electric_task_lux;
	c.level = 1.0;
	c.pending_since = -1;
	for (int doy = 1; doy <= DAYS; doy++) {
		struct ps_room *room;
		int m;
		if (psd_room_from_year(r, doy, day, &p) != 0)
			return -1;
		p.gain = c.sensor_gain;
		p.ballast.min_level = 0;
		room = ps_room_new(&p, 0.0);
		if (!room)
			return -1;
		{
			static const int start[13] = { 0, 31, 59, 90, 120, 151, 181, 212, 243, 273, 304, 334, 365 };
			m = 0;
			while (m < 11 && doy > start[m + 1])
				m++;
		}
		ps_room_command(room, 0.0, c.level);
		for (int s = 0; s < steps_day; s++) {
			double t = s * o->period, volts, dv, dl, level, prev = c.level, ideal, truth;
			int occ = t >= o->occ_start && t < o->occ_end;
			double mean_ratio = r->year.mean_ratio > 0 ? r->year.mean_ratio : c.daylight_ratio;
			double dated = NAN;
			if (ps_room_sensor(room, t, &volts) != 0)
				volts = 0;
			dated = psd_dated_ratio(r, m + 1, t, NULL);
			c.daylight_ratio = o->dated && dated > 0 ? dated : mean_ratio;
			level = psd_control_step(&c, volts, t);
			ps_room_command(room, t, level);
			ps_room_daylight(room, t, &dv, &dl);
			truth = ps_room_true_task_lux(room, t);
			a->steps++;
			if (o->task_img && s * o->period < 86400) {
				int row = (int)(t / 600.0);
				if (row < ROWS && fmod(t, 600.0) < o->period) {
					o->task_img[row * DAYS + doy - 1] = (float)truth;
					o->level_img[row * DAYS + doy - 1] = (float)level;
				}
			}
			if (!occ)
				continue;
			{
				double h = o->period / 3600.0;
				ideal = clamp((c.target_lux - dl) / c.elec_task_lux, c.min_level, 1.0);
				a->occ_h += h;
				a->energy_h += level * h;
				a->ideal_h += ideal * h;
				a->month[m].occ_h += h;
				a->month[m].energy_h += level * h;
				a->month[m].ideal_h += ideal * h;
				if (truth < 0.9 * c.target_lux) {
					a->below_h += h;
					a->month[m].below_h += h;
				}
				if (level < ideal - 0.01 && truth < c.target_lux) {
					a->overdim_h += h;
					a->month[m].overdim_h += h;
				}
				if (fabs(level - prev) > 0.005)
					a->changes++;
			}
			if (dl >= 50) {
				/* the law's daylight estimate with each ratio */
				double resp = c.daylight_volts / c.sensor_gain;
				double est[2] = { mean_ratio * resp, (dated > 0 ? dated : mean_ratio) * resp };
				for (int k = 0; k < 2; k++) {
					double err = est[k] / dl - 1;
					ps_sum_add(&em[k], err);
					ps_sum_add(&e2[k], err * err);
				}
				a->est_n++;
			}
		}
		ps_room_free(room);
	}
	a->savings = a->occ_h > 0 ? 1 - a->energy_h / a->occ_h : NAN;
	a->ideal_savings = a->occ_h > 0 ? 1 - a->ideal_h / a->occ_h : NAN;
	a->effectiveness = a->ideal_savings > 0 ? a->savings / a->ideal_savings : NAN;
	a->changes_per_h = a->occ_h > 0 ? a->changes / a->occ_h : NAN;
	for (int k = 0; k < 2; k++) {
		a->est_mean[k] = a->est_n ? 100 * ps_sum_get(&em[k]) / a->est_n : NAN;
		a->est_rms[k] = a->est_n ? 100 * sqrt(ps_sum_get(&e2[k]) / a->est_n) : NAN;
	}
	clock_gettime(CLOCK_MONOTONIC, &t1);
	a->seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
	return 0;
}

int psd_annual_png(const char *path, const float *task_img, const float *level_img,
                   double target, const char *title, char *err, size_t errlen)
{
	static const uint8_t white[3] = { 255, 255, 255 };
	static const double ink[3] = { 0, 0, 0 };
	const int z = 2, left = 50, top = 34, gap = 40, pw = DAYS * z, ph = ROWS * z, lw = 230;
	struct ps_canvas cv;
	struct ps_err e;
	struct ps_fcscale sc = { 100 * target, 1, 3 };   /* 0.1 to 100 x target, log */
	int W = left + pw + lw, H = top + 2 * ph + gap + 30;
	if (ps_canvas_init(&cv, W, H, white, &e) != 0)
		return snprintf(err, errlen, "%s", e.msg), -1;
	ps_canvas_begin(&cv);
	for (int row = 0; row < ROWS; row++)
		for (int d = 0; d < DAYS; d++) {
			uint8_t rgb[3];
			int y = ROWS - 1 - row;   /* midnight at the bottom */
			double v = task_img[row * DAYS + d], f = ps_fcscale_fraction(&sc, v);
			ps_falsecolor_rgb8(clamp(f, 0, 1), rgb);
			ps_canvas_set(&cv, left + d * z, top + y * z, z, rgb);
			v = clamp(level_img[row * DAYS + d], 0, 1);
			rgb[0] = rgb[1] = rgb[2] = (uint8_t)(40 + 215 * v);
			ps_canvas_set(&cv, left + d * z, top + ph + gap + y * z, z, rgb);
		}
	ps_canvas_end(&cv);
	ps_canvas_label(&cv, left, 14, 13, -1, ink, 0, title);
	{
		char buf[96];
		ps_canvas_label(&cv, left + pw + 8, top + 10, 11, -1, ink, 0, "true task lux (log scale)");
		ps_canvas_label(&cv, left + pw + 8, top + ph + gap + 10, 11, -1, ink, 0,
		                "light output");
		ps_canvas_begin(&cv);
		for (int k = 0; k <= 3; k++) {
			uint8_t rgb[3];
			ps_falsecolor_rgb8(k / 3.0, rgb);
			for (int yy = 0; yy < 12; yy++)
				for (int xx = 0; xx < 16; xx++)
					ps_canvas_set(&cv, left + pw + 8 + xx, top + 24 + 18 * k + yy, 1, rgb);
			rgb[0] = rgb[1] = rgb[2] = (uint8_t)(40 + 215 * (k / 3.0));
			for (int yy = 0; yy < 12; yy++)
				for (int xx = 0; xx < 16; xx++)
					ps_canvas_set(&cv, left + pw + 8 + xx, top + ph + gap + 24 + 18 * k + yy, 1, rgb);
		}
		ps_canvas_end(&cv);
		for (int k = 0; k <= 3; k++) {
			snprintf(buf, sizeof buf, "%.0f lx%s", 0.1 * target * pow(10, k), k == 3 ? " and over" : "");
			ps_canvas_label(&cv, left + pw + 30, top + 30 + 18 * k, 11, -1, ink, 0, buf);
			snprintf(buf, sizeof buf, "%.2f", k / 3.0);
			ps_canvas_label(&cv, left + pw + 30, top + ph + gap + 30 + 18 * k, 11, -1, ink, 0, buf);
		}
		for (int hr = 0; hr <= 24; hr += 6) {
			snprintf(buf, sizeof buf, "%02d:00", hr);
			ps_canvas_label(&cv, left - 4, top + ph - hr * 6 * z, 10, 1, ink, 0, buf);
			ps_canvas_label(&cv, left - 4, top + ph + gap + ph - hr * 6 * z, 10, 1, ink, 0, buf);
		}
		for (int mo = 0; mo < 12; mo++) {
			static const char *const mn[] = { "Jan", "Feb", "Mar", "Apr", "May", "Jun",
			                                  "Jul", "Aug", "Sep", "Oct", "Nov", "Dec" };
			static const int start[12] = { 0, 31, 59, 90, 120, 151, 181, 212, 243, 273, 304, 334 };
			ps_canvas_label(&cv, left + (start[mo] + 15) * z, top + 2 * ph + gap + 12, 10, 0, ink,
			                0, mn[mo]);
		}
		ps_canvas_label(&cv, left, top + ph + gap / 2, 12, -1, ink, 0,
		                "hour of day (standard time) against day of the year");
	}
	if (ps_canvas_save_png(&cv, path, &e) != 0) {
		ps_canvas_free(&cv);
		return snprintf(err, errlen, "%s", e.msg), -1;
	}
	ps_canvas_free(&cv);
	return 0;
}
