/* SPDX-License-Identifier: ISC */
/* Exact pixel weights against analytic integrals: the paper's cosine check
 * at every size, cut-off and azimuthal sensitivities whose edges cross
 * pixels, 180- and 360-degree angular and hemispherical fisheyes, rotations,
 * cones down to 1e-8 degrees, and sums that must lose nothing. */
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
#include "integrate.h"
#include "picture.h"
#include "sensor.h"
#include "view.h"
#include "weights.h"

#define DEG (M_PI / 180.0)

static double relerr(double got, double want)
{
	return fabs(got - want) / fabs(want);
}

static void view_of(struct ps_view *v, int type, double vh, double vv)
{
	ps_view_default_fisheye(v);
	v->type = type;
	v->vh = vh;
	v->vv = vv;
}

/* A table from a function of (theta, phi) in degrees. */
static void table_sensor(struct ps_sensor *s, int reading, const double *th, int nth,
                         const double *ph, int nph, double (*f)(double, double))
{
	char *text = malloc(1 << 20);
	size_t n = 0;
	struct ps_err e;
	n += (size_t)sprintf(text + n, "Elevation field %.17g\ndegrees", th[nth - 1]);
	for (int j = 0; j < nph; j++)
		n += (size_t)sprintf(text + n, "\t%.17g", ph[j]);
	n += (size_t)sprintf(text + n, "\n");
	for (int i = 0; i < nth; i++) {
		n += (size_t)sprintf(text + n, "%.17g", th[i]);
		for (int j = 0; j < nph; j++)
			n += (size_t)sprintf(text + n, " %.17g", f(th[i], ph[j]));
		n += (size_t)sprintf(text + n, "\n");
	}
	if (ps_sensor_parse(s, text, n, "table", &e) != 0)
		fail_msg("%s", e.msg);
	if (ps_sensor_set_reading(s, reading, &e) != 0)
		fail_msg("%s", e.msg);
	free(text);
}

static double one(double t, double p)
{
	(void)t;
	(void)p;
	return 1.0;
}

static double sum_weights(const struct ps_sensor *s, double rot, const struct ps_view *v, int w,
                          int h, int method)
{
	struct ps_weights wt;
	struct ps_err e;
	double sum;
	if (ps_weights_build(&wt, s, rot, v, w, h, method, &e) != 0)
		fail_msg("%s", e.msg);
	sum = wt.sens_sum;
	ps_weights_free(&wt);
	return sum;
}

/* The paper's check: an ideal cosine sensor normalised to 1 gives 1 on a
 * uniform picture: here to 1e-9 at every size, square or not. */
static void cosine_at_every_size(void **state)
{
	struct ps_sensor s;
	struct ps_view v;
	struct ps_err e;
	static const int big[][2] = { { 300, 300 }, { 333, 301 }, { 512, 512 }, { 640, 480 },
	                              { 1000, 1000 }, { 1023, 1025 }, { 2048, 2048 }, { 4096, 4096 } };
	(void)state;
	assert_int_equal(ps_sensor_builtin(&s, PS_SENS_COSINE, &e), 0);
	view_of(&v, PS_VT_ANGULAR, 180, 180);
	for (int n = 16; n <= 256; n++) {
		assert_true(relerr(sum_weights(&s, 0, &v, n, n, PS_W_EXACT) / M_PI, 1.0) <= 1e-9);
		assert_true(relerr(sum_weights(&s, 0, &v, n, n + 7, PS_W_EXACT) / M_PI, 1.0) <= 1e-9);
	}
	for (size_t k = 0; k < sizeof big / sizeof *big; k++) {
		double r = sum_weights(&s, 0, &v, big[k][0], big[k][1], PS_W_EXACT) / M_PI;
		if (relerr(r, 1.0) > 1e-9)
			fail_msg("%d x %d: %.17g", big[k][0], big[k][1], r);
	}
	/* 1 x 1 and 2 x 2 pictures too: the exact weights do not care */
	assert_true(relerr(sum_weights(&s, 0, &v, 1, 1, PS_W_EXACT) / M_PI, 1.0) <= 1e-12);
	assert_true(relerr(sum_weights(&s, 0, &v, 2, 2, PS_W_EXACT) / M_PI, 1.0) <= 1e-12);
	/* the paper's centre-point weights are good to about 1e-6 at 200 x 200 only */
	{
		double c = sum_weights(&s, 0, &v, 200, 200, PS_W_CENTRE) / M_PI;
		assert_true(relerr(c, 1.0) > 1e-8 && relerr(c, 1.0) < 1e-5);
	}
	ps_sensor_free(&s);
}

