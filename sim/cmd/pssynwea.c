/* SPDX-License-Identifier: ISC */
/* pssynwea: a synthetic typical year as a Radiance .wea file (hourly direct
 * normal and diffuse horizontal irradiance), for when no measured typical
 * year may be shipped.  NOT measured weather: a clear-sky model times a
 * seeded random sequence of clear, partly cloudy and overcast days.
 *   pssynwea [-n place] [-a lat] [-o lon] [-z tz] [-e elev] [-s seed] [-C]
 * See pssynwea(1) for the model. */
#include <getopt.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

#include "sun.h"

#define DEG (M_PI / 180.0)

/* xorshift64*: a small, fully determined generator (the same seed gives the
 * same year on every machine) */
static uint64_t rng_state;
static double uniform(void)
{
	rng_state ^= rng_state >> 12;
	rng_state ^= rng_state << 25;
	rng_state ^= rng_state >> 27;
	return (double)((rng_state * 2685821657736338717ULL) >> 11) / 9007199254740992.0;
}

/* Clear sky: ASHRAE Handbook of Fundamentals (2013, chapter 14) form,
 * Eb = E0 exp(-tb m^ab), Ed = E0 exp(-td m^ad), with the handbook's air-mass
 * exponents and Kasten and Young's (1989) air mass.  tb, td: one pair for the
 * year (a coastal site: see pssynwea(1)), not the handbook's station table. */
static void clear_sky(int doy, double alt, double tb, double td, double *dn, double *dh)
{
	double e0 = 1367.0 * (1 + 0.033 * cos(2 * M_PI * (doy - 3) / 365.0));
	double h = alt / DEG, m, ab, ad;
	if (h <= 0) {
		*dn = *dh = 0;
		return;
	}
	m = 1.0 / (sin(alt) + 0.50572 * pow(6.07995 + h, -1.6364));
	ab = 1.454 - 0.406 * tb - 0.268 * td + 0.021 * tb * td;
	ad = 0.507 + 0.205 * tb - 0.080 * td - 0.190 * tb * td;
	*dn = e0 * exp(-tb * pow(m, ab));
	*dh = e0 * exp(-td * pow(m, ad));
}

enum { CLEAR, PARTLY, OVERCAST };

static void usage(FILE *fp)
{
	fprintf(fp, "usage: pssynwea [-n place] [-a lat] [-o lon] [-z tz] [-e elev] [-s seed] [-C]\n"
	            "  a synthetic year (not measured weather) as a .wea on stdout;\n"
	            "  default site San Francisco (37.62 N, 122.40 W, UTC-8, 2 m), seed 1;\n"
	            "  -n PLACE  the site's name          -a DEG  latitude (north +)\n"
	            "  -o DEG    longitude (east +; Radiance's letters, not an output file)\n"
	            "  -z HOURS  time zone (UTC+)         -e M    elevation\n"
	            "  -s N      the random seed          -C      every day clear\n"
	            "  -h, --help  this help;  -V, --version  the version\n");
}

