/* SPDX-License-Identifier: ISC */
/* Calibration arithmetic against analytic answers: a first-order settling
 * with seeded noise, exact and noisy lines, exact daylight ratios, and the
 * drift detector's timing. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <string.h>
#include <cmocka.h>

#include "calfit.h"

/* a small reproducible Gaussian (xorshift + Box-Muller) */
static uint64_t rng_state;
static double uniform(void)
{
	rng_state ^= rng_state << 13;
	rng_state ^= rng_state >> 7;
	rng_state ^= rng_state << 17;
	return ((rng_state >> 11) + 0.5) / 9007199254740992.0;
}
static double gauss(void)
{
	return sqrt(-2 * log(uniform())) * cos(2 * M_PI * uniform());
}

/* v(t) = 2 + 1.5 exp(-t / tau) + N(0, 0.002): settled means land within 4
 * standard errors (plus the floor) of 2 (the standard error comes from 8
 * readings: Student's t with 7 degrees of freedom, 99.5 % at 3.5), and settling is never declared
 * while the transient is still more than 20 sigma away. */
static void settling_of_a_lag(void **state)
{
	const double A = 2, B = 1.5, sigma = 0.002, floor = 1e-4;
	int outside = 0, runs = 0;
	(void)state;
	/* time constants up to a quarter of the window: a window judges a
	 * transient only when it spans several time constants */
	for (int tau100 = 10; tau100 <= 50; tau100 += 20) {
		double tau = tau100 / 100.0;
		for (int seed = 1; seed <= 100; seed++) {
			struct psd_calfit_settle s;
			double mean, se, t;
			int done = 0;
			rng_state = 0x9e3779b97f4a7c15ull * (uint64_t)(seed + 1000 * tau100);
			psd_calfit_settle_init(&s, 2.0, 8, 3.0, floor);
			for (t = 0; t < 60 && !done; t += 0.25) {
				double v = A + B * exp(-t / tau) + sigma * gauss();
				done = psd_calfit_settle_add(&s, t, v, &mean, &se);
			}
			assert_true(done);
			/* the transient at the window's start was small */
			assert_true(B * exp(-(t - 0.25 - 2.0) / tau) < 20 * sigma);
			runs++;
			outside += fabs(mean - A) > 4 * se + floor;
		}
	}
	/* 1.3 % of these 300 runs fall outside; allow 3 % */
	assert_true(outside <= runs * 3 / 100);
}

static void night_fit_exact_line(void **state)
{
	struct psd_calfit_level p[6];
	struct psd_calfit_line f;
	char err[128];
	const double levels[6] = { 1, 0.75, 0.5, 0.25, 0.1, 0 };
	(void)state;
	for (int i = 0; i < 6; i++)
		p[i] = (struct psd_calfit_level){ levels[i], 0.05 + 0.547 * levels[i], 0.001,
		                                 12 + 1265.4 * levels[i] };
	assert_int_equal(psd_calfit_night(p, 6, &f, err, sizeof err), 0);
	assert_true(fabs(f.gain / 0.547 - 1) < 1e-12);
	assert_true(fabs(f.offset - 0.05) < 1e-12);
	assert_true(fabs(f.r2 - 1) < 1e-12);
	assert_true(f.max_resid_pct < 1e-9);
	assert_true(fabs(f.lux_gain / 1265.4 - 1) < 1e-12);
	assert_true(fabs(f.lux_offset - 12) < 1e-9);
}

/* noise of known sigma on each point: the fitted gain lies within 3 of its
 * quoted standard errors of the truth in at least 97 % of 400 runs */
static void night_fit_noisy(void **state)
{
	int inside = 0;
	(void)state;
	for (int seed = 1; seed <= 400; seed++) {
		struct psd_calfit_level p[6];
		struct psd_calfit_line f;
		char err[128];
		rng_state = 0xdeadbeefcafef00dull * (uint64_t)seed;
		for (int i = 0; i < 6; i++) {
			double u = i / 5.0;
			p[i] = (struct psd_calfit_level){ u, 0.05 + 0.547 * u + 0.003 * gauss(), 0.003, NAN };
		}
		assert_int_equal(psd_calfit_night(p, 6, &f, err, sizeof err), 0);
		assert_true(f.gain_se > 0.001 && f.gain_se < 0.01);
		inside += fabs(f.gain - 0.547) <= 3 * f.gain_se;
	}
	assert_true(inside >= 388);
}

static void night_fit_refuses(void **state)
{
	struct psd_calfit_level same[3] = { { 0.5, 1, 0.01, NAN }, { 0.5, 1.1, 0.01, NAN }, { 0.5, 0.9, 0.01, NAN } };
	struct psd_calfit_level nan[3] = { { 0, 1, 0.01, NAN }, { 0.5, NAN, 0.01, NAN }, { 1, 0.9, 0.01, NAN } };
	struct psd_calfit_line f;
	char err[128];
	(void)state;
	assert_int_equal(psd_calfit_night(same, 2, &f, err, sizeof err), -1);
	assert_string_equal(err, "a night fit needs at least 3 levels (have 2)");
	assert_int_equal(psd_calfit_night(same, 3, &f, err, sizeof err), -1);
	assert_string_equal(err, "every point is at one level: the gain is undetermined");
	assert_int_equal(psd_calfit_night(nan, 3, &f, err, sizeof err), -1);
	assert_string_equal(err, "level 2 is not a number");
}

/* V = 0.05 + 0.547 u + vd, E = 1265.4 u + 236.2/0.5 vd: the ratio is exactly
 * 472.4 lux per volt whatever the level and the daylight */
