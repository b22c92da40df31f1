/* SPDX-License-Identifier: ISC */
/* Re-evaluation without re-weighting (sim/weights/rescan.h) against the direct
 * exact route (weights built at each rotation): a 256 x 256 picture with a
 * bright window and a sensor whose sensitivity changes with azimuth, cells
 * of 0.25 x 0.25 degree (what psens -r a:b:s uses for steps of 1 degree).  The
 * error bound asserted here is the one README and psens(1) state; the projection loses nothing (its total is the uniform sensor's
 * exact response), and a uniform picture gives pi for the cosine at every
 * rotation. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "integrate.h"
#include "picture.h"
#include "rescan.h"
#include "scancheck.h"
#include "sensor.h"
#include "view.h"
#include "weights.h"

enum { N = 256 };
#define BOUND 2e-4   /* the stated error of the scan against the exact route */
#define PSENS_DPHI 0.25   /* psens -r a:b:s's cells in azimuth for steps of 1 degree */

static const double coef[3] = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B };

static const char table[] = "Elevation field 90\n"
                            "degrees 0 45 90 135 180 225 270 315\n"
                            "0 1 1 1 1 1 1 1 1\n"
                            "20 0.95 0.9 0.7 0.6 0.8 0.9 0.85 0.9\n"
                            "40 0.8 0.6 0.4 0.3 0.5 0.7 0.7 0.75\n"
                            "60 0.5 0.3 0.2 0.1 0.2 0.4 0.45 0.5\n"
                            "80 0.1 0.05 0.02 0.01 0.03 0.08 0.1 0.1\n"
                            "90 0 0 0 0 0 0 0 0\n";

static void picture(struct ps_picture *pic, int window)
{
	double *rgb = malloc(sizeof(double) * 3 * N * N);
	char *buf = NULL;
	size_t n = 0;
	FILE *fp = open_memstream(&buf, &n);
	struct ps_err e;
	for (int y = 0; y < N; y++)
		for (int x = 0; x < N; x++) {
			double *p = rgb + 3 * ((size_t)y * N + x);
			double v = window ? 0.5 + 0.3 * sin(x * 0.05) * cos(y * 0.03) : 1.0;
			if (window && x > 150 && x < 200 && y > 40 && y < 120)
				v = 40.0;   /* a window */
			p[0] = v;
			p[1] = window ? v * 0.9 : v;
			p[2] = window ? v * 0.8 : v;
		}
	assert_int_equal(ps_picture_write_fp(fp, "mem", N, N, rgb, "-vta -vh 180 -vv 180", NULL, &e), 0);
	fclose(fp);
	if (ps_picture_read_mem(pic, (uint8_t *)buf, n, "mem", &e) != 0)
		fail_msg("%s", e.msg);
	free(buf);
	free(rgb);
}

static double exact(const struct ps_sensor *s, double rot, const struct ps_picture *pic)
{
	struct ps_view v;
	struct ps_weights w;
	struct ps_response r;
	struct ps_err e;
	memset(&r, 0, sizeof r);
	ps_view_default_fisheye(&v);
	if (ps_weights_build(&w, s, rot, &v, N, N, PS_W_EXACT, &e) != 0 ||
	    ps_integrate(&w, pic, coef, &r, &e) != 0)
		fail_msg("%s", e.msg);
	ps_weights_free(&w);
	return r.response;
}

static void project(struct ps_rescan *p, const struct ps_picture *pic, double dphi, double *total)
{
	struct ps_sensor u;
	struct ps_view v;
	struct ps_weights om;
	struct ps_err e;
	struct ps_response r;
	assert_int_equal(ps_sensor_builtin(&u, PS_SENS_UNIFORM, &e), 0);
	ps_view_default_fisheye(&v);
	assert_int_equal(ps_weights_build(&om, &u, 0, &v, N, N, PS_W_EXACT, &e), 0);
	if (ps_rescan_project(p, &om, pic, &v, coef, 0.25, dphi, 0, 180, &e) != 0)
		fail_msg("%s", e.msg);
	assert_int_equal(ps_integrate(&om, pic, coef, &r, &e), 0);
	*total = r.response;
	ps_weights_free(&om);
	ps_sensor_free(&u);
}

