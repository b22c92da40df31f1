/* SPDX-License-Identifier: ISC */
#include "year.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "integrate.h"
#include "patches.h"
#include "sum.h"

int ps_year_class(double epsilon)
{
	if (epsilon < 1.23)
		return PS_SKY_OVERCAST;
	if (epsilon >= 4.5)
		return PS_SKY_CLEAR;
	return PS_SKY_INTERMEDIATE;
}

const char *ps_year_class_name(int c)
{
	static const char *const names[] = { "clear", "intermediate", "overcast" };
	return c >= 0 && c < PS_SKY_NCLASS ? names[c] : "?";
}

void ps_year_free(struct ps_year *y)
{
	if (!y)
		return;
	free(y->h);
	memset(y, 0, sizeof *y);
}

void ps_year_tabulate(struct ps_year *y)
{
	struct ps_sum st[12][24][PS_SKY_NCLASS], ss[12][24][PS_SKY_NCLASS];
	struct ps_sum at, as;
	ps_sum_init(&at);
	ps_sum_init(&as);
	for (int m = 0; m < 12; m++)
		for (int h = 0; h < 24; h++)
			for (int c = 0; c < PS_SKY_NCLASS; c++) {
				ps_sum_init(&st[m][h][c]);
				ps_sum_init(&ss[m][h][c]);
				y->count[m][h][c] = 0;
			}
	for (size_t i = 0; i < y->n; i++) {
		const struct ps_year_hour *k = &y->h[i];
		int m = k->month - 1, h = (int)floor(k->hour), c = k->sky_class;
		if (m < 0 || m > 11 || h < 0 || c < 0 || c >= PS_SKY_NCLASS)
			continue;
		if (h > 23)
			h = 23;
		ps_sum_add(&st[m][h][c], k->task_lux);
		ps_sum_add(&ss[m][h][c], k->sensor);
		ps_sum_add(&at, k->task_lux);
		ps_sum_add(&as, k->sensor);
		y->count[m][h][c]++;
	}
	for (int m = 0; m < 12; m++)
		for (int h = 0; h < 24; h++)
			for (int c = 0; c < PS_SKY_NCLASS; c++) {
				double s = ps_sum_get(&ss[m][h][c]);
				y->ratio[m][h][c] = y->count[m][h][c] && s > 0 ? ps_sum_get(&st[m][h][c]) / s : NAN;
			}
	y->mean_ratio = ps_sum_get(&as) > 0 ? ps_sum_get(&at) / ps_sum_get(&as) : NAN;
}

int ps_year_run(const struct ps_dcset_row *srow, const double scoef[3], const struct ps_dcset_row *trow,
                const struct ps_weather *w, const struct ps_sky_opt *o, struct ps_year *y,
                struct ps_err *e)
{
	static const double vl[3] = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B };
	struct ps_patches P;
	double *sky, sv[4], v1;
	int *list, nlist = 0;
	int alt = o->sun_disc <= 0 && o->nsun > 1;
	memset(y, 0, sizeof *y);
	if (srow->n != trow->n || srow->mf != trow->mf)
		return ps_err_set(e, PS_EINVAL, "year: the rows have %d and %d patches", srow->n, trow->n);
	if (ps_patches_init(&P, srow->mf, e) != 0)
		return -1;
	sky = malloc((size_t)P.n * 3 * sizeof *sky);
	list = malloc((size_t)P.n * sizeof *list);
	y->h = w->n ? malloc(w->n * sizeof *y->h) : NULL;
	if (!sky || !list || (w->n && !y->h)) {
		free(sky);
		free(list);
		ps_patches_free(&P);
		ps_year_free(y);
		return ps_err_set(e, PS_ENOMEM, "year: out of memory for %zu hours", w->n);
	}
	for (int p = 0; p < P.n; p++) {
		int any = 0;
		for (int c = 0; c < 3; c++)
			any |= srow->c[3 * p + c] != 0 || trow->c[3 * p + c] != 0;
		if (any)
			list[nlist++] = p;
	}
	y->patches = P.n;
	y->used = nlist;
	y->steps = w->n;
	y->site = w->site;
	y->have_site = 1;
	y->leap = w->leap;
	y->have_alt = alt;
	for (size_t i = 0; i < w->n; i++) {
		struct ps_sky s;
		struct ps_year_hour *k;
		if (ps_sky_step(&s, w, i, o, e) != 0) {
			free(sky);
			free(list);
			ps_patches_free(&P);
			ps_year_free(y);
			return -1;
		}
		if (s.dark) {
			y->dark++;
			continue;
		}
		ps_sky_vector(&s, &P, PS_SKY_ALL, sky);
		k = &y->h[y->n++];
		k->month = w->step[i].month;
		k->day = w->step[i].day;
		k->hour = w->step[i].hour;
		k->sensor = ps_dcset_row_apply_list(srow, scoef, sky, list, nlist);
		k->task_lux = PS_YEAR_LUX_PER_WM2 * ps_dcset_row_apply_list(trow, vl, sky, list, nlist);
		k->epsilon = s.model.epsilon;
		k->sky_class = ps_year_class(s.model.epsilon);
		k->horiz_lux = s.model.dif_lux + (s.sun_alt > 0 ? s.model.dir_lux * sin(s.sun_alt) : 0.0);
		k->sensor_alt = k->task_alt = NAN;
		if (alt) {
			/* the hour again with the sun's light all in its nearest
			 * patch instead of shared: only those patches change */
			int idx[4], nk = ps_sky_sun_patches(&s, &P, idx, sv, &v1);
			double ds = 0, dt = 0;
			for (int q = 0; q < nk; q++)
				for (int c = 0; c < 3; c++) {
					double dv = ((q == 0 ? v1 : 0.0) - sv[q]) * s.opt.sun_color[c];
					ds += scoef[c] * srow->c[3 * idx[q] + c] * dv;
					dt += vl[c] * trow->c[3 * idx[q] + c] * dv;
				}
			k->sensor_alt = fmax(k->sensor + ds, 0.0);   /* rounding of a sun that is all one patch */
			k->task_alt = fmax(k->task_lux + PS_YEAR_LUX_PER_WM2 * dt, 0.0);
		}
	}
	free(sky);
	free(list);
	ps_patches_free(&P);
	ps_year_tabulate(y);
	return 0;
}
