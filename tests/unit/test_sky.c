/* SPDX-License-Identifier: ISC */
/* The sky against Radiance and against analytic answers:
 *   - all 24,528 values of Radiance's own gendaymtx test (tests/data/gendaymtx);
 *   - the sun patches the reference implies are the ones computed here;
 *   - the solar position against published positions (Meeus; the 2021
 *     solstices and equinoxes) and the IES formulas' error over a year;
 *   - the patches: counts, solid angles, numbering, directions;
 *   - the normalised continuous sky integrates to the diffuse illuminance
 *     (checked by an independent rule), and the patch sky converges to it;
 *   - stiff and extreme cases stay finite (sun on the horizon, zero diffuse,
 *     clearness on every bin edge, a gradation term that grows at the horizon);
 *   - the exact coefficient pictures partition the fisheye. */
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

#include "dcpic.h"
#include "fileio.h"
#include "integrate.h"
#include "patches.h"
#include "perez.h"
#include "picture.h"
#include "sensor.h"
#include "sky.h"
#include "sun.h"
#include "view.h"
#include "weather.h"
#include "weights.h"

#define DEG (M_PI / 180.0)

static void data_path(char *buf, size_t n, const char *rel)
{
	const char *top = getenv("TOP");
	snprintf(buf, n, "%s/%s", top ? top : ".", rel);
}

static void read_test_wea(struct ps_weather *w)
{
	char path[4096];
	struct ps_err e;
	data_path(path, sizeof path, "tests/data/gendaymtx/test.wea");
	if (ps_weather_read(w, path, 0, &e) != 0)
		fail_msg("%s", e.msg);
}

/* the reference's values: tokens as printed, and their count */
static char **read_reference(size_t *count, int *nrows, int *ncols)
{
	char path[4096], *p, **tok;
	uint8_t *data;
	size_t len, n = 0, cap = 32768;
	struct ps_err e;
	data_path(path, sizeof path, "tests/data/gendaymtx/test.smx");
	if (ps_fileio_read(path, 1 << 24, &data, &len, &e) != 0)
		fail_msg("%s", e.msg);
	p = strstr((char *)data, "NROWS=");
	assert_non_null(p);
	*nrows = atoi(p + 6);
	p = strstr((char *)data, "NCOLS=");
	assert_non_null(p);
	*ncols = atoi(p + 6);
	assert_non_null(strstr((char *)data, "FORMAT=ascii"));
	p = strstr((char *)data, "\n\n");
	assert_non_null(p);
	tok = malloc(cap * sizeof *tok);
	for (char *t = strtok(p, " \n"); t; t = strtok(NULL, " \n")) {
		if (n == cap)
			tok = realloc(tok, (cap *= 2) * sizeof *tok);
		tok[n++] = strdup(t);
	}
	free(data);
	*count = n;
	return tok;
}

static void reference_options(struct ps_sky_opt *o)
{
	ps_sky_opt_default(o);
	o->rotation = 90;
	o->ground[0] = .3;
	o->ground[1] = .2;
	o->ground[2] = .1;
	o->sky_color[0] = .9;
	o->sky_color[1] = .9;
	o->sky_color[2] = 1.2;
}

/* the unit of the last digit %.3g prints for v */
static double last_digit(double v)
{
	return pow(10.0, floor(log10(fabs(v))) - 2);
}

