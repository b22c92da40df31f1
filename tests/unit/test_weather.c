/* SPDX-License-Identifier: ISC */
/* Weather files: .wea and .epw read to the same series; every bad input of
 * the issue (missing or extra fields, NaN, negative irradiance, times out of
 * order, a header that names no site, bad dates) gives file:line and leaves
 * nothing behind; leap years; the missing dew point's substitution; polar
 * day and night. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "sky.h"
#include "sun.h"
#include "weather.h"

#define DEG (M_PI / 180.0)

static const char wea_head[] = "place Mountain View/Moffet N_USA\nlatitude 37.42\n"
                               "longitude 122.05\ntime_zone 120\nsite_elevation 12.0\n"
                               "weather_data_file_units 1\n";

/* An .epw with the given records (each "month,day,hour,dew,dni,dhi"). */
static char *epw_text(const char *location, const char *const *rec, int n)
{
	size_t cap = 4096 + (size_t)n * 400, len = 0;
	char *t = malloc(cap);
	len += (size_t)snprintf(t + len, cap - len, "%s\n",
	                        location ? location
	                                 : "LOCATION,Mountain View,CA,USA,TMY3,724945,37.42,-122.05,-8.0,12.0");
	len += (size_t)snprintf(t + len, cap - len,
	                        "DESIGN CONDITIONS,0\nTYPICAL/EXTREME PERIODS,0\nGROUND TEMPERATURES,0\n"
	                        "HOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0\nCOMMENTS 1,test\nCOMMENTS 2,\n"
	                        "DATA PERIODS,1,1,Data,Sunday, 1/ 1,12/31\n");
	for (int i = 0; i < n; i++) {
		int mo, da, hr;
		double dni, dhi;
		char dew[32] = "";
		if (sscanf(rec[i], "%d,%d,%d,%31[^,],%lf,%lf", &mo, &da, &hr, dew, &dni, &dhi) != 6 &&
		    (sscanf(rec[i], "%d,%d,%d,,%lf,%lf", &mo, &da, &hr, &dni, &dhi) != 5)) {
			len += (size_t)snprintf(t + len, cap - len, "%s\n", rec[i]);   /* raw line */
			continue;
		}
		len += (size_t)snprintf(t + len, cap - len,
		                        "1999,%d,%d,%d,60,?9?9?9?9E0?9?9?9?9?9?9?9?9?9?9?9?9?9?9?9*9*9?9?9?9,"
		                        "10.0,%s,80,101300,0,0,300,%g,%g,%g,999999,999999,999999,9999,"
		                        "180,2.0,5,5,16.0,77777,9,999999999,10,0.100,0,88,0.200,0.0,0.0\n",
		                        mo, da, hr, dew, dni + dhi, dni, dhi);
	}
	return t;
}

static void parse_ok(struct ps_weather *w, const char *text, unsigned flags)
{
	struct ps_err e;
	if (ps_weather_parse(w, text, strlen(text), "t", flags, &e) != 0)
		fail_msg("%s", e.msg);
}

