/* SPDX-License-Identifier: ISC */
/* mksens: a sensor's angular sensitivity as an angular-fisheye Radiance
 * picture (whiter = more sensitive), to see how the sensor is oriented; or as
 * a PNG with its marks (azimuth 0 = the picture's up, the sensor's rotation,
 * polar-angle rings, contours and a legend), or its contours over a render
 * of the room from the sensor (the paper's Figure 5).
 *   mksens [-S resolution] [--rotation deg] [-m linear|cell] sensfile > picture
 *   mksens [...] --output sensor.png sensfile
 *   mksens [...] --overlay room.hdr --output fig5.png sensfile
 * Each pixel holds the sensitivity averaged over its footprint (its exact
 * weight divided by its solid angle), normalised to the table's maximum.
 * See mksens(1). */
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "binout.h"
#include "canvas.h"
#include "falsecolor.h"
#include "fisheye.h"
#include "marks.h"
#include "picdraw.h"
#include "picture.h"
#include "sensor.h"
#include "tonemap.h"
#include "version.h"
#include "view.h"
#include "weights.h"

#define MAX_LEVELS 16

struct opts {
	long res;
	double rot;
	int reading;
	const char *out, *overlay, *sensfile;
	int png;               /* 1: PNG, 0: Radiance */
	double levels[MAX_LEVELS];
	int nlevels;
	double exposure;       /* overlay background; <= 0 auto */
	int tone;
	int zoom;              /* 0: auto */
};

static void usage(FILE *fp)
{
	fprintf(fp,
	        "usage: mksens [-S resolution] [--rotation deg] [-m linear|cell] sensfile > picture.hdr\n"
	        "       mksens [options] -o sensor.png sensfile\n"
	        "       mksens [options] --overlay room.hdr -o overlay.png sensfile\n"
	        "  -S, --resolution N  pixels on a side (default 256, at most 8192)\n"
	        "      --rotation DEG  turn the sensitivity towards growing azimuth (as psens -r)\n"
	        "  -m, --reading MODE  linear (default) or cell, as psens -m\n"
	        "  -o, --output FILE   write FILE (PNG when it ends in .png) instead of\n"
	        "                      standard output (never a terminal)\n"
	        "      --format F      hdr (Radiance, the default) or png\n"
	        "      --overlay PIC   the sensitivity's contours over PIC, a fisheye render\n"
	        "                      from the sensor (its VIEW= gives the geometry); PNG\n"
	        "      --levels LIST   contour levels, percent of the peak (default 10,25,50,75,90)\n"
	        "      --exposure E    --overlay: the render's exposure (multiplier, +N/-N\n"
	        "                      stops or auto, the default)\n"
	        "      --tone CURVE    --overlay: linear, gamma, srgb or reinhard (default)\n"
	        "      --zoom N        PNG: each pixel as N x N (default: the smallest making\n"
	        "                      the picture 512 pixels or more, at most 4)\n"
	        "  -h, --help          this help;  -V, --version  the version\n"
	        "  (old spellings, for this release: -r N for -S N, -o DEG for --rotation DEG)\n");
}

static int parse_levels(const char *s, struct opts *o)
{
	const char *p = s;
	o->nlevels = 0;
	while (*p) {
		char *end;
		double v = strtod(p, &end);
		if (end == p || !isfinite(v) || !(v > 0) || !(v < 100) || o->nlevels >= MAX_LEVELS ||
		    (*end && *end != ','))
			return -1;
		o->levels[o->nlevels++] = v;
		p = *end ? end + 1 : end;
	}
	return o->nlevels ? 0 : -1;
}

