/* SPDX-License-Identifier: ISC */
/* psshare: where a photosensor's signal comes from.  Each pixel's share of
 * the response of a fisheye render, a PNG of it, and the shares of the
 * scene's surfaces (from its Radiance geometry) or of angular sectors.
 *   psshare -s sensfile [-r rotation] [-R r -G g -B b | -f filter]
 *           [--geometry scene.rad]... [-o share.png] picture
 * See psshare(1). */
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "binout.h"
#include "canvas.h"
#include "falsecolor.h"
#include "integrate.h"
#include "marks.h"
#include "picdraw.h"
#include "picture.h"
#include "radgeom.h"
#include "regions.h"
#include "sensor.h"
#include "share.h"
#include "filter.h"
#include "tonemap.h"
#include "version.h"
#include "view.h"
#include "weights.h"

#define MAX_GEOM 32

struct opts {
	const char *sensfile, *picture, *out, *hdr, *viewopts;
	const char *geom[MAX_GEOM];
	int ngeom, group, sub, top, zoom, reading, quiet;
	double rot, coef[3];
};

static void usage(FILE *fp)
{
	fprintf(fp,
	        "usage: psshare -s sensfile [options] picture.hdr\n"
	        "  -s, --sensor FILE     sensitivity table, or builtin:cosine (as psens -s)\n"
	        "  -r, --rotation DEG    turn the sensitivity (as psens -r)\n"
	        "  -R -G -B NUM          colour coefficients (default psens's, V(lambda))\n"
	        "  -f, --filter FILE     colour filter, as psens -f\n"
	        "  -m, --reading MODE    linear (default) or cell\n"
	        "      --geometry FILE   the scene's Radiance description (polygons and\n"
	        "                        !genbox | xform); repeat for more files.  Without:\n"
	        "                        angular sectors\n"
	        "      --group RULE      auto (default), name or material\n"
	        "      --view OPTS       view options applied after the picture's VIEW=\n"
	        "      --samples N       rays a pixel: N x N (default 4)\n"
	        "  -o, --output FILE     the share picture, PNG\n"
	        "      --hdr FILE        each pixel's share in percent as a Radiance picture\n"
	        "      --top N           regions named in the summary line (default 5)\n"
	        "  -z, --zoom N          PNG pixels per picture pixel (default: the smallest\n"
	        "                        making the picture 512 pixels or more, at most 4)\n"
	        "  -q, --quiet           no warnings\n"
	        "  -h, --help            this help;  -V, --version  the version\n");
}

static int parse_num(const char *opt, const char *s, double *out)
{
	char *end;
	*out = strtod(s, &end);
	if (end == s || *end || !isfinite(*out)) {
		fprintf(stderr, "psshare: %s: '%s' is not a number\n", opt, s);
		return -1;
	}
	return 0;
}

static int parse_int(const char *opt, const char *s, int lo, int hi, int *out)
{
	char *end;
	long v = strtol(s, &end, 10);
	if (end == s || *end || v < lo || v > hi) {
		fprintf(stderr, "psshare: %s: '%s' is not a whole number from %d to %d\n", opt, s, lo, hi);
		return -1;
	}
	*out = (int)v;
	return 0;
}