/* gendaymtx -r 90 -m 1 -g .3 .2 .1 -c .9 .9 1.2 test.wea: every printed value */
static void reference_matrix(void **state)
{
	struct ps_weather w;
	struct ps_patches P;
	struct ps_sky_opt o;
	struct ps_err e;
	size_t count, match = 0;
	int nrows, ncols;
	char **ref = read_reference(&count, &nrows, &ncols);
	double *m, worst = 0.0, worst_rel = 0.0;
	(void)state;
	read_test_wea(&w);
	reference_options(&o);
	assert_int_equal(ps_patches_init(&P, 1, &e), 0);
	assert_int_equal(nrows, P.n);
	assert_int_equal(ncols, (int)w.n);
	assert_int_equal(count, (size_t)nrows * (size_t)ncols * 3);
	m = malloc((size_t)ncols * (size_t)nrows * 3 * sizeof *m);
	for (int c = 0; c < ncols; c++) {
		struct ps_sky s;
		assert_int_equal(ps_sky_step(&s, &w, (size_t)c, &o, &e), 0);
		ps_sky_vector(&s, &P, PS_SKY_ALL, m + (size_t)c * (size_t)nrows * 3);
	}
	/* the file: patch by patch, step by step */
	for (int r = 0; r < nrows; r++)
		for (int c = 0; c < ncols; c++)
			for (int k = 0; k < 3; k++) {
				const char *t = ref[3 * ((size_t)r * (size_t)ncols + (size_t)c) + (size_t)k];
				double mine = m[3 * ((size_t)c * (size_t)nrows + (size_t)r) + (size_t)k];
				double want = strtod(t, NULL), d;
				char buf[64];
				snprintf(buf, sizeof buf, "%.3g", mine);
				if (strcmp(buf, t) == 0)
					match++;
				else
					print_message("# patch %d step %d comp %d: %s, reference %s\n", r, c, k,
					              buf, t);
				/* distance in units of the last printed digit */
				d = want == 0 ? (mine == 0 ? 0 : INFINITY) : fabs(mine - want) / last_digit(want);
				if (d > worst)
					worst = d;
				if (want != 0 && fabs(mine - want) / fabs(want) > worst_rel)
					worst_rel = fabs(mine - want) / fabs(want);
			}
	print_message("# Radiance's gendaymtx test: %zu of %zu values equal printed with %%.3g; worst "
	              "|pssky - reference| = %.3f units of the last printed digit (%.2e relative)\n",
	              match, count, worst, worst_rel);
	assert_int_equal(match, count);
	assert_true(worst <= 0.5 + 1e-9);
	for (size_t i = 0; i < count; i++)
		free(ref[i]);
	free(ref);
	free(m);
	ps_patches_free(&P);
	ps_weather_free(&w);
}

/* Where the reference exceeds the sky without a sun by more than its
 * rounding, the sun was put; those patches are the ones computed here. */
static void implied_sun_positions(void **state)
{
	struct ps_weather w;
	struct ps_patches P;
	struct ps_sky_opt o;
	struct ps_err e;
	size_t count;
	int nrows, ncols, steps = 0;
	char **ref = read_reference(&count, &nrows, &ncols);
	double sky[3 * 146], sun[3 * 146];
	(void)state;
	read_test_wea(&w);
	reference_options(&o);
	assert_int_equal(ps_patches_init(&P, 1, &e), 0);
	for (int c = 0; c < ncols; c++) {
		struct ps_sky s;
		int found = 0;
		assert_int_equal(ps_sky_step(&s, &w, (size_t)c, &o, &e), 0);
		ps_sky_vector(&s, &P, PS_SKY_GROUND | PS_SKY_DIFFUSE, sky);
		ps_sky_vector(&s, &P, PS_SKY_SUN, sun);
		for (int r = 1; r < nrows; r++) {
			double want = strtod(ref[3 * ((size_t)r * (size_t)ncols + (size_t)c) + 1], NULL);
			double excess = want - sky[3 * r + 1];
			int implied = excess > (want > 0 ? last_digit(want) : 0);
			if (implied) {
				found++;
				if (!(sun[3 * r + 1] > 0))
					fail_msg("step %d: the reference has a sun in patch %d, not computed here", c, r);
			} else if (sun[3 * r + 1] > 2 * (want > 0 ? last_digit(want) : 1e-9)) {
				fail_msg("step %d: sun %g in patch %d, not in the reference", c, sun[3 * r + 1], r);
			}
		}
		if (found)
			steps++;
	}
	print_message("# the reference's sun patches found in %d of %d steps, all where computed\n",
	              steps, ncols);
	assert_true(steps >= 40);
	for (size_t i = 0; i < count; i++)
		free(ref[i]);
	free(ref);
	ps_patches_free(&P);
	ps_weather_free(&w);
}

/* Published positions: Meeus, Astronomical Algorithms, examples 25.a and
 * 28.a (1992 October 13, 0h TD: apparent declination -7 47' 06" =
 * -7.78507 deg, equation of time +13 min 42.6 s), and the declination at
 * the 2021 equinoxes and solstices (USNO: March 20 09:37, June 21 03:32,
 * September 22 19:21, December 21 15:59 UT; obliquity 23.4364 deg). */