/* Cosine on the other projections and fields. */
static void cosine_on_hemispherical_and_360(void **state)
{
	struct ps_sensor s, u;
	struct ps_view v;
	struct ps_err e;
	(void)state;
	assert_int_equal(ps_sensor_builtin(&s, PS_SENS_COSINE, &e), 0);
	assert_int_equal(ps_sensor_builtin(&u, PS_SENS_UNIFORM, &e), 0);
	for (int n = 16; n <= 200; n += 23) {
		view_of(&v, PS_VT_HEMI, 180, 180);
		assert_true(relerr(sum_weights(&s, 0, &v, n, n, PS_W_EXACT), M_PI) <= 1e-9);
		assert_true(relerr(sum_weights(&u, 0, &v, n, n, PS_W_EXACT), 2 * M_PI) <= 1e-9);
		view_of(&v, PS_VT_ANGULAR, 360, 360);
		assert_true(relerr(sum_weights(&s, 0, &v, n, n, PS_W_EXACT), M_PI) <= 1e-9);
		assert_true(relerr(sum_weights(&u, 0, &v, n, n, PS_W_EXACT), 4 * M_PI) <= 1e-9);
	}
	/* the whole 180-degree angular square: exact solid angle, which the
	 * centre-point sums of the fixtures approach as 1/N^2 */
	{
		struct ps_weights w;
		view_of(&v, PS_VT_ANGULAR, 180, 180);
		assert_int_equal(ps_weights_build(&w, &u, 0, &v, 256, 256, PS_W_CENTRE, &e), 0);
		assert_true(fabs(w.solid_angle - 7.456041) < 1e-6);   /* fixtures README, 256 */
		ps_weights_free(&w);
		assert_int_equal(ps_weights_build(&w, &u, 0, &v, 256, 256, PS_W_EXACT, &e), 0);
		assert_true(fabs(w.solid_angle - (4 * 7.456019 - 7.456041) / 3) < 1e-6);
		ps_weights_free(&w);
	}
	ps_sensor_free(&s);
	ps_sensor_free(&u);
}

/* A flat sensitivity cut off at 37.3 degrees: its edge crosses pixels. */
static void flat_cut_off_sensitivity(void **state)
{
	static const double ph[] = { 0, 90, 180, 270 };
	double th_lin[] = { 0, 37.3 };
	double th_cell[] = { 0, 37.3 / 1.5 };   /* cell ends at 1.5 last - 0.5 previous */
	double want = 2 * M_PI * (1 - cos(37.3 * DEG));
	struct ps_sensor s;
	struct ps_view v;
	(void)state;
	view_of(&v, PS_VT_ANGULAR, 180, 180);
	table_sensor(&s, PS_READ_LINEAR, th_lin, 2, ph, 4, one);
	assert_true(relerr(ps_sensor_integral(&s), want) < 1e-14);
	for (int n = 16; n <= 300; n += 7)
		assert_true(relerr(sum_weights(&s, 0, &v, n, n, PS_W_EXACT), want) <= 1e-9);
	ps_sensor_free(&s);
	table_sensor(&s, PS_READ_CELL, th_cell, 2, ph, 4, one);
	assert_true(relerr(ps_sensor_integral(&s), want) < 1e-14);
	for (int n = 16; n <= 300; n += 7)
		assert_true(relerr(sum_weights(&s, 0, &v, n, n + 1, PS_W_EXACT), want) <= 1e-9);
	view_of(&v, PS_VT_HEMI, 180, 180);
	assert_true(relerr(sum_weights(&s, 0, &v, 99, 99, PS_W_EXACT), want) <= 1e-9);
	ps_sensor_free(&s);
}