static int parse_args(int argc, char **argv, struct opts *o)
{
	static const struct option longopts[] = {
		{ "sensor", required_argument, NULL, 's' },   { "rotation", required_argument, NULL, 'r' },
		{ "filter", required_argument, NULL, 'f' },   { "reading", required_argument, NULL, 'm' },
		{ "geometry", required_argument, NULL, 'g' }, { "group", required_argument, NULL, 'P' },
		{ "view", required_argument, NULL, 'v' },     { "samples", required_argument, NULL, 'S' },
		{ "output", required_argument, NULL, 'o' },   { "hdr", required_argument, NULL, 'H' },
		{ "top", required_argument, NULL, 'T' },      { "zoom", required_argument, NULL, 'z' },
		{ "quiet", no_argument, NULL, 'q' },          
		PS_CLI_LONGOPTS,        { NULL, 0, NULL, 0 }
	};
	int opt;
	struct ps_err e;
	memset(o, 0, sizeof *o);
	o->coef[0] = PS_RGB_DEFAULT_R;
	o->coef[1] = PS_RGB_DEFAULT_G;
	o->coef[2] = PS_RGB_DEFAULT_B;
	o->sub = 4;
	o->top = 5;
	while ((opt = getopt_long(argc, argv, "s:r:R:G:B:f:m:o:z:qhV", longopts, NULL)) != -1) {
		switch (opt) {
		case 's': o->sensfile = optarg; break;
		case 'r': if (parse_num("-r", optarg, &o->rot)) return 2; break;
		case 'R': if (parse_num("-R", optarg, &o->coef[0])) return 2; break;
		case 'G': if (parse_num("-G", optarg, &o->coef[1])) return 2; break;
		case 'B': if (parse_num("-B", optarg, &o->coef[2])) return 2; break;
		case 'f':
			if (ps_filter_rgb(optarg, o->coef, &e) != 0) {
				fprintf(stderr, "psshare: %s\n", e.msg);
				return 1;
			}
			break;
		case 'm':
			o->reading = ps_sensor_reading_parse(optarg);
			if (o->reading < 0) {
				fprintf(stderr, "psshare: -m: '%s' is not linear or cell\n", optarg);
				return 2;
			}
			break;
		case 'g':
			if (o->ngeom == MAX_GEOM) {
				fprintf(stderr, "psshare: --geometry: at most %d files\n", MAX_GEOM);
				return 2;
			}
			o->geom[o->ngeom++] = optarg;
			break;
		case 'P':
			o->group = ps_regions_group_parse(optarg);
			if (o->group < 0) {
				fprintf(stderr, "psshare: --group: '%s' is not auto, name or material\n", optarg);
				return 2;
			}
			break;
		case 'v': o->viewopts = optarg; break;
		case 'S': if (parse_int("--samples", optarg, 1, 16, &o->sub)) return 2; break;
		case 'o': o->out = optarg; break;
		case 'H': o->hdr = optarg; break;
		case 'T': if (parse_int("--top", optarg, 1, 1000, &o->top)) return 2; break;
		case 'z': if (parse_int("-z", optarg, 1, 16, &o->zoom)) return 2; break;
		case 'q': o->quiet = 1; break;
		case 'h': usage(stdout); return 0;
		case 'V': return ps_cli_version("psshare");
		default: usage(stderr); return 2;
		}
	}
	if (!o->sensfile || optind != argc - 1) {
		usage(stderr);
		return 2;
	}
	o->picture = argv[optind];
	return -1;
}

/* the picture and its view (VIEW= then --view) */
static int load(const struct opts *o, struct ps_picture *pic, struct ps_view *v, struct ps_err *e)
{
	char where[600];
	if (ps_picture_read(pic, o->picture, e) != 0)
		return -1;
	snprintf(where, sizeof where, "%s: VIEW", o->picture);
	if (!pic->view) {
		ps_view_default_fisheye(v);
		if (!o->quiet && !o->viewopts)
			fprintf(stderr, "psshare: warning: %s has no VIEW=; assuming -vta -vh 180 -vv 180 "
			        "from 0 0 0\n", o->picture);
	} else {
		ps_view_default(v);
		if (ps_view_parse(v, pic->view, where, e) != 0)
			goto fail;
	}
	if (o->viewopts && ps_view_parse(v, o->viewopts, "--view", e) != 0)
		goto fail;
	if (ps_view_check_fisheye(v, where, e) != 0)
		goto fail;
	return 0;
fail:
	ps_picture_free(pic);
	return -1;
}