static void solar_position(void **state)
{
	struct ps_site greenwich = { "Greenwich", 51.4769, 0.0, 0.0, 0.0 };
	struct ps_site mv = { "Mountain View", 37.42, -122.05, -8.0, 12.0 };
	struct ps_sunpos p, q;
	double d, eot, worst_d = 0, worst_e = 0, worst_angle = 0;
	static const struct {
		int mo, da;
		double hour, decl;
	} cardinal[] = { { 3, 20, 9 + 37 / 60.0, 0.0 }, { 6, 21, 3 + 32 / 60.0, 23.4364 },
	                 { 9, 22, 19 + 21 / 60.0, 0.0 }, { 12, 21, 15 + 59 / 60.0, -23.4364 } };
	(void)state;
	ps_sun_almanac_jd(2448908.5, &d, &eot);
	print_message("# Almanac at 1992-10-13 0h: declination %.5f deg (Meeus -7.78507), equation of "
	              "time %.3f min (Meeus 13.710)\n", d / DEG, eot * 60);
	assert_true(fabs(d / DEG - -7.78507) < 0.01);
	assert_true(fabs(eot * 60 - 13.710) < 0.1);
	for (int k = 0; k < 4; k++) {
		ps_sun_almanac(&greenwich, 2021, cardinal[k].mo, cardinal[k].da, cardinal[k].hour, &p);
		assert_true(fabs(p.decl / DEG - cardinal[k].decl) < 0.01);
	}
	/* the IES formulas over 2021, every hour the sun is up at Mountain View */
	for (int doy = 1; doy <= 365; doy++) {
		int mo = 1, da = doy;
		static const int ml[12] = { 31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31 };
		while (da > ml[mo - 1]) {
			da -= ml[mo - 1];
			mo++;
		}
		assert_int_equal(ps_sun_day_of_year(mo, da, 0), doy);
		for (double h = 0.5; h < 24; h += 1.0) {
			double a[3], b[3], c;
			ps_sun_position(&mv, doy, h, &p);
			ps_sun_almanac(&mv, 2021, mo, da, h, &q);
			if (fabs(p.decl - q.decl) > worst_d)
				worst_d = fabs(p.decl - q.decl);
			ps_sun_almanac_jd(2459215.5 + doy - 1 + (h + 8) / 24, &d, &eot);
			if (fabs(ps_sun_equation_of_time(doy) - eot) > worst_e)
				worst_e = fabs(ps_sun_equation_of_time(doy) - eot);
			if (q.alt < 0)
				continue;
			ps_sun_direction(p.alt, p.azi, a);
			ps_sun_direction(q.alt, q.azi, b);
			c = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
			if (acos(fmin(1, c)) > worst_angle)
				worst_angle = acos(fmin(1, c));
		}
	}
	print_message("# IES formulas against the Almanac over 2021: declination within %.3f deg, "
	              "equation of time within %.2f min, the sun's direction within %.3f deg\n",
	              worst_d / DEG, worst_e * 60, worst_angle / DEG);
	assert_true(worst_d / DEG < 1.3);
	assert_true(worst_e * 60 < 1.5);
	assert_true(worst_angle / DEG < 1.2);
	/* the formulas' own geometry: at solar noon the sun is due south at
	 * 90 - latitude + declination */
	for (int doy = 1; doy <= 365; doy += 7) {
		double t12 = 12.0 - (ps_sun_solar_hour(&mv, doy, 12.0) - 12.0);
		ps_sun_position(&mv, doy, t12, &p);
		assert_true(fabs(p.solar_hour - 12.0) < 1e-12);
		assert_true(fabs(p.azi - M_PI) < 1e-9);
		assert_true(fabs(p.alt - (M_PI / 2 - mv.lat * DEG + p.decl)) < 1e-9);
	}
}

