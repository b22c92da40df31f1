/* SPDX-License-Identifier: ISC */
/* Colour filters to R,G,B coefficients, f1' and reading errors, against
 * answers this test computes itself from the CIE tables (plain loops, its own
 * 3 x 3 inverse), and bad filter files. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "cie.h"
#include "filter.h"

/* a filter file from a function of wavelength, every nm from lo to hi */
static void make_filter(struct ps_filter *f, double lo, double hi, double (*fn)(double))
{
	char *text = malloc(64 * 2000);
	size_t n = 0;
	struct ps_err e;
	for (double nm = lo; nm <= hi; nm += 1.0)
		n += (size_t)sprintf(text + n, "%g %.17g\n", nm, fn(nm));
	if (ps_filter_parse(f, text, n, "gen.txt", PS_FILTER_FRACTION, &e) != 0)
		fail_msg("%s", e.msg);
	free(text);
}

static double vbar(double nm)
{
	return ps_cie_spectrum_at(ps_cie_v(), nm);
}

static double xbar(double nm)
{
	return ps_cie_spectrum_at(ps_cie_cmf(0), nm);
}

static double flat(double nm)
{
	(void)nm;
	return 0.8;
}

static double silicon(double nm)
{
	/* a silicon photodiode's responsivity rises about linearly with wavelength;
	 * the file starts at 400 nm, so the response is 0 below */
	return nm < 400 ? 0.0 : nm / 1100.0;
}

static double shifted(double nm)
{
	return ps_cie_spectrum_at(ps_cie_v(), nm - 20.0);
}

/* sum over the 1-nm grid lo..hi of f(nm) * g(nm), trapezoid ends */
static double isum(double lo, double hi, double (*f)(double), const struct ps_spectrum *g)
{
	double s = 0;
	for (double nm = lo; nm <= hi; nm += 1.0)
		s += (nm == lo || nm == hi ? 0.5 : 1.0) * f(nm) * (g ? ps_cie_spectrum_at(g, nm) : 1.0);
	return s;
}

static void v_lambda_gives_the_psens_defaults(void **state)
{
	struct ps_filter f;
	struct ps_filter_report r;
	struct ps_err e;
	(void)state;
	make_filter(&f, 360, 830, vbar);
	assert_int_equal(ps_filter_analyse(&f, "A", &r, &e), 0);
	/* 6 significant digits, as psens's defaults are given */
	assert_true(fabs(r.rgb[0] / 0.265074126 - 1) < 5e-7);
	assert_true(fabs(r.rgb[1] / 0.670114631 - 1) < 5e-7);
	assert_true(fabs(r.rgb[2] / 0.064811243 - 1) < 5e-7);
	assert_true(r.residual < 1e-12);
	assert_true(r.f1p < 1e-12);
	for (int i = 0; i < r.nillum; i++) {
		assert_true(fabs(r.illum[i].spectral) < 1e-12);
		assert_true(fabs(r.illum[i].rgb) < 1e-12);
	}
	assert_int_equal(r.nillum, 13);
	ps_filter_free(&f);
}

/* x-bar is in the span: residual 0, coefficients = the X row of Radiance's
 * RGB-to-XYZ matrix, computed here by hand from the chromaticities. */