/* the same hours through both readers give the same series */
static void wea_and_epw_agree(void **state)
{
	struct ps_weather a, b;
	const char *rec[] = { "3,21,7,11,13,112", "3,21,13,11,40,305", "6,21,13,11,835,161" };
	char wea[1024], *epw = epw_text(NULL, rec, 3);
	(void)state;
	snprintf(wea, sizeof wea, "%s3 21 6.5 13 112\n3 21 12.5 40 305\n6 21 12.5 835 161\n", wea_head);
	parse_ok(&a, wea, 0);
	parse_ok(&b, epw, 0);
	assert_int_equal(a.format, PS_WX_WEA);
	assert_int_equal(b.format, PS_WX_EPW);
	assert_int_equal(a.n, 3);
	assert_int_equal(b.n, 3);
	assert_string_equal(b.site.name, "Mountain View, USA");
	assert_true(fabs(a.site.lat - b.site.lat) < 1e-12 && fabs(a.site.lon - b.site.lon) < 1e-12);
	assert_true(fabs(a.site.tz - b.site.tz) < 1e-12);
	for (size_t i = 0; i < 3; i++) {
		assert_int_equal(a.step[i].doy, b.step[i].doy);
		assert_true(a.step[i].hour == b.step[i].hour);
		assert_true(a.step[i].dir == b.step[i].dir && a.step[i].dif == b.step[i].dif);
		assert_true(fabs(a.step[i].dew - 11.0) < 1e-12 && fabs(b.step[i].dew - 11.0) < 1e-12);
		assert_true(a.step[i].sun.alt == b.step[i].sun.alt);
	}
	/* the .epw's illuminances when asked: all missing here, so an error */
	{
		struct ps_weather c;
		struct ps_err e;
		assert_int_equal(ps_weather_parse(&c, epw, strlen(epw), "x.epw", PS_WX_EPW_ILLUM, &e), -1);
		assert_non_null(strstr(e.msg, "x.epw:9: direct normal illuminance is missing (999999)"));
	}
	ps_weather_free(&a);
	ps_weather_free(&b);
	free(epw);
}

struct bad {
	const char *body;     /* after the standard .wea header, or a whole file if it starts with '!' */
	const char *want;     /* expected in the message */
};

static void wea_bad_input(void **state)
{
	static const struct bad cases[] = {
		{ "3 21 5.5 0\n", "t:7: 4 fields, expected 5 (month day hour direct diffuse)" },
		{ "3 21 5.5 0 0 0\n", "t:7: 6 fields, expected 5" },
		{ "3 21 5.5 nan 0\n", "t:7: direct 'nan' is not a finite number" },
		{ "3 21 5.5 NaN 0\n", "t:7: direct 'NaN' is not a finite number" },
		{ "3 21 5.5 10 inf\n", "t:7: diffuse 'inf' is not a finite number" },
		{ "3 21 5.5 1e999 3\n", "t:7: direct '1e999' is not a finite number" },
		{ "3 21 5.5 x 0\n", "t:7: direct 'x' is not a number" },
		{ "3 21 5.5 -1 0\n", "t:7: negative direct irradiance -1" },
		{ "3 21 5.5 1 -0.5\n", "t:7: negative diffuse irradiance -0.5" },
		{ "3 21 6.5 1 1\n3 21 5.5 1 1\n", "t:8: 3/21 5.5 h does not come after 3/21 6.5 h (line 7)" },
		{ "3 21 6.5 1 1\n3 21 6.5 1 1\n", "t:8: 3/21 6.5 h does not come after" },
		{ "3 22 6.5 1 1\n3 21 7.5 1 1\n", "t:8: 3/21 7.5 h does not come after 3/22 6.5 h" },
		{ "13 1 6.5 1 1\n", "t:7: month 13 is not 1 to 12" },
		{ "4 31 6.5 1 1\n", "t:7: day 31 is not in April (1 to 30)" },
		{ "2 30 6.5 1 1\n", "t:7: day 30 is not in February (1 to 29)" },
		{ "2 1 24.5 1 1\n", "t:7: hour 24.5 is not 0 to 24" },
		{ "2.5 1 2 1 1\n", "t:7: month and day must be whole numbers" },
		{ "", "t: no data lines after the header" },
		{ "\n\n", "t: no data lines after the header" },
		{ "!latitude 37\n", "t:1: not a weather file" },
		{ "!place \nlatitude 1\n", "t:1: the header names no site" },
		{ "!place X\nlongitude 1\n", "t:2: expected 'latitude <degrees north>'" },
		{ "!place X\nlatitude 91\nlongitude 1\ntime_zone 0\nsite_elevation 0\n", "t:2: latitude 91" },
		{ "!place X\nlatitude 1\nlongitude 1\ntime_zone 200\nsite_elevation 0\n",
		  "t:4: time zone 200 is not -180 to 180 degrees west" },
		{ "!place X\nlatitude 1\nlongitude 1 2\n", "t:3: 'longitude' takes one value" },
		{ "!place X\nlatitude 1\nlongitude 1\ntime_zone 0\nsite_elevation 0\n"
		  "weather_data_file_units 4\n", "t:6: weather_data_file_units 4 is not 1" },
		{ "!place X\nlatitude 1\n", "t:3: the header ends before 'longitude <degrees west>'" },
	};
	(void)state;
	for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
		char text[2048];
		struct ps_weather w;
		struct ps_err e;
		if (cases[k].body[0] == '!')
			snprintf(text, sizeof text, "%s", cases[k].body + 1);
		else
			snprintf(text, sizeof text, "%s%s", wea_head, cases[k].body);
		memset(&e, 0, sizeof e);
		if (ps_weather_parse(&w, text, strlen(text), "t", 0, &e) != -1)
			fail_msg("case %zu accepted: %s", k, cases[k].body);
		if (!strstr(e.msg, cases[k].want))
			fail_msg("case %zu: got '%s', want '%s'", k, e.msg, cases[k].want);
		/* nothing half-written */
		assert_int_equal(w.n, 0);
		assert_null(w.step);
	}
}

