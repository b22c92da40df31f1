/* psens: the signal a photosensor gives for fisheye pictures of a room.
 *   psens -s sensfile [-r rotation] [-R r -G g -B b] [-m linear|cell] [-c] [-j] picture...
 * See psens(1). */
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "fisheye.h"
#include "integrate.h"
#include "picture.h"
#include "sensor.h"
#include "spectral.h"
#include "view.h"
#include "weights.h"

static void usage(FILE *fp)
{
	fprintf(fp, "usage: psens -s sensfile [-r rotation] [-R r -G g -B b] [-m linear|cell]\n"
	            "             [-f filter] [-c] [-j] [-q] picture...\n"
	            "  -s FILE   sensitivity table (rsensor/SPOT layout), or builtin:cosine\n"
	            "  -r DEG    turn the sensitivity about the sensor axis (growing azimuth)\n"
	            "  -R -G -B  colour coefficients (default 0.265074126 0.670114631 0.064811243)\n"
	            "  -f FILE   colour filter (wavelength, response): coefficients as psfilter gives\n"
	            "  -m MODE   reading of the table: linear (default) or cell (rsensor's)\n"
	            "  -c        the paper's centre-point weights instead of exact ones\n"
	            "  -j        one JSON object per picture\n"
	            "  -q        no warnings\n"
	            "  -h, --help     this help;  -V, --version  the version\n");
}

static int parse_num(const char *opt, const char *s, double *out)
{
	char *end;
	*out = strtod(s, &end);
	if (end == s || *end || !isfinite(*out)) {
		fprintf(stderr, "psens: %s: '%s' is not a number\n", opt, s);
		return -1;
	}
	return 0;
}

static void json_string(const char *s)
{
	putchar('"');
	for (; *s; s++) {
		if (*s == '"' || *s == '\\')
			printf("\\%c", *s);
		else if ((unsigned char)*s < 0x20)
			printf("\\u%04x", *s);
		else
			putchar(*s);
	}
	putchar('"');
}

/* Read a picture and its view; 0 on success, message printed otherwise. */
static int load(const char *path, struct ps_picture *pic, struct ps_view *view, int quiet)
{
	struct ps_err e;
	char where[600];
	if (ps_pic_read(pic, path, &e) != 0) {
		fprintf(stderr, "psens: %s\n", e.msg);
		return -1;
	}
	snprintf(where, sizeof where, "%s: VIEW", path);
	if (!pic->view) {
		ps_view_default_fisheye(view);
		if (!quiet)
			fprintf(stderr, "psens: warning: %s has no VIEW=; assuming -vta -vh 180 -vv 180\n", path);
	} else {
		/* VIEW= options apply on top of Radiance's default view */
		ps_view_default(view);
		if (ps_view_parse(view, pic->view, where, &e) != 0)
			goto fail;
	}
	if (ps_view_check_fisheye(view, where, &e) != 0)
		goto fail;
	return 0;
fail:
	fprintf(stderr, "psens: %s\n", e.msg);
	ps_pic_free(pic);
	return -1;
}

static void warnings(const char *path, const struct ps_weights *w, const struct ps_response *r,
                     const struct ps_sensor *sens, const struct ps_view *view)
{
	if (w->coverage < 1.0 - 1e-9) {
		double ext = ps_sensor_extent(sens);
		fprintf(stderr, "psens: warning: %s covers %.2f %% of the sensitivity; ", path,
		        100 * w->coverage);
		if (view->type == PS_VT_HEMI && ext > M_PI / 2 + 1e-12)
			fprintf(stderr, "it reaches past 90 degrees: render -vta -vh %.0f -vv %.0f\n",
			        ceil(ps_fisheye_vh_for(PS_VT_ANGULAR, ext)),
			        ceil(ps_fisheye_vh_for(PS_VT_ANGULAR, ext)));
		else
			fprintf(stderr, "-vt%c -vh %.0f -vv %.0f would hold it all\n", view->type,
			        ceil(ps_fisheye_vh_for(view->type, ext)),
			        ceil(ps_fisheye_vh_for(view->type, ext)));
	}
	if (r->brightest_share > 0.01)
		fprintf(stderr, "psens: warning: %s: the brightest pixel (x %d, row %d) gives %.1f %% "
		        "of the response and the brightest 1 %% of pixels %.1f %%: the result "
		        "depends on the resolution\n", path, r->brightest_x, r->brightest_row,
		        100 * r->brightest_share, 100 * r->top1_share);
}