static void patch_geometry(void **state)
{
	static const int mfs[4] = { 1, 2, 4, 6 }, counts[4] = { 146, 578, 2306, 5186 };
	(void)state;
	for (int k = 0; k < 4; k++) {
		struct ps_patches P;
		struct ps_err e;
		double sum = 0;
		assert_int_equal(ps_patches_init(&P, mfs[k], &e), 0);
		assert_int_equal(P.n, counts[k]);
		assert_int_equal(ps_patches_mf_for_count(counts[k]), mfs[k]);
		for (int i = 1; i < P.n; i++) {
			double b[4], exact;
			sum += P.omega[i];
			assert_int_equal(ps_patches_find(&P, P.dir + 3 * i), i);
			ps_patches_bounds(&P, i, b);
			exact = (b[3] - b[2]) * (sin(b[1]) - sin(b[0]));
			assert_true(fabs(exact - P.omega[i]) < 1e-15);
			/* just inside each corner */
			for (int c = 0; c < 4; c++) {
				double alt = c & 1 ? b[1] - 1e-9 : b[0] + 1e-9;
				double azi = c & 2 ? b[3] - 1e-9 : b[2] + 1e-9, d[3];
				if (i == P.n - 1)
					alt = b[0] + 1e-9;
				ps_sun_direction(alt, azi, d);
				assert_int_equal(ps_patches_find(&P, d), i);
			}
		}
		assert_true(fabs(sum - 2 * M_PI) < 1e-12);
		/* patch 1 due north on the horizon row, patch 2 east of it, the last the zenith */
		assert_true(P.azi[1] == 0 && P.dir[3 * 1 + 1] > 0.99);
		assert_true(P.dir[3 * 2 + 0] > 0);
		assert_true(P.dir[3 * (P.n - 1) + 2] == 1.0);
		{
			const double down[3] = { 0.3, 0.2, -0.1 }, flat[3] = { 1, 0, 0 };
			assert_int_equal(ps_patches_find(&P, down), 0);
			assert_int_equal(ps_patches_find(&P, flat), 0);
		}
		ps_patches_free(&P);
	}
}

/* independent rule: midpoints of an equal-area grid, N rings in cos(zenith) */
static double grid_horizontal(const struct ps_sky *s, int n)
{
	double sum = 0;
	for (int i = 0; i < n; i++) {
		double u = (i + 0.5) / n, st = sqrt(1 - u * u), ring = 0;
		int m = 2 * n;
		for (int j = 0; j < m; j++) {
			double ph = 2 * M_PI * (j + 0.5) / m, d[3] = { st * sin(ph), st * cos(ph), u }, rgb[3];
			ps_sky_radiance(s, d, PS_SKY_DIFFUSE, rgb);
			ring += rgb[1] / s->opt.sky_color[1] * u;
		}
		sum += ring * (2 * M_PI / m) / n;
	}
	return sum;
}

static void sky_of(struct ps_sky *s, double dir, double dif, double alt_deg, double azi_deg,
                   int exact_sine)
{
	struct ps_sky_in in = { dir, dif, PS_WX_DN_DH, 11.0, 172, alt_deg * DEG, azi_deg * DEG };
	struct ps_sky_opt o;
	ps_sky_opt_default(&o);
	o.exact_sine = exact_sine;
	ps_sky_init(s, &in, &o);
}

/* a sky of given clearness and brightness (diffuse and direct solved for) */
static void sky_eps_delta(struct ps_sky *s, double eps, double delta, double alt_deg, double azi_deg)
{
	double z, k, dif;
	sky_of(s, 100, 100, alt_deg, azi_deg, 1);   /* for the air mass and eccentricity */
	z = s->model.zenith;
	k = 1.041 * z * z * z;
	dif = delta * PS_SOLAR_CONSTANT * s->model.eccentricity / s->model.air_mass;
	sky_of(s, dif * (eps - 1) * (1 + k), dif, alt_deg, azi_deg, 1);
}

/* the integral of patch i of the cosine: azimuth width x (sin^2 a1 - sin^2 a0) / 2 */
static double patch_cos(const struct ps_patches *P, int i)
{
	double b[4];
	ps_patches_bounds(P, i, b);
	return (b[3] - b[2]) * 0.5 * (sin(b[1]) * sin(b[1]) - sin(b[0]) * sin(b[0]));
}

