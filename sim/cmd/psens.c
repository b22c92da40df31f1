/* psens: the signal a photosensor gives for fisheye pictures of a room.
 *   psens -s sensfile [-r rotation] [-R r -G g -B b] [-m linear|cell] [-c] [-j|-o{a|f|d}]
 *         [-n threads] [-C cachedir | -N] picture...
 * See psens(1). */
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "batch.h"
#include "cache.h"
#include "file.h"
#include "fisheye.h"
#include "integrate.h"
#include "mtx.h"
#include "picture.h"
#include "picview.h"
#include "sensor.h"
#include "spectral.h"
#include "view.h"
#include "wcache.h"
#include "weights.h"

static void usage(FILE *fp)
{
	fprintf(fp, "usage: psens -s sensfile [-r rotation] [-R r -G g -B b] [-m linear|cell]\n"
	            "             [-f filter] [-c] [-j|-oa|-of|-od] [-n threads] [-C dir|-N] [-q]\n"
	            "             picture...\n"
	            "  -s FILE   sensitivity table (rsensor/SPOT layout), or builtin:cosine\n"
	            "  -r DEG    turn the sensitivity about the sensor axis (growing azimuth)\n"
	            "  -R -G -B  colour coefficients (default 0.265074126 0.670114631 0.064811243)\n"
	            "  -f FILE   colour filter (wavelength, response): coefficients as psfilter gives\n"
	            "  -m MODE   reading of the table: linear (default) or cell (rsensor's)\n"
	            "  -c        the paper's centre-point weights instead of exact ones\n"
	            "  -j        one JSON object per picture\n"
	            "  -oa -of -od  one Radiance matrix (ascii, float, double): one row (the\n"
	            "            sensor), one column per picture, components r g b\n"
	            "  -n N      threads reading and integrating pictures (default 2)\n"
	            "  -C DIR    cache directory for weight maps (default $XDG_CACHE_HOME/psensd\n"
	            "            or ~/.cache/psensd, as psscene's)\n"
	            "  -N        no cache\n"
	            "  -q        no warnings\n");
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

static void warnings(const char *path, double coverage, const struct ps_response *r,
                     const struct ps_sensor *sens, const struct ps_view *view)
{
	if (coverage < 1.0 - 1e-9) {
		double ext = ps_sensor_extent(sens);
		fprintf(stderr, "psens: warning: %s covers %.2f %% of the sensitivity; ", path,
		        100 * coverage);
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

/* What psens keeps of each picture until it prints them in order. */
struct item {
	int done;
	struct ps_batch_result res;
	double coverage;
	struct ps_view view;
};

static void print_result(const char *path, const struct item *it, const struct ps_sensor *sens,
                         int method, int json, int several)
{
	const struct ps_response *r = &it->res.r;
	if (json) {
		char top1[32] = "null";
		if (!isnan(r->top1_share))
			snprintf(top1, sizeof top1, "%.6g", r->top1_share);
		printf("{\"picture\": ");
		json_string(path);
		printf(", \"solid_angle\": %.10g, \"sensitivity_total\": %.10g, \"response\": %.10g, "
		       "\"r\": %.10g, \"g\": %.10g, \"b\": %.10g, \"coverage\": %.10g, "
		       "\"brightest_share\": %.6g, \"top1_share\": %s, \"pixels\": %zu, "
		       "\"width\": %d, \"height\": %d, \"method\": \"%s\", \"reading\": \"%s\"}\n",
		       r->solid_angle, sens->total, r->response, r->rgb[0], r->rgb[1], r->rgb[2],
		       it->coverage, r->brightest_share, top1, r->npixels, it->res.width, it->res.height,
		       method == PS_W_CENTRE ? "centre" : "exact", ps_reading_name(sens->reading));
	} else {
		if (several)
			printf("%s: ", path);
		printf("Total solid angle: %g Total sensitivity: %g Response: %.9g\n", r->solid_angle,
		       sens->total, r->response);
	}
}

/* The command line, for the matrix header. */
static char *command_line(int argc, char **argv)
{
	size_t len = 1;
	char *cmd;
	for (int k = 0; k < argc; k++)
		len += strlen(argv[k]) + 1;
	cmd = malloc(len);
	if (!cmd)
		return NULL;
	cmd[0] = '\0';
	for (int k = 0; k < argc; k++) {
		if (k)
			strcat(cmd, " ");
		strcat(cmd, k ? argv[k] : "psens");
	}
	return cmd;
}

static int write_matrix(int argc, char **argv, const struct item *items, size_t n, int format)
{
	struct ps_mtx_header h;
	struct ps_err e;
	double *data = malloc(3 * n * sizeof *data);
	char *cmd = command_line(argc, argv);
	int rc = 0;
	if (!data || !cmd) {
		fprintf(stderr, "psens: out of memory\n");
		free(data);
		free(cmd);
		return 1;
	}
	for (size_t c = 0; c < n; c++)
		for (int k = 0; k < 3; k++)
			data[3 * c + k] = items[c].res.r.rgb[k];
	memset(&h, 0, sizeof h);
	h.command = cmd;
	h.nrows = 1;
	h.ncols = (int)n;
	h.format = format;
	h.digits = 10;
	if (ps_mtx_write(stdout, "(stdout)", &h, 1, data, 1, &e) != 0) {
		fprintf(stderr, "psens: %s\n", e.msg);
		rc = 1;
	}
	free(data);
	free(cmd);
	return rc;
}

int main(int argc, char **argv)
{
	const char *sensfile = NULL;
	double rot = 0.0, coef[3] = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B };
	int reading = PS_READ_LINEAR, method = PS_W_EXACT, json = 0, quiet = 0, opt, status = 0;
	int nthreads = PS_BATCH_THREADS_DEFAULT, mtx = 0, nocache = 0, cache_warned = 0;
	const char *cachedir = NULL;
	char cachebuf[4096];
	struct ps_sensor sens;
	struct ps_err e;
	const char *const *paths;
	struct item *items;
	size_t *idx, n;

	while ((opt = getopt(argc, argv, "s:r:R:G:B:f:m:n:o:C:Ncjqh")) != -1) {
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
		case 'n': {
			double v;
			if (parse_num("-n", optarg, &v))
				return 2;
			if (v < 1 || v > PS_BATCH_THREADS_MAX || v != floor(v)) {
				fprintf(stderr, "psens: -n: '%s' threads: give 1 to %d\n", optarg,
				        PS_BATCH_THREADS_MAX);
				return 2;
			}
			nthreads = (int)v;
			break;
		}
		case 'o':
			if (!optarg[0] || optarg[1] || !strchr("afd", optarg[0])) {
				fprintf(stderr, "psens: -o%s: the matrix format is -oa, -of or -od\n", optarg);
				return 2;
			}
			mtx = optarg[0];
			break;
		case 'C': cachedir = optarg; break;
		case 'N': nocache = 1; break;
		case 'c': method = PS_W_CENTRE; break;
		case 'j': json = 1; break;
		case 'q': quiet = 1; break;
		case 'h': usage(stdout); return 0;
		default: usage(stderr); return 2;
		}
	}
	if (!sensfile || optind >= argc) {
		usage(stderr);
		return 2;
	}
	if (mtx && json) {
		fprintf(stderr, "psens: -j and -o%c: one output at a time\n", mtx);
		return 2;
	}
	if (ps_sensor_open(&sens, sensfile, &e) != 0 || ps_sensor_set_reading(&sens, reading, &e) != 0) {
		fprintf(stderr, "psens: %s\n", e.msg);
		return 1;
	}
	if (nocache) {
		cachedir = NULL;
	} else if (!cachedir) {
		ps_cache_default_dir(cachebuf, sizeof cachebuf);
		cachedir = cachebuf;
	}
	paths = (const char *const *)argv + optind;
	n = (size_t)(argc - optind);
	items = calloc(n, sizeof *items);
	idx = malloc(n * sizeof *idx);
	if (!items || !idx) {
		fprintf(stderr, "psens: out of memory\n");
		return 1;
	}
	/* Each round reads the first picture not done, builds the weights for its
	 * view and size once, and integrates it with every picture left of that
	 * size in parallel; a picture of another view or size waits for a later
	 * round (with a matrix, where every column must share one map, it is an
	 * error naming the file). */
	for (size_t first = 0; first < n; first++) {
		struct ps_picture pic;
		struct ps_view view;
		struct ps_batch b;
		struct ps_filemap fm;
		const char **list;
		size_t m = 0, off;
		int assumed;
		if (items[first].done)
			continue;
		items[first].done = 1;
		/* the first picture's header sets the batch's view and size */
		if (ps_map_file(paths[first], (size_t)4 << 30, &fm, &items[first].res.err) != 0) {
			items[first].res.status = PS_BATCH_FAILED;
			continue;
		}
		if (ps_pic_head_mem(&pic, fm.data, fm.len, paths[first], &off,
		                    &items[first].res.err) != 0 ||
		    ps_pic_fisheye_view(&pic, paths[first], &view, &assumed,
		                        &items[first].res.err) != 0) {
			items[first].res.status = PS_BATCH_FAILED;
			ps_pic_free(&pic);
			ps_unmap_file(&fm);
			continue;
		}
		{
			struct ps_err warn;
			int how;
			if (ps_batch_init_cache(&b, &sens, rot, &view, pic.width, pic.height, method, coef,
			                        nthreads, cachedir, ps_cache_max_bytes(), &how, &warn,
			                        &e) != 0) {
				fprintf(stderr, "psens: %s: %s\n", paths[first], e.msg);
				return 1;
			}
			/* a cache that cannot be written: one warning, then no cache */
			if (how == PS_WC_UNWRITABLE) {
				if (!quiet && !cache_warned)
					fprintf(stderr, "psens: warning: weights not cached (%s); going on "
					                "without the cache\n", warn.msg);
				cache_warned = 1;
				cachedir = NULL;
			} else if (how == PS_WC_REBUILT && !quiet) {
				fprintf(stderr, "psens: warning: %s; weights rebuilt\n", warn.msg);
			}
		}
		idx[m++] = first;
		for (size_t i = first + 1; i < n; i++)
			if (!items[i].done && (items[i].res.width == 0 ||
			                       (items[i].res.width == pic.width &&
			                        items[i].res.height == pic.height)))
				idx[m++] = i;
		{
			struct ps_batch_result *res = malloc(m * sizeof *res);
			list = malloc(m * sizeof *list);
			if (!res || !list) {
				fprintf(stderr, "psens: out of memory\n");
				return 1;
			}
			for (size_t k = 0; k < m; k++)
				list[k] = paths[idx[k]];
			if (ps_batch_run_files_first(&b, list, m, fm.data, fm.len, res, &e) < 0) {
				fprintf(stderr, "psens: %s\n", e.msg);
				return 1;
			}
			for (size_t k = 0; k < m; k++) {
				struct item *it = &items[idx[k]];
				it->res = res[k];
				if (res[k].status == PS_BATCH_MISMATCH && !mtx)
					continue;   /* a later round */
				it->done = 1;
				it->coverage = b.w.coverage;
				it->view = view;
			}
			free(res);
			free(list);
			ps_unmap_file(&fm);
		}
		ps_pic_free(&pic);
		ps_batch_free(&b);
	}
	for (size_t i = 0; i < n; i++) {
		struct item *it = &items[i];
		if (it->res.status != PS_BATCH_OK) {
			fprintf(stderr, "psens: %s\n", it->res.err.msg);
			status = 1;
			continue;
		}
		if (!quiet && it->res.view_assumed)
			fprintf(stderr, "psens: warning: %s has no VIEW=; assuming -vta -vh 180 -vv 180\n",
			        paths[i]);
		if (!quiet)
			warnings(paths[i], it->coverage, &it->res.r, &sens, &it->view);
		if (!mtx)
			print_result(paths[i], it, &sens, method, json, n > 1);
	}
	if (mtx && status == 0)
		status = write_matrix(argc, argv, items, n, mtx);
	else if (mtx)
		fprintf(stderr, "psens: no matrix written: every picture must give a column\n");
	free(items);
	free(idx);
	ps_sensor_free(&sens);
	return status;
}