static void epw_bad_input(void **state)
{
	static const char *const good = "3,21,7,11,13,112";
	struct {
		const char *loc;
		const char *rec;
		const char *want;
	} cases[] = {
		{ NULL, "1999,3,21,7,60,x,10,11,80", "t:9: 9 fields, expected 35" },
		{ NULL, "3,21,7,11,nan,112", "t:9: direct normal irradiance (field 15) 'nan' is not a finite" },
		{ NULL, "3,21,7,11,-3,112", "t:9: negative direct irradiance -3" },
		{ NULL, "3,21,7,11,13,9999", "t:9: diffuse horizontal irradiance is missing (9999)" },
		{ NULL, "3,21,6,11,13,112", "t:10: 3/21 5.5 h does not come after 3/21 6.5 h (line 9)" },
		{ NULL, "3,21,7,75,13,112", "t:9: dew point 75 C is not between -70 and 70" },
		{ NULL, "2,30,7,10,13,112", "t:9: day 30 is not in February" },
		{ NULL, "3,21,0,10,13,112", "t:9: hour 0 minute 60" },
		{ "LOCATION,,CA,USA,TMY3,1,37.42,-122.05,-8.0,12.0", NULL, "t:1: the header names no site" },
		{ "LOCATION,X,CA,USA,TMY3,1,37.42,-122.05,-8.0", NULL, "t:1: LOCATION has 9 fields" },
		{ "LOCATION,X,CA,USA,TMY3,1,37.42,-222.05,-8.0,1", NULL, "t:1: longitude -222.05" },
		{ "LOCATION,X,CA,USA,TMY3,1,north,-122.05,-8.0,1", NULL, "t:1: latitude 'north' is not a number" },
	};
	(void)state;
	for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
		const char *recs[2];
		int n = 0;
		char *text;
		struct ps_weather w;
		struct ps_err e;
		if (cases[k].rec && strstr(cases[k].want, "does not come after"))
			recs[n++] = good;
		if (cases[k].rec)
			recs[n++] = cases[k].rec;
		else
			recs[n++] = good;
		text = epw_text(cases[k].loc, recs, n);
		if (ps_weather_parse(&w, text, strlen(text), "t", 0, &e) != -1)
			fail_msg("case %zu accepted", k);
		if (!strstr(e.msg, cases[k].want))
			fail_msg("case %zu: got '%s', want '%s'", k, e.msg, cases[k].want);
		assert_int_equal(w.n, 0);
		assert_null(w.step);
		free(text);
	}
	/* a header line out of place */
	{
		const char *t = "LOCATION,X,CA,USA,TMY3,1,37.42,-122.05,-8.0,12.0\nDESIGN CONDITIONS,0\n"
		                "GROUND TEMPERATURES,0\n";
		struct ps_weather w;
		struct ps_err e;
		assert_int_equal(ps_weather_parse(&w, t, strlen(t), "t", 0, &e), -1);
		assert_non_null(strstr(e.msg, "t:3: expected the 'TYPICAL/EXTREME PERIODS,' header line"));
	}
	/* an extra field */
	{
		char *t = epw_text(NULL, (const char *[]){ good }, 1);
		char *nl = strrchr(t, '\n');
		struct ps_weather w;
		struct ps_err e;
		strcpy(nl, ",7\n");
		assert_int_equal(ps_weather_parse(&w, t, strlen(t), "t", 0, &e), -1);
		assert_non_null(strstr(e.msg, "t:9: 36 fields, expected 35"));
		free(t);
	}
}