static void x_bar_projects_exactly(void **state)
{
	static const double xy[4][2] = { { .64, .33 }, { .29, .60 }, { .15, .06 }, { .3333, .3333 } };
	double P[3][3], W[3], S[3], det;
	struct ps_filter f;
	struct ps_filter_report r;
	struct ps_err e;
	(void)state;
	for (int k = 0; k < 3; k++) {
		P[0][k] = xy[k][0] / xy[k][1];
		P[1][k] = 1;
		P[2][k] = (1 - xy[k][0] - xy[k][1]) / xy[k][1];
	}
	W[0] = xy[3][0] / xy[3][1];
	W[1] = 1;
	W[2] = (1 - xy[3][0] - xy[3][1]) / xy[3][1];
	/* Cramer's rule for P S = W */
	det = P[0][0] * (P[1][1] * P[2][2] - P[1][2] * P[2][1]) - P[0][1] * (P[1][0] * P[2][2] - P[1][2] * P[2][0]) +
	      P[0][2] * (P[1][0] * P[2][1] - P[1][1] * P[2][0]);
	for (int k = 0; k < 3; k++) {
		double Q[3][3];
		memcpy(Q, P, sizeof Q);
		for (int i = 0; i < 3; i++)
			Q[i][k] = W[i];
		S[k] = (Q[0][0] * (Q[1][1] * Q[2][2] - Q[1][2] * Q[2][1]) - Q[0][1] * (Q[1][0] * Q[2][2] - Q[1][2] * Q[2][0]) +
		        Q[0][2] * (Q[1][0] * Q[2][1] - Q[1][1] * Q[2][0])) / det;
	}
	make_filter(&f, 360, 830, xbar);
	assert_int_equal(ps_filter_analyse(&f, "A", &r, &e), 0);
	assert_true(fabs(r.xyz[0] - 1) < 1e-10 && fabs(r.xyz[1]) < 1e-10 && fabs(r.xyz[2]) < 1e-10);
	assert_true(r.residual < 1e-10);
	for (int k = 0; k < 3; k++)
		assert_true(fabs(r.rgb[k] - P[0][k] * S[k]) < 1e-9);
	ps_filter_free(&f);
}

/* A flat filter reads the illuminants' full power: its error follows from
 * the tables alone. */
static void flat_filter_errors(void **state)
{
	struct ps_filter f;
	struct ps_filter_report r;
	struct ps_err e;
	const struct ps_spectrum *a = ps_cie_illuminant("A");
	double ka;
	(void)state;
	make_filter(&f, 360, 830, flat);
	assert_int_equal(ps_filter_analyse(&f, "A", &r, &e), 0);
	ka = isum(360, 830, flat, a) / isum(360, 830, vbar, a);
	for (int i = 0; i < r.nillum; i++) {
		const struct ps_spectrum *il = ps_cie_illuminant(r.illum[i].name);
		double want = (isum(360, 830, flat, il) / isum(360, 830, vbar, il)) / ka - 1;
		if (fabs(r.illum[i].spectral - want) > 1e-12)
			fail_msg("%s: %g vs %g", r.illum[i].name, r.illum[i].spectral, want);
	}
	/* A spends most of its power in the red where V is small: a flat sensor
	 * calibrated under A under-reads the bluer D65 */
	assert_true(r.illum[1].spectral < -0.05);
	ps_filter_free(&f);
}

/* f1' by its definition, computed here */
static double f1p_of(double (*fn)(double))
{
	const struct ps_spectrum *a = ps_cie_illuminant("A");
	double k = isum(380, 780, vbar, a) / isum(380, 780, fn, a), num = 0, den = 0;
	for (double nm = 380; nm <= 780; nm += 1.0) {
		double w = (nm == 380 || nm == 780) ? 0.5 : 1.0;
		num += w * fabs(k * fn(nm) - vbar(nm));
		den += w * vbar(nm);
	}
	return num / den;
}

static void f1_prime_of_shifted_and_silicon(void **state)
{
	struct ps_filter f;
	struct ps_filter_report r;
	struct ps_err e;
	(void)state;
	make_filter(&f, 380, 850, shifted);
	assert_int_equal(ps_filter_analyse(&f, "A", &r, &e), 0);
	assert_true(fabs(r.f1p - f1p_of(shifted)) < 1e-12);
	/* a 20 nm shift of a curve 100 nm wide is a large mismatch */
	assert_true(r.f1p > 0.2 && r.f1p < 0.6);
	assert_true(r.residual > 0.01);
	ps_filter_free(&f);
	make_filter(&f, 400, 1100, silicon);
	assert_int_equal(ps_filter_analyse(&f, "D65", &r, &e), 0);
	assert_true(fabs(r.f1p - f1p_of(silicon)) < 1e-12);
	assert_true(r.f1p > 0.5);
	assert_true(r.outside);   /* 400 nm start: 0 from 380 to 400 */
	assert_string_equal(r.illum[1].name, "D65");
	assert_true(fabs(r.illum[1].spectral) < 1e-12);   /* the calibration illuminant */
	ps_filter_free(&f);
}