int main(int argc, char **argv)
{
	const char *sensfile = NULL;
	double rot = 0.0, coef[3] = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B };
	int reading = PS_READ_LINEAR, method = PS_W_EXACT, json = 0, quiet = 0, opt, status = 0;
	struct ps_sensor sens;
	struct ps_weights w;
	struct ps_err e;
	int have_w = 0;

	static const struct option longopts[] = { PS_CLI_LONGOPTS, { NULL, 0, NULL, 0 } };
	while ((opt = getopt_long(argc, argv, "s:r:R:G:B:f:m:cjqhV", longopts, NULL)) != -1) {
		switch (opt) {
		case 's': sensfile = optarg; break;
		case 'r': if (parse_num("-r", optarg, &rot)) return 2; break;
		case 'R': if (parse_num("-R", optarg, &coef[0])) return 2; break;
		case 'G': if (parse_num("-G", optarg, &coef[1])) return 2; break;
		case 'B': if (parse_num("-B", optarg, &coef[2])) return 2; break;
		case 'f':
			if (ps_filter_rgb(optarg, coef, &e) != 0) {
				fprintf(stderr, "psens: %s\n", e.msg);
				return 1;
			}
			break;
		case 'm':
			reading = ps_reading_parse(optarg);
			if (reading < 0) {
				fprintf(stderr, "psens: -m: '%s' is not linear or cell\n", optarg);
				return 2;
			}
			break;
		case 'c': method = PS_W_CENTRE; break;
		case 'j': json = 1; break;
		case 'q': quiet = 1; break;
		case 'h': usage(stdout); return 0;
		case 'V': return ps_cli_version("psens");
		default: usage(stderr); return 2;
		}
	}
	if (!sensfile || optind >= argc) {
		usage(stderr);
		return 2;
	}
	if (ps_sensor_open(&sens, sensfile, &e) != 0 || ps_sensor_set_reading(&sens, reading, &e) != 0) {
		fprintf(stderr, "psens: %s\n", e.msg);
		return 1;
	}
	memset(&w, 0, sizeof w);
	for (int a = optind; a < argc; a++) {
		const char *path = argv[a];
		struct ps_picture pic;
		struct ps_view view;
		struct ps_response r;
		char key[512];
		if (load(path, &pic, &view, quiet) != 0) {
			status = 1;
			continue;
		}
		/* one weight map per (sensor, rotation, view, size), reused */
		ps_weights_key(&sens, rot, &view, pic.width, pic.height, method, key, sizeof key);
		if (!have_w || strcmp(key, w.key) != 0) {
			ps_weights_free(&w);
			have_w = ps_weights_build(&w, &sens, rot, &view, pic.width, pic.height, method, &e) == 0;
		}
		if (!have_w || ps_integrate(&w, &pic, coef, &r, &e) != 0) {
			fprintf(stderr, "psens: %s: %s\n", path, e.msg);
			ps_pic_free(&pic);
			status = 1;
			continue;
		}
		if (!quiet)
			warnings(path, &w, &r, &sens, &view);
		if (json) {
			char top1[32] = "null";
			if (!isnan(r.top1_share))
				snprintf(top1, sizeof top1, "%.6g", r.top1_share);
			printf("{\"picture\": ");
			json_string(path);
			printf(", \"solid_angle\": %.10g, \"sensitivity_total\": %.10g, \"response\": %.10g, "
			       "\"r\": %.10g, \"g\": %.10g, \"b\": %.10g, \"coverage\": %.10g, "
			       "\"brightest_share\": %.6g, \"top1_share\": %s, \"pixels\": %zu, "
			       "\"width\": %d, \"height\": %d, \"method\": \"%s\", \"reading\": \"%s\"}\n",
			       r.solid_angle, sens.total, r.response, r.rgb[0], r.rgb[1], r.rgb[2], w.coverage,
			       r.brightest_share, top1, r.npixels, pic.width, pic.height,
			       method == PS_W_CENTRE ? "centre" : "exact", ps_reading_name(sens.reading));
		} else {
			if (argc - optind > 1)
				printf("%s: ", path);
			printf("Total solid angle: %g Total sensitivity: %g Response: %.9g\n", r.solid_angle,
			       sens.total, r.response);
		}
		ps_pic_free(&pic);
	}
	ps_weights_free(&w);
	ps_sensor_free(&sens);
	return status;
}