/* February 29: day 60, and the rest of the year one day later */
static void leap_years(void **state)
{
	char text[1024];
	struct ps_weather w;
	(void)state;
	snprintf(text, sizeof text, "%s2 28 12.5 0 100\n2 29 12.5 0 100\n3 1 12.5 0 100\n"
	                            "12 31 12.5 0 100\n", wea_head);
	parse_ok(&w, text, 0);
	assert_int_equal(w.leap, 1);
	assert_int_equal(w.step[0].doy, 59);
	assert_int_equal(w.step[1].doy, 60);
	assert_int_equal(w.step[2].doy, 61);
	assert_int_equal(w.step[3].doy, 366);
	ps_weather_free(&w);
	snprintf(text, sizeof text, "%s2 28 12.5 0 100\n3 1 12.5 0 100\n12 31 12.5 0 100\n", wea_head);
	parse_ok(&w, text, 0);
	assert_int_equal(w.leap, 0);
	assert_int_equal(w.step[1].doy, 60);
	assert_int_equal(w.step[2].doy, 365);
	/* Feb 29 noon's sun lies between Feb 28's and Mar 1's */
	ps_weather_free(&w);
	snprintf(text, sizeof text, "%s2 28 12.5 0 100\n2 29 12.5 0 100\n3 1 12.5 0 100\n", wea_head);
	parse_ok(&w, text, 0);
	assert_true(w.step[0].sun.alt < w.step[1].sun.alt && w.step[1].sun.alt < w.step[2].sun.alt);
	{
		struct ps_sky_opt o;
		struct ps_sky s;
		struct ps_err e;
		ps_sky_opt_default(&o);
		assert_int_equal(ps_sky_step(&s, &w, 1, &o, &e), 0);
		assert_true(isfinite(s.dif_lum) && s.dif_lum > 0);
	}
	ps_weather_free(&w);
	/* an .epw with February 29 */
	{
		const char *rec[] = { "2,28,13,5,0,100", "2,29,13,5,0,100", "3,1,13,5,0,100" };
		char *t = epw_text(NULL, rec, 3);
		parse_ok(&w, t, 0);
		assert_int_equal(w.step[1].doy, 60);
		assert_int_equal(w.step[2].doy, 61);
		ps_weather_free(&w);
		free(t);
	}
}

