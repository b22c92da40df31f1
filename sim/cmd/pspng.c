/* SPDX-License-Identifier: ISC */
/* pspng: a Radiance picture as a PNG to look at: exposure, a tone curve, or
 * false colour of luminance with a legend in cd/m2.
 *   pspng [-o out.png] [-e EXP|auto] [-t linear|gamma|srgb|reinhard] [-g G]
 *         [-F [-s MAX] [-l] [--decades N]] [-z ZOOM] picture
 * See pspng(1). */
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "cli.h"
#include "binout.h"
#include "canvas.h"
#include "falsecolor.h"
#include "lum.h"
#include "picdraw.h"
#include "picture.h"
#include "tonemap.h"
#include "version.h"

/* An output name saying PNG: ends in .png, any case. */
static int png_name(const char *path)
{
	size_t n = strlen(path);
	return n >= 4 && strcasecmp(path + n - 4, ".png") == 0;
}

static void usage(FILE *fp)
{
	fprintf(fp,
	        "usage: pspng [options] picture.hdr [-o out.png]\n"
	        "  -o, --output FILE   the PNG (default: standard output, never a terminal)\n"
	        "  -e, --exposure E    multiplier on radiance, +N/-N stops, or auto (default):\n"
	        "                      auto maps the log-average luminance to 0.18 of white\n"
	        "  -t, --tone CURVE    linear (clipped), gamma, srgb, or reinhard (default:\n"
	        "                      Reinhard's photographic operator, sRGB encoded)\n"
	        "  -g, --gamma G       the gamma curve's exponent (default 2.2)\n"
	        "      --white L       reinhard: the smallest luminance shown white, cd/m2\n"
	        "                      (default: the picture's largest)\n"
	        "  -F, --falsecolor    false colour of luminance with a legend in cd/m2\n"
	        "  -s, --scale MAX     top of the false-colour scale, cd/m2 (default: the\n"
	        "                      largest luminance rounded up to 1, 1.5, 2, 2.5, 3, 4, 5,\n"
	        "                      6 or 8 x 10^k)\n"
	        "  -l, --log           logarithmic scale\n"
	        "      --decades N     -l: the scale spans N decades below MAX (default 3)\n"
	        "  -z, --zoom N        each picture pixel as N x N (default 1)\n"
	        "  -q, --quiet         no summary on standard error\n"
	        "  -h, --help          this help;  -V, --version  the version\n");
}

static int parse_pos(const char *opt, const char *s, double *out)
{
	char *end;
	*out = strtod(s, &end);
	if (end == s || *end || !isfinite(*out) || !(*out > 0)) {
		fprintf(stderr, "pspng: %s: '%s' is not a positive number\n", opt, s);
		return -1;
	}
	return 0;
}

