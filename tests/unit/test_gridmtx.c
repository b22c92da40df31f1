/* SPDX-License-Identifier: ISC */
/* Work-plane grids in Radiance's matrix format (sim/sky/gridmtx):
 *   - ascii, float and double matrices with known values (both byte
 *     orders), NCOMP=1 spread to three components, read to the value;
 *   - the example's rfluxmtx -I+ file (config/example/ofb/dc/points_mf1.mtx)
 *     read as an independent fscanf reads it, bit for bit;
 *   - the grid route against the picture route at the task point under the
 *     sensor (the example's task pictures, 1.85 2.285 0.762 facing up):
 *     uniform sky within 1.5 % (measured +0.77 %) and the sums over the
 *     example's weather year (4413 hours with light) within 2.5 % (measured
 *     +1.58 %: the two routes are Monte Carlo estimates by different paths,
 *     and the sun's few patches, the noisiest, carry much of the year);
 *   - bad matrices: no #?RADIANCE, no NROWS, a count no subdivision has,
 *     an unknown FORMAT, too few and too many values, NaN, infinity, a
 *     negative value, a short binary: each refused naming file and line
 *     (or byte);
 *   - the electric irradiance (rtrace -I+ lines) to lux, a header skipped,
 *     a wrong count or a bad line refused naming file and line. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <unistd.h>
#include <cmocka.h>

#include "dcset.h"
#include "gridmtx.h"
#include "integrate.h"
#include "patches.h"
#include "sensor.h"
#include "sky.h"
#include "view.h"
#include "weather.h"

static const double V[3] = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B };

static void data_path(char *buf, size_t n, const char *rel)
{
	const char *top = getenv("TOP");
	snprintf(buf, n, "%s/%s", top ? top : ".", rel);
}

/* a 2 x 146 matrix whose value (r, p, k) is r + p / 1000 + k / 8 (exact in float) */
static double known(int r, int p, int k)
{
	return r + p / 1024.0 + k / 8.0;
}

static size_t header(char *buf, size_t n, int nrows, int ncols, int ncomp, const char *fmt, const char *order)
{
	return (size_t)snprintf(buf, n, "#?RADIANCE\nrmtxop -f%c x.mtx\nNROWS=%d\nNCOLS=%d\nNCOMP=%d\n%s%s%sFORMAT=%s\n\n",
	                        fmt[0], nrows, ncols, ncomp, order ? "BYTEORDER=" : "", order ? order : "",
	                        order ? "\n" : "", fmt);
}

static int is_little(void)
{
	const uint16_t one = 1;
	return *(const uint8_t *)&one == 1;
}

static void check_known(const struct ps_gridmtx *m, int ncomp)
{
	assert_int_equal(m->npoints, 2);
	assert_int_equal(m->npatch, 146);
	assert_int_equal(m->mf, 1);
	for (int r = 0; r < 2; r++)
		for (int p = 0; p < 146; p++)
			for (int k = 0; k < 3; k++)
				assert_true(m->c[3 * (r * 146 + p) + k] == known(r, p, ncomp == 3 ? k : 0));
}