static int parse_args(int argc, char **argv, struct opts *o)
{
	static const struct option longopts[] = {
		{ "resolution", required_argument, NULL, 'S' }, { "rotation", required_argument, NULL, 'a' },
		{ "reading", required_argument, NULL, 'm' },    { "output", required_argument, NULL, 'o' },
		{ "format", required_argument, NULL, 'f' },     { "overlay", required_argument, NULL, 'v' },
		{ "levels", required_argument, NULL, 'L' },     { "exposure", required_argument, NULL, 'e' },
		{ "tone", required_argument, NULL, 't' },       { "zoom", required_argument, NULL, 'z' },
		             PS_CLI_LONGOPTS,
		{ NULL, 0, NULL, 0 }
	};
	int opt, format = -1, rc;
	char *end;
	memset(o, 0, sizeof *o);
	o->res = 256;
	o->reading = PS_READ_LINEAR;
	o->tone = PS_TONE_REINHARD;
	parse_levels("10,25,50,75,90", o);
	while ((opt = getopt_long(argc, argv, "S:r:o:m:hV", longopts, NULL)) != -1) {
		switch (opt) {
		case 'r':   /* the old spelling: -r becomes the rotation in the next release */
			ps_cli_deprecated("mksens", "-r as the resolution", "-S (-r will be the rotation, as psens -r)");
			/* fall through */
		case 'S':
			o->res = strtol(optarg, &end, 10);
			if (end == optarg || *end || o->res < 1 || o->res > 8192) {
				fprintf(stderr, "mksens: -S: '%s' is not a resolution from 1 to 8192\n", optarg);
				return 2;
			}
			break;
		case 'o':   /* the output file; a number is the old rotation */
			if (!ps_cli_is_number(optarg)) {
				o->out = optarg;
				break;
			}
			ps_cli_deprecated("mksens", "-o as the rotation", "--rotation (-o is the output file)");
			/* fall through */
		case 'a':
			o->rot = strtod(optarg, &end);
			if (end == optarg || *end || !isfinite(o->rot)) {
				fprintf(stderr, "mksens: --rotation: '%s' is not an angle\n", optarg);
				return 2;
			}
			break;
		case 'm':
			o->reading = ps_sensor_reading_parse(optarg);
			if (o->reading < 0) {
				fprintf(stderr, "mksens: -m: '%s' is not linear or cell\n", optarg);
				return 2;
			}
			break;
		case 'f':
			format = strcmp(optarg, "png") == 0 ? 1 : strcmp(optarg, "hdr") == 0 ? 0 : -2;
			if (format == -2) {
				fprintf(stderr, "mksens: --format: '%s' is not hdr or png\n", optarg);
				return 2;
			}
			break;
		case 'v': o->overlay = optarg; break;
		case 'L':
			if (parse_levels(optarg, o) != 0) {
				fprintf(stderr, "mksens: --levels: '%s' is not a list of up to %d percentages "
				        "between 0 and 100, comma separated\n", optarg, MAX_LEVELS);
				return 2;
			}
			break;
		case 'e':
			rc = ps_tonemap_exposure_parse(optarg, &o->exposure);
			if (rc < 0) {
				fprintf(stderr, "mksens: --exposure: '%s' is not auto, a positive multiplier "
				        "or +N/-N stops\n", optarg);
				return 2;
			}
			if (rc == 1)
				o->exposure = 0;
			break;
		case 't':
			o->tone = ps_tonemap_parse(optarg);
			if (o->tone < 0) {
				fprintf(stderr, "mksens: --tone: '%s' is not linear, gamma, srgb or reinhard\n",
				        optarg);
				return 2;
			}
			break;
		case 'z':
			o->zoom = (int)strtol(optarg, &end, 10);
			if (end == optarg || *end || o->zoom < 1 || o->zoom > 16) {
				fprintf(stderr, "mksens: --zoom: '%s' is not a whole number from 1 to 16\n", optarg);
				return 2;
			}
			break;
		case 'h': usage(stdout); return 0;
		case 'V': return ps_cli_version("mksens");
		default: usage(stderr); return 2;
		}
	}
	if (optind != argc - 1) {
		usage(stderr);
		return 2;
	}
	o->sensfile = argv[optind];
	if (format >= 0)
		o->png = format;
	else if (o->overlay)
		o->png = 1;
	else if (o->out) {
		size_t n = strlen(o->out);
		o->png = n >= 4 && strcasecmp(o->out + n - 4, ".png") == 0;
	}
	if (o->overlay && !o->png) {
		fprintf(stderr, "mksens: --overlay draws a PNG: --format hdr does not go with it\n");
		return 2;
	}
	return -1;
}