static void sky_integrates_to_diffuse(void **state)
{
	static const struct {
		const char *name;
		double dir, dif, alt, azi;
	} skies[] = {
		{ "clear, high sun", 835, 161, 75.0, 200.0 },
		{ "intermediate", 434, 283, 52.0, 170.0 },
		{ "overcast", 0, 305, 45.0, 220.0 },
		{ "low sun", 13, 112, 8.0, 95.0 },
		{ "sun on the horizon (89.9 deg zenith)", 300, 60, 0.1, 270.0 },
		{ "black below 1 deg (b > 0 > a)", -3.0, 0.45, 4.0, 90.0 },
	};
	(void)state;
	for (size_t k = 0; k < sizeof skies / sizeof skies[0]; k++) {
		struct ps_sky s;
		struct ps_err e;
		double want, grid, err_mf[4];
		if (skies[k].dir < 0) {   /* given as clearness and brightness */
			sky_eps_delta(&s, -skies[k].dir, skies[k].dif, skies[k].alt, skies[k].azi);
			assert_true(s.model.coef[1] > 0 && s.model.coef[0] < 0);
		} else {
			sky_of(&s, skies[k].dir, skies[k].dif, skies[k].alt, skies[k].azi, 1);
		}
		want = s.dif_lum / PS_WHITE_EFFICACY;
		if (ps_sky_normalise(&s, 1e-10, &e) != 0)
			fail_msg("%s: %s", skies[k].name, e.msg);
		assert_true(s.norm > 0 && s.norm_err < 1e-9 * s.norm);
		grid = grid_horizontal(&s, 1000);
		/* The patch skies: sum of radiance x the patch's exact integral of
		 * the cosine.  Normalised at the centres, each band patch's share is
		 * off by exactly cos(alpha / 2) ((sin a0 + sin a1) / (2 sin ac)), the
		 * cap's by (1 + cos(alpha / 2)) / 2: the error is that, weighted. */
		for (int q = 0; q < 4; q++) {
			static const int mfs[4] = { 1, 2, 4, 6 };
			struct ps_patches P;
			double *v, sum = 0, expect = 0, ca;
			assert_int_equal(ps_patches_init(&P, mfs[q], &e), 0);
			ca = cos(P.alpha / 2);
			v = malloc((size_t)P.n * 3 * sizeof *v);
			ps_sky_vector(&s, &P, PS_SKY_DIFFUSE, v);
			for (int i = 1; i < P.n; i++) {
				double l = v[3 * i + 1] / s.opt.sky_color[1], share = l * sin(P.alt[i]) * P.omega[i];
				assert_true(isfinite(l) && l >= 0);
				sum += l * patch_cos(&P, i);
				expect += share * ((i == P.n - 1 ? (1 + ca) / 2 : ca) - 1);
			}
			err_mf[q] = sum / want - 1;
			assert_true(fabs(err_mf[q] - expect / want) < 1e-12);
			free(v);
			ps_patches_free(&P);
		}
		print_message("# %-42s bin %d: continuous %+.1e (grid), patches MF 1 %+.1e, 2 %+.1e, "
		              "4 %+.1e, 6 %+.1e\n",
		              skies[k].name, s.model.bin, grid / want - 1, err_mf[0], err_mf[1],
		              err_mf[2], err_mf[3]);
		assert_true(fabs(grid / want - 1) < 2e-5);
		assert_true(fabs(err_mf[3]) < fabs(err_mf[0]) || fabs(err_mf[3]) < 1e-4);
		assert_true(fabs(err_mf[3]) < 0.01);
	}
}

/* gendaymtx's table sine against the exact one */
static void table_sine_normalisation(void **state)
{
	struct ps_sky a, b;
	struct ps_patches P;
	struct ps_err e;
	double va[3 * 5186], vb[3 * 5186], worst[2] = { 0, 0 };
	(void)state;
	for (int x = 0; x <= 9000; x++) {   /* the table: nearest of 1024 a quadrant */
		double t = x * (M_PI / 2 / 9000);
		assert_true(fabs(ps_sky_table_sin(t) - sin(t)) <= sin(M_PI / 4096) + 1e-15);
	}
	for (int q = 0; q < 2; q++) {
		assert_int_equal(ps_patches_init(&P, q ? 6 : 1, &e), 0);
		sky_of(&a, 434, 283, 52.0, 170.0, 0);
		sky_of(&b, 434, 283, 52.0, 170.0, 1);
		ps_sky_vector(&a, &P, PS_SKY_DIFFUSE, va);
		ps_sky_vector(&b, &P, PS_SKY_DIFFUSE, vb);
		{
			double sa = 0, sb = 0;
			for (int i = 1; i < P.n; i++) {
				sa += va[3 * i + 1] * sin(P.alt[i]) * P.omega[i];
				sb += vb[3 * i + 1] * sin(P.alt[i]) * P.omega[i];
			}
			sa /= a.dif_lum / PS_WHITE_EFFICACY * a.opt.sky_color[1];
			sb /= b.dif_lum / PS_WHITE_EFFICACY * b.opt.sky_color[1];
			assert_true(fabs(sb - 1) < 1e-12);
			worst[q] = sa - 1;
		}
		ps_patches_free(&P);
	}
	print_message("# gendaymtx's table sine puts the patches' horizontal illuminance %+.2e (MF 1) "
	              "and %+.2e (MF 6) off the diffuse; the exact sine 0\n", worst[0], worst[1]);
	assert_true(fabs(worst[0]) < 2e-3 && fabs(worst[1]) < 2e-3);
}