/* cos^n theta integrates to 2 pi / (n + 1); on a 2-degree table the readings
 * have their own (known) sampling error, which the weights must reproduce. */
static double cos3(double t, double p)
{
	(void)p;
	return t <= 90 ? pow(cos(t * DEG), 3) : 0.0;
}

static void table_integral_is_reproduced(void **state)
{
	double th[46], ph[180];
	struct ps_sensor s;
	struct ps_view v;
	(void)state;
	for (int i = 0; i < 46; i++)
		th[i] = 2.0 * i;
	for (int j = 0; j < 180; j++)
		ph[j] = 2.0 * j;
	view_of(&v, PS_VT_ANGULAR, 180, 180);
	for (int reading = 0; reading < 2; reading++) {
		table_sensor(&s, reading, th, 46, ph, 180, cos3);
		/* the reading's integral is within its sampling error of 2 pi / 4 */
		assert_true(relerr(ps_sensor_integral(&s), M_PI / 2) < 5e-4);
		for (int n = 17; n <= 257; n += 40)
			assert_true(relerr(sum_weights(&s, 0, &v, n, n, PS_W_EXACT), ps_sensor_integral(&s)) <= 1e-9);
		ps_sensor_free(&s);
	}
}

/* A sensor that sees only the azimuths within 45 degrees of its zero: which
 * half of the picture it sees follows the rotation exactly. */
static void rotations_move_the_sensitivity(void **state)
{
	static const double rots[] = { 0, 90, 359.5, -90, 720 };
	struct ps_sensor s;
	struct ps_view v;
	struct ps_err e;
	double full;
	(void)state;
	view_of(&v, PS_VT_ANGULAR, 180, 180);
	{
		/* value 1 at azimuth 0 only; cells are +-45 degrees */
		char text[] = "Elevation field 60\ndegrees 0 90 180 270\n0 1 0 0 0\n60 1 0 0 0\n";
		assert_int_equal(ps_sensor_parse(&s, text, strlen(text), "wedge", &e), 0);
		assert_int_equal(ps_sensor_set_reading(&s, PS_READ_CELL, &e), 0);
	}
	full = ps_sensor_integral(&s);
	assert_true(relerr(full, 0.25 * 2 * M_PI * (1 - cos(90 * DEG))) < 1e-14);
	for (size_t k = 0; k < sizeof rots / sizeof *rots; k++) {
		struct ps_weights w;
		double left = 0, right = 0, top = 0, bottom = 0;
		int n = 64;   /* even: no pixel straddles the axes */
		assert_int_equal(ps_weights_build(&w, &s, rots[k], &v, n, n, PS_W_EXACT, &e), 0);
		for (size_t r = 0; r < w.nruns; r++)
			for (int i = 0; i < w.runs[r].n; i++) {
				int x = w.runs[r].x0 + i, row = w.runs[r].row;
				double wt = w.w[w.runs[r].off + i];
				if (x < n / 2)
					left += wt;
				else
					right += wt;
				if (row < n / 2)
					top += wt;
				else
					bottom += wt;
			}
		assert_true(relerr(left + right, full) < 1e-12);
		if (rots[k] == 0 || rots[k] == 720) {
			/* azimuth 0 is up: the wedge is in the top half, split evenly */
			assert_true(bottom < 1e-12 * full);
			assert_true(relerr(left, full / 2) < 1e-10);
		} else if (rots[k] == 90) {
			/* azimuth grows to the left */
			assert_true(right < 1e-12 * full);
			assert_true(relerr(top, full / 2) < 1e-10);
		} else if (rots[k] == -90) {
			assert_true(left < 1e-12 * full);
		} else {
			/* 359.5: wedge from -45.5 to 44.5 degrees: 44.5/90 of it on the left */
			assert_true(bottom < 1e-12 * full);
			assert_true(relerr(left, full * 44.5 / 90) < 1e-10);
		}
		ps_weights_free(&w);
	}
	ps_sensor_free(&s);
}