static void formats(void **state)
{
	static unsigned char buf[1 << 16];
	struct ps_gridmtx m;
	struct ps_err e;
	size_t n;
	(void)state;
	/* ascii, one row a line, tab-separated, as rfluxmtx writes */
	n = header((char *)buf, sizeof buf, 2, 146, 3, "ascii", NULL);
	for (int r = 0; r < 2; r++) {
		for (int p = 0; p < 146; p++)
			for (int k = 0; k < 3; k++)
				n += (size_t)snprintf((char *)buf + n, sizeof buf - n, "%.17g\t", known(r, p, k));
		buf[n++] = '\n';
	}
	assert_int_equal(ps_gridmtx_parse(&m, buf, n, "a.mtx", &e), 0);
	check_known(&m, 3);
	ps_gridmtx_free(&m);
	/* ascii with one component, three values a line (rmtxop's layout) */
	n = header((char *)buf, sizeof buf, 2, 146, 1, "ascii", NULL);
	for (int r = 0; r < 2; r++)
		for (int p = 0; p < 146; p++)
			n += (size_t)snprintf((char *)buf + n, sizeof buf - n, "%.17g\n", known(r, p, 0));
	assert_int_equal(ps_gridmtx_parse(&m, buf, n, "a1.mtx", &e), 0);
	check_known(&m, 1);
	ps_gridmtx_free(&m);
	/* float and double, in both byte orders */
	for (int size = 4; size <= 8; size += 4)
		for (int swap = 0; swap < 2; swap++) {
			const char *order = is_little() != swap ? "LittleEndian" : "BigEndian";
			n = header((char *)buf, sizeof buf, 2, 146, 3, size == 4 ? "float" : "double", order);
			for (int r = 0; r < 2; r++)
				for (int p = 0; p < 146; p++)
					for (int k = 0; k < 3; k++) {
						unsigned char b[8];
						double d = known(r, p, k);
						float f = (float)d;
						memcpy(b, size == 4 ? (void *)&f : (void *)&d, (size_t)size);
						for (int i = 0; i < size; i++)
							buf[n + (size_t)i] = b[swap ? size - 1 - i : i];
						n += (size_t)size;
					}
			if (ps_gridmtx_parse(&m, buf, n, "b.mtx", &e) != 0)
				fail_msg("%s", e.msg);
			check_known(&m, 3);
			ps_gridmtx_free(&m);
		}
}

/* the example's point route file as fscanf reads it */
static void read_points(double m[2][146 * 3])
{
	char path[4096], line[8192];
	FILE *fp;
	data_path(path, sizeof path, "config/example/ofb/dc/points_mf1.mtx");
	fp = fopen(path, "r");
	assert_non_null(fp);
	while (fgets(line, sizeof line, fp) && line[0] != '\n')
		;
	for (int r = 0; r < 2; r++)
		for (int k = 0; k < 146 * 3; k++)
			assert_int_equal(fscanf(fp, "%lf", &m[r][k]), 1);
	fclose(fp);
}

static void example_file(void **state)
{
	static double ref[2][146 * 3];
	struct ps_gridmtx m;
	struct ps_err e;
	char path[4096];
	(void)state;
	read_points(ref);
	data_path(path, sizeof path, "config/example/ofb/dc/points_mf1.mtx");
	if (ps_gridmtx_read(&m, path, &e) != 0)
		fail_msg("%s", e.msg);
	assert_int_equal(m.npoints, 2);
	assert_int_equal(m.mf, 1);
	for (int r = 0; r < 2; r++)
		for (int k = 0; k < 146 * 3; k++)
			assert_true(m.c[r * 146 * 3 + k] == ref[r][k]);
	ps_gridmtx_free(&m);
}

static void grid_route_against_pictures(void **state)
{
	static double sky[146 * 3], one[146 * 3];
	struct ps_gridmtx m;
	struct ps_dcset_row grid, pic;
	struct ps_view v;
	struct ps_sensor cos;
	struct ps_weather w;
	struct ps_patches P;
	struct ps_sky_opt o;
	struct ps_err e;
	char path[4096];
	double sg = 0, sp = 0;
	int hours = 0;
	(void)state;
	data_path(path, sizeof path, "config/example/ofb/dc/points_mf1.mtx");
	assert_int_equal(ps_gridmtx_read(&m, path, &e), 0);
	ps_gridmtx_row(&m, 1, &grid);   /* the task point, facing up */
	ps_view_default(&v);   /* the options not given keep Radiance's defaults */
	assert_int_equal(ps_view_parse(&v, "-vta -vp 1.85 2.285 0.762 -vd 0 0 1 -vu 0 1 0 -vh 180 -vv 180", "task", &e),
	                 0);
	assert_int_equal(ps_sensor_builtin(&cos, PS_SENS_COSINE, &e), 0);
	data_path(path, sizeof path, "config/example/ofb/dc/task/dc_%03d.hdr");
	if (ps_dcset_row(path, &v, 1, &cos, 0.0, &pic, &e) != 0)
		fail_msg("%s", e.msg);
	for (int i = 0; i < 146 * 3; i++)
		one[i] = 1.0;
	{
		double a = ps_dcset_row_apply(&grid, V, one), b = ps_dcset_row_apply(&pic, V, one);
		print_message("uniform sky: grid %.5f pictures %.5f (%+.2f %%)\n", a, b, 100 * (a / b - 1));
		assert_true(fabs(a / 0.32188 - 1) < 1e-3);   /* the fixture README's point route figure */
		assert_true(fabs(a / b - 1) < 0.015);
	}
	data_path(path, sizeof path, "config/example/ofb/weather/sf-tmy3.wea");
	assert_int_equal(ps_weather_read(&w, path, 0, &e), 0);
	assert_int_equal(ps_patches_init(&P, 1, &e), 0);
	ps_sky_opt_default(&o);
	for (size_t i = 0; i < w.n; i++) {
		struct ps_sky s;
		assert_int_equal(ps_sky_step(&s, &w, i, &o, &e), 0);
		if (s.dark)
			continue;
		ps_sky_vector(&s, &P, PS_SKY_ALL, sky);
		sg += ps_dcset_row_apply(&grid, V, sky);
		sp += ps_dcset_row_apply(&pic, V, sky);
		hours++;
	}
	print_message("year: %d hours, grid route against pictures %+.2f %%\n", hours, 100 * (sg / sp - 1));
	assert_true(hours > 4000);
	assert_true(fabs(sg / sp - 1) < 0.025);
	ps_patches_free(&P);
	ps_weather_free(&w);
	ps_dcset_row_free(&pic);
	ps_sensor_free(&cos);
	ps_gridmtx_free(&m);
}