static int write_hdr(const struct opts *o, const struct ps_share *s, const char *view,
                     struct ps_err *e)
{
	size_t n = (size_t)s->width * (size_t)s->height;
	double *rgb = malloc(n * 3 * sizeof *rgb);
	char extra[700];
	int rc;
	if (!rgb)
		return ps_err_set(e, PS_ENOMEM, "out of memory");
	for (size_t k = 0; k < n; k++)
		rgb[3 * k] = rgb[3 * k + 1] = rgb[3 * k + 2] = 100.0 * s->share[k];
	snprintf(extra, sizeof extra, "psshare -s %s -r %g %s\n"
	         "COMMENT= each pixel holds its share of the sensor's response, in percent\n",
	         o->sensfile, o->rot, o->picture);
	rc = ps_picture_write(o->hdr, s->width, s->height, rgb, view, extra, e);
	free(rgb);
	return rc;
}

/* The share picture: the render in grey under the shares in false colour
 * (log scale, 3 decades below the largest pixel share), the regions'
 * outlines and names, and the fisheye's azimuth marks. */
static int write_png(const struct opts *o, const struct ps_picture *pic, const struct ps_view *v,
                     const struct ps_share *s, const struct ps_regions *r,
                     const struct ps_region_share *rs, int nrs, struct ps_err *e)
{
	struct ps_canvas c;
	struct ps_marks_place pl;
	struct ps_tonemap t;
	struct ps_falsecolor_legend leg;
	struct ps_falsecolor_scale scale = { 0, 1, 3 };
	uint8_t bg[3] = { 28, 28, 28 };
	int w = s->width, h = s->height, zoom, margin, strip, rc;
	double font, top = 0, fg[3] = { 0.92, 0.92, 0.92 };
	char caption[700];
	zoom = o->zoom ? o->zoom : (511 + (w > h ? w : h)) / (w > h ? w : h);
	if (!o->zoom && zoom > 4)
		zoom = 4;
	font = h * zoom >= 480 ? 13.0 : 11.0;
	margin = (int)(3.0 * font);
	strip = (int)(8.5 * font) + 8;
	for (size_t p = 0; p < (size_t)w * (size_t)h; p++)
		top = fmax(top, s->share[p]);
	scale.max = ps_falsecolor_nice_ceil(100.0 * top);
	if (ps_canvas_init(&c, margin + w * zoom + margin + strip, margin + h * zoom + 2 * margin, bg,
	                   e) != 0)
		return -1;
	ps_marks_place_init(&pl, v, w, h, margin, margin, zoom);
	ps_tonemap_init(&t, pic, PS_TONE_REINHARD, 0, 2.2, 0);
	ps_picdraw_grey(&c, pic, &t, margin, margin, zoom, 0.6);
	ps_canvas_begin(&c);
	for (int row = 0; row < h; row++)
		for (int x = 0; x < w; x++) {
			double f = ps_falsecolor_scale_fraction(&scale, 100.0 * s->share[(size_t)row * (size_t)w + (size_t)x]);
			uint8_t rgb[3];
			if (!(f >= 0))
				continue;
			ps_falsecolor_rgb8(f, rgb);
			ps_canvas_set(&c, margin + zoom * x, margin + zoom * row, zoom, rgb);
		}
	ps_canvas_end(&c);
	/* outlines: pixel edges between different major labels */
	cairo_save(c.cr);
	for (int row = 0; row < h; row++)
		for (int x = 0; x < w; x++) {
			int a = r->major[(size_t)row * (size_t)w + (size_t)x];
			double x0 = margin + zoom * x, y0 = margin + zoom * row;
			if (x + 1 < w && r->major[(size_t)row * (size_t)w + (size_t)x + 1] != a) {
				cairo_move_to(c.cr, x0 + zoom, y0);
				cairo_line_to(c.cr, x0 + zoom, y0 + zoom);
			}
			if (row + 1 < h && r->major[(size_t)(row + 1) * (size_t)w + (size_t)x] != a) {
				cairo_move_to(c.cr, x0, y0 + zoom);
				cairo_line_to(c.cr, x0 + zoom, y0 + zoom);
			}
		}
	cairo_set_source_rgba(c.cr, 1, 1, 1, 0.8);
	cairo_set_line_width(c.cr, 1.0);
	cairo_stroke(c.cr);
	cairo_restore(c.cr);
	ps_marks_draw(&c, &pl, PS_MARK_AZIMUTH, o->rot, font);
	/* names of the regions with 1 % or more, at the labelled pixel nearest
	 * to the share-weighted centre of the region */
	for (int i = 0; i < nrs; i++) {
		double sx = 0, sy = 0, sw = 0, best = INFINITY, bx = 0, by = 0;
		char lab[320];
		int l = rs[i].label;
		if (rs[i].share < 0.01)
			continue;
		for (int row = 0; row < h; row++)
			for (int x = 0; x < w; x++) {
				size_t p = (size_t)row * (size_t)w + (size_t)x;
				if (r->major[p] == l && s->share[p] > 0) {
					sx += s->share[p] * x;
					sy += s->share[p] * row;
					sw += s->share[p];
				}
			}
		if (!(sw > 0))
			continue;
		sx /= sw;
		sy /= sw;
		for (int row = 0; row < h; row++)
			for (int x = 0; x < w; x++)
				if (r->major[(size_t)row * (size_t)w + (size_t)x] == l &&
				    hypot(x - sx, row - sy) < best) {
					best = hypot(x - sx, row - sy);
					bx = x;
					by = row;
				}
		snprintf(lab, sizeof lab, "%s %.0f %%", r->label[l], 100 * rs[i].share);
		ps_canvas_label(&c, margin + zoom * (bx + 0.5), margin + zoom * (by + 0.5), font, 0, fg, 1,
		                lab);
	}
	ps_falsecolor_legend_layout(&leg, margin + w * zoom + margin, margin, strip, h * zoom);
	leg.above = 0;
	ps_falsecolor_legend_draw(&c, &leg, &scale, "% per pixel");
	snprintf(caption, sizeof caption, "%s seen by %s, rotation %g\xc2\xb0; %s",
	         strrchr(o->picture, '/') ? strrchr(o->picture, '/') + 1 : o->picture,
	         strrchr(o->sensfile, '/') ? strrchr(o->sensfile, '/') + 1 : o->sensfile, o->rot,
	         r->sectors ? "angular sectors" : "regions from the geometry");
	ps_canvas_label(&c, margin, margin + h * zoom + 1.5 * margin, font, -1, fg, 0, caption);
	ps_canvas_text_chunk(&c, "Software", "psshare (psensd) " PS_VERSION);
	ps_canvas_text_chunk(&c, "Source", o->picture);
	rc = ps_canvas_save_png(&c, o->out, e);
	ps_canvas_free(&c);
	ps_canvas_shutdown();
	return rc;
}