/* A 180-degree picture holds only the hemisphere of a sensor that sees
 * behind itself: coverage says how much. */
static void coverage_of_a_wide_sensor(void **state)
{
	static const double ph[] = { 0, 90, 180, 270 };
	static const double th[] = { 0, 135 };
	struct ps_sensor s;
	struct ps_view v;
	struct ps_weights w;
	struct ps_err e;
	(void)state;
	table_sensor(&s, PS_READ_LINEAR, th, 2, ph, 4, one);
	view_of(&v, PS_VT_ANGULAR, 360, 360);
	assert_int_equal(ps_weights_build(&w, &s, 0, &v, 101, 101, PS_W_EXACT, &e), 0);
	assert_true(relerr(w.sens_sum, 2 * M_PI * (1 - cos(135 * DEG))) < 1e-9);
	assert_true(relerr(w.coverage, 1.0) < 1e-9);
	ps_weights_free(&w);
	view_of(&v, PS_VT_HEMI, 180, 180);
	assert_int_equal(ps_weights_build(&w, &s, 0, &v, 101, 101, PS_W_EXACT, &e), 0);
	assert_true(relerr(w.coverage, (1 - cos(90 * DEG)) / (1 - cos(135 * DEG))) < 1e-9);
	ps_weights_free(&w);
	assert_true(fabs(ps_fisheye_vh_for(PS_VT_ANGULAR, 135 * DEG) - 270) < 1e-9);
	ps_sensor_free(&s);
}

/* A sharp peak: all the sensitivity in a 1-degree cap. */
static double peak(double t, double p)
{
	(void)p;
	return t <= 0.5 ? 1e6 : 0.0;
}

static void one_sharp_peak(void **state)
{
	static const double th[] = { 0, 0.5, 1, 2, 90 };
	static const double ph[] = { 0, 90, 180, 270 };
	struct ps_sensor s;
	struct ps_view v;
	(void)state;
	table_sensor(&s, PS_READ_LINEAR, th, 5, ph, 4, peak);
	view_of(&v, PS_VT_ANGULAR, 180, 180);
	for (int n = 3; n <= 400; n += 37)
		assert_true(relerr(sum_weights(&s, 0, &v, n, n, PS_W_EXACT), ps_sensor_integral(&s)) <= 1e-9);
	ps_sensor_free(&s);
}

/* Very narrow cones, 1e-1 down to 1e-8 degrees (sensitivity 1 to the cone's
 * edge, then falling linearly to 0 over as much again for the linear
 * reading; a plain cone for the cell reading), on even and odd pictures
 * (the axis on a pixel corner or inside a pixel) and turned: the sum of the
 * weights, the response to a uniform picture of radiance 1, against the
 * analytic integral computed without cancellation,
 *   cell (the table ends at 1.5 a): 2 pi (1 - cos 1.5a) = 4 pi sin^2(0.75 a)
 *   linear: 2 pi [ int_0^a sin t dt + int_a^2a (2 - t/a) sin t dt ],
 *           summed term by term from the series of sin t.
 * The closed form of M lost these to cancellation: -1.4e-3 at 1e-5 degrees,
 * -27 % at 1e-6, and 0 from 1e-7 degrees down. */
static double cone_cell_integral(double a)
{
	double sh = sin(a / 2);
	return 4 * M_PI * sh * sh;
}

/* 2 pi int_0^2a S(t) sin t dt, S = 1 to a, then 2 - t/a, by the series of
 * sin (each term t^(2n+1) integrated exactly, 12 terms: exact to 1e-30 at
 * a = 2e-3 rad) */