static void percent_and_bad_files(void **state)
{
	static const struct {
		const char *text, *want;
	} bad[] = {
		{ "500 1\n400 1\n", "bad.txt:2: wavelength 400 nm comes after 500 nm" },
		{ "400 1\n400 1\n", "bad.txt:2: wavelength 400 nm appears twice" },
		{ "400 1\n500 -0.1\n", "bad.txt:2: negative transmittance" },
		{ "# head\n400 x\n", "bad.txt:2: 'x' is not a number" },
		{ "abc 1\n", "bad.txt:1: 'abc' is not a wavelength" },
		{ "400 1 2\n", "bad.txt:1: more than two numbers" },
		{ "500 1\n", "at least two points" },
		{ "900 1\n1000 1\n", "does not overlap 380-780" },
		{ "", "at least two points" },
	};
	struct ps_filter f;
	struct ps_err e;
	const char *pct = "# percent\n400 50\n700 100\n";
	(void)state;
	for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
		assert_int_equal(ps_filter_parse(&f, bad[k].text, strlen(bad[k].text), "bad.txt",
		                                 PS_FILTER_PERCENT_AUTO, &e), -1);
		if (!strstr(e.msg, bad[k].want))
			fail_msg("case %zu: '%s' lacks '%s'", k, e.msg, bad[k].want);
	}
	assert_int_equal(ps_filter_parse(&f, pct, strlen(pct), "p.txt", PS_FILTER_PERCENT_AUTO, &e), 0);
	assert_true(f.percent);
	assert_true(fabs(ps_filter_at(&f, 550) - 0.75) < 1e-15);
	assert_true(ps_filter_at(&f, 399) == 0.0 && ps_filter_at(&f, 701) == 0.0);
	ps_filter_free(&f);
	assert_int_equal(ps_filter_parse(&f, pct, strlen(pct), "p.txt", PS_FILTER_FRACTION, &e), 0);
	assert_false(f.percent);
	assert_true(fabs(ps_filter_at(&f, 550) - 75) < 1e-13);
	ps_filter_free(&f);
	assert_int_equal(ps_filter_read(&f, "/nonexistent/f.txt", PS_FILTER_PERCENT_AUTO, &e), -1);
	assert_non_null(strstr(e.msg, "/nonexistent/f.txt"));
}

static void tables_are_whole(void **state)
{
	(void)state;
	/* y-bar(555) = 1 = V(555); grids as documented */
	assert_true(fabs(ps_cie_spectrum_at(ps_cie_cmf(1), 555) - 1.0) < 1e-12);
	assert_true(fabs(ps_cie_spectrum_at(ps_cie_v(), 555) - 1.0) < 1e-12);
	assert_int_equal(ps_cie_cmf(0)->n, 471);
	assert_true(ps_cie_illuminant("A")->start == 300 && ps_cie_illuminant("A")->step == 1);
	assert_true(ps_cie_illuminant("HP3")->step == 5);
	assert_true(fabs(ps_cie_spectrum_at(ps_cie_illuminant("A"), 560) - 100.0) < 1e-12);
	assert_null(ps_cie_illuminant("XYZ"));
	for (int i = 0; ps_cie_illuminant_names[i]; i++)
		assert_non_null(ps_cie_illuminant(ps_cie_illuminant_names[i]));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(v_lambda_gives_the_psens_defaults),
		cmocka_unit_test(x_bar_projects_exactly),
		cmocka_unit_test(flat_filter_errors),
		cmocka_unit_test(f1_prime_of_shifted_and_silicon),
		cmocka_unit_test(percent_and_bad_files),
		cmocka_unit_test(tables_are_whole),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