int main(int argc, char **argv)
{
	struct opts o;
	struct ps_sensor sens, uni;
	struct ps_picture pic;
	struct ps_view v;
	struct ps_weights w, sa;
	struct ps_response resp;
	struct ps_share s;
	struct ps_regions r;
	struct ps_radgeom g;
	struct ps_region_share *rs = NULL;
	struct ps_err e;
	char view[1024];
	int rc = parse_args(argc, argv, &o), status = 1;
	if (rc >= 0)
		return rc;
	memset(&w, 0, sizeof w);
	memset(&sa, 0, sizeof sa);
	memset(&s, 0, sizeof s);
	memset(&r, 0, sizeof r);
	ps_radgeom_init(&g);
	if (ps_sensor_open(&sens, o.sensfile, &e) != 0) {
		fprintf(stderr, "psshare: %s\n", e.msg);
		return 1;
	}
	if (ps_sensor_set_reading(&sens, o.reading, &e) != 0 ||
	    ps_sensor_builtin(&uni, PS_SENS_UNIFORM, &e) != 0) {
		fprintf(stderr, "psshare: %s\n", e.msg);
		ps_sensor_free(&sens);
		return 1;
	}
	if (load(&o, &pic, &v, &e) != 0) {
		fprintf(stderr, "psshare: %s\n", e.msg);
		ps_sensor_free(&sens);
		ps_sensor_free(&uni);
		return 1;
	}
	for (int i = 0; i < o.ngeom; i++)
		if (ps_radgeom_read(&g, o.geom[i], &e) != 0)
			goto fail;
	if (ps_weights_build(&w, &sens, o.rot, &v, pic.width, pic.height, PS_W_EXACT, &e) != 0 ||
	    ps_weights_build(&sa, &uni, 0, &v, pic.width, pic.height, PS_W_EXACT, &e) != 0 ||
	    ps_integrate(&w, &pic, o.coef, &resp, &e) != 0 ||
	    ps_share_compute(&s, &w, &pic, o.coef, &e) != 0)
		goto fail;
	if (o.ngeom ? ps_regions_geometry(&r, &g, o.group, &v, pic.width, pic.height, o.sub, &e)
	            : ps_regions_sectors(&r, &v, pic.width, pic.height, o.sub, &e))
		goto fail;
	if (ps_share_regions(&s, &r, &sa, &pic, &rs, &e) != 0)
		goto fail;
	/* the table */
	if (o.ngeom) {
		printf("regions: %zu surfaces in", g.npoly);
		for (int i = 0; i < o.ngeom; i++)
			printf(" %s", o.geom[i]);
		printf(", grouped by %s into %d; %d x %d rays a pixel\n",
		       o.group == PS_GROUP_NAME ? "name" : o.group == PS_GROUP_MATERIAL ? "material"
		                                                                       : "auto",
		       r.nlabels, o.sub, o.sub);
	} else {
		printf("regions: no geometry given (--geometry): angular sectors, polar-angle bands "
		       "from the view direction x quadrants around the picture's up\n");
	}
	printf("response %.9g (psens: %.9g)\n", s.response, resp.response);
	printf("%-24s %8s %10s %12s\n", "region", "share %", "sr", "cd/m2");
	for (int i = 0; i < r.nlabels; i++) {
		if (rs[i].share == 0 && rs[i].solid_angle == 0)
			continue;
		printf("%-24s %8.2f %10.4f %12.4g\n", r.label[rs[i].label], 100 * rs[i].share,
		       rs[i].solid_angle, rs[i].luminance);
	}
	{
		double tot = 0, tsa = 0;
		for (int i = 0; i < r.nlabels; i++) {
			tot += rs[i].share;
			tsa += rs[i].solid_angle;
		}
		printf("%-24s %8.2f %10.4f\n", "(total)", 100 * tot, tsa);
	}
	printf("top:");
	for (int i = 0; i < o.top && i < r.nlabels && rs[i].share > 0; i++)
		printf("%s %s %.0f %%", i ? "," : "", r.label[rs[i].label], 100 * rs[i].share);
	printf("\n");
	ps_view_format(&v, view, sizeof view);
	if (o.hdr && write_hdr(&o, &s, view, &e) != 0)
		goto fail;
	if (o.out && write_png(&o, &pic, &v, &s, &r, rs, r.nlabels, &e) != 0)
		goto fail;
	status = fflush(stdout) != 0;
	goto done;
fail:
	fprintf(stderr, "psshare: %s\n", e.msg);
done:
	free(rs);
	ps_regions_free(&r);
	ps_share_free(&s);
	ps_weights_free(&w);
	ps_weights_free(&sa);
	ps_radgeom_free(&g);
	ps_picture_free(&pic);
	ps_sensor_free(&sens);
	ps_sensor_free(&uni);
	return status;
}