static double cone_linear_integral(double a)
{
	double sum = 0.0;
	double fact = 1.0;   /* (2n+1)! */
	for (int n = 0; n < 12; n++) {
		double p = 2 * n + 1, sign = n % 2 ? -1.0 : 1.0;
		double a_p2 = pow(a, p + 1), two_p1 = pow(2.0, p + 1), two_p2 = pow(2.0, p + 2);
		/* int_0^a t^p + int_a^2a (2 - t/a) t^p */
		double part = a_p2 / (p + 1) + 2 * a_p2 * (two_p1 - 1) / (p + 1) -
		              a_p2 * (two_p2 - 1) / (p + 2);
		if (n > 0)
			fact *= (2 * n) * (2 * n + 1);
		sum += sign * part / fact;
	}
	return 2 * M_PI * sum;
}

static double cone_profile_a;
static double cone_profile(double t, double p)
{
	(void)p;
	return t <= cone_profile_a * (1 + 1e-12) ? 1.0 : 0.0;
}

static void narrow_cones_stay_exact(void **state)
{
	static const double ph[] = { 0, 90, 180, 270 };
	struct ps_view v;
	double worst = 0;
	(void)state;
	view_of(&v, PS_VT_ANGULAR, 180, 180);
	for (int k = 1; k <= 8; k++) {
		double a = pow(10.0, -k), ar = a * M_PI / 180;
		double thl[] = { 0, a, 2 * a }, thc[] = { 0, a };
		struct ps_sensor lin, cell;
		cone_profile_a = a;
		table_sensor(&lin, PS_READ_LINEAR, thl, 3, ph, 4, cone_profile);
		/* cell reading: each value holds to the midpoints, the table
		 * ends at 1.5 a */
		table_sensor(&cell, PS_READ_CELL, thc, 2, ph, 4, one);
		for (int n = 32; n <= 33; n++)
			for (int r = 0; r < 2; r++) {
				double rot = r ? 33.0 : 0.0;
				double gl = sum_weights(&lin, rot, &v, n, n, PS_W_EXACT);
				double gc = sum_weights(&cell, rot, &v, n, n, PS_W_EXACT);
				double wl = cone_linear_integral(ar), wc = cone_cell_integral(1.5 * ar);
				if (relerr(gl, wl) > 1e-12 || relerr(gc, wc) > 1e-12)
					fail_msg("cone %g deg, %d px, rot %g: linear %.17g want %.17g, cell %.17g want %.17g",
					         a, n, rot, gl, wl, gc, wc);
				worst = fmax(worst, fmax(relerr(gl, wl), relerr(gc, wc)));
			}
		assert_true(relerr(ps_sensor_integral(&lin), cone_linear_integral(ar)) <= 1e-12);
		ps_sensor_free(&lin);
		ps_sensor_free(&cell);
	}
	print_message("narrow cones 1e-1 to 1e-8 degrees: largest relative error %.1e\n", worst);
}

/* A 1e9 sun in one pixel next to 1e-2 walls: the walls' part of the response
 * survives the sum to 1e-12. */
static void sun_and_walls_lose_nothing(void **state)
{
	int n = 200;
	struct ps_sensor s;
	struct ps_view v;
	struct ps_weights w;
	struct ps_picture pic;
	struct ps_response r;
	struct ps_err e;
	double coef[3] = { 1, 0, 0 }, wall, sun, wsun = 0;
	uint8_t wallpx[4], sunpx[4];
	(void)state;
	assert_int_equal(ps_sensor_builtin(&s, PS_SENS_COSINE, &e), 0);
	view_of(&v, PS_VT_ANGULAR, 180, 180);
	assert_int_equal(ps_weights_build(&w, &s, 0, &v, n, n, PS_W_EXACT, &e), 0);
	memset(&pic, 0, sizeof pic);
	pic.width = pic.height = n;
	pic.exposure[0] = pic.exposure[1] = pic.exposure[2] = 1;
	pic.pix = malloc((size_t)n * n * 4);
	ps_picture_rgbe_encode((double[3]){ 1e-2, 1e-2, 1e-2 }, wallpx);
	ps_picture_rgbe_encode((double[3]){ 1e9, 1e9, 1e9 }, sunpx);
	wall = (wallpx[0] + 0.5) * ldexp(1, wallpx[3] - 136);
	sun = (sunpx[0] + 0.5) * ldexp(1, sunpx[3] - 136);
	for (int i = 0; i < n * n; i++)
		memcpy(pic.pix + 4 * i, wallpx, 4);
	memcpy(pic.pix + 4 * (70 * n + 120), sunpx, 4);
	for (size_t k = 0; k < w.nruns; k++)
		if (w.runs[k].row == 70 && w.runs[k].x0 <= 120 && 120 < w.runs[k].x0 + w.runs[k].n)
			wsun = w.w[w.runs[k].off + (120 - w.runs[k].x0)];
	assert_true(wsun > 0);
	assert_int_equal(ps_integrate(&w, &pic, coef, &r, &e), 0);
	/* walls: wall x (pi - wsun); the sum of the other weights is pi - wsun */
	assert_true(relerr(r.response - sun * wsun, wall * (M_PI - wsun)) < 1e-9);
	assert_true(relerr(r.brightest_share, sun * wsun / r.response) < 1e-12);
	assert_int_equal(r.brightest_x, 120);
	assert_int_equal(r.brightest_row, 70);
	ps_picture_free(&pic);
	ps_weights_free(&w);
	ps_sensor_free(&s);
}