int main(int argc, char **argv)
{
	static const struct option longopts[] = {
		{ "output", required_argument, NULL, 'o' },  { "exposure", required_argument, NULL, 'e' },
		{ "tone", required_argument, NULL, 't' },    { "gamma", required_argument, NULL, 'g' },
		{ "white", required_argument, NULL, 'W' },   { "falsecolor", no_argument, NULL, 'F' },
		{ "scale", required_argument, NULL, 's' },   { "log", no_argument, NULL, 'l' },
		{ "decades", required_argument, NULL, 'D' }, { "zoom", required_argument, NULL, 'z' },
		{ "quiet", no_argument, NULL, 'q' },         
		PS_CLI_LONGOPTS,       { NULL, 0, NULL, 0 }
	};
	const char *out = NULL, *path;
	double exposure = 0, gamma = 2.2, white = 0, scale_max = 0, d;
	int curve = PS_TONE_REINHARD, falsecolor = 0, logscale = 0, decades = 3, zoom = 1, quiet = 0;
	int opt, rc;
	struct ps_picture pic;
	struct ps_canvas c;
	struct ps_err e;
	uint8_t bg[3] = { 28, 28, 28 };
	char summary[512];

	while ((opt = getopt_long(argc, argv, "o:e:t:g:Fs:lz:qhV", longopts, NULL)) != -1) {
		switch (opt) {
		case 'o': out = optarg; break;
		case 'e':
			rc = ps_tonemap_exposure_parse(optarg, &exposure);
			if (rc < 0) {
				fprintf(stderr, "pspng: -e: '%s' is not auto, a positive multiplier or "
				        "+N/-N stops\n", optarg);
				return 2;
			}
			if (rc == 1)
				exposure = 0;
			break;
		case 't':
			curve = ps_tonemap_parse(optarg);
			if (curve < 0) {
				fprintf(stderr, "pspng: -t: '%s' is not linear, gamma, srgb or reinhard\n", optarg);
				return 2;
			}
			break;
		case 'g': if (parse_pos("-g", optarg, &gamma)) return 2; break;
		case 'W': if (parse_pos("--white", optarg, &white)) return 2; break;
		case 'F': falsecolor = 1; break;
		case 's': if (parse_pos("-s", optarg, &scale_max)) return 2; break;
		case 'l': logscale = 1; break;
		case 'D':
			if (parse_pos("--decades", optarg, &d) || d != floor(d) || d > 12) {
				fprintf(stderr, "pspng: --decades: a whole number from 1 to 12\n");
				return 2;
			}
			decades = (int)d;
			break;
		case 'z':
			if (parse_pos("-z", optarg, &d) || d != floor(d) || d > 16) {
				fprintf(stderr, "pspng: -z: a whole number from 1 to 16\n");
				return 2;
			}
			zoom = (int)d;
			break;
		case 'q': quiet = 1; break;
		case 'h': usage(stdout); return 0;
		case 'V': return ps_cli_version("pspng");
		default: usage(stderr); return 2;
		}
	}
	if (optind != argc - 1) {
		if (optind >= argc)
			fprintf(stderr, "pspng: no picture (give one HDR picture)\n");
		else
			fprintf(stderr, "pspng: one picture at a time ('%s' is a second)\n", argv[optind + 1]);
		usage(stderr);
		return 2;
	}
	path = argv[optind];
	if (out && !png_name(out)) {
		fprintf(stderr, "pspng: -o: '%s' does not end in .png (pspng writes PNG only)\n", out);
		return 2;
	}
	if (ps_binout_check(out, "pspng picture.hdr > picture.png", &e) != 0) {
		fprintf(stderr, "pspng: %s\n", e.msg);
		return 2;
	}
	if (ps_picture_read(&pic, path, &e) != 0) {
		fprintf(stderr, "pspng: %s\n", e.msg);
		return 1;
	}
	if (falsecolor) {
		struct ps_lum l;
		struct ps_falsecolor_scale s;
		struct ps_falsecolor_legend leg;
		int ph = pic.height * zoom, pw = pic.width * zoom, sw;
		double top;
		ps_lum_init(&l, &pic);
		top = ps_picdraw_max_cdm2(&pic, &l);
		s.max = scale_max > 0 ? scale_max : top > 0 ? ps_falsecolor_nice_ceil(top) : 1.0;
		s.log = logscale;
		s.decades = decades;
		ps_falsecolor_legend_layout(&leg, pw, 0, 0, ph < 160 ? 160 : ph);
		sw = (int)(leg.font * 8.5) + 8;
		if (ps_canvas_init(&c, pw + sw, ph < 160 ? 160 : ph, bg, &e) != 0)
			goto fail;
		ps_picdraw_false(&c, &pic, &l, &s, 0, 0, zoom);
		ps_falsecolor_legend_draw(&c, &leg, &s, logscale ? "cd/m\xc2\xb2 (log)" : "cd/m\xc2\xb2");
		snprintf(summary, sizeof summary, "false colour, %s scale %g to %g cd/m2%s, largest %.4g cd/m2",
		         logscale ? "log" : "linear", logscale ? s.max / pow(10, decades) : 0.0, s.max,
		         scale_max > 0 ? "" : " (auto)", top);
	} else {
		struct ps_tonemap t;
		double logavg, ymax;
		ps_tonemap_init(&t, &pic, curve, exposure, gamma, white > 0 ? white / PS_LUM_EFFICACY : 0);
		ps_tonemap_stats(&pic, &t.lum, &logavg, &ymax);
		if (ps_canvas_init(&c, pic.width * zoom, pic.height * zoom, bg, &e) != 0)
			goto fail;
		ps_picdraw_tone(&c, &pic, &t, 0, 0, zoom);
		if (curve == PS_TONE_LINEAR || curve == PS_TONE_GAMMA) {
			c.encoding = PS_PNG_GAMMA;
			c.gamma = curve == PS_TONE_LINEAR ? 1.0 : gamma;
		}
		rc = snprintf(summary, sizeof summary, "log-average %.4g cd/m2, largest %.4g cd/m2; "
		              "exposure %.4g%s, tone %s", PS_LUM_EFFICACY * logavg,
		              PS_LUM_EFFICACY * ymax, t.exposure, exposure > 0 ? "" : " (auto)",
		              ps_tonemap_name(curve));
		if (curve == PS_TONE_REINHARD && rc > 0 && (size_t)rc < sizeof summary)
			snprintf(summary + rc, sizeof summary - (size_t)rc, " (white %.4g cd/m2)",
			         PS_LUM_EFFICACY * t.white / t.exposure);
		else if (curve == PS_TONE_GAMMA && rc > 0 && (size_t)rc < sizeof summary)
			snprintf(summary + rc, sizeof summary - (size_t)rc, " %g", gamma);
	}
	ps_canvas_text_chunk(&c, "Software", "pspng (psensd) " PS_VERSION);
	ps_canvas_text_chunk(&c, "Source", path);
	ps_canvas_text_chunk(&c, "Comment", summary);
	rc = out ? ps_canvas_save_png(&c, out, &e) : ps_canvas_write_png(&c, stdout, "(stdout)", &e);
	ps_canvas_free(&c);
	ps_canvas_shutdown();
	if (rc != 0)
		goto fail;
	if (!quiet)
		fprintf(stderr, "pspng: %s: %d x %d, %s -> %s\n", path, pic.width, pic.height, summary,
		        out ? out : "(stdout)");
	ps_picture_free(&pic);
	return 0;
fail:
	fprintf(stderr, "pspng: %s\n", e.msg);
	ps_picture_free(&pic);
	return 1;
}
