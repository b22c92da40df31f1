/* SPDX-License-Identifier: ISC */
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
#include "cli.h"
#include "fileio.h"
#include "fisheye.h"
#include "integrate.h"
#include "mtx.h"
#include "picture.h"
#include "picview.h"
#include "rescan.h"
#include "scancheck.h"
#include "sensor.h"
#include "filter.h"
#include "stream.h"
#include "view.h"
#include "wcache.h"
#include "weights.h"

static void usage(FILE *fp)
{
	fprintf(fp, "usage: psens -s sensfile [-r rotation] [-R r -G g -B b] [-m linear|cell]\n"
	            "             [-f filter] [-c] [-j|-oa|-of|-od] [-n threads] [-C dir|-N] [-q]\n"
	            "             [--tolerance T]\n"
	            "             picture...\n"
	            "  -s FILE   sensitivity table (rsensor/SPOT layout), or builtin:cosine\n"
	            "  -r DEG    turn the sensitivity about the sensor axis (growing azimuth)\n"
	            "  -r A:B:S  a rotation scan: rotations A, A + S, ... below B\n"
	            "  --tolerance T  the scan's error estimate above which psens warns\n"
	            "            (relative, default 1e-3; 0: no estimate)\n"
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

static void print_result(const char *path, const char *sensname, const struct item *it,
                         const struct ps_sensor *sens, int method, int json, int several)
{
	const struct ps_response *r = &it->res.r;
	if (json) {
		char top1[32] = "null";
		if (!isnan(r->top1_share))
			snprintf(top1, sizeof top1, "%.6g", r->top1_share);
		printf("{\"picture\": ");
		json_string(path);
		if (sensname) {
			printf(", \"sensor\": ");
			json_string(sensname);
		}
		printf(", \"solid_angle\": %.10g, \"sensitivity_total\": %.10g, \"response\": %.10g, "
		       "\"r\": %.10g, \"g\": %.10g, \"b\": %.10g, \"coverage\": %.10g, "
		       "\"brightest_share\": %.6g, \"top1_share\": %s, \"pixels\": %zu, "
		       "\"width\": %d, \"height\": %d, \"method\": \"%s\", \"reading\": \"%s\"}\n",
		       r->solid_angle, sens->total, r->response, r->rgb[0], r->rgb[1], r->rgb[2],
		       it->coverage, r->brightest_share, top1, r->npixels, it->res.width, it->res.height,
		       method == PS_W_CENTRE ? "centre" : "exact", ps_sensor_reading_name(sens->reading));
	} else {
		if (several)
			printf("%s: ", path);
		if (sensname)
			printf("%s: ", sensname);
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

/* items[s n + c]: sensor s (a row), picture c (a column). */
static int write_matrix(int argc, char **argv, const struct item *items, size_t n, int nsens,
                        int format)
{
	struct ps_mtx_header h;
	struct ps_err e;
	double *data = malloc(3 * n * (size_t)nsens * sizeof *data);
	char *cmd = command_line(argc, argv);
	int rc = 0;
	if (!data || !cmd) {
		fprintf(stderr, "psens: out of memory\n");
		free(data);
		free(cmd);
		return 1;
	}
	for (size_t c = 0; c < n; c++)
		for (int r = 0; r < nsens; r++)
			for (int k = 0; k < 3; k++)
				data[3 * (c * (size_t)nsens + (size_t)r) + k] = items[(size_t)r * n + c].res.r.rgb[k];
	memset(&h, 0, sizeof h);
	h.command = cmd;
	h.nrows = nsens;
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

/* Options shared by the routes. */
struct opts {
	double rot, coef[3];
	int method, json, quiet, nthreads, mtx, cache_warned;
	int scan, nrot;           /* -r a:b:s */
	double rot_a, rot_step;
	double tolerance;         /* --tolerance: the scan's error estimate allowed */
	const char *cachedir;
};

/* A cache outcome's warning, once for an unwritable cache. */
static void cache_warning(struct opts *o, int how, const struct ps_err *warn)
{
	if (how == PS_WC_UNWRITABLE) {
		if (!o->quiet && !o->cache_warned)
			fprintf(stderr, "psens: warning: weights not cached (%s); going on without the "
			                "cache\n", warn->msg);
		o->cache_warned = 1;
		o->cachedir = NULL;
	} else if (how == PS_WC_REBUILT && !o->quiet) {
		fprintf(stderr, "psens: warning: %s; weights rebuilt\n", warn->msg);
	}
}

/* The direct route for one sensor: items[i] for paths[i]. */
static int direct(const struct ps_sensor *sens, struct opts *o, const char *const *paths, size_t n,
                  struct item *items)
{
	struct ps_err e;
	size_t *idx = malloc(n * sizeof *idx);
	if (!idx) {
		fprintf(stderr, "psens: out of memory\n");
		return -1;
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
		struct ps_fileio_map fm;
		const char **list;
		size_t m = 0, off;
		int assumed, how;
		struct ps_err warn;
		if (items[first].done)
			continue;
		items[first].done = 1;
		/* the first picture's header sets the batch's view and size */
		if (ps_fileio_map(paths[first], (size_t)4 << 30, &fm, &items[first].res.err) != 0) {
			items[first].res.status = PS_BATCH_FAILED;
			continue;
		}
		if (ps_picture_head_mem(&pic, fm.data, fm.len, paths[first], &off,
		                        &items[first].res.err) != 0 ||
		    ps_picview_fisheye(&pic, paths[first], &view, &assumed,
		                       &items[first].res.err) != 0) {
			items[first].res.status = PS_BATCH_FAILED;
			ps_picture_free(&pic);
			ps_fileio_unmap(&fm);
			continue;
		}
		/* the weights, stored in the cache while the pictures are integrated */
		struct ps_batch_spec sp = {
			.map = { .sensor = sens, .rotation_deg = o->rot, .view = &view, .width = pic.width,
			         .height = pic.height, .method = o->method },
			.coef = o->coef,
			.nthreads = o->nthreads,
		};
		struct ps_wcache_dir cache = { .path = o->cachedir, .max_bytes = ps_cache_max_bytes() };
		if (ps_batch_init_cache_async(&b, &sp, &cache, &how, &warn, &e) != 0) {
			fprintf(stderr, "psens: %s: %s\n", paths[first], e.msg);
			goto fail;
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
				ps_batch_free(&b);
				goto fail;
			}
			for (size_t k = 0; k < m; k++)
				list[k] = paths[idx[k]];
			if (ps_batch_run_files_first(&b, list, m, fm.data, fm.len, res, &e) < 0) {
				fprintf(stderr, "psens: %s\n", e.msg);
				ps_batch_free(&b);
				goto fail;
			}
			/* the store's outcome: a cache that cannot be written gives one
			 * warning, then no cache */
			ps_batch_finish_store(&b, &how, &warn);
			cache_warning(o, how, &warn);
			for (size_t k = 0; k < m; k++) {
				struct item *it = &items[idx[k]];
				it->res = res[k];
				if (res[k].status == PS_BATCH_MISMATCH && !o->mtx)
					continue;   /* a later round */
				it->done = 1;
				it->coverage = b.w.coverage;
				it->view = view;
			}
			free(res);
			free(list);
			ps_fileio_unmap(&fm);
		}
		ps_picture_free(&pic);
		ps_batch_free(&b);
	}
	free(idx);
	return 0;
fail:
	free(idx);
	return -1;
}

/* Several sensors: each picture is decoded once and integrated against
 * every sensor's weights at once (sim/weights/stream.h), its rows shared among the
 * threads; the maps are kept while the pictures' view and size stay the
 * same.  items[k n + i]: sensor k, picture i, as direct() gives them. */
static int direct_multi(const struct ps_sensor *sens, int nsens, struct opts *o,
                        const char *const *paths, size_t n, struct item *items)
{
	struct ps_weights *w = calloc((size_t)nsens, sizeof *w);
	const struct ps_weights **ws = calloc((size_t)nsens, sizeof *ws);
	struct ps_response *rs = calloc((size_t)nsens, sizeof *rs);
	struct ps_wcache_store **pend = calloc((size_t)nsens, sizeof *pend);
	struct ps_view cur;
	int have = 0, cw = 0, ch = 0, rc = 0;
	if (!w || !ws || !rs || !pend) {
		fprintf(stderr, "psens: out of memory\n");
		free(w);
		free(ws);
		free(rs);
		free(pend);
		return -1;
	}
	memset(&cur, 0, sizeof cur);
	for (size_t i = 0; i < n && rc == 0; i++) {
		struct ps_fileio_map fm;
		struct ps_picture head;
		struct ps_view view;
		struct ps_err pe;
		size_t off;
		int assumed = 0, width = 0, height = 0, status = PS_BATCH_FAILED;
		memset(&pe, 0, sizeof pe);
		memset(&view, 0, sizeof view);
		if (ps_fileio_map(paths[i], (size_t)4 << 30, &fm, &pe) != 0)
			goto give;
		if (ps_picture_head_mem(&head, fm.data, fm.len, paths[i], &off, &pe) != 0) {
			ps_fileio_unmap(&fm);
			goto give;
		}
		width = head.width;
		height = head.height;
		if (ps_picview_fisheye(&head, paths[i], &view, &assumed, &pe) != 0)
			goto done;
		if (have && (width != cw || height != ch || view.type != cur.type || view.vh != cur.vh ||
		             view.vv != cur.vv || view.vs != cur.vs || view.vl != cur.vl)) {
			if (o->mtx) {   /* every column must share the first picture's maps */
				char vs[400];
				status = PS_BATCH_MISMATCH;
				ps_view_format(&view, vs, sizeof vs);
				if (width != cw || height != ch)
					ps_err_set(&pe, PS_EINVAL, "%s: picture is %d x %d, the batch's weights are "
					           "for %d x %d", paths[i], width, height, cw, ch);
				else
					ps_err_set(&pe, PS_EINVAL, "%s: its view (%s) is not the batch's", paths[i], vs);
				goto done;
			}
			for (int k = 0; k < nsens; k++)
				ps_weights_free(&w[k]);
			have = 0;
		}
		if (!have) {
			for (int k = 0; k < nsens; k++) {
				struct ps_err warn, e;
				int how;
				/* stored in the cache while the picture is integrated */
				struct ps_wcache_key key = { .sensor = &sens[k], .rotation_deg = o->rot,
				                             .view = &view, .width = width, .height = height,
				                             .method = o->method };
				struct ps_wcache_dir cache = { .path = o->cachedir,
				                               .max_bytes = ps_cache_max_bytes() };
				if (ps_wcache_get_async(&w[k], &key, &cache, &how, &warn, &pend[k], &e) != 0) {
					fprintf(stderr, "psens: %s: %s\n", paths[i], e.msg);
					for (int q = 0; q < k; q++) {
						ps_wcache_store_finish(pend[q], NULL, NULL);
						pend[q] = NULL;
						ps_weights_free(&w[q]);
					}
					rc = -1;
					goto done;
				}
				if (!pend[k])
					cache_warning(o, how, &warn);
				ws[k] = &w[k];
			}
			have = 1;
			cw = width;
			ch = height;
			cur = view;
		}
		if (ps_stream_integrate_multi(ws, nsens, &head, fm.data, fm.len, off, paths[i], o->coef,
		                              o->nthreads, rs, &pe) == 0)
			status = PS_BATCH_OK;
		for (int k = 0; k < nsens; k++)
			if (pend[k]) {   /* the stores' outcomes */
				struct ps_err warn;
				int how;
				ps_wcache_store_finish(pend[k], &how, &warn);
				pend[k] = NULL;
				cache_warning(o, how, &warn);
			}
done:
		ps_picture_free(&head);
		ps_fileio_unmap(&fm);
give:
		for (int k = 0; k < nsens; k++) {
			struct item *it = &items[(size_t)k * n + i];
			it->done = 1;
			it->res.status = status;
			it->res.width = width;
			it->res.height = height;
			it->res.view_assumed = assumed;
			if (status == PS_BATCH_OK) {
				it->res.r = rs[k];
				it->coverage = w[k].coverage;
				it->view = view;
			} else {
				it->res.err = pe;
			}
		}
	}
	if (have)
		for (int k = 0; k < nsens; k++)
			ps_weights_free(&w[k]);
	free(w);
	free(ws);
	free(rs);
	free(pend);
	return rc;
}

/* "a:b:s": rotations a, a + s, ... below b (b > a, s > 0, at most 100000). */
static int parse_scan(const char *arg, struct opts *o)
{
	double a, b, st;
	char *end;
	a = strtod(arg, &end);
	if (end == arg || *end != ':')
		return -1;
	arg = end + 1;
	b = strtod(arg, &end);
	if (end == arg || *end != ':')
		return -1;
	arg = end + 1;
	st = strtod(arg, &end);
	if (end == arg || *end || !isfinite(a) || !isfinite(b) || !(st > 0) || !(b > a) ||
	    (b - a) / st > 100000)
		return -1;
	o->scan = 1;
	o->rot_a = a;
	o->rot_step = st;
	o->nrot = (int)ceil((b - a) / st - 1e-9);
	return 0;
}

/* The scan's error estimate: a line (or a JSON object) after its rotations,
 * and a warning when it exceeds the tolerance. */
static void print_estimate(const struct opts *o, const char *path, size_t n,
                           const struct ps_sensor *s, int nsens, const struct ps_scancheck *c)
{
	if (o->json) {
		printf("{\"picture\": ");
		json_string(path);
		printf(", \"sensor\": ");
		json_string(s->path);
		printf(", \"scan_error_estimate\": %.3g, \"at\": %.10g, \"tolerance\": %g, "
		       "\"checked\": [", c->estimate, c->at_deg, c->tolerance);
		for (int i = 0; i < c->nchecked; i++)
			printf("%s%.10g", i ? ", " : "", c->checked_deg[i]);
		printf("]}\n");
	} else {
		if (n > 1)
			printf("%s: ", path);
		if (nsens > 1)
			printf("%s: ", s->path);
		printf("Scan error estimate: %.2e at rotation %g (the exact route at", c->estimate,
		       c->at_deg);
		for (int i = 0; i < c->nchecked; i++)
			printf(" %g", c->checked_deg[i]);
		printf("; tolerance %g)\n", c->tolerance);
	}
	/* not silenced by -q: the numbers above are off by more than asked */
	if (c->estimate > c->tolerance)
		fprintf(stderr, "psens: warning: %s: %s: the rotation scan is off by %.2e of the exact "
		        "route at rotation %g (tolerance %g)%s: psens -r ROTATION gives the exact "
		        "route\n", path, s->path, c->estimate, c->at_deg, c->tolerance,
		        c->refined ? ", refined" : ", and no better on finer cells");
}

/* The rotation scan: each picture projected once (sim/weights/rescan.h), every
 * sensor evaluated at every rotation from the projection. */
static int scan_route(const struct ps_sensor *sens, int nsens, struct opts *o,
                      const char *const *paths, size_t n)
{
	struct ps_sensor uni;
	struct ps_err e;
	int status = 0;
	/* cells: 0.25 degrees in polar angle, at most 0.25 degree in azimuth
	 * and a whole number of them per step (test_rescan, doc/simulation.md:
	 * the error against the exact route; sim/weights/scancheck.h checks it) */
	double cells = ceil(o->rot_step / 0.25 - 1e-9), dphi = o->rot_step / cells;
	double *out = malloc((size_t)o->nrot * sizeof *out);
	if (!out || ps_sensor_builtin(&uni, PS_SENS_UNIFORM, &e) != 0) {
		fprintf(stderr, "psens: out of memory\n");
		free(out);
		return 1;
	}
	if (fabs(360.0 / dphi - round(360.0 / dphi)) > 1e-9) {
		fprintf(stderr, "psens: -r: a step of %g degrees must divide 360 into whole cells of at "
		                "most 0.25 degree\n", o->rot_step);
		free(out);
		ps_sensor_free(&uni);
		return 2;
	}
	for (size_t i = 0; i < n; i++) {
		struct ps_picture pic;
		struct ps_view view;
		struct ps_weights om;
		struct ps_rescan p;
		struct ps_err warn;
		double ext = 0;
		int assumed, how;
		if (ps_picture_read(&pic, paths[i], &e) != 0 ||
		    ps_picview_fisheye(&pic, paths[i], &view, &assumed, &e) != 0) {
			fprintf(stderr, "psens: %s\n", e.msg);
			ps_picture_free(&pic);
			status = 1;
			continue;
		}
		if (assumed && !o->quiet)
			fprintf(stderr, "psens: warning: %s has no VIEW=; assuming -vta -vh 180 -vv 180\n",
			        paths[i]);
		for (int k = 0; k < nsens; k++)
			if (ps_sensor_extent(&sens[k]) > ext)
				ext = ps_sensor_extent(&sens[k]);
		/* the pixels' solid angles: the uniform sensor's exact weights */
		struct ps_wcache_key key = { .sensor = &uni, .rotation_deg = 0, .view = &view,
		                             .width = pic.width, .height = pic.height,
		                             .method = PS_W_EXACT };
		struct ps_wcache_dir cache = { .path = o->cachedir, .max_bytes = ps_cache_max_bytes() };
		if (ps_wcache_get(&om, &key, &cache, &how, &warn, &e) != 0 ||
		    ps_rescan_project(&p, &om, &pic, &view, o->coef, 0.25, dphi, o->rot_a,
		                      ext / (M_PI / 180) + 0.25, &e) != 0) {
			fprintf(stderr, "psens: %s: %s\n", paths[i], e.msg);
			ps_weights_free(&om);
			ps_picture_free(&pic);
			status = 1;
			continue;
		}
		if (how == PS_WC_UNWRITABLE) {
			if (!o->quiet && !o->cache_warned)
				fprintf(stderr, "psens: warning: weights not cached (%s); going on without "
				                "the cache\n", warn.msg);
			o->cache_warned = 1;
			o->cachedir = NULL;
		}
		for (int k = 0; k < nsens; k++) {
			struct ps_scancheck chk = { .tolerance = o->tolerance };
			if (ps_scancheck_scan(&p, &om, &pic, &view, o->coef, &sens[k], o->rot_a, o->rot_step,
			                      o->nrot, o->nthreads, &cache, out, &chk, &e) != 0) {
				fprintf(stderr, "psens: %s: %s\n", paths[i], e.msg);
				status = 1;
				continue;
			}
			{
				int bad = -1;
				for (int r = 0; r < o->nrot && bad < 0; r++)
					if (!isfinite(out[r]))
						bad = r;
				if (bad >= 0) {
					fprintf(stderr, "psens: %s: rotation %g: the response is %s: the colour "
					        "coefficients (%g %g %g) times the picture overflow, or the sensor's "
					        "sensitivities are too large\n", paths[i], o->rot_a + bad * o->rot_step,
					        isnan(out[bad]) ? "not a number" : "infinite", o->coef[0], o->coef[1],
					        o->coef[2]);
					status = 1;
					continue;
				}
			}
			for (int r = 0; r < o->nrot; r++) {
				double rot = o->rot_a + r * o->rot_step;
				if (o->json) {
					printf("{\"picture\": ");
					json_string(paths[i]);
					printf(", \"sensor\": ");
					json_string(sens[k].path);
					printf(", \"rotation\": %.10g, \"response\": %.10g, \"route\": \"rescan\"}\n",
					       rot, out[r]);
				} else {
					if (n > 1)
						printf("%s: ", paths[i]);
					if (nsens > 1)
						printf("%s: ", sens[k].path);
					printf("Rotation: %g Response: %.9g\n", rot, out[r]);
				}
			}
			if (chk.nchecked > 0)
				print_estimate(o, paths[i], n, &sens[k], nsens, &chk);
		}
		ps_rescan_free(&p);
		ps_weights_free(&om);
		ps_picture_free(&pic);
	}
	free(out);
	ps_sensor_free(&uni);
	return status;
}

enum { MAX_SENSORS = 64 };

int main(int argc, char **argv)
{
	const char *sensfiles[MAX_SENSORS];
	int nsens = 0, reading = PS_READ_LINEAR, opt, status = 0, nocache = 0;
	char cachebuf[4096];
	struct ps_sensor sens[MAX_SENSORS];
	struct ps_err e;
	const char *const *paths;
	struct item *items;
	size_t n;
	struct opts o = { .rot = 0.0, .coef = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B },
	                  .method = PS_W_EXACT, .nthreads = PS_BATCH_THREADS_DEFAULT,
	                  .tolerance = PS_SCANCHECK_TOLERANCE };

	enum { OPT_TOLERANCE = 1000 };
	static const struct option longopts[] = { PS_CLI_LONGOPTS,
	                                           { "tolerance", required_argument, NULL,
	                                             OPT_TOLERANCE },
	                                           { NULL, 0, NULL, 0 } };
	while ((opt = getopt_long(argc, argv, "s:r:R:G:B:f:m:n:o:C:NcjqhV", longopts, NULL)) != -1) {
		switch (opt) {
		case 's':
			if (nsens == MAX_SENSORS) {
				fprintf(stderr, "psens: -s: at most %d sensors\n", MAX_SENSORS);
				return 2;
			}
			sensfiles[nsens++] = optarg;
			break;
		case 'r':
			if (strchr(optarg, ':')) {
				if (parse_scan(optarg, &o) != 0) {
					fprintf(stderr, "psens: -r: '%s' is not start:end:step (end above start, "
					                "step above 0)\n", optarg);
					return 2;
				}
			} else if (parse_num("-r", optarg, &o.rot)) {
				return 2;
			}
			break;
		case 'R': if (parse_num("-R", optarg, &o.coef[0])) return 2; break;
		case 'G': if (parse_num("-G", optarg, &o.coef[1])) return 2; break;
		case 'B': if (parse_num("-B", optarg, &o.coef[2])) return 2; break;
		case 'f':
			if (ps_filter_rgb(optarg, o.coef, &e) != 0) {
				fprintf(stderr, "psens: %s\n", e.msg);
				return 1;
			}
			break;
		case 'm':
			reading = ps_sensor_reading_parse(optarg);
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
			o.nthreads = (int)v;
			break;
		}
		case 'o':
			if (!optarg[0] || optarg[1] || !strchr("afd", optarg[0])) {
				fprintf(stderr, "psens: -o%s: the matrix format is -oa, -of or -od\n", optarg);
				return 2;
			}
			o.mtx = optarg[0];
			break;
		case 'C': o.cachedir = optarg; break;
		case 'N': nocache = 1; break;
		case 'c': o.method = PS_W_CENTRE; break;
		case 'j': o.json = 1; break;
		case 'q': o.quiet = 1; break;
		case OPT_TOLERANCE:
			if (parse_num("--tolerance", optarg, &o.tolerance))
				return 2;
			if (o.tolerance < 0) {
				fprintf(stderr, "psens: --tolerance: '%s' is below 0\n", optarg);
				return 2;
			}
			break;
		case 'h': usage(stdout); return 0;
		case 'V': return ps_cli_version("psens");
		default: usage(stderr); return 2;
		}
	}
	if (!nsens || optind >= argc) {
		fprintf(stderr, "psens: %s\n", !nsens ? "no sensitivity (-s FILE or -s builtin:cosine)"
		                                        : "no picture (give one or more HDR pictures)");
		usage(stderr);
		return 2;
	}
	if (o.mtx && o.json) {
		fprintf(stderr, "psens: -j and -o%c: one output at a time\n", o.mtx);
		return 2;
	}
	if (o.scan && (o.mtx || o.method == PS_W_CENTRE)) {
		fprintf(stderr, "psens: a rotation scan (-r start:end:step) prints lines or JSON, with "
		                "the exact solid angles: not with -o or -c\n");
		return 2;
	}
	for (int k = 0; k < nsens; k++)
		if (ps_sensor_open(&sens[k], sensfiles[k], &e) != 0 ||
		    ps_sensor_set_reading(&sens[k], reading, &e) != 0) {
			fprintf(stderr, "psens: %s\n", e.msg);
			return 1;
		}
	if (nocache) {
		o.cachedir = NULL;
	} else if (!o.cachedir) {
		ps_cache_default_dir(cachebuf, sizeof cachebuf);
		o.cachedir = cachebuf;
	}
	paths = (const char *const *)argv + optind;
	n = (size_t)(argc - optind);
	if (o.scan) {
		status = scan_route(sens, nsens, &o, paths, n);
		for (int k = 0; k < nsens; k++)
			ps_sensor_free(&sens[k]);
		return status;
	}
	items = calloc(n * (size_t)nsens, sizeof *items);
	if (!items) {
		fprintf(stderr, "psens: out of memory\n");
		return 1;
	}
	/* one sensor: batches of pictures in parallel; several: each picture
	 * decoded once for all of them */
	if (nsens == 1 ? direct(&sens[0], &o, paths, n, items) != 0
	               : direct_multi(sens, nsens, &o, paths, n, items) != 0)
		return 1;
	for (size_t i = 0; i < n; i++)
		for (int k = 0; k < nsens; k++) {
			struct item *it = &items[(size_t)k * n + i];
			if (it->res.status != PS_BATCH_OK) {
				/* a picture that cannot be read says so once, not per sensor */
				if (k == 0 || strcmp(it->res.err.msg, items[i].res.err.msg) != 0)
					fprintf(stderr, "psens: %s\n", it->res.err.msg);
				status = 1;
				continue;
			}
			if (!o.quiet && it->res.view_assumed && k == 0)
				fprintf(stderr, "psens: warning: %s has no VIEW=; assuming -vta -vh 180 -vv 180\n",
				        paths[i]);
			if (!o.quiet)
				warnings(paths[i], it->coverage, &it->res.r, &sens[k], &it->view);
			if (!o.mtx)
				print_result(paths[i], nsens > 1 ? sensfiles[k] : NULL, it, &sens[k], o.method,
				             o.json, n > 1);
		}
	if (o.mtx && status == 0)
		status = write_matrix(argc, argv, items, n, nsens, o.mtx);
	else if (o.mtx)
		fprintf(stderr, "psens: no matrix written: every picture must give a column\n");
	free(items);
	for (int k = 0; k < nsens; k++)
		ps_sensor_free(&sens[k]);
	return status;
}