int main(int argc, char **argv)
{
	/* share of clear and of overcast days by month (the rest partly
	 * cloudy): a coastal Californian climate, winter rain, summer morning
	 * fog (pssynwea(1)) */
	static const double p_clear[12] = { .45, .45, .50, .55, .55, .55, .50, .50, .60, .60, .50, .45 };
	static const double p_over[12] = { .30, .30, .25, .15, .10, .10, .10, .10, .10, .15, .25, .30 };
	static const double p_fog[12] = { 0, 0, 0, 0, .2, .4, .5, .5, .4, .2, 0, 0 };
	static const int mdays[12] = { 31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31 };
	struct ps_site site = { "San_Francisco_CA_synthetic", 37.62, -122.40, -8.0, 2.0 };
	unsigned long long seed = 1;
	int all_clear = 0, opt, state = CLEAR, doy = 0;
	static const struct option longopts[] = { PS_CLI_LONGOPTS, { NULL, 0, NULL, 0 } };
	while ((opt = getopt_long(argc, argv, "n:a:o:z:e:s:ChV", longopts, NULL)) != -1) {
		char *end = NULL;
		double v = 0;
		if (opt != 'n' && opt != 'C' && opt != 'h' && opt != 'V' && opt != '?') {
			v = strtod(optarg, &end);
			if (end == optarg || *end || !isfinite(v)) {
				fprintf(stderr, "pssynwea: -%c: '%s' is not a number\n", opt, optarg);
				return 2;
			}
		}
		switch (opt) {
		case 'n':   /* the place says what the year is, wherever the file goes */
			snprintf(site.name, sizeof site.name, strstr(optarg, "synthetic") ? "%s" : "%.100s_synthetic", optarg);
			break;
		case 'a': site.lat = v; break;
		case 'o': site.lon = v; break;
		case 'z': site.tz = v; break;
		case 'e': site.elevation = v; break;
		case 's': seed = (unsigned long long)v; break;
		case 'C': all_clear = 1; break;
		case 'h': usage(stdout); return 0;
		case 'V': return ps_cli_version("pssynwea");
		default: usage(stderr); return 2;
		}
	}
	if (optind != argc) {
		fprintf(stderr, "pssynwea: unexpected argument '%s'\n", argv[optind]);
		usage(stderr);
		return 2;
	}
	if (fabs(site.lat) > 90) {
		fprintf(stderr, "pssynwea: -a: latitude %g is not -90 to 90 degrees\n", site.lat);
		return 2;
	}
	if (fabs(site.lon) > 180) {
		fprintf(stderr, "pssynwea: -o: longitude %g is not -180 to 180 degrees\n", site.lon);
		return 2;
	}
	if (fabs(site.tz) > 14) {
		fprintf(stderr, "pssynwea: -z: time zone %g is not -14 to 14 hours\n", site.tz);
		return 2;
	}
	if (strpbrk(site.name, " \t\n")) {
		fprintf(stderr, "pssynwea: -n: '%s' has a blank (a .wea place is one word)\n", site.name);
		return 2;
	}
	rng_state = 0x9E3779B97F4A7C15ULL ^ (seed * 0xBF58476D1CE4E5B9ULL);
	if (!rng_state)
		rng_state = 1;
	/* .wea: longitude and time zone in degrees west */
	printf("place %s\nlatitude %.2f\nlongitude %.2f\ntime_zone %.0f\nsite_elevation %.1f\n"
	       "weather_data_file_units 1\n",
	       site.name, site.lat, -site.lon, -15.0 * site.tz, site.elevation);
	for (int mo = 0; mo < 12; mo++)
		for (int d = 1; d <= mdays[mo]; d++) {
			double r = uniform(), u;
			int fog;
			doy++;
			/* persistence: half the days repeat yesterday's sky */
			if (r >= 0.5) {
				u = uniform();
				state = u < p_clear[mo] ? CLEAR : u < p_clear[mo] + p_over[mo] ? OVERCAST : PARTLY;
			}
			if (all_clear)
				state = CLEAR;
			fog = !all_clear && uniform() < p_fog[mo];
			for (int h = 0; h < 24; h++) {
				struct ps_sunpos sp;
				double hour = h + 0.5, dn, dh, gh, c, s = state;
				ps_sun_position(&site, doy, hour, &sp);
				clear_sky(doy, sp.alt, 0.36, 2.25, &dn, &dh);
				gh = dn * sin(fmax(sp.alt, 0)) + dh;
				if (fog && sp.solar_hour < 11)
					s = OVERCAST;
				if (s == PARTLY) {
					c = 0.2 + 0.6 * uniform();      /* the hour's cloud cover */
					dh = dh + c * 0.35 * gh;
					dn = dn * (1 - c) * (0.6 + 0.4 * uniform());
				} else if (s == OVERCAST) {
					dn = 0;
					dh = (0.25 + 0.20 * uniform()) * gh;
				}
				printf("%d %d %.3f %.0f %.0f\n", mo + 1, d, hour, dn, dh);
			}
		}
	return 0;
}