/* 99.9: the previous hour's value, then the three-reading mean restarts */
static void missing_dew_point(void **state)
{
	const char *rec[] = { "6,21,10,9,500,100",  "6,21,11,12,500,100", "6,21,12,15,500,100",
	                      "6,21,13,99.9,500,100", "6,21,14,6,500,100", "6,21,15,9,500,100" };
	char *t = epw_text(NULL, rec, 6);
	struct ps_weather w;
	(void)state;
	parse_ok(&w, t, 0);
	assert_int_equal(w.dew_missing, 1);
	assert_true(fabs(w.step[0].dew - 9.0) < 1e-12);                 /* (9 + 9 + 9) / 3 */
	assert_true(fabs(w.step[1].dew - 10.0) < 1e-12);                /* (9 + 9 + 12) / 3 */
	assert_true(fabs(w.step[2].dew - 12.0) < 1e-12);                /* (9 + 12 + 15) / 3 */
	assert_true(fabs(w.step[3].dew - 12.0) < 1e-12);                /* missing: the last */
	assert_int_equal(w.step[3].dew_given, 0);
	assert_true(fabs(w.step[4].dew - 6.0) < 1e-12);                 /* restart: (6 + 6 + 6) / 3 */
	assert_true(fabs(w.step[5].dew - 7.0) < 1e-12);                 /* (6 + 6 + 9) / 3 */
	/* the sky of the missing hour is the one with the substituted value */
	{
		struct ps_sky_opt o;
		struct ps_sky s, ref;
		struct ps_sky_in in;
		struct ps_err e;
		ps_sky_opt_default(&o);
		assert_int_equal(ps_sky_step(&s, &w, 3, &o, &e), 0);
		in.dir = 500;
		in.dif = 100;
		in.units = PS_WX_DN_DH;
		in.dew = 12.0;
		in.doy = w.step[3].doy;
		in.sun_alt = w.step[3].sun.alt;
		in.sun_azi = w.step[3].sun.azi;
		ps_sky_init(&ref, &in, &o);
		assert_true(s.dif_lum == ref.dif_lum && s.dir_lum == ref.dir_lum);
	}
	ps_weather_free(&w);
	free(t);
	/* missing from the start: 11 C */
	{
		const char *r2[] = { "6,21,10,99.9,500,100", "6,21,11,,500,100" };
		t = epw_text(NULL, r2, 2);
		parse_ok(&w, t, 0);
		assert_int_equal(w.dew_missing, 2);
		assert_true(w.step[0].dew == PS_WX_DEW_DEFAULT && w.step[1].dew == PS_WX_DEW_DEFAULT);
		ps_weather_free(&w);
		free(t);
	}
}

/* 78 N: the sun never sets on June 21 and never rises on December 21 */
static void polar_day_and_night(void **state)
{
	char text[4096];
	size_t n;
	struct ps_weather w;
	struct ps_sky_opt o;
	(void)state;
	n = (size_t)snprintf(text, sizeof text, "place Longyearbyen_NOR\nlatitude 78.22\n"
	                                        "longitude -15.65\ntime_zone -15\nsite_elevation 28\n"
	                                        "weather_data_file_units 1\n");
	for (int h = 0; h < 24; h++)
		n += (size_t)snprintf(text + n, sizeof text - n, "6 21 %d.5 300 120\n", h);
	for (int h = 0; h < 24; h++)
		n += (size_t)snprintf(text + n, sizeof text - n, "12 21 %d.5 0 %d\n", h, h == 12 ? 4 : 0);
	parse_ok(&w, text, 0);
	ps_sky_opt_default(&o);
	for (int i = 0; i < 48; i++) {
		struct ps_sky s;
		struct ps_err e;
		struct ps_patches P;
		double v[3 * 146];
		if (i < 24)
			assert_true(w.step[i].sun.alt > 10 * DEG);   /* lowest at midnight: 11.2 deg */
		else
			assert_true(w.step[i].sun.alt < -10 * DEG);  /* highest at noon: -11.7 deg */
		assert_int_equal(ps_sky_step(&s, &w, (size_t)i, &o, &e), 0);
		assert_int_equal(ps_patches_init(&P, 1, &e), 0);
		ps_sky_vector(&s, &P, PS_SKY_ALL, v);
		for (int k = 0; k < 3 * 146; k++)
			assert_true(isfinite(v[k]) && v[k] >= 0);
		if (i >= 24 && i != 36)
			assert_int_equal(s.dark, 1);
		if (i == 36) {   /* twilight: a diffuse sky with the sun held on the horizon */
			assert_true(fabs(s.model.zenith - M_PI / 2) < 1e-15);
			assert_true(v[3 * 145 + 1] > 0);
			assert_int_equal(ps_sky_normalise(&s, 1e-9, &e), 0);
		}
		ps_patches_free(&P);
	}
	ps_weather_free(&w);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(wea_and_epw_agree),
		cmocka_unit_test(wea_bad_input),
		cmocka_unit_test(epw_bad_input),
		cmocka_unit_test(leap_years),
		cmocka_unit_test(missing_dew_point),
		cmocka_unit_test(polar_day_and_night),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
