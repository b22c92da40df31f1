/* SPDX-License-Identifier: ISC */
/* The exact weights' fast route (an axis-parallel edge inside one cell:
 * Gauss-Legendre in the plane coordinate, its order from an error bound)
 * against analytic answers, for a sensor that changes with azimuth (no
 * mirroring): the map's total is the table's integral over the sphere
 * (it ends at 90 degrees, inside the field) to 1e-12 at several sizes, both
 * readings, both fisheye projections; and with the cell reading, a pixel
 * wholly inside one cell weighs the cell's sensitivity times the pixel's
 * solid angle (computed by the general route, ps_weights_rect_solid_angle),
 * within 1e-10 of the largest weight (a single weight is exact only to the
 * cancellation of its four edge integrals: test_weights_symmetry.c). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "fisheye.h"
#include "sensor.h"
#include "view.h"
#include "weights.h"

static const char table_text[] = "Elevation field 90\n"
                                 "degrees 0 45 90 135 180 225 270 315\n"
                                 "0 1 1 1 1 1 1 1 1\n"
                                 "20 0.95 0.9 0.7 0.6 0.8 0.9 0.85 0.9\n"
                                 "40 0.8 0.6 0.4 0.3 0.5 0.7 0.7 0.75\n"
                                 "60 0.5 0.3 0.2 0.1 0.2 0.4 0.45 0.5\n"
                                 "80 0.1 0.05 0.02 0.01 0.03 0.08 0.1 0.1\n"
                                 "90 0 0 0 0 0 0 0 0\n";

static void load(struct ps_sensor *s, int reading)
{
	struct ps_err e;
	if (ps_sensor_parse(s, table_text, sizeof table_text - 1, "table", &e) != 0 ||
	    ps_sensor_set_reading(s, reading, &e) != 0)
		fail_msg("%s", e.msg);
}

static void totals_are_the_integral(void **state)
{
	static const int sizes[] = { 64, 255, 600 };
	(void)state;
	for (int r = 0; r < 2; r++)
		for (int t = 0; t < 2; t++)
			for (int k = 0; k < 3; k++) {
				struct ps_sensor s;
				struct ps_view v;
				struct ps_weights w;
				struct ps_err e;
				load(&s, r ? PS_READ_CELL : PS_READ_LINEAR);
				ps_view_default_fisheye(&v);
				v.type = t ? PS_VT_HEMI : PS_VT_ANGULAR;
				if (ps_weights_build(&w, &s, 10.0, &v, sizes[k], sizes[k], PS_W_EXACT, &e) != 0)
					fail_msg("%s", e.msg);
				if (fabs(w.sens_sum / ps_sensor_integral(&s) - 1) > 1e-12)
					fail_msg("reading %d type %d size %d: total %.17g, integral %.17g", r, t,
					         sizes[k], w.sens_sum, ps_sensor_integral(&s));
				ps_weights_free(&w);
				ps_sensor_free(&s);
			}
}

static int cell_of(const struct ps_fisheye *f, const struct ps_sensor *s, double rot, double u,
                   double v, int *i, int *j)
{
	double rho = hypot(u, v), phi = atan2(v, u) - M_PI / 2 - rot;
	if (rho >= 1.0)
		return -1;
	ps_sensor_locate(s, ps_fisheye_theta(f, rho), &phi, i, j);
	return 0;
}

static void cell_pixels_weigh_value_times_solid_angle(void **state)
{
	const int n = 200;
	const double rot = 10.0 * M_PI / 180;
	(void)state;
	for (int t = 0; t < 2; t++) {
		struct ps_sensor s;
		struct ps_view v;
		struct ps_weights w;
		struct ps_fisheye f;
		struct ps_err e;
		double wmax = 0;
		long checked = 0;
		load(&s, PS_READ_CELL);
		ps_view_default_fisheye(&v);
		v.type = t ? PS_VT_HEMI : PS_VT_ANGULAR;
		ps_fisheye_init(&f, &v, n, n);
		if (ps_weights_build(&w, &s, 10.0, &v, n, n, PS_W_EXACT, &e) != 0)
			fail_msg("%s", e.msg);
		for (size_t k = 0; k < w.nw; k++)
			wmax = fmax(wmax, fabs(w.w[k]));
		for (size_t r = 0; r < w.nruns; r++) {
			const struct ps_weights_run *run = &w.runs[r];
			int jb = n - 1 - run->row;   /* bottom-based */
			double v0 = ps_fisheye_v(&f, jb), v1 = ps_fisheye_v(&f, jb + 1);
			if (v0 <= 0 && v1 >= 0)
				continue;   /* a circle may cross an edge twice */
			for (int q = 0; q < run->n; q++) {
				int x = run->x0 + q, ci[4], cj[4], ok = 1;
				double u0 = ps_fisheye_u(&f, x), u1 = ps_fisheye_u(&f, x + 1), sa, want;
				if (u0 <= 0 && u1 >= 0)
					continue;
				ok &= cell_of(&f, &s, rot, u0, v0, &ci[0], &cj[0]) == 0;
				ok &= cell_of(&f, &s, rot, u1, v0, &ci[1], &cj[1]) == 0;
				ok &= cell_of(&f, &s, rot, u1, v1, &ci[2], &cj[2]) == 0;
				ok &= cell_of(&f, &s, rot, u0, v1, &ci[3], &cj[3]) == 0;
				for (int c = 1; c < 4 && ok; c++)
					ok = ci[c] == ci[0] && cj[c] == cj[0];
				if (!ok || ci[0] >= s.nt)
					continue;
				sa = ps_weights_rect_solid_angle(v.type, u0, v0, u1, v1);
				{
					double uc = 0.5 * (u0 + u1), vc = 0.5 * (v0 + v1);
					want = sa * ps_sensor_value(&s, ps_fisheye_theta(&f, hypot(uc, vc)),
					                            atan2(vc, uc) - M_PI / 2 - rot);
				}
				if (fabs(w.w[run->off + (size_t)q] - want) > 1e-10 * wmax)
					fail_msg("type %d pixel (%d, row %d): %.17g, cell value x solid angle "
					         "%.17g", t, x, run->row, w.w[run->off + (size_t)q], want);
				checked++;
			}
		}
		assert_true(checked > n * n / 4);
		ps_weights_free(&w);
		ps_sensor_free(&s);
	}
}