static void day_ratio_exact(void **state)
{
	struct psd_calfit_sample s[5];
	struct psd_calfit_ratio f;
	char err[128];
	const double r = 236.2 / 0.5;
	(void)state;
	for (int i = 0; i < 5; i++) {
		double u = 0.1 + 0.2 * i, vd = 0.5 + 0.7 * i;
		s[i] = (struct psd_calfit_sample){ 36000 + 600 * i, u, 0.05 + 0.547 * u + vd, 1265.4 * u + r * vd };
	}
	assert_int_equal(psd_calfit_day(s, 5, 0.05, 0.547, 1265.4, 0.1, &f, err, sizeof err), 0);
	assert_true(fabs(f.ratio / r - 1) < 1e-12);
	assert_true(f.sd < 1e-9);
	assert_int_equal(f.n, 5);
	assert_true(fabs(f.mean_tod - 37200) < 1e-9);
	/* the paper's Table 2 sign: simulated above measured is positive */
	assert_true(fabs(psd_calfit_error_pct(1.1 * r, r) - 10) < 1e-9);
	/* too little daylight: refused, not a NaN */
	assert_int_equal(psd_calfit_day(s, 5, 0.05, 0.547, 1265.4, 10, &f, err, sizeof err), -1);
	assert_string_equal(err, "0 of 5 samples have daylight above 10 V: at least 2 are needed");
}

static void drift_timing(void **state)
{
	struct psd_calfit_drift d;
	int flagged_at = -1, cleared_at = -1;
	(void)state;
	psd_calfit_drift_init(&d, 0.2, 3600, 0.1);
	/* matched for two hours, then the sensor is half covered (the measured
	 * ratio doubles: ln 2 = 0.69 > 0.2), uncovered again at 6 h */
	for (int t = 0; t <= 8 * 3600; t += 60) {
		double vd = 2.0 * (t >= 7200 && t < 21600 ? 0.5 : 1), sim = 472.4;
		int r = psd_calfit_drift_update(&d, t, vd, sim * 2.0, sim);
		if (r > 0)
			flagged_at = t;
		if (r < 0)
			cleared_at = t;
	}
	assert_int_equal(flagged_at, 7200 + 3600);   /* exactly the hold after it began */
	assert_int_equal(cleared_at, 21600);
	/* a 50-minute excursion never flags; darkness (in both signals) is no
	 * judgement */
	psd_calfit_drift_init(&d, 0.2, 3600, 0.1);
	for (int t = 0; t <= 8 * 3600; t += 60) {
		double vd = t >= 7200 && t < 10200 ? 1.0 : 2.0;
		assert_int_equal(psd_calfit_drift_update(&d, t, vd, 944.8, 472.4), 0);
		assert_int_equal(psd_calfit_drift_update(&d, t + 30, 0.01, 4.7, 472.4), 0);
	}
}

/* A sensor covered completely: no daylight in its signal (even a little
 * below zero from noise), plenty on the desk.  The task's daylight alone
 * qualifies the sample, and the ratio is off by the floor of 1000x. */
static void drift_covered_sensor(void **state)
{
	struct psd_calfit_drift d;
	int flagged_at = -1;
	(void)state;
	psd_calfit_drift_init(&d, 0.25, 1800, 0.05);
	for (int t = 0; t <= 3 * 3600; t += 60) {
		double vd = t >= 3600 ? (t % 120 ? -0.002 : 0.001) : 2.0;
		int r = psd_calfit_drift_update(&d, t, vd, 944.8, 472.4);
		if (r > 0)
			flagged_at = t;
	}
	assert_int_equal(flagged_at, 3600 + 1800);
	assert_true(d.last_ln > log(999) && d.last_ln < log(1001));
}

/* An evening's judged sample, then the dark: the dark sample is not judged,
 * so no drift figure is left from the evening (status showed -99.9 % all
 * night beside drift: false). */
static void drift_dark_not_judged(void **state)
{
	struct psd_calfit_drift d;
	(void)state;
	psd_calfit_drift_init(&d, 0.25, 1800, 0.05);
	psd_calfit_drift_update(&d, 0, 0.2, 0.1, 472.4);   /* dusk: judged, far off */
	assert_true(isfinite(d.last_ln) && d.last_ln < -5);
	psd_calfit_drift_update(&d, 60, 0.001, 0.0, 472.4);   /* night: too dark */
	assert_true(isnan(d.last_ln));
}

/* Night with an unknown sensor offset at the judging threshold: the
 * daylight part of the signal flickers across it on noise, the task sees
 * none.  Each judged sample is out, but the dark ones between them end the
 * excursion: no drift in a whole night. */
static void drift_night_offset(void **state)
{
	struct psd_calfit_drift d;
	unsigned seed = 12345;
	(void)state;
	psd_calfit_drift_init(&d, 0.25, 3600, 0.05);
	for (int t = 0; t <= 10 * 3600; t += 60) {
		double vd, lux;
		seed = seed * 1103515245u + 12345u;
		vd = 0.05 + 0.002 * (((seed >> 16) & 0x7fff) / 16383.5 - 1);   /* 0.048 to 0.052 */
		seed = seed * 1103515245u + 12345u;
		lux = 2.0 * (((seed >> 16) & 0x7fff) / 16383.5 - 1);           /* +-2 lx meter noise */
		assert_int_equal(psd_calfit_drift_update(&d, t, vd, lux, 472.4), 0);
	}
	assert_false(d.flagged);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(settling_of_a_lag),
		cmocka_unit_test(night_fit_exact_line),
		cmocka_unit_test(night_fit_noisy),
		cmocka_unit_test(night_fit_refuses),
		cmocka_unit_test(day_ratio_exact),
		cmocka_unit_test(drift_timing),
		cmocka_unit_test(drift_covered_sensor),
		cmocka_unit_test(drift_night_offset),
		cmocka_unit_test(drift_dark_not_judged),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