static void expect_bad(const char *text, size_t len, const char *want)
{
	struct ps_gridmtx m;
	struct ps_err e;
	assert_int_not_equal(ps_gridmtx_parse(&m, (const unsigned char *)text, len, "g.mtx", &e), 0);
	if (!strstr(e.msg, want))
		fail_msg("'%s' lacks '%s'", e.msg, want);
	assert_null(m.c);
}

static void bad_matrices(void **state)
{
	static char buf[1 << 16];
	size_t n;
	(void)state;
	expect_bad("NROWS=1\nNCOLS=146\nFORMAT=ascii\n\n", 30, "g.mtx:1: not a Radiance matrix");
	n = (size_t)snprintf(buf, sizeof buf, "#?RADIANCE\nNCOLS=146\nNCOMP=3\nFORMAT=ascii\n\n1 2 3\n");
	expect_bad(buf, n, "g.mtx:5: the header gives no NROWS");
	n = (size_t)snprintf(buf, sizeof buf, "#?RADIANCE\nNROWS=1\nNCOLS=145\nNCOMP=3\nFORMAT=ascii\n\n1 2 3\n");
	expect_bad(buf, n, "g.mtx:6: NCOLS=145 is no sky subdivision");
	n = (size_t)snprintf(buf, sizeof buf, "#?RADIANCE\nNROWS=x\nNCOLS=146\n\n");
	expect_bad(buf, n, "g.mtx:2: bad NROWS");
	n = (size_t)snprintf(buf, sizeof buf, "#?RADIANCE\nNROWS=1\nNCOLS=146\nFORMAT=32-bit_rle_rgbe\n\n");
	expect_bad(buf, n, "g.mtx:4: FORMAT=32-bit_rle_rgbe");
	n = (size_t)snprintf(buf, sizeof buf, "#?RADIANCE\nNROWS=1\nNCOLS=146\nNCOMP=3\nFORMAT=ascii\n");
	expect_bad(buf, n, "g.mtx:6: the header has no end");
	/* too few values: the line where the data ended */
	n = header(buf, sizeof buf, 2, 146, 3, "ascii", NULL);
	for (int i = 0; i < 146 * 3; i++)
		n += (size_t)snprintf(buf + n, sizeof buf - n, "1\t");
	n += (size_t)snprintf(buf + n, sizeof buf - n, "\n");
	expect_bad(buf, n, "g.mtx:9: 438 values where NROWS x NCOLS x NCOMP = 2 x 146 x 3 = 876");
	/* too many: the line of the first extra */
	n = header(buf, sizeof buf, 1, 146, 3, "ascii", NULL);
	for (int i = 0; i < 146 * 3; i++)
		n += (size_t)snprintf(buf + n, sizeof buf - n, "1\t");
	n += (size_t)snprintf(buf + n, sizeof buf - n, "\n\n7\n");
	expect_bad(buf, n, "g.mtx:10: more values than");
	/* NaN, infinity, negative, not a number: on their line */
	for (int kind = 0; kind < 4; kind++) {
		static const char *const word[] = { "nan", "inf", "-0.5", "1.2.3" };
		static const char *const say[] = { "g.mtx:9: NaN", "g.mtx:9: infinity", "g.mtx:9: negative",
		                                   "g.mtx:9: not a number" };
		n = header(buf, sizeof buf, 2, 146, 3, "ascii", NULL);
		for (int i = 0; i < 146 * 3; i++)
			n += (size_t)snprintf(buf + n, sizeof buf - n, "1\t");
		n += (size_t)snprintf(buf + n, sizeof buf - n, "\n1 %s", word[kind]);
		for (int i = 2; i < 146 * 3; i++)
			n += (size_t)snprintf(buf + n, sizeof buf - n, " 1");
		n += (size_t)snprintf(buf + n, sizeof buf - n, "\n");
		expect_bad(buf, n, say[kind]);
	}
	/* a binary one byte short */
	n = header(buf, sizeof buf, 1, 146, 3, "float", NULL);
	memset(buf + n, 0, 146 * 3 * 4 - 1);
	expect_bad(buf, n + 146 * 3 * 4 - 1, "1751 bytes of data where NROWS x NCOLS x NCOMP = 438 float values take 1752");
	/* a float NaN names its byte */
	{
		float f = NAN;
		size_t h = header(buf, sizeof buf, 1, 146, 3, "float", NULL);
		memset(buf + h, 0, 146 * 3 * 4);
		memcpy(buf + h + 8, &f, 4);
		snprintf(buf + 3000, 64, "g.mtx: byte %zu: NaN", h + 8);
		expect_bad(buf, h + 146 * 3 * 4, buf + 3000);
	}
}