static double max_rel_change(const double *a, const double *b, int n)
{
	double w = 0;
	for (int i = 0; i < 3 * n; i++) {
		double m = fmax(fabs(a[i]), fabs(b[i]));
		if (m > 0 && fabs(a[i] - b[i]) / m > w)
			w = fabs(a[i] - b[i]) / m;
	}
	return w;
}

static void extreme_cases(void **state)
{
	struct ps_patches P;
	struct ps_err e;
	struct ps_sky s, t;
	double v[3 * 146], u[3 * 146], jump_eff[8], jump_sky[8];
	(void)state;
	assert_int_equal(ps_patches_init(&P, 1, &e), 0);
	/* zero diffuse: no sky, the sun and the ground only */
	sky_of(&s, 800, 0, 60, 180, 1);
	ps_sky_vector(&s, &P, PS_SKY_ALL, v);
	assert_true(s.model.epsilon == 11.9 && s.model.bin == 7 && s.dif_lum == 0);
	{
		double sun = 0;
		for (int i = 1; i < P.n; i++)
			sun += v[3 * i + 1] * P.omega[i];
		assert_true(fabs(sun - s.dir_lum / PS_WHITE_EFFICACY) < 1e-9 * sun);
	}
	assert_true(fabs(v[1] - s.dir_lum * sin(60 * DEG) / M_PI / PS_WHITE_EFFICACY * 0.2) < 1e-12);
	assert_int_equal(ps_sky_normalise(&s, 1e-10, &e), 0);
	/* the sun crossing the horizon: the diffuse sky and the ground move
	 * continuously (the model holds the sun's zenith at 90 degrees) */
	sky_of(&s, 200, 80, -1e-4, 90, 1);
	sky_of(&t, 200, 80, 1e-4, 90, 1);
	ps_sky_vector(&s, &P, PS_SKY_GROUND | PS_SKY_DIFFUSE, v);
	ps_sky_vector(&t, &P, PS_SKY_GROUND | PS_SKY_DIFFUSE, u);
	assert_true(max_rel_change(v, u, P.n) < 1e-5);
	/* and past 87 degrees (the zenith held at 3) */
	sky_of(&s, 800, 100, 87 - 1e-6, 90, 1);
	sky_of(&t, 800, 100, 87 + 1e-6, 90, 1);
	ps_sky_vector(&s, &P, PS_SKY_GROUND | PS_SKY_DIFFUSE, v);
	ps_sky_vector(&t, &P, PS_SKY_GROUND | PS_SKY_DIFFUSE, u);
	assert_true(max_rel_change(v, u, P.n) < 1e-5);
	/* clearness on every bin edge: the edge belongs to the bin above, and
	 * the model jumps there (its coefficients are per bin) */
	for (int k = 1; k < PS_PEREZ_NBINS; k++) {
		double edge = ps_perez_bin_edge(k), z = 30 * DEG, kk = 1.041 * z * z * z;
		double dn = 100 * (edge - 1) * (1 + kk);   /* clearness = edge with 100 W/m2 diffuse */
		assert_int_equal(ps_perez_bin(edge), k);
		assert_int_equal(ps_perez_bin(nextafter(edge, 0)), k - 1);
		sky_of(&s, dn * (1 - 1e-9), 100, 60, 180, 1);
		sky_of(&t, dn * (1 + 1e-9), 100, 60, 180, 1);
		assert_int_equal(s.model.bin, k - 1);
		assert_int_equal(t.model.bin, k);
		ps_sky_vector(&s, &P, PS_SKY_DIFFUSE, v);
		ps_sky_vector(&t, &P, PS_SKY_DIFFUSE, u);
		for (int i = 0; i < 3 * P.n; i++)
			assert_true(isfinite(v[i]) && isfinite(u[i]) && v[i] >= 0 && u[i] >= 0);
		jump_eff[k] = t.dif_lum / s.dif_lum - 1;
		/* the distribution's jump: patch radiance per unit of diffuse illuminance */
		for (int i = 0; i < 3 * P.n; i++) {
			v[i] /= s.dif_lum;
			u[i] /= t.dif_lum;
		}
		jump_sky[k] = max_rel_change(v, u, P.n);
		assert_int_equal(ps_sky_normalise(&s, 1e-10, &e), 0);
		assert_int_equal(ps_sky_normalise(&t, 1e-10, &e), 0);
	}
	print_message("# at the clearness bin edges 1.065 ... 6.2 the diffuse efficacy jumps by "
	              "%+.1f%% %+.1f%% %+.1f%% %+.1f%% %+.1f%% %+.1f%% %+.1f%%\n",
	              100 * jump_eff[1], 100 * jump_eff[2], 100 * jump_eff[3], 100 * jump_eff[4],
	              100 * jump_eff[5], 100 * jump_eff[6], 100 * jump_eff[7]);
	print_message("# and the normalised patch radiances by up to %.0f%% %.0f%% %.0f%% %.0f%% %.0f%% "
	              "%.0f%% %.0f%%\n",
	              100 * jump_sky[1], 100 * jump_sky[2], 100 * jump_sky[3], 100 * jump_sky[4],
	              100 * jump_sky[5], 100 * jump_sky[6], 100 * jump_sky[7]);
	for (int k = 1; k < PS_PEREZ_NBINS; k++)
		assert_true(fabs(jump_eff[k]) < 0.35 && jump_sky[k] < 1.0);
	/* bin 5 with the sun on the horizon and a bright sky: a > 0 and b > 0,
	 * so a exp(b / cos zeta) grows without bound towards the horizon; the
	 * continuous sky holds cos zeta at 0.01, the patches sample their centres */
	sky_eps_delta(&s, 3.65, 0.6, 0.5, 90);
	assert_int_equal(s.model.bin, 5);
	assert_true(s.model.coef[0] > 0 && s.model.coef[1] > 0.3);
	{
		struct ps_sky s2 = s;
		struct ps_patches P6;
		double *v6, up[3] = { 0, 0, 1 }, flat[3] = { 0, 1, 1e-3 }, lo[3], hi[3], ratio[2];
		assert_int_equal(ps_sky_normalise(&s, 1e-8, &e), 0);
		assert_int_equal(ps_sky_normalise(&s2, 1e-11, &e), 0);
		assert_true(isfinite(s.norm) && fabs(s.norm / s2.norm - 1) < 2e-8);
		ps_sky_radiance(&s, up, PS_SKY_DIFFUSE, hi);
		ps_sky_radiance(&s, flat, PS_SKY_DIFFUSE, lo);
		assert_int_equal(ps_patches_init(&P6, 6, &e), 0);
		v6 = malloc((size_t)P6.n * 3 * sizeof *v6);
		ps_sky_vector(&s, &P, PS_SKY_DIFFUSE, v);
		ps_sky_vector(&s, &P6, PS_SKY_DIFFUSE, v6);
		for (int i = 0; i < 3 * P6.n; i++)
			assert_true(isfinite(v6[i]) && v6[i] >= 0);
		ratio[0] = v[3 * 1 + 1] / v[3 * (P.n - 1) + 1];
		ratio[1] = v6[3 * 1 + 1] / v6[3 * (P6.n - 1) + 1];
		print_message("# bin 5, sun 0.5 deg up, brightness 0.6: a = %.3f, b = %.3f; horizon over "
		              "zenith: continuous %.2g (at cos 0.01), patches MF 1 %.3g, MF 6 %.3g\n",
		              s.model.coef[0], s.model.coef[1], lo[1] / hi[1], ratio[0], ratio[1]);
		assert_true(isfinite(lo[1]) && lo[1] > hi[1] && ratio[1] > ratio[0]);
		free(v6);
		ps_patches_free(&P6);
	}
	/* dark */
	sky_of(&s, 0, 0, 30, 180, 1);
	ps_sky_vector(&s, &P, PS_SKY_ALL, v);
	for (int i = 0; i < 3 * P.n; i++)
		assert_true(v[i] == 0.0);
	ps_patches_free(&P);
}

