/* mksens: a sensor's angular sensitivity as an angular-fisheye Radiance
 * picture (whiter = more sensitive), to see how the sensor is oriented.
 *   mksens [-r resolution] [-o rotation] [-m linear|cell] sensfile > picture
 * Each pixel holds the sensitivity averaged over its footprint (its exact
 * weight divided by its solid angle), normalised to the table's maximum.
 * See mksens(1). */
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fisheye.h"
#include "picture.h"
#include "sensor.h"
#include "view.h"
#include "weights.h"

static void usage(FILE *fp)
{
	fprintf(fp, "usage: mksens [-r resolution] [-o rotation] [-m linear|cell] sensfile > picture\n");
}

int main(int argc, char **argv)
{
	long res = 256;
	double rot = 0.0, vh, *rgb;
	int reading = PS_READ_LINEAR, opt;
	struct ps_sensor s, uni;
	struct ps_view v;
	struct ps_weights w, sa;
	struct ps_err e;
	char view[512], *end;

	while ((opt = getopt(argc, argv, "r:o:m:h")) != -1) {
		switch (opt) {
		case 'r':
			res = strtol(optarg, &end, 10);
			if (end == optarg || *end || res < 1 || res > 8192) {
				fprintf(stderr, "mksens: -r: '%s' is not a resolution from 1 to 8192\n", optarg);
				return 2;
			}
			break;
		case 'o':
			rot = strtod(optarg, &end);
			if (end == optarg || *end || !isfinite(rot)) {
				fprintf(stderr, "mksens: -o: '%s' is not an angle\n", optarg);
				return 2;
			}
			break;
		case 'm':
			reading = ps_reading_parse(optarg);
			if (reading < 0) {
				fprintf(stderr, "mksens: -m: '%s' is not linear or cell\n", optarg);
				return 2;
			}
			break;
		case 'h': usage(stdout); return 0;
		default: usage(stderr); return 2;
		}
	}
	if (optind != argc - 1) {
		usage(stderr);
		return 2;
	}
	if (ps_sensor_open(&s, argv[optind], &e) != 0 || ps_sensor_set_reading(&s, reading, &e) != 0 ||
	    ps_sensor_builtin(&uni, PS_SENS_UNIFORM, &e) != 0) {
		fprintf(stderr, "mksens: %s\n", e.msg);
		return 1;
	}
	/* 180 degrees, or the smallest field that holds the whole sensitivity */
	vh = fmax(180.0, ceil(ps_fisheye_vh_for(PS_VT_ANGULAR, ps_sensor_extent(&s))));
	ps_view_default_fisheye(&v);
	v.vh = v.vv = vh;
	if (ps_weights_build(&w, &s, rot, &v, (int)res, (int)res, PS_W_EXACT, &e) != 0 ||
	    ps_weights_build(&sa, &uni, 0, &v, (int)res, (int)res, PS_W_EXACT, &e) != 0) {
		fprintf(stderr, "mksens: %s\n", e.msg);
		return 1;
	}
	rgb = calloc((size_t)res * (size_t)res * 3, sizeof *rgb);
	if (!rgb) {
		fprintf(stderr, "mksens: out of memory\n");
		return 1;
	}
	/* pixel solid angles (the uniform sensor's weights), dense */
	{
		double *omega = calloc((size_t)res * (size_t)res, sizeof *omega);
		if (!omega) {
			fprintf(stderr, "mksens: out of memory\n");
			return 1;
		}
		for (size_t q = 0; q < sa.nruns; q++)
			for (int i = 0; i < sa.runs[q].n; i++)
				omega[(size_t)sa.runs[q].row * (size_t)res + (size_t)(sa.runs[q].x0 + i)] =
				        sa.w[sa.runs[q].off + (size_t)i];
		for (size_t k = 0; k < w.nruns; k++) {
			const struct ps_wrun *r = &w.runs[k];
			for (int i = 0; i < r->n; i++) {
				size_t at = (size_t)r->row * (size_t)res + (size_t)(r->x0 + i);
				if (omega[at] > 0) {
					double val = w.w[r->off + (size_t)i] / omega[at] / s.max_value;
					rgb[3 * at] = rgb[3 * at + 1] = rgb[3 * at + 2] = val > 0 ? val : 0.0;
				}
			}
		}
		free(omega);
	}
	snprintf(view, sizeof view, "-vta -vp 0 0 0 -vd 0 0 -1 -vu 0 1 0 -vh %g -vv %g", vh, vh);
	{
		char extra[600];
		snprintf(extra, sizeof extra, "mksens -r %ld -o %g -m %s %s\n", res, rot,
		         ps_reading_name(reading), argv[optind]);
		if (ps_pic_write_fp(stdout, "(stdout)", (int)res, (int)res, rgb, view, extra, &e) != 0) {
			fprintf(stderr, "mksens: %s\n", e.msg);
			return 1;
		}
	}
	free(rgb);
	ps_weights_free(&w);
	ps_weights_free(&sa);
	ps_sensor_free(&s);
	ps_sensor_free(&uni);
	return fflush(stdout) == 0 ? 0 : 1;
}