static void scan_against_exact(void **state)
{
	static const double rots[] = { 0, 10, 90, 137, 275 };
	struct ps_picture pic;
	struct ps_sensor s;
	struct ps_rescan p;
	struct ps_err e;
	double out[360], total, worst = 0;
	(void)state;
	picture(&pic, 1);
	if (ps_sensor_parse(&s, table, sizeof table - 1, "table", &e) != 0 ||
	    ps_sensor_set_reading(&s, PS_READ_LINEAR, &e) != 0)
		fail_msg("%s", e.msg);
	project(&p, &pic, PSENS_DPHI, &total);
	/* nothing lost: every pixel's energy is in some cell */
	assert_true(fabs(p.total / total - 1) < 1e-12);
	assert_int_equal(ps_rescan_scan(&p, &s, 0, 1, 360, out, &e), 0);
	for (size_t k = 0; k < sizeof rots / sizeof rots[0]; k++) {
		double want = exact(&s, rots[k], &pic), err = fabs(out[(int)rots[k]] / want - 1);
		if (err > worst)
			worst = err;
	}
	printf("# rescan 0.25 x 0.25 degree cells, 256 x 256, window: worst error %.2e\n", worst);
	assert_true(worst <= BOUND);
	/* shared among threads, the same numbers bit for bit */
	for (int nt = 2; nt <= 3; nt++) {
		double again[360];
		assert_int_equal(ps_rescan_scan_mt(&p, &s, 0, 1, 360, nt, again, &e), 0);
		assert_memory_equal(again, out, sizeof out);
	}
	/* the error estimate finds no fault here: within the tolerance and the
	 * stated bound, checked at rotations of their own */
	{
		struct ps_scancheck c = { .tolerance = PS_SCANCHECK_TOLERANCE };
		struct ps_view v;
		double again[360];
		ps_view_default_fisheye(&v);
		if (ps_scancheck_scan(&p, NULL, &pic, &v, coef, &s, 0, 1, 360, 2, NULL, again, &c, &e) != 0)
			fail_msg("%s", e.msg);
		printf("# the window's estimate %.2e at %g (%d checked)\n", c.estimate, c.at_deg,
		       c.nchecked);
		assert_memory_equal(again, out, sizeof out);
		assert_true(c.nchecked >= 3);
		assert_true(c.estimate > 0 && c.estimate <= BOUND);
	}
	/* a rotation that is not a whole number of cells is refused */
	assert_int_equal(ps_rescan_scan(&p, &s, 0.1, 1, 3, out, &e), -1);
	ps_rescan_free(&p);
	ps_sensor_free(&s);
	ps_picture_free(&pic);
}

static void uniform_cosine_is_pi(void **state)
{
	struct ps_picture pic;
	struct ps_sensor s;
	struct ps_rescan p;
	struct ps_err e;
	double out[8], total;
	(void)state;
	picture(&pic, 0);
	assert_int_equal(ps_sensor_builtin(&s, PS_SENS_COSINE, &e), 0);
	project(&p, &pic, PSENS_DPHI, &total);
	assert_int_equal(ps_rescan_scan(&p, &s, 0, 45, 8, out, &e), 0);
	for (int k = 0; k < 8; k++)
		assert_true(fabs(out[k] / (M_PI * 1.00390625) - 1) < BOUND);
	ps_rescan_free(&p);
	ps_sensor_free(&s);
	ps_picture_free(&pic);
}

/* The scan's definition, cell by cell: sum over every cell of its energy
 * times the sensitivity at its centre turned by the rotation (what the scan
 * computes with the rings collapsed onto the table's rows). */
static double by_definition(const struct ps_rescan *p, const struct ps_sensor *s, int rot)
{
	double sum = 0.0, comp = 0.0;
	for (int it = 0; it < p->ntheta; it++)
		for (int m = 0; m < p->nphi; m++) {
			/* the cell m - rot (whole cells of 1 degree) taken into [0, nphi)
			 * as the scan does, so a centre on a boundary of rsensor's
			 * cells reads the same side */
			int mr = ((m - rot) % p->nphi + p->nphi) % p->nphi;
			double ph = (mr + 0.5) * p->dphi, t, x;
			x = p->e[(size_t)it * (size_t)p->nphi + (size_t)m] *
			    ps_sensor_value(s, (it + 0.5) * p->dtheta, ph);
			t = sum + x;   /* Neumaier */
			comp += fabs(sum) >= fabs(x) ? (sum - t) + x : (x - t) + sum;
			sum = t;
		}
	return sum + comp;
}