/* The picture of the sensitivity: each pixel's weight over its solid angle,
 * as a fraction of the table's maximum (res x res, row 0 at the top). */
static double *sensitivity_picture(const struct ps_sensor *s, double rot, const struct ps_view *v,
                                   int res, struct ps_err *e)
{
	struct ps_sensor uni;
	struct ps_weights w, sa;
	double *val, *omega;
	if (ps_sensor_builtin(&uni, PS_SENS_UNIFORM, e) != 0)
		return NULL;
	if (ps_weights_build(&w, s, rot, v, res, res, PS_W_EXACT, e) != 0) {
		ps_sensor_free(&uni);
		return NULL;
	}
	if (ps_weights_build(&sa, &uni, 0, v, res, res, PS_W_EXACT, e) != 0) {
		ps_weights_free(&w);
		ps_sensor_free(&uni);
		return NULL;
	}
	val = calloc((size_t)res * (size_t)res, sizeof *val);
	omega = calloc((size_t)res * (size_t)res, sizeof *omega);
	if (!val || !omega) {
		free(val);
		val = NULL;
		ps_err_set(e, PS_ENOMEM, "out of memory");
		goto done;
	}
	/* pixel solid angles (the uniform sensor's weights), dense */
	for (size_t q = 0; q < sa.nruns; q++)
		for (int i = 0; i < sa.runs[q].n; i++)
			omega[(size_t)sa.runs[q].row * (size_t)res + (size_t)(sa.runs[q].x0 + i)] =
			        sa.w[sa.runs[q].off + (size_t)i];
	for (size_t k = 0; k < w.nruns; k++) {
		const struct ps_weights_run *r = &w.runs[k];
		for (int i = 0; i < r->n; i++) {
			size_t at = (size_t)r->row * (size_t)res + (size_t)(r->x0 + i);
			if (omega[at] > 0) {
				double x = ps_weights_run_at(&w, r, i) / omega[at] / s->max_value;
				val[at] = x > 0 ? x : 0.0;
			}
		}
	}
done:
	free(omega);
	ps_weights_free(&w);
	ps_weights_free(&sa);
	ps_sensor_free(&uni);
	return val;
}

static int write_hdr(const struct opts *o, const double *val, double vh, struct ps_err *e)
{
	size_t n = (size_t)o->res * (size_t)o->res;
	double *rgb = malloc(n * 3 * sizeof *rgb);
	char view[512], extra[600];
	FILE *fp = stdout;
	int rc;
	if (!rgb)
		return ps_err_set(e, PS_ENOMEM, "out of memory");
	for (size_t k = 0; k < n; k++)
		rgb[3 * k] = rgb[3 * k + 1] = rgb[3 * k + 2] = val[k];
	snprintf(view, sizeof view, "-vta -vp 0 0 0 -vd 0 0 -1 -vu 0 1 0 -vh %g -vv %g", vh, vh);
	snprintf(extra, sizeof extra, "mksens -S %ld --rotation %g -m %s %s\n", o->res, o->rot,
	         ps_sensor_reading_name(o->reading), o->sensfile);
	if (o->out && !(fp = fopen(o->out, "wb"))) {
		free(rgb);
		return ps_err_sys(e, "%s", o->out);
	}
	rc = ps_picture_write_fp(fp, o->out ? o->out : "(stdout)", (int)o->res, (int)o->res, rgb, view,
	                         extra, e);
	free(rgb);
	if (fp != stdout) {
		if (fclose(fp) != 0 && rc == 0)
			rc = ps_err_sys(e, "%s", o->out);
	} else if (rc == 0 && fflush(stdout) != 0) {
		rc = ps_err_sys(e, "(stdout)");
	}
	return rc;
}