/* Radiance RGB to XYZ: the Y row of the standard primaries is psens's
 * default coefficients. */
static void default_coefficients_are_the_primaries_luminance(void **state)
{
	double m[3][3];
	(void)state;
	ps_integrate_rgb_to_xyz(ps_integrate_std_primaries, m);
	assert_true(fabs(m[1][0] - PS_RGB_DEFAULT_R) < 5e-9);
	assert_true(fabs(m[1][1] - PS_RGB_DEFAULT_G) < 5e-9);
	assert_true(fabs(m[1][2] - PS_RGB_DEFAULT_B) < 5e-9);
}

/* An overflowing response names each channel as a number, "infinite" or
 * "not a number": never the C library's "nan" or "inf" as a figure. */
static int has_nonfinite_word(const char *msg)
{
	for (const char *p = msg; *p; p++) {
		int start = p == msg || !((p[-1] >= 'a' && p[-1] <= 'z') || (p[-1] >= 'A' && p[-1] <= 'Z'));
		if (start && (strncmp(p, "nan", 3) == 0 || strncmp(p, "inf", 3) == 0) &&
		    !(p[3] >= 'a' && p[3] <= 'z'))
			return 1;
	}
	return 0;
}

static void overflow_messages_print_no_nan(void **state)
{
	struct ps_response r = { .response = NAN, .rgb = { INFINITY, NAN, 2.5 } };
	const double coef[3] = { 0.2651, 0.6701, 0.0648 };
	struct ps_err e = { .code = 0 };
	(void)state;
	assert_int_not_equal(ps_integrate_check_finite(&r, coef, 1.0, &e), 0);
	assert_false(has_nonfinite_word(e.msg));
	assert_non_null(strstr(e.msg, "R infinite G not a number B 2.5"));
	r.rgb[0] = 1.5;
	r.rgb[1] = 2;
	r.response = -INFINITY;
	assert_int_not_equal(ps_integrate_check_finite(&r, coef, 1.0, &e), 0);
	assert_false(has_nonfinite_word(e.msg));
	assert_non_null(strstr(e.msg, "R 1.5 G 2 B 2.5"));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(cosine_at_every_size),
		cmocka_unit_test(cosine_on_hemispherical_and_360),
		cmocka_unit_test(flat_cut_off_sensitivity),
		cmocka_unit_test(table_integral_is_reproduced),
		cmocka_unit_test(rotations_move_the_sensitivity),
		cmocka_unit_test(coverage_of_a_wide_sensor),
		cmocka_unit_test(one_sharp_peak),
		cmocka_unit_test(narrow_cones_stay_exact),
		cmocka_unit_test(sun_and_walls_lose_nothing),
		cmocka_unit_test(default_coefficients_are_the_primaries_luminance),
		cmocka_unit_test(overflow_messages_print_no_nan),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