static void scan_equals_its_definition(void **state)
{
	static const int readings[] = { PS_READ_LINEAR, PS_READ_CELL };
	static const int rots[] = { 0, 1, 44, 90, 181, 359 };
	struct ps_picture pic;
	struct ps_rescan p;
	struct ps_err e;
	double out[360], total;
	(void)state;
	picture(&pic, 1);
	project(&p, &pic, 1.0, &total);
	for (size_t k = 0; k < 3; k++) {
		struct ps_sensor s;
		if (k < 2) {
			if (ps_sensor_parse(&s, table, sizeof table - 1, "table", &e) != 0 ||
			    ps_sensor_set_reading(&s, readings[k], &e) != 0)
				fail_msg("%s", e.msg);
		} else {
			assert_int_equal(ps_sensor_builtin(&s, PS_SENS_COSINE, &e), 0);
		}
		assert_int_equal(ps_rescan_scan(&p, &s, 0, 1, 360, out, &e), 0);
		for (size_t r = 0; r < sizeof rots / sizeof rots[0]; r++) {
			double want = by_definition(&p, &s, rots[r]);
			if (fabs(out[rots[r]] / want - 1) > 1e-12)
				fail_msg("sensor %zu, rotation %d: scan %.17g, definition %.17g", k, rots[r],
				         out[rots[r]], want);
		}
		ps_sensor_free(&s);
	}
	ps_rescan_free(&p);
	ps_picture_free(&pic);
}

/* A sensor's table made on one picture's projection serves another
 * projected on the same cells: the other picture's scan equals its own
 * definition (cell by cell) and the scan made with the sensor itself, bit
 * for bit, for a table and a builtin; a projection on other cells is
 * refused. */
static void table_shared_between_pictures(void **state)
{
	static const int rots[] = { 0, 7, 90, 200, 359 };
	struct ps_picture pic0, pic1;
	struct ps_rescan p0, p1, p2;
	struct ps_err e;
	double out[360], fresh[360], total;
	(void)state;
	picture(&pic0, 0);
	picture(&pic1, 1);
	project(&p0, &pic0, 1.0, &total);
	project(&p1, &pic1, 1.0, &total);
	project(&p2, &pic1, 2.0, &total);
	for (int k = 0; k < 2; k++) {
		struct ps_sensor s;
		struct ps_rescan_sens t;
		if (k == 0) {
			if (ps_sensor_parse(&s, table, sizeof table - 1, "table", &e) != 0)
				fail_msg("%s", e.msg);
		} else {
			assert_int_equal(ps_sensor_builtin(&s, PS_SENS_COSINE, &e), 0);
		}
		assert_int_equal(ps_rescan_sens_init(&t, &p0, &s, 0, &e), 0);
		assert_int_equal(ps_rescan_scan_sens(&p1, &t, 1, 360, 2, out, &e), 0);
		assert_int_equal(ps_rescan_scan(&p1, &s, 0, 1, 360, fresh, &e), 0);
		assert_memory_equal(out, fresh, sizeof out);
		for (size_t r = 0; r < sizeof rots / sizeof rots[0]; r++) {
			double want = by_definition(&p1, &s, rots[r]);
			if (fabs(out[rots[r]] / want - 1) > 1e-12)
				fail_msg("sensor %d, rotation %d: shared table %.17g, definition %.17g", k, rots[r],
				         out[rots[r]], want);
		}
		/* cells of 2 degrees: not the table's */
		assert_int_equal(ps_rescan_scan_sens(&p2, &t, 2, 180, 1, out, &e), -1);
		assert_int_equal(e.code, PS_EINVAL);
		ps_rescan_sens_free(&t);
		ps_sensor_free(&s);
	}
	ps_rescan_free(&p0);
	ps_rescan_free(&p1);
	ps_rescan_free(&p2);
	ps_picture_free(&pic0);
	ps_picture_free(&pic1);
}