static int auto_zoom(int size, int zoom)
{
	int z = (511 + size) / size;
	if (zoom > 0)
		return zoom;
	return z < 1 ? 1 : z > 4 ? 4 : z;
}

/* Contours of the sensitivity at the levels, labelled where they cross
 * azimuth 320 degrees: white over the false colour, light blue over a
 * render (apart from the white rings and the yellow arrow). */
static int draw_contours(struct ps_canvas *c, const struct ps_marks_place *pl, const struct ps_sensor *s,
                         const struct opts *o, double font, struct ps_err *e)
{
	static const double white[3] = { 1, 1, 1 }, light_blue[3] = { 0.55, 0.88, 1 };
	int nx, ny;
	double *grid = ps_marks_place_sensitivity(pl, s, o->rot, &nx, &ny);
	if (!grid)
		return ps_err_set(e, PS_ENOMEM, "out of memory");
	ps_marks_contours(c, pl, grid, nx, ny, o->levels, o->nlevels, o->overlay ? light_blue : white, font);
	free(grid);
	return 0;
}

static int write_png(const struct opts *o, const struct ps_sensor *s, const double *val,
                     const struct ps_view *v, struct ps_err *e)
{
	struct ps_picture room;
	struct ps_view rv;
	struct ps_canvas c;
	struct ps_marks_place pl;
	struct ps_falsecolor_legend leg;
	struct ps_falsecolor_scale scale = { 100.0, 0, 0 };
	uint8_t bg[3] = { 28, 28, 28 };
	int w, h, zoom, margin, strip = 0, rc, have_room = 0;
	double font, fg[3] = { 0.92, 0.92, 0.92 };
	char caption[600];
	const char *base = strrchr(o->sensfile, '/') ? strrchr(o->sensfile, '/') + 1 : o->sensfile;
	memset(&room, 0, sizeof room);
	if (o->overlay) {
		char where[600];
		if (ps_picture_read(&room, o->overlay, e) != 0)
			return -1;
		have_room = 1;
		snprintf(where, sizeof where, "%s: VIEW", o->overlay);
		if (!room.view) {
			ps_view_default_fisheye(&rv);
		} else {
			ps_view_default(&rv);
			if (ps_view_parse(&rv, room.view, where, e) != 0)
				goto fail;
		}
		if (ps_view_check_fisheye(&rv, where, e) != 0)
			goto fail;
		w = room.width;
		h = room.height;
		v = &rv;
	} else {
		w = h = (int)o->res;
	}
	zoom = auto_zoom(w > h ? w : h, o->zoom);
	font = h * zoom >= 480 ? 13.0 : 11.0;
	margin = (int)(3.0 * font);
	if (!o->overlay)
		strip = (int)(8.5 * font) + 8;   /* the legend */
	if (ps_canvas_init(&c, margin + w * zoom + margin + strip, margin + h * zoom + 2 * margin, bg,
	                   e) != 0)
		goto fail;
	ps_marks_place_init(&pl, v, w, h, margin, margin, zoom);
	if (have_room) {
		struct ps_tonemap t;
		ps_tonemap_init(&t, &room, o->tone, o->exposure, 2.2, 0);
		ps_picdraw_tone(&c, &room, &t, margin, margin, zoom);
	} else {
		/* the sensitivity in false colour inside the field */
		ps_canvas_begin(&c);
		for (int row = 0; row < h; row++)
			for (int x = 0; x < w; x++) {
				double th, ph;
				uint8_t rgb[3];
				if (ps_fisheye_pixel_dir(&pl.f, x, row, &th, &ph) != 0)
					continue;
				ps_falsecolor_rgb8(val[(size_t)row * (size_t)w + (size_t)x], rgb);
				ps_canvas_set(&c, margin + zoom * x, margin + zoom * row, zoom, rgb);
			}
		ps_canvas_end(&c);
	}
	ps_marks_draw(&c, &pl, PS_MARK_RINGS | PS_MARK_AZIMUTH | PS_MARK_SENSOR, o->rot, font);
	if (draw_contours(&c, &pl, s, o, font, e) != 0) {
		ps_canvas_free(&c);
		ps_canvas_shutdown();
		goto fail;
	}
	if (!o->overlay) {
		ps_falsecolor_legend_layout(&leg, margin + w * zoom + margin, margin, strip, h * zoom);
		leg.above = 0;
		ps_falsecolor_legend_draw(&c, &leg, &scale, "% of peak");
	}
	if (o->overlay) {
		snprintf(caption, sizeof caption, "%s over %s, rotation %g\xc2\xb0", base,
		         strrchr(o->overlay, '/') ? strrchr(o->overlay, '/') + 1 : o->overlay, o->rot);
		ps_canvas_label(&c, margin, margin + h * zoom + 0.9 * margin, font, -1, fg, 0, caption);
		ps_canvas_label(&c, margin, margin + h * zoom + 1.6 * margin, font, -1, fg, 0,
		                "contours: sensitivity in % of its peak");
	} else {
		snprintf(caption, sizeof caption, "%s, rotation %g\xc2\xb0, %s reading", base, o->rot,
		         ps_sensor_reading_name(o->reading));
		ps_canvas_label(&c, margin, margin + h * zoom + 1.5 * margin, font, -1, fg, 0, caption);
	}
	{
		char cmd[700];
		snprintf(cmd, sizeof cmd, "mksens -S %ld --rotation %g -m %s%s%s %s", o->res, o->rot,
		         ps_sensor_reading_name(o->reading), o->overlay ? " --overlay " : "",
		         o->overlay ? o->overlay : "", o->sensfile);
		ps_canvas_text_chunk(&c, "Software", "mksens (psensd) " PS_VERSION);
		ps_canvas_text_chunk(&c, "Comment", cmd);
	}
	rc = o->out ? ps_canvas_save_png(&c, o->out, e) : ps_canvas_write_png(&c, stdout, "(stdout)", e);
	ps_canvas_free(&c);
	ps_canvas_shutdown();
	ps_picture_free(&room);
	return rc;
fail:
	if (have_room)
		ps_picture_free(&room);
	return -1;
}