static void electric(void **state)
{
	double lux[3];
	struct ps_err e;
	const char *good = "#?RADIANCE\nrtrace -I+ -ab 4\nFORMAT=ascii\n\n1 1 1\n\n2 0 0\n0 0 4\n";
	(void)state;
	assert_int_equal(ps_gridmtx_elec_parse(good, strlen(good), "e.dat", 3, lux, &e), 0);
	assert_true(fabs(lux[0] - 179.0) < 1e-9);   /* V's coefficients sum to 1 */
	assert_true(fabs(lux[1] - 179.0 * 2 * V[0]) < 1e-9);
	assert_true(fabs(lux[2] - 179.0 * 4 * V[2]) < 1e-9);
	assert_int_not_equal(ps_gridmtx_elec_parse(good, strlen(good), "e.dat", 4, lux, &e), 0);
	assert_non_null(strstr(e.msg, "e.dat:8: 3 points where the grid has 4"));
	assert_int_not_equal(ps_gridmtx_elec_parse(good, strlen(good), "e.dat", 2, lux, &e), 0);
	assert_non_null(strstr(e.msg, "e.dat:8: more points than the grid's 2"));
	assert_int_not_equal(ps_gridmtx_elec_parse("1 1 1\n1 nan 1\n", 14, "e.dat", 2, lux, &e), 0);
	assert_non_null(strstr(e.msg, "e.dat:2: not a finite"));
	assert_int_not_equal(ps_gridmtx_elec_parse("1 1\n", 4, "e.dat", 1, lux, &e), 0);
	assert_non_null(strstr(e.msg, "e.dat:1: expected R G B"));
	/* from a file: its name in the message */
	{
		char path[64] = "/tmp/test_gridmtx_XXXXXX";
		int fd = mkstemp(path);
		FILE *fp = fd >= 0 ? fdopen(fd, "w") : NULL;
		assert_non_null(fp);
		fputs("1 1 1\n2 2 2\n", fp);
		fclose(fp);
		assert_int_equal(ps_gridmtx_elec_read(path, 2, lux, &e), 0);
		assert_true(fabs(lux[1] - 358.0) < 1e-9);
		assert_int_not_equal(ps_gridmtx_elec_read(path, 3, lux, &e), 0);
		assert_non_null(strstr(e.msg, path));
		remove(path);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(formats),
		cmocka_unit_test(example_file),
		cmocka_unit_test(grid_route_against_pictures),
		cmocka_unit_test(bad_matrices),
		cmocka_unit_test(electric),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