/* Three projections of one picture made together (each pixel's direction
 * found once) are each the projection made alone, cell for cell, bit for
 * bit; and they sum to the picture's integral with those coefficients. */
static void projections_together(void **state)
{
	static const double co[3][3] = { { 1, 0, 0 }, { 0.2, 0.7, 0.1 }, { 0, 0, 1 } };
	struct ps_picture pic;
	struct ps_sensor u;
	struct ps_view v;
	struct ps_weights om;
	struct ps_rescan many[3], one;
	struct ps_err e;
	(void)state;
	picture(&pic, 1);
	assert_int_equal(ps_sensor_builtin(&u, PS_SENS_UNIFORM, &e), 0);
	ps_view_default_fisheye(&v);
	assert_int_equal(ps_weights_build(&om, &u, 0, &v, N, N, PS_W_EXACT, &e), 0);
	assert_int_equal(ps_rescan_project_many(many, 3, co, &om, &pic, &v, 2, 5, 0, 180, &e), 0);
	for (int c = 0; c < 3; c++) {
		struct ps_response r;
		assert_int_equal(ps_rescan_project(&one, &om, &pic, &v, co[c], 2, 5, 0, 180, &e), 0);
		assert_int_equal(one.ntheta, many[c].ntheta);
		assert_int_equal(one.nphi, many[c].nphi);
		assert_memory_equal(one.e, many[c].e, (size_t)one.ntheta * (size_t)one.nphi * sizeof *one.e);
		assert_memory_equal(&one.total, &many[c].total, sizeof one.total);
		assert_int_equal(ps_integrate(&om, &pic, co[c], &r, &e), 0);
		assert_true(fabs(many[c].total / r.response - 1) < 1e-12 || r.response == 0);
		ps_rescan_free(&one);
		ps_rescan_free(&many[c]);
	}
	/* more at once than it takes: refused */
	assert_int_equal(ps_rescan_project_many(many, PS_RESCAN_MAX_COEF + 1, co, &om, &pic, &v, 2, 5, 0, 180, &e), -1);
	ps_weights_free(&om);
	ps_sensor_free(&u);
	ps_picture_free(&pic);
}

/* A sun disc (a few pixels far brighter than the sky) on a sensor's sharp
 * azimuthal edge: the sensitivity falls from 1 to a floor within 2 degrees
 * of azimuth.  The sun sits at polar angle 40 degrees, azimuth 90 (left of
 * the centre); turning the sensor by r reads the table at 90 - r, so the
 * edge crosses the sun between rotations -2 and 0 and again between 178 and
 * 180.  The exact route at every rotation near the edges is the reference. */
static const char edge_table[] = "Elevation field 90\n"
                                 "degrees 0 90 92 270 272\n"
                                 "0 1 1 0.05 0.05 1\n"
                                 "80 1 1 0.05 0.05 1\n"
                                 "90 0 0 0 0 0\n";
static const char steep_table[] = "Elevation field 90\n"
                                  "degrees 0 90 90.5 270 270.5\n"
                                  "0 1 1 0.05 0.05 1\n"
                                  "80 1 1 0.05 0.05 1\n"
                                  "90 0 0 0 0 0\n";
static const char cliff_table[] = "Elevation field 90\n"
                                  "degrees 0 90 92 270 272\n"
                                  "0 1 1 0 0 1\n"
                                  "80 1 1 0 0 1\n"
                                  "90 0 0 0 0 0\n";

static void sun_picture(struct ps_picture *pic, double sun)
{
	double *rgb = malloc(sizeof(double) * 3 * N * N);
	char *buf = NULL;
	size_t n = 0;
	FILE *fp = open_memstream(&buf, &n);
	struct ps_err e;
	/* -vta: rho = theta / 90 degrees, azimuth 90 is -u (x below the centre) */
	double cx = N / 2.0 - (40.0 / 90.0) * (N / 2.0), cy = N / 2.0;
	for (int y = 0; y < N; y++)
		for (int x = 0; x < N; x++) {
			double *p = rgb + 3 * ((size_t)y * N + x), dx = x + 0.5 - cx, dy = y + 0.5 - cy;
			double v = dx * dx + dy * dy <= 1.6 * 1.6 ? sun : 1.0;
			p[0] = p[1] = p[2] = v;
		}
	assert_int_equal(ps_picture_write_fp(fp, "mem", N, N, rgb, "-vta -vh 180 -vv 180", NULL, &e), 0);
	fclose(fp);
	if (ps_picture_read_mem(pic, (uint8_t *)buf, n, "mem", &e) != 0)
		fail_msg("%s", e.msg);
	free(buf);
	free(rgb);
}