int main(int argc, char **argv)
{
	struct opts o;
	struct ps_sensor s;
	struct ps_view v;
	struct ps_err e;
	double vh, *val = NULL;
	int rc = parse_args(argc, argv, &o);
	if (rc >= 0)
		return rc;
	if (ps_binout_check(o.out, o.png ? "mksens --format png sensor.sen > sensor.png"
	                                 : "mksens sensor.sen > sensor.hdr", &e) != 0) {
		fprintf(stderr, "mksens: %s\n", e.msg);
		return 2;
	}
	if (ps_sensor_open(&s, o.sensfile, &e) != 0 || ps_sensor_set_reading(&s, o.reading, &e) != 0) {
		fprintf(stderr, "mksens: %s\n", e.msg);
		return 1;
	}
	/* 180 degrees, or the smallest field that holds the whole sensitivity */
	vh = fmax(180.0, ceil(ps_fisheye_vh_for(PS_VT_ANGULAR, ps_sensor_extent(&s))));
	ps_view_default_fisheye(&v);
	v.vh = v.vv = vh;
	if (!o.overlay && !(val = sensitivity_picture(&s, o.rot, &v, (int)o.res, &e))) {
		fprintf(stderr, "mksens: %s\n", e.msg);
		ps_sensor_free(&s);
		return 1;
	}
	rc = o.png ? write_png(&o, &s, val, &v, &e) : write_hdr(&o, val, vh, &e);
	if (rc != 0)
		fprintf(stderr, "mksens: %s\n", e.msg);
	free(val);
	ps_sensor_free(&s);
	return rc != 0;
}
