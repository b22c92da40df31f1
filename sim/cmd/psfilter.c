/* SPDX-License-Identifier: ISC */
/* psfilter: a photosensor's colour filter as psens's R, G, B coefficients, and
 * how far its reading strays from true illuminance under the CIE illuminants.
 *   psfilter [-c illuminant] [-p | -P] [-j] FILTER
 * See psfilter(1). */
#include <getopt.h>
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "filter.h"

static void usage(FILE *fp)
{
	fprintf(fp, "usage: psfilter [-c illuminant] [-p | -P] [-j] filter\n"
	            "  -c NAME  calibration illuminant (default A)\n"
	            "  -p / -P  values are percent / fractions (default: percent if any exceeds 2)\n"
	            "  -j       JSON\n"
	            "  -h, --help  this help;  -V, --version  the version\n");
}

int main(int argc, char **argv)
{
	const char *cal = "A";
	int percent = PS_FILTER_PERCENT_AUTO, json = 0, opt;
	struct ps_filter f;
	struct ps_filter_report r;
	struct ps_err e;
	static const struct option longopts[] = { PS_CLI_LONGOPTS, { NULL, 0, NULL, 0 } };
	while ((opt = getopt_long(argc, argv, "c:pPjhV", longopts, NULL)) != -1) {
		switch (opt) {
		case 'c': cal = optarg; break;
		case 'p': percent = PS_FILTER_PERCENT; break;
		case 'P': percent = PS_FILTER_FRACTION; break;
		case 'j': json = 1; break;
		case 'h': usage(stdout); return 0;
		case 'V': return ps_cli_version("psfilter");
		default: usage(stderr); return 2;
		}
	}
	if (optind != argc - 1) {
		usage(stderr);
		return 2;
	}
	if (ps_filter_read(&f, argv[optind], percent, &e) != 0 || ps_filter_analyse(&f, cal, &r, &e) != 0) {
		fprintf(stderr, "psfilter: %s\n", e.msg);
		return 1;
	}
	if (json) {
		printf("{\"filter\": \"%s\", \"R\": %.9g, \"G\": %.9g, \"B\": %.9g, \"X\": %.9g, \"Y\": %.9g, "
		       "\"Z\": %.9g, \"residual\": %.6g, \"condition\": %.6g, \"f1p\": %.6g, \"lo_nm\": %g, "
		       "\"hi_nm\": %g, \"percent\": %s, \"calibration\": \"%s\", \"illuminants\": [",
		       argv[optind], r.rgb[0], r.rgb[1], r.rgb[2], r.xyz[0], r.xyz[1], r.xyz[2], r.residual,
		       r.condition, r.f1p, r.lo, r.hi, f.percent ? "true" : "false", cal);
		for (int i = 0; i < r.nillum; i++)
			printf("%s{\"name\": \"%s\", \"spectral\": %.6g, \"rgb\": %.6g}", i ? ", " : "",
			       r.illum[i].name, r.illum[i].spectral, r.illum[i].rgb);
		printf("]}\n");
	} else {
		printf("-R %.6f -G %.6f -B %.6f\n", r.rgb[0], r.rgb[1], r.rgb[2]);
		printf("filter: %s, %g to %g nm%s%s\n", argv[optind], r.lo, r.hi,
		       f.percent ? ", read as percent" : "",
		       r.outside ? "; transmittance taken as 0 outside that range" : "");
		printf("projection residual: %.2f %% of the response is not a mix of x-bar, y-bar, z-bar "
		       "(condition number %.0f)\n", 100 * r.residual, r.condition);
		printf("f1' (CIE 53, ISO/CIE 19476, normalised under A, 380-780 nm): %.2f %%\n", 100 * r.f1p);
		printf("reading error against true illuminance, calibrated under %s:\n", cal);
		printf("  %-8s %12s %14s\n", "source", "spectral %", "through RGB %");
		for (int i = 0; i < r.nillum; i++)
			printf("  %-8s %12.2f %14.2f\n", r.illum[i].name, 100 * r.illum[i].spectral,
			       100 * r.illum[i].rgb);
	}
	ps_filter_free(&f);
	return 0;
}