/* The checked scan of the sun against an edge; *worst is its largest error
 * against the exact route over the rotations near the edges. */
static void sun_scan(const char *name, const char *table_text, size_t len, double sun,
                     struct ps_scancheck *c, double *worst, double *plain_worst)
{
	static const int rots[] = { 355, 357, 358, 359, 0, 1, 2, 5, 90,
	                            176, 177, 178, 179, 180, 181, 183 };
	struct ps_picture pic;
	struct ps_sensor s, u;
	struct ps_rescan p;
	struct ps_weights om;
	struct ps_view v;
	struct ps_err e;
	double out[360], plain[360], total;
	sun_picture(&pic, sun);
	if (ps_sensor_parse(&s, table_text, len, name, &e) != 0 ||
	    ps_sensor_set_reading(&s, PS_READ_LINEAR, &e) != 0)
		fail_msg("%s", e.msg);
	project(&p, &pic, PSENS_DPHI, &total);
	ps_view_default_fisheye(&v);
	assert_int_equal(ps_sensor_builtin(&u, PS_SENS_UNIFORM, &e), 0);
	assert_int_equal(ps_weights_build(&om, &u, 0, &v, N, N, PS_W_EXACT, &e), 0);
	if (ps_scancheck_scan(&p, &om, &pic, &v, coef, &s, 0, 1, 360, 1, NULL, out, c, &e) != 0)
		fail_msg("%s", e.msg);
	assert_int_equal(ps_rescan_scan(&p, &s, 0, 1, 360, plain, &e), 0);
	*worst = *plain_worst = 0;
	for (size_t k = 0; k < sizeof rots / sizeof rots[0]; k++) {
		double want = exact(&s, rots[k], &pic);
		*worst = fmax(*worst, fabs(out[rots[k]] / want - 1));
		*plain_worst = fmax(*plain_worst, fabs(plain[rots[k]] / want - 1));
	}
	printf("# sun %g on the %s: the scan is off by %.2e, the checked scan by %.2e; "
	       "estimate %.2e at %g (%d checked; %.2e before refining, refined %d)\n", sun, name,
	       *plain_worst, *worst, c->estimate, c->at_deg, c->nchecked, c->first_estimate,
	       c->refined);
	ps_weights_free(&om);
	ps_sensor_free(&u);
	ps_rescan_free(&p);
	ps_sensor_free(&s);
	ps_picture_free(&pic);
}

static void sun_on_sharp_edge(void **state)
{
	struct ps_scancheck c = { .tolerance = PS_SCANCHECK_TOLERANCE };
	double worst, plain;
	(void)state;
	/* a 2-degree edge: the scan is within the tolerance */
	sun_scan("2-degree edge", edge_table, sizeof edge_table - 1, 2e4, &c, &worst, &plain);
	assert_true(worst <= c.tolerance);
	assert_true(c.estimate <= c.tolerance);
	/* a half-degree edge: the scan alone is off by more than the tolerance;
	 * the estimate finds it and the refined scan is within it */
	sun_scan("half-degree edge", steep_table, sizeof steep_table - 1, 2e4, &c, &worst, &plain);
	assert_true(plain > c.tolerance);
	assert_true(c.first_estimate > c.tolerance);
	assert_int_equal(c.refined, 1);
	assert_true(worst <= c.tolerance);
	assert_true(c.estimate <= c.tolerance);
	/* down to nothing beyond the edge, a brighter sun: the checked scan is
	 * within the tolerance or its estimate says it is not */
	sun_scan("edge down to 0", cliff_table, sizeof cliff_table - 1, 1e6, &c, &worst, &plain);
	assert_true(worst <= c.tolerance || c.estimate > c.tolerance);
}