/* The weight of pixel (x, row) of a map, 0 where no run holds it. */
static double weight_at(const struct ps_weights *w, int x, int row)
{
	for (size_t r = 0; r < w->nruns; r++)
		if (w->runs[r].row == row)
			return x >= w->runs[r].x0 && x < w->runs[r].x0 + w->runs[r].n
			           ? w->w[w->runs[r].off + (size_t)(x - w->runs[r].x0)]
			           : 0.0;
	return 0.0;
}

/* Additivity, an exact identity: a pixel of an n x n map weighs what its
 * four quarters in the 2n x 2n map weigh together.  Before the orders came
 * from an error bound, pieces near a singularity of the edge integrand got
 * 3 points and single weights erred by up to 4.5e-6 (2.5e-6 of the largest
 * weight) with the hemispherical projection's cell reading. */
static void quarters_add_up(void **state)
{
	const int n = 150;
	(void)state;
	for (int t = 0; t < 2; t++)
		for (int r = 0; r < 2; r++) {
			struct ps_sensor s;
			struct ps_view v;
			struct ps_weights w1, w2;
			struct ps_err e;
			double wmax = 0, worst = 0;
			load(&s, r ? PS_READ_CELL : PS_READ_LINEAR);
			ps_view_default_fisheye(&v);
			v.type = t ? PS_VT_HEMI : PS_VT_ANGULAR;
			if (ps_weights_build(&w1, &s, 10.0, &v, n, n, PS_W_EXACT, &e) != 0 ||
			    ps_weights_build(&w2, &s, 10.0, &v, 2 * n, 2 * n, PS_W_EXACT, &e) != 0)
				fail_msg("%s", e.msg);
			for (size_t k = 0; k < w1.nw; k++)
				wmax = fmax(wmax, fabs(w1.w[k]));
			for (int row = 0; row < n; row++)
				for (int x = 0; x < n; x++) {
					double q = weight_at(&w2, 2 * x, 2 * row) + weight_at(&w2, 2 * x + 1, 2 * row) +
					           weight_at(&w2, 2 * x, 2 * row + 1) +
					           weight_at(&w2, 2 * x + 1, 2 * row + 1);
					worst = fmax(worst, fabs(weight_at(&w1, x, row) - q) / wmax);
				}
			if (worst > 1e-10)
				fail_msg("type %d reading %d: a pixel and its quarters differ by %.3g of the "
				         "largest weight", t, r, worst);
			ps_weights_free(&w1);
			ps_weights_free(&w2);
			ps_sensor_free(&s);
		}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(totals_are_the_integral),
		cmocka_unit_test(cell_pixels_weigh_value_times_solid_angle),
		cmocka_unit_test(quarters_add_up),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