/* the pictures partition the fisheye: their coefficients add up to the whole */
static void coefficient_pictures(void **state)
{
	struct ps_patches P;
	struct ps_sensor cosine;
	struct ps_view v;
	struct ps_weights w;
	struct ps_err e;
	const double coef[3] = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B };
	int res[2] = { 64, 256 };
	double worst[2];
	(void)state;
	assert_int_equal(ps_patches_init(&P, 1, &e), 0);
	assert_int_equal(ps_sensor_builtin(&cosine, PS_SENS_COSINE, &e), 0);
	ps_view_default_fisheye(&v);
	v.vd[2] = 1.0;   /* looking up, north at the top */
	for (int r = 0; r < 2; r++) {
		int n = res[r], *map = malloc((size_t)n * n * sizeof *map);
		double c[146], sum = 0;
		assert_int_equal(ps_dcpic_map(&P, &v, n, n, map, &e), 0);
		assert_int_equal(ps_weights_build(&w, &cosine, 0, &v, n, n, PS_W_EXACT, &e), 0);
		assert_int_equal(ps_dcpic_coefficients(&w, map, P.n, coef, c, &e), 0);
		worst[r] = 0;
		for (int i = 0; i < P.n; i++) {
			sum += c[i];
			if (i > 0 && fabs(c[i] - patch_cos(&P, i)) / patch_cos(&P, i) > worst[r])
				worst[r] = fabs(c[i] - patch_cos(&P, i)) / patch_cos(&P, i);
		}
		/* the ground: only pixels whose centre is below the horizon but
		 * whose footprint reaches above it */
		assert_true(c[0] >= 0 && c[0] < 1e-3 * M_PI);
		assert_true(fabs(sum - M_PI) < 1e-12);
		free(map);
		ps_weights_free(&w);
	}
	print_message("# exact coefficient pictures, cosine sensor, MF 1: worst patch %.2f%% off its "
	              "integral at 64 x 64, %.2f%% at 256 x 256 (pixel centres decide the patch)\n",
	              100 * worst[0], 100 * worst[1]);
	assert_true(worst[1] < worst[0]);
	/* written and read back: the same coefficient, radiance exactly 1 */
	{
		char dir[] = "/tmp/pstdcXXXXXX", fmt[64], path[96];
		int n = 32, *map = malloc((size_t)n * n * sizeof *map);
		struct ps_picture pic, mem;
		struct ps_response a, b;
		double rgb[3];
		assert_non_null(mkdtemp(dir));
		snprintf(fmt, sizeof fmt, "%s/dc_%%03d.hdr", dir);
		assert_int_equal(ps_dcpic_map(&P, &v, n, n, map, &e), 0);
		assert_int_equal(ps_dcpic_write(fmt, &P, map, n, n, NULL, &e), 0);
		snprintf(path, sizeof path, "%s/dc_145.hdr", dir);
		assert_int_equal(ps_picture_read(&pic, path, &e), 0);
		assert_int_equal(ps_dcpic_picture(map, n, n, 145, &mem, &e), 0);
		assert_int_equal(ps_weights_build(&w, &cosine, 0, &v, n, n, PS_W_EXACT, &e), 0);
		assert_int_equal(ps_integrate(&w, &pic, coef, &a, &e), 0);
		assert_int_equal(ps_integrate(&w, &mem, coef, &b, &e), 0);
		assert_true(a.response == b.response && a.response > 0);
		ps_picture_get(&pic, n / 2, n / 2, rgb);
		assert_true(rgb[0] == 1.0 && rgb[1] == 1.0 && rgb[2] == 1.0);
		assert_int_equal(ps_dcpic_write("/tmp/no%s", &P, map, n, n, NULL, &e), -1);
		ps_picture_free(&pic);
		ps_picture_free(&mem);
		ps_weights_free(&w);
		for (int i = 0; i < P.n; i++) {
			snprintf(path, sizeof path, "%s/dc_%03d.hdr", dir, i);
			unlink(path);
		}
		rmdir(dir);
		free(map);
	}
	ps_sensor_free(&cosine);
	ps_patches_free(&P);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(reference_matrix),
		cmocka_unit_test(implied_sun_positions),
		cmocka_unit_test(solar_position),
		cmocka_unit_test(patch_geometry),
		cmocka_unit_test(sky_integrates_to_diffuse),
		cmocka_unit_test(table_sine_normalisation),
		cmocka_unit_test(extreme_cases),
		cmocka_unit_test(coefficient_pictures),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