/* The rotations checked: both sides of the largest jump, of the largest
 * jump relative to the smaller response beside it, and the largest
 * response, around the turn when the rotations close it. */
/* Cells coarser than the table's steps: each polar cell falls in its own
 * table step and feeds that step's two rows, so the rows outnumber the
 * cells two to one; the scan's row buffers must hold them (they were sized
 * by the cells, a heap overrun AddressSanitizer caught).  A table of 1
 * degree steps under 10 degree cells, on a uniform sky: the scan within
 * 2 % of the exact route at every rotation checked (the coarse cells' own
 * error), every number finite. */
static void coarse_cells_fine_table(void **state)
{
	char text[16384];
	size_t len = 0;
	struct ps_picture pic;
	struct ps_sensor s, u;
	struct ps_rescan p;
	struct ps_view v;
	struct ps_weights om;
	struct ps_err e;
	double out[36];
	(void)state;
	len += (size_t)snprintf(text + len, sizeof text - len, "Elevation field 180\ndegrees 0 90 180 270\n");
	for (int t = 0; t <= 180; t++) {   /* to 180: every polar cell inside the table */
		double c = t <= 90 ? cos(t * M_PI / 180) : 0;
		len += (size_t)snprintf(text + len, sizeof text - len, "%d %.6f %.6f %.6f %.6f\n", t, c, 0.8 * c, 0.6 * c,
		                        0.9 * c);
	}
	picture(&pic, 0);
	if (ps_sensor_parse(&s, text, len, "fine", &e) != 0 || ps_sensor_builtin(&u, PS_SENS_UNIFORM, &e) != 0)
		fail_msg("%s", e.msg);
	ps_view_default_fisheye(&v);
	assert_int_equal(ps_weights_build(&om, &u, 0, &v, N, N, PS_W_EXACT, &e), 0);
	if (ps_rescan_project(&p, &om, &pic, &v, coef, 10, 10, 0, 180, &e) != 0)
		fail_msg("%s", e.msg);
	assert_int_equal(ps_rescan_scan_mt(&p, &s, 0, 10, 36, 2, out, &e), 0);
	for (int k = 0; k < 36; k += 9) {
		double want = exact(&s, 10.0 * k, &pic);
		assert_true(isfinite(out[k]));
		assert_true(fabs(out[k] / want - 1) < 0.02);
	}
	ps_rescan_free(&p);
	ps_weights_free(&om);
	ps_sensor_free(&s);
	ps_sensor_free(&u);
	ps_picture_free(&pic);
}

static void pick_rotations(void **state)
{
	/* the largest jump 1 -> 9 between rotations 0 and 1; the largest
	 * relative jump 0.3 -> 0.01 (29 times the smaller) between 10 and 11;
	 * the largest response 9.5 at 2 */
	static const double out[13] = { 1, 9, 9.5, 6, 4, 2.5, 1.5, 1, 0.6, 0.4, 0.3, 0.01, 0.1 };
	static const int want[5] = { 1, 0, 11, 10, 2 };
	int idx[PS_SCANCHECK_MAX];
	(void)state;
	assert_int_equal(ps_scancheck_pick(out, 13, 0, idx), 5);
	assert_memory_equal(idx, want, sizeof want);
	/* closed: the turn 0.1 -> 1 (9 times) changes nothing */
	assert_int_equal(ps_scancheck_pick(out, 13, 1, idx), 5);
	assert_memory_equal(idx, want, sizeof want);
	/* one rotation: itself */
	assert_int_equal(ps_scancheck_pick(out, 1, 0, idx), 1);
	assert_int_equal(idx[0], 0);
	assert_int_equal(ps_scancheck_pick(out, 0, 0, idx), 0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(scan_against_exact),
		cmocka_unit_test(scan_equals_its_definition),
		cmocka_unit_test(table_shared_between_pictures),
		cmocka_unit_test(projections_together),
		cmocka_unit_test(uniform_cosine_is_pi),
		cmocka_unit_test(sun_on_sharp_edge),
		cmocka_unit_test(coarse_cells_fine_table),
		cmocka_unit_test(pick_rotations),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
