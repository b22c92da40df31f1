/* SPDX-License-Identifier: ISC */
/* psplace: where to put which sensor.  Every combination of a candidate
 * pose (its daylight-coefficient pictures and electric picture), a rotation
 * about the sensor's axis, a sensor and a control law is run through the
 * weather year with the zone's real law and device model (annual.h, the
 * engine psensd -Y runs) and scored against a work-plane grid (gridmtx.h);
 * psplace(1) says what each figure means.
 *
 * It is a program of daemon/ because it runs the control laws and the
 * device model, which sim/ must not know; the simulation (pictures,
 * projections, the sky, the grid) comes from libpsim.
 *
 * The route: each pose's pictures are projected once per colour channel
 * onto a (theta, phi) grid (rescan.h), and every sensor at every rotation
 * read from the projection (one pass over the cells), not integrated
 * again; the year's sky vectors are made once and shared by every
 * combination.  The best combinations are then integrated exactly
 * (ps_weights_build at their rotation) and run again: the table prints
 * the projection's error on the year's sensor signal and on the energy. */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "annual.h"
#include "canvas.h"
#include "cli.h"
#include "config.h"
#include "scene.h"
#include "control.h"
#include "falsecolor.h"
#include "gridmtx.h"
#include "integrate.h"
#include "json.h"
#include "log.h"
#include "patches.h"
#include "picture.h"
#include "rescan.h"
#include "results.h"
#include "sensor.h"
#include "sky.h"
#include "time.h"
#include "view.h"
#include "weather.h"
#include "weights.h"
#include "year.h"

#define MAX_LIST 64
#define LINE 4096

static const double V[3] = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B };

struct pose {
	char id[64];
	char view_text[512];
	struct ps_view view;
	double *row;       /* nrot x nsens x npatch x 3 (projection route), per channel */
	double *elec;      /* nrot x nsens: the response to the electric picture */
};

/* the year's hours with light, shared by every combination */
struct hours {
	size_t n;
	struct ps_year_hour *h;   /* sensor left 0: filled per combination */
	double *sky;              /* n x npatch x 3 */
	double *task;             /* n: the grid's figure of daylight lux */
	int npatch, leap;
	struct ps_site site;
};

struct combo {
	int pose, rot, sens, law;
	int exact;                 /* run again with the exact route */
	struct psd_annual a;
	double deficit_lxh;        /* sum over occupied time of (target - task), where below */
	double over_h;             /* hours with more light output than the ideal photocell's + 0.01 */
	double spread[PS_SKY_NCLASS];   /* task/sensor ratio: sd / mean by sky class, % */
	double spread_max;
	double days_pass, days;    /* days passing the acceptance tests, days judged */
	double sensor_sum;         /* the year's sensor signal (for the exact check) */
	double exact_sensor_err, exact_energy_err;   /* projection against exact, % */
	int pareto;
	int fail;
};

struct opts {
	const char *conf, *zone, *cands, *dir, *grid, *elec, *weather, *stat;
	const char *json_out, *results_out, *schedule, *csv, *zone_out, *plan;
	const char *sens[MAX_LIST];
	int nsens;
	int laws[PSD_ALG_COUNT], nlaws;
	int nrot, top, threads, quiet, json;
	double rot_step;
	double period, cell_theta, max_below;
};

struct search {
	const struct opts *o;
	struct psd_config *cf;
	const struct psd_zone_conf *zc;
	struct pose *poses;
	int nposes;
	struct ps_sensor *sens;
	int npatch, mf;
	double cell_theta;         /* degrees: the projection's cells in polar angle */
	double theta_max;          /* degrees: the projection's extent (the sensors') */
	struct hours hrs;
	double elec_task;          /* the grid's figure at full electric output */
	struct psd_annual_opt ao;
	struct combo *c;
	size_t nc;
	size_t next;
	pthread_mutex_t lock;
	int failed;
};

static void usage(FILE *fp)
{
	fprintf(fp, "usage: psplace -f psensd.conf [-z zone] -c candidates.txt [-d dir] -g grid.mtx\n"
	            "               -e grid_elec.dat -w weather [-s sensor]... [-a law]... [-r step]\n"
	            "               [-t figure] [-T top] [-n threads] [-p period] [-u hours] [-k deg]\n"
	            "               [-j] [-o out.json] [-x results] [-E schedule.csv] [-y year.csv]\n"
	            "               [-Z zone.conf] [-P plan.png] [-q]\n"
	            "  -f FILE   psensd.conf: the zone's law, devices and [simulate] power curve\n"
	            "  -z ZONE   the zone (default the first)\n"
	            "  -c FILE   candidate poses: an id and a Radiance view a line\n"
	            "  -d DIR    where each pose's DIR/id/dc_%%03d.hdr and elec.hdr are (default .)\n"
	            "  -g FILE   the work-plane grid's coefficients (rfluxmtx -I+ matrix)\n"
	            "  -e FILE   the grid's electric irradiance (rtrace -I+ lines)\n"
	            "  -w FILE   the weather (.wea or .epw)\n"
	            "  -s FILE   a sensor: a table or builtin:cosine, builtin:uniform (repeat)\n"
	            "  -a LAW    a control law (repeat; default all five)\n"
	            "  -r DEG    the rotation step about the sensor axis (default 10: 36 rotations)\n"
	            "  -t FIG    the grid's figure: min, mean (default), pNN, points:i,j,...\n"
	            "  -T N      re-check the best N by the exact route (default 3)\n"
	            "  -n N      threads for the years (default 2)\n"
	            "  -p S      control period, s (default the zone's)\n"
	            "  -u H      hours below 90 %% of the target still ranked by energy\n"
	            "  -k DEG    the projection's cells in polar angle (default 2)\n"
	            "  -j        the whole table as JSON;  -o FILE  the JSON to a file\n"
	            "  -x FILE   the winner's results for psensd\n"
	            "  -E FILE   the winner's year as an EnergyPlus Schedule:File CSV\n"
	            "  -y FILE   the winner's year as a plain CSV\n"
	            "  -Z FILE   the winner's settings as a psensd.conf zone section\n"
	            "  -P FILE   the plan of the poses as a PNG\n"
	            "  -q        only the best 10 rows\n"
	            "  -h, --help     this help;  -V, --version  the version\n");
}

/* ---- reading the candidates ---------------------------------------- */

static int read_candidates(struct search *s, char *err, size_t errlen)
{
	FILE *fp = fopen(s->o->cands, "r");
	char line[LINE];
	int ln = 0;
	if (!fp)
		return snprintf(err, errlen, "%s: %s", s->o->cands, strerror(errno)), -1;
	while (fgets(line, sizeof line, fp)) {
		char *p = line + strspn(line, " \t"), *q;
		struct pose *np;
		struct ps_err e;
		ln++;
		p[strcspn(p, "\r\n")] = 0;
		if (!*p || *p == '#')
			continue;
		q = p + strcspn(p, " \t");
		if (!*q || (size_t)(q - p) >= sizeof np->id) {
			fclose(fp);
			return snprintf(err, errlen, "%s:%d: expected an id and a view", s->o->cands, ln), -1;
		}
		np = realloc(s->poses, (size_t)(s->nposes + 1) * sizeof *np);
		if (!np) {
			fclose(fp);
			return snprintf(err, errlen, "out of memory"), -1;
		}
		s->poses = np;
		np = &s->poses[s->nposes];
		memset(np, 0, sizeof *np);
		memcpy(np->id, p, (size_t)(q - p));
		q += strspn(q, " \t");
		snprintf(np->view_text, sizeof np->view_text, "%s", q);
		{
			char where[600];
			snprintf(where, sizeof where, "%s:%d", s->o->cands, ln);
			if (ps_view_parse(&np->view, q, where, &e) != 0) {
				fclose(fp);
				return snprintf(err, errlen, "%s", e.msg), -1;
			}
		}
		s->nposes++;
	}
	fclose(fp);
	if (!s->nposes)
		return snprintf(err, errlen, "%s: no candidate", s->o->cands), -1;
	return 0;
}

static void pose_path(const struct search *s, const struct pose *p, const char *name, char *out, size_t n)
{
	snprintf(out, n, "%s/%s/%s", s->o->dir, p->id, name);
}

/* The pose's pictures, in memory: npatch coefficient pictures and the
 * electric one.  Every error names the candidate. */
static int load_pictures(const struct search *s, const struct pose *p, struct ps_picture *pics,
                         struct ps_picture *elec, char *err, size_t errlen)
{
	char path[LINE + 128];
	struct ps_err e;
	int i;
	memset(pics, 0, (size_t)s->npatch * sizeof *pics);
	memset(elec, 0, sizeof *elec);
	for (i = 0; i < s->npatch; i++) {
		char name[32];
		snprintf(name, sizeof name, "dc_%03d.hdr", i);
		pose_path(s, p, name, path, sizeof path);
		if (ps_picture_read(&pics[i], path, &e) != 0) {
			snprintf(err, errlen, "candidate %s: patch %d of %d: %s", p->id, i, s->npatch, e.msg);
			goto bad;
		}
		if (pics[i].width != pics[0].width || pics[i].height != pics[0].height) {
			snprintf(err, errlen, "candidate %s: %.600s is %d x %d where dc_000.hdr is %d x %d: a mismatched set",
			         p->id, path, pics[i].width, pics[i].height, pics[0].width, pics[0].height);
			i++;
			goto bad;
		}
	}
	{
		char name[32];
		snprintf(name, sizeof name, "dc_%03d.hdr", s->npatch);
		pose_path(s, p, name, path, sizeof path);
		FILE *fp = fopen(path, "rb");
		if (fp) {
			fclose(fp);
			snprintf(err, errlen, "candidate %s: %.600s exists: more pictures than the grid's %d patches (MF %d)",
			         p->id, path, s->npatch, s->mf);
			goto bad;
		}
	}
	pose_path(s, p, "elec.hdr", path, sizeof path);
	if (ps_picture_read(elec, path, &e) != 0) {
		char alt[LINE + 128];
		struct ps_err e2;
		pose_path(s, p, "elec_128.hdr", alt, sizeof alt);
		if (ps_picture_read(elec, alt, &e2) != 0) {
			snprintf(err, errlen, "candidate %s: no electric picture: %s", p->id, e.msg);
			goto bad;
		}
	}
	return 0;
bad:
	for (int k = 0; k < i && k < s->npatch; k++)
		ps_picture_free(&pics[k]);
	return -1;
}

/* cells: cell_theta degrees in polar angle; in azimuth the rotation step
 * split into whole cells of at most 10 degrees */
static double cell_phi(const struct search *s)
{
	double step = 360.0 / s->o->nrot;
	return step / ceil(step / 10.0 - 1e-9);
}

/* project one picture per channel and read every sensor at every rotation */
static int scan_picture(const struct search *s, const struct ps_weights *om, const struct ps_picture *pic,
                        const struct ps_view *v, int channels, double *out, size_t stride, char *err,
                        size_t errlen)
{
	struct ps_err e;
	double *tmp = malloc((size_t)s->o->nrot * sizeof *tmp);
	if (!tmp)
		return snprintf(err, errlen, "out of memory"), -1;
	for (int c = 0; c < channels; c++) {
		double coef[3] = { 0, 0, 0 };
		struct ps_rescan pr;
		if (channels == 3)
			coef[c] = 1;
		else
			memcpy(coef, V, sizeof coef);
		if (ps_rescan_project(&pr, om, pic, v, coef, s->cell_theta, cell_phi(s), 0, s->theta_max,
		                      &e) != 0) {
			free(tmp);
			return snprintf(err, errlen, "%s", e.msg), -1;
		}
		for (int k = 0; k < s->o->nsens; k++) {
			if (ps_rescan_scan(&pr, &s->sens[k], 0, 360.0 / s->o->nrot, s->o->nrot, tmp, &e) != 0) {
				ps_rescan_free(&pr);
				free(tmp);
				return snprintf(err, errlen, "%s", e.msg), -1;
			}
			for (int r = 0; r < s->o->nrot; r++)
				out[((size_t)r * (size_t)s->o->nsens + (size_t)k) * stride + (size_t)c] = tmp[r];
		}
		ps_rescan_free(&pr);
	}
	free(tmp);
	return 0;
}

static int project_pose(struct search *s, struct pose *p, char *err, size_t errlen)
{
	struct ps_picture *pics = calloc((size_t)s->npatch, sizeof *pics), elec;
	struct ps_sensor uni;
	struct ps_weights om, ome;
	struct ps_err e;
	int rc = -1;
	size_t nrs = (size_t)s->o->nrot * (size_t)s->o->nsens;
	if (!pics)
		return snprintf(err, errlen, "out of memory"), -1;
	if (load_pictures(s, p, pics, &elec, err, errlen) != 0) {
		free(pics);
		return -1;
	}
	p->row = calloc(nrs * (size_t)s->npatch * 3, sizeof *p->row);
	p->elec = calloc(nrs, sizeof *p->elec);
	memset(&om, 0, sizeof om);
	memset(&ome, 0, sizeof ome);
	if (!p->row || !p->elec || ps_sensor_builtin(&uni, PS_SENS_UNIFORM, &e) != 0) {
		snprintf(err, errlen, "out of memory");
		goto out;
	}
	if (ps_weights_build(&om, &uni, 0, &p->view, pics[0].width, pics[0].height, PS_W_EXACT, &e) != 0 ||
	    ps_weights_build(&ome, &uni, 0, &p->view, elec.width, elec.height, PS_W_EXACT, &e) != 0) {
		snprintf(err, errlen, "candidate %s: %s", p->id, e.msg);
		ps_sensor_free(&uni);
		goto out;
	}
	ps_sensor_free(&uni);
	for (int i = 0; i < s->npatch; i++) {
		/* row[((r nsens + k) npatch + i) 3 + c] */
		double *tmp = malloc(nrs * 3 * sizeof *tmp);
		if (!tmp) {
			snprintf(err, errlen, "out of memory");
			goto out;
		}
		if (scan_picture(s, &om, &pics[i], &p->view, 3, tmp, 3, err, errlen) != 0) {
			free(tmp);
			goto out;
		}
		for (size_t rk = 0; rk < nrs; rk++)
			for (int c = 0; c < 3; c++)
				p->row[(rk * (size_t)s->npatch + (size_t)i) * 3 + (size_t)c] = tmp[rk * 3 + (size_t)c];
		free(tmp);
	}
	if (scan_picture(s, &ome, &elec, &p->view, 1, p->elec, 1, err, errlen) != 0)
		goto out;
	rc = 0;
out:
	ps_weights_free(&om);
	ps_weights_free(&ome);
	for (int i = 0; i < s->npatch; i++)
		ps_picture_free(&pics[i]);
	ps_picture_free(&elec);
	free(pics);
	return rc;
}

/* The exact route for one pose, sensor and rotation: the coefficient row
 * (npatch x 3, ps_dcset_row) and the electric response. */
static int exact_row(const struct search *s, const struct pose *p, int k, double rot, double *row, double *elec,
                     char *err, size_t errlen)
{
	char pattern[LINE + 128], path[LINE + 128];
	struct ps_dcset_row dr;
	struct ps_picture ep;
	struct ps_weights we;
	struct ps_response r;
	struct ps_err e;
	pose_path(s, p, "dc_%03d.hdr", pattern, sizeof pattern);
	if (ps_dcset_row(pattern, &p->view, s->mf, &s->sens[k], rot, &dr, &e) != 0)
		return snprintf(err, errlen, "candidate %s: %s", p->id, e.msg), -1;
	memcpy(row, dr.c, (size_t)dr.n * 3 * sizeof *row);
	ps_dcset_row_free(&dr);
	pose_path(s, p, "elec.hdr", path, sizeof path);
	if (ps_picture_read(&ep, path, &e) != 0) {
		pose_path(s, p, "elec_128.hdr", path, sizeof path);
		if (ps_picture_read(&ep, path, &e) != 0)
			return snprintf(err, errlen, "candidate %s: %s", p->id, e.msg), -1;
	}
	if (ps_weights_build(&we, &s->sens[k], rot, &p->view, ep.width, ep.height, PS_W_EXACT, &e) != 0) {
		ps_picture_free(&ep);
		return snprintf(err, errlen, "candidate %s: %s", p->id, e.msg), -1;
	}
	if (ps_integrate(&we, &ep, V, &r, &e) != 0) {
		ps_weights_free(&we);
		ps_picture_free(&ep);
		return snprintf(err, errlen, "candidate %s: %s", p->id, e.msg), -1;
	}
	*elec = r.response;
	ps_weights_free(&we);
	ps_picture_free(&ep);
	return 0;
}

/* ---- the grid and the year ---------------------------------------- */

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return x < y ? -1 : x > y;
}

/* The grid's figure of the points' lux v[n]: min, mean, pNN (the NN-th
 * percentile, nearest rank) or points:i,j,... (the mean of those rows,
 * from 1). */
static double grid_stat(const char *stat, const double *v, int n, double *scratch)
{
	double sum = 0;
	if (!strcmp(stat, "min")) {
		double m = v[0];
		for (int i = 1; i < n; i++)
			m = v[i] < m ? v[i] : m;
		return m;
	}
	if (!strcmp(stat, "mean")) {
		for (int i = 0; i < n; i++)
			sum += v[i];
		return sum / n;
	}
	if (stat[0] == 'p' && stat[1] != 'o') {
		double q = atof(stat + 1) / 100.0;
		int k = (int)ceil(q * n) - 1;
		memcpy(scratch, v, (size_t)n * sizeof *v);
		qsort(scratch, (size_t)n, sizeof *scratch, cmp_double);
		return scratch[k < 0 ? 0 : k >= n ? n - 1 : k];
	}
	{
		/* points:i,j */
		const char *p = strchr(stat, ':') + 1;
		int cnt = 0;
		while (*p) {
			char *end;
			long i = strtol(p, &end, 10);
			sum += v[i - 1];
			cnt++;
			p = *end == ',' ? end + 1 : end;
		}
		return sum / cnt;
	}
}

/* 0, or -1 with err: stat names a figure of an n-point grid */
static int check_stat(const char *stat, int n, char *err, size_t errlen)
{
	if (!strcmp(stat, "min") || !strcmp(stat, "mean"))
		return 0;
	if (stat[0] == 'p' && stat[1] != 'o') {
		char *end;
		double q = strtod(stat + 1, &end);
		if (end != stat + 1 && !*end && q >= 0 && q <= 100)
			return 0;
	} else if (!strncmp(stat, "points:", 7) && stat[7]) {
		const char *p = stat + 7;
		while (*p) {
			char *end;
			long i = strtol(p, &end, 10);
			if (end == p || i < 1 || i > n || (*end && *end != ','))
				return snprintf(err, errlen, "-t %s: a point is a row of the grid, 1 to %d", stat, n), -1;
			p = *end == ',' ? end + 1 : end;
		}
		return 0;
	}
	return snprintf(err, errlen, "-t %s: the grid's figure is min, mean, pNN (a percentile) or points:i,j,...",
	                stat), -1;
}

static int make_hours(struct search *s, const struct ps_gridmtx *g, char *err, size_t errlen)
{
	struct ps_weather w;
	struct ps_patches P;
	struct ps_sky_opt so;
	struct ps_err e;
	struct hours *H = &s->hrs;
	double *lux = malloc((size_t)g->npoints * 2 * sizeof *lux);
	if (!lux)
		return snprintf(err, errlen, "out of memory"), -1;
	if (ps_weather_read(&w, s->o->weather, 0, &e) != 0) {
		free(lux);
		return snprintf(err, errlen, "%s", e.msg), -1;
	}
	if (ps_patches_init(&P, g->mf, &e) != 0) {
		free(lux);
		ps_weather_free(&w);
		return snprintf(err, errlen, "%s", e.msg), -1;
	}
	ps_sky_opt_default(&so);
	H->npatch = P.n;
	H->h = calloc(w.n ? w.n : 1, sizeof *H->h);
	H->sky = malloc((w.n ? w.n : 1) * (size_t)P.n * 3 * sizeof *H->sky);
	H->task = malloc((w.n ? w.n : 1) * sizeof *H->task);
	if (!H->h || !H->sky || !H->task) {
		free(lux);
		ps_weather_free(&w);
		ps_patches_free(&P);
		return snprintf(err, errlen, "out of memory for %zu hours", w.n), -1;
	}
	H->site = w.site;
	H->leap = w.leap;
	for (size_t i = 0; i < w.n; i++) {
		struct ps_sky sk;
		struct ps_year_hour *k;
		double *sky = H->sky + H->n * (size_t)P.n * 3;
		if (ps_sky_step(&sk, &w, i, &so, &e) != 0) {
			free(lux);
			ps_weather_free(&w);
			ps_patches_free(&P);
			return snprintf(err, errlen, "%s", e.msg), -1;
		}
		if (sk.dark)
			continue;
		ps_sky_vector(&sk, &P, PS_SKY_ALL, sky);
		k = &H->h[H->n];
		k->month = w.step[i].month;
		k->day = w.step[i].day;
		k->hour = w.step[i].hour;
		k->epsilon = sk.model.epsilon;
		k->sky_class = ps_year_class(sk.model.epsilon);
		k->horiz_lux = sk.model.dif_lux + (sk.sun_alt > 0 ? sk.model.dir_lux * sin(sk.sun_alt) : 0.0);
		for (int pt = 0; pt < g->npoints; pt++) {
			struct ps_dcset_row row;
			ps_gridmtx_row(g, pt, &row);
			lux[pt] = PS_YEAR_LUX_PER_WM2 * ps_dcset_row_apply(&row, V, sky);
		}
		H->task[H->n] = grid_stat(s->o->stat, lux, g->npoints, lux + g->npoints);
		H->n++;
	}
	free(lux);
	ps_weather_free(&w);
	ps_patches_free(&P);
	return 0;
}

/* The results psensd would read for one combination: the year's hours
 * with this sensor's signal, a daylight condition holding the year's mean
 * ratio (the year's mean signals, at noon of any day) and the electric one.  row: npatch x 3 per channel. */
static int make_results(const struct search *s, const double *row, double elec, const struct ps_sensor *sens,
                        struct ps_results *r, double *sensor_sum)
{
	const struct hours *H = &s->hrs;
	double ssum = 0, tsum = 0;
	memset(r, 0, sizeof *r);
	r->version = PS_RESULTS_VERSION;
	r->year.h = malloc((H->n ? H->n : 1) * sizeof *r->year.h);
	r->cond = calloc(2, sizeof *r->cond);
	if (!r->year.h || !r->cond) {
		free(r->year.h);
		free(r->cond);
		return -1;
	}
	for (size_t i = 0; i < H->n; i++) {
		const double *sky = H->sky + i * (size_t)H->npatch * 3;
		double v = 0;
		for (int p = 0; p < H->npatch; p++)
			for (int c = 0; c < 3; c++)
				v += V[c] * row[3 * p + c] * sky[3 * p + c];
		r->year.h[i] = H->h[i];
		r->year.h[i].sensor = v;
		r->year.h[i].task_lux = H->task[i];
		ssum += v;
		tsum += H->task[i];
	}
	*sensor_sum = ssum;
	r->year.n = H->n;
	r->year.patches = H->npatch;
	r->year.used = H->npatch;
	r->year.leap = H->leap;
	r->year.have_site = 1;
	r->year.site = H->site;
	ps_year_tabulate(&r->year);
	r->have_year = 1;
	r->year_mf = s->mf;
	r->weather = (char *)s->o->weather;
	r->sensitivity = sens->path;
	r->reading = (char *)"linear";
	memcpy(r->rgb, V, sizeof r->rgb);
	r->scene = (char *)s->o->cands;
	r->scene_hash = (char *)"";
	r->ncond = 2;
	r->cond[0] = (struct ps_result_cond){ .label = (char *)"year_mean", .kind = PS_COND_DAYLIGHT, .date = (char *)"", .tod_s = 43200,
	                                      .computed = 1, .sensor_response = H->n ? ssum / (double)H->n : 0,
	                                      .task_lux = H->n ? tsum / (double)H->n : 0 };
	r->cond[1] = (struct ps_result_cond){ .label = (char *)"elec", .kind = PS_COND_ELECTRIC, .date = (char *)"", .tod_s = -1,
	                                      .computed = 1, .sensor_response = elec, .task_lux = s->elec_task };
	for (int k = 0; k < 2; k++) {
		r->cond[k].task_irradiance = r->cond[k].task_lux / PS_YEAR_LUX_PER_WM2;
		r->cond[k].ratio = r->cond[k].sensor_response > 0 ? r->cond[k].task_lux / r->cond[k].sensor_response : NAN;
	}
	ps_results_summarise(r);
	return 0;
}

static void results_release(struct ps_results *r)
{
	free(r->year.h);
	free(r->cond);
	memset(r, 0, sizeof *r);
}

/* ---- one combination through the year ------------------------------ */

/* what the step hook gathers */
struct watch {
	const struct psd_annual_opt *o;
	const struct psd_control *c;
	double deficit_lxh, over_h;
	/* the acceptance tests of a day (accept.h's criteria on the simulated day) */
	int day, day_seen, day_fail;
	double days, days_pass;
	double last_swing_t, last_out;
	int last_dir;
	double *hour_power;   /* 8784 hours: the power fraction's sum, or NULL */
	double *hour_level;
	double *hour_steps;
};

static void day_close(struct watch *w)
{
	if (w->day_seen) {
		w->days++;
		if (!w->day_fail)
			w->days_pass++;
	}
	w->day_seen = w->day_fail = 0;
	w->last_dir = 0;
	w->last_swing_t = -1e30;
}

static void step_hook(void *ctx, int doy, double t, double level, double output, double truth, double dl)
{
	struct watch *w = ctx;
	const struct psd_annual_opt *o = w->o;
	(void)level;
	const struct psd_control *c = w->c;
	double h = o->period / 3600.0;
	if (doy != w->day) {
		day_close(w);
		w->day = doy;
		w->last_out = output;
	}
	if (w->hour_power) {
		int hr = (doy - 1) * 24 + (int)(t / 3600.0);
		if (hr >= 0 && hr < 8784) {
			w->hour_power[hr] += psd_annual_power(o, output);
			w->hour_level[hr] += output;
			w->hour_steps[hr] += 1;
		}
	}
	if (!(t >= o->occ_start && t < o->occ_end)) {
		w->last_out = output;
		return;
	}
	w->day_seen = 1;
	if (truth < c->target_lux)
		w->deficit_lxh += (c->target_lux - truth) * h;
	{
		double ideal = (c->target_lux - dl) / c->elec_task_lux;
		ideal = ideal < c->min_level ? c->min_level : ideal > 1 ? 1 : ideal;
		if (output > ideal + 0.01)
			w->over_h += h;
	}
	/* full daylight: with daylight at 150 % of the target, power at most 35 % */
	if (dl >= 1.5 * c->target_lux && psd_annual_power(o, output) > 0.35)
		w->day_fail = 1;
	/* low daylight: with daylight below 10 % of the target, the task at 90 % */
	if (dl < 0.1 * c->target_lux && truth < 0.9 * c->target_lux && t - o->period >= o->occ_start)
		w->day_fail = 1;
	/* cycling: swings of more than 0.05 against the last one's direction no
	 * closer together than the zone's delay */
	if (fabs(output - w->last_out) > 0.05 && t - o->period >= o->occ_start) {
		int dir = output > w->last_out ? 1 : -1;
		if (w->last_dir && dir != w->last_dir && t - w->last_swing_t < c->delay)
			w->day_fail = 1;
		w->last_dir = dir;
		w->last_swing_t = t;
	}
	w->last_out = output;
}

/* The ctl psensd's engine makes for a zone from results (engine.c's zone
 * set-up, and -Y's automatic switching thresholds). */
static void law_for(const struct search *s, const struct ps_results *r, int alg, struct psd_control *c)
{
	*c = s->zc->ctl;
	c->daylight_ratio = r->daylight_ratio_mean;
	c->elec_sensor = r->electric_sensor_response;
	c->elec_task_lux = r->electric_task_lux;
	c->level = 1.0;
	c->pending_since = -1;
	c->algorithm = alg;
	if (alg == PSD_ALG_SWITCHING && c->s_off >= 1e9) {
		double full = c->sensor_gain * c->elec_sensor;
		double need = c->sensor_gain * c->target_lux / r->year.mean_ratio;
		c->s_on = need;
		c->s_off = full + need;
	}
}

/* the task/sensor ratio's spread (sd / mean, %) by sky class over the
 * hours with 50 lx or more at the task */
static void spread(const struct ps_results *r, struct combo *k)
{
	double n[PS_SKY_NCLASS] = { 0 }, m[PS_SKY_NCLASS] = { 0 }, q[PS_SKY_NCLASS] = { 0 };
	for (size_t i = 0; i < r->year.n; i++) {
		const struct ps_year_hour *h = &r->year.h[i];
		if (h->task_lux >= 50 && h->sensor > 0) {
			double x = h->task_lux / h->sensor;
			n[h->sky_class]++;
			m[h->sky_class] += x;
			q[h->sky_class] += x * x;
		}
	}
	k->spread_max = 0;
	for (int c = 0; c < PS_SKY_NCLASS; c++) {
		double mean = n[c] ? m[c] / n[c] : NAN, var = n[c] ? q[c] / n[c] - mean * mean : NAN;
		k->spread[c] = n[c] > 1 && mean > 0 ? 100 * sqrt(var > 0 ? var : 0) / mean : NAN;
		if (isfinite(k->spread[c]) && k->spread[c] > k->spread_max)
			k->spread_max = k->spread[c];
	}
}

/* Run combination k's law on results r (its row's); w (may be NULL)
 * gathers the hours. */
static int run_law(const struct search *s, struct combo *k, const struct ps_results *r, struct watch *wx)
{
	struct psd_control c;
	struct psd_annual_opt o = s->ao;
	struct watch w0, *w = wx ? wx : &w0;
	if (!wx)
		memset(&w0, 0, sizeof w0);
	law_for(s, r, s->o->laws[k->law], &c);
	w->o = &o;
	w->c = &c;
	w->day = 0;
	w->last_swing_t = -1e30;
	o.step = step_hook;
	o.step_ctx = w;
	if (psd_annual_run(r, &c, &o, &k->a) != 0) {
		k->fail = 1;
		return -1;
	}
	day_close(w);
	k->deficit_lxh = w->deficit_lxh;
	k->over_h = w->over_h;
	k->days = w->days;
	k->days_pass = w->days_pass;
	return 0;
}

/* Run the laws of combinations k[0 .. n-1], which share one row. */
static int run_row(const struct search *s, struct combo *k, int n, const double *row, double elec, struct watch *wx)
{
	struct ps_results r;
	int rc = 0;
	double sum;
	if (make_results(s, row, elec, &s->sens[k[0].sens], &r, &sum) != 0)
		return -1;
	for (int i = 0; i < n; i++) {
		k[i].sensor_sum = sum;
		spread(&r, &k[i]);
		if (run_law(s, &k[i], &r, wx) != 0)
			rc = -1;
	}
	results_release(&r);
	return rc;
}

static const double *combo_row(const struct search *s, const struct combo *k)
{
	const struct pose *p = &s->poses[k->pose];
	size_t rk = (size_t)k->rot * (size_t)s->o->nsens + (size_t)k->sens;
	return p->row + rk * (size_t)s->npatch * 3;
}

static double combo_elec(const struct search *s, const struct combo *k)
{
	return s->poses[k->pose].elec[(size_t)k->rot * (size_t)s->o->nsens + (size_t)k->sens];
}

static void *worker(void *arg)
{
	struct search *s = arg;
	size_t nl = (size_t)s->o->nlaws;
	for (;;) {
		size_t i;
		pthread_mutex_lock(&s->lock);
		i = s->next;
		s->next += nl;
		pthread_mutex_unlock(&s->lock);
		if (i >= s->nc)
			break;
		if (run_row(s, &s->c[i], (int)nl, combo_row(s, &s->c[i]), combo_elec(s, &s->c[i]), NULL) != 0) {
			pthread_mutex_lock(&s->lock);
			s->failed++;
			pthread_mutex_unlock(&s->lock);
		}
	}
	return NULL;
}

/* ---- ranking and output -------------------------------------------- */

static const struct search *rank_s;

static int rank_cmp(const void *a, const void *b)
{
	const struct combo *x = a, *y = b;
	double lim = rank_s->o->max_below;
	int ox = x->a.below_h <= lim, oy = y->a.below_h <= lim;
	if (x->fail != y->fail)
		return x->fail - y->fail;
	if (ox != oy)
		return oy - ox;
	if (ox) {
		if (x->a.energy_h != y->a.energy_h)
			return x->a.energy_h < y->a.energy_h ? -1 : 1;
	} else if (x->a.below_h != y->a.below_h)
		return x->a.below_h < y->a.below_h ? -1 : 1;
	if (x->deficit_lxh != y->deficit_lxh)
		return x->deficit_lxh < y->deficit_lxh ? -1 : 1;
	if (x->pose != y->pose)
		return x->pose - y->pose;
	if (x->rot != y->rot)
		return x->rot - y->rot;
	if (x->sens != y->sens)
		return x->sens - y->sens;
	return x->law - y->law;
}

/* the front between energy and under-lighting (deficit): no other is at
 * least as good in both and better in one */
static void pareto(struct search *s)
{
	for (size_t i = 0; i < s->nc; i++) {
		struct combo *x = &s->c[i];
		x->pareto = !x->fail;
		for (size_t j = 0; j < s->nc && x->pareto; j++) {
			const struct combo *y = &s->c[j];
			if (j != i && !y->fail && y->a.energy_h <= x->a.energy_h && y->deficit_lxh <= x->deficit_lxh &&
			    (y->a.energy_h < x->a.energy_h || y->deficit_lxh < x->deficit_lxh))
				x->pareto = 0;
		}
	}
}

static double rot_deg(const struct search *s, int r)
{
	return r * 360.0 / s->o->nrot;
}

static void print_table(const struct search *s, size_t rows)
{
	printf("%4s %-8s %6s %-24s %-20s %8s %8s %8s %9s %8s %7s %7s %6s %s\n", "rank", "pose", "rot", "sensor", "law",
	       "energy%", "kWh", "below_h", "def_klxh", "over_h", "chg/h", "sprd%", "days%", "front");
	for (size_t i = 0; i < rows && i < s->nc; i++) {
		const struct combo *k = &s->c[i];
		char sname[64];
		snprintf(sname, sizeof sname, "%s", s->sens[k->sens].path ? s->sens[k->sens].path : "?");
		if (k->fail) {
			printf("%4zu %-8s %6.1f %-24.24s %-20s  (the year did not run)\n", i + 1, s->poses[k->pose].id,
			       rot_deg(s, k->rot), sname, psd_control_algorithm_names[s->o->laws[k->law]]);
			continue;
		}
		printf("%4zu %-8s %6.1f %-24.24s %-20s %8.2f %8.1f %8.1f %9.2f %8.1f %7.3f %7.1f %6.1f %s\n", i + 1,
		       s->poses[k->pose].id, rot_deg(s, k->rot), sname, psd_control_algorithm_names[s->o->laws[k->law]],
		       100 * k->a.energy_h / k->a.occ_h, k->a.kwh, k->a.below_h, k->deficit_lxh / 1000, k->over_h,
		       k->a.changes_per_h, k->spread_max, k->days > 0 ? 100 * k->days_pass / k->days : NAN,
		       k->pareto ? "*" : "");
	}
}

static json_object *combo_json(const struct search *s, const struct combo *k, size_t rank)
{
	json_object *o = json_object_new_object(), *sp = json_object_new_object();
	static const char *const cls[] = { "clear", "intermediate", "overcast" };
	json_object_object_add(o, "rank", json_object_new_int64((int64_t)rank));
	psd_json_str(o, "pose", s->poses[k->pose].id);
	psd_json_str(o, "view", s->poses[k->pose].view_text);
	psd_json_num(o, "rotation", rot_deg(s, k->rot));
	psd_json_str(o, "sensor", s->sens[k->sens].path);
	psd_json_str(o, "law", psd_control_algorithm_names[s->o->laws[k->law]]);
	psd_json_num(o, "occupied_h", k->a.occ_h);
	psd_json_num(o, "energy_pct", 100 * k->a.energy_h / k->a.occ_h);
	psd_json_num(o, "energy_h", k->a.energy_h);
	psd_json_num(o, "light_h", k->a.light_h);
	psd_json_num(o, "kwh", k->a.kwh);
	psd_json_num(o, "savings_pct", 100 * k->a.savings);
	psd_json_num(o, "below90_h", k->a.below_h);
	psd_json_num(o, "deficit_lxh", k->deficit_lxh);
	psd_json_num(o, "overdim_h", k->a.overdim_h);
	psd_json_num(o, "over_h", k->over_h);
	psd_json_num(o, "changes_per_h", k->a.changes_per_h);
	for (int c = 0; c < PS_SKY_NCLASS; c++)
		psd_json_num(sp, cls[c], k->spread[c]);
	json_object_object_add(o, "ratio_spread_pct", sp);
	psd_json_num(o, "days_passing_pct", k->days > 0 ? 100 * k->days_pass / k->days : NAN);
	json_object_object_add(o, "pareto", json_object_new_boolean(k->pareto));
	if (k->exact) {
		psd_json_num(o, "exact_sensor_err_pct", k->exact_sensor_err);
		psd_json_num(o, "exact_energy_err_pts", k->exact_energy_err);
	}
	return o;
}

static int write_json(const struct search *s, FILE *fp, double seconds)
{
	json_object *root = json_object_new_object(), *arr = json_object_new_array();
	psd_json_str(root, "candidates", s->o->cands);
	psd_json_str(root, "grid", s->o->grid);
	psd_json_str(root, "statistic", s->o->stat);
	psd_json_str(root, "weather", s->o->weather);
	psd_json_num(root, "target_lux", s->zc->ctl.target_lux);
	psd_json_num(root, "grid_electric_lux", s->elec_task);
	psd_json_num(root, "period_s", s->ao.period);
	psd_json_num(root, "seconds", seconds);
	for (size_t i = 0; i < s->nc; i++)
		json_object_array_add(arr, combo_json(s, &s->c[i], i + 1));
	json_object_object_add(root, "combinations", arr);
	fprintf(fp, "%s\n", psd_json_text(root, 17));
	json_object_put(root);
	return ferror(fp) ? -1 : 0;
}

/* month and day of day-of-year doy (from 1) */
static void month_day(int doy, int leap, int *m, int *d)
{
	static const int md[12] = { 31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31 };
	int i = 0;
	while (i < 11 && doy > md[i] + (i == 1 && leap)) {
		doy -= md[i] + (i == 1 && leap);
		i++;
	}
	*m = i + 1;
	*d = doy;
}

/* The winner's year again, hour by hour: the schedule, the CSV, the
 * results and the zone section. */
static int exports(const struct search *s, const struct combo *k0, char *err, size_t errlen)
{
	const struct opts *o = s->o;
	struct combo k = *k0;
	struct watch w;
	static double power[8784], level[8784], steps[8784];
	int days;
	if (!o->schedule && !o->csv && !o->results_out && !o->zone_out)
		return 0;
	memset(&w, 0, sizeof w);
	memset(power, 0, sizeof power);
	memset(level, 0, sizeof level);
	memset(steps, 0, sizeof steps);
	w.hour_power = power;
	w.hour_level = level;
	w.hour_steps = steps;
	if (run_row(s, &k, 1, combo_row(s, &k), combo_elec(s, &k), &w) != 0)
		return snprintf(err, errlen, "the chosen combination's year did not run"), -1;
	days = k.a.days;
	if (o->schedule || o->csv) {
		for (int pass = 0; pass < 2; pass++) {
			const char *path = pass ? o->csv : o->schedule;
			FILE *fp;
			if (!path)
				continue;
			fp = fopen(path, "w");
			if (!fp)
				return snprintf(err, errlen, "%s: %s", path, strerror(errno)), -1;
			if (!pass)
				fprintf(fp, "lighting_power_fraction\n");
			else
				fprintf(fp, "month,day,hour_ending,light_output,power_fraction\n");
			for (int hr = 0; hr < days * 24; hr++) {
				double pw = steps[hr] > 0 ? power[hr] / steps[hr] : 0, lv = steps[hr] > 0 ? level[hr] / steps[hr] : 0;
				if (!pass)
					fprintf(fp, "%.6f\n", pw);
				else {
					int m, d;
					month_day(hr / 24 + 1, days == 366, &m, &d);
					fprintf(fp, "%d,%d,%d,%.6f,%.6f\n", m, d, hr % 24 + 1, lv, pw);
				}
			}
			if (fclose(fp) != 0)
				return snprintf(err, errlen, "%s: %s", path, strerror(errno)), -1;
		}
	}
	if (o->results_out) {
		struct ps_results r;
		struct ps_err e;
		double ss;
		if (make_results(s, combo_row(s, &k), combo_elec(s, &k), &s->sens[k.sens], &r, &ss) != 0)
			return snprintf(err, errlen, "out of memory"), -1;
		if (ps_results_write(&r, o->results_out, &e) != 0) {
			results_release(&r);
			return snprintf(err, errlen, "%s", e.msg), -1;
		}
		results_release(&r);
	}
	if (o->zone_out) {
		FILE *fp = fopen(o->zone_out, "w");
		const struct psd_control *c = &s->zc->ctl;
		if (!fp)
			return snprintf(err, errlen, "%s: %s", o->zone_out, strerror(errno)), -1;
		fprintf(fp, "; psplace's choice for zone %s: pose %s (%s), the sensor %s turned %g degrees\n"
		            "; about its axis; over the year: %.1f %% energy, %.1f h below 90 %% of the target.\n"
		            "; Merge into the zone's section of psensd.conf (its points stay as they are).\n"
		            "[zone %s]\nalgorithm = %s\ntarget_lux = %g\nmin_level = %g\n",
		        s->zc->name, s->poses[k.pose].id, s->poses[k.pose].view_text, s->sens[k.sens].path,
		        rot_deg(s, k.rot), 100 * k.a.energy_h / k.a.occ_h, k.a.below_h, s->zc->name,
		        psd_control_algorithm_names[o->laws[k.law]], c->target_lux, c->min_level);
		if (o->results_out)
			fprintf(fp, "results = %s\n", o->results_out);
		if (fclose(fp) != 0)
			return snprintf(err, errlen, "%s: %s", o->zone_out, strerror(errno)), -1;
	}
	return 0;
}

/* ---- the plan ------------------------------------------------------ */

/* The room's plan seen from above (x across, y up the picture): each pose
 * a disc coloured by its best combination's energy (blue least, red most,
 * grey when none stays within the under-lighting allowed), its aim's
 * horizontal part an arrow, the winner ringed. */
static int plan_png(const struct search *s, const char *path, char *err, size_t errlen)
{
	static const uint8_t white[3] = { 255, 255, 255 };
	static const double ink[3] = { 0, 0, 0 };
	const int W = 640, H = 560, top = 50, side = 60;
	double x0 = 1e30, x1 = -1e30, y0 = 1e30, y1 = -1e30, emin = 1e30, emax = -1e30, scale;
	double *best = calloc((size_t)s->nposes, sizeof *best);
	int *have = calloc((size_t)s->nposes, sizeof *have);
	struct ps_canvas cv;
	struct ps_err e;
	char buf[160];
	if (!best || !have) {
		free(best);
		free(have);
		return snprintf(err, errlen, "out of memory"), -1;
	}
	for (size_t i = 0; i < s->nc; i++) {
		const struct combo *k = &s->c[i];
		if (k->fail || have[k->pose])
			continue;
		have[k->pose] = k->a.below_h <= s->o->max_below ? 1 : 2;
		best[k->pose] = 100 * k->a.energy_h / k->a.occ_h;
		if (have[k->pose] == 1) {
			emin = fmin(emin, best[k->pose]);
			emax = fmax(emax, best[k->pose]);
		}
	}
	for (int i = 0; i < s->nposes; i++) {
		x0 = fmin(x0, s->poses[i].view.vp[0]);
		x1 = fmax(x1, s->poses[i].view.vp[0]);
		y0 = fmin(y0, s->poses[i].view.vp[1]);
		y1 = fmax(y1, s->poses[i].view.vp[1]);
	}
	x0 -= 0.6, x1 += 0.6, y0 -= 0.6, y1 += 0.6;
	scale = fmin((W - 2 * side) / (x1 - x0), (H - top - side) / (y1 - y0));
	if (ps_canvas_init(&cv, W, H, white, &e) != 0) {
		free(best);
		free(have);
		return snprintf(err, errlen, "%s", e.msg), -1;
	}
	{
		cairo_t *cr = cv.cr;
		double px0 = side, py0 = top + (y1 - y0) * scale;
		cairo_set_source_rgb(cr, 0.4, 0.4, 0.4);
		cairo_set_line_width(cr, 1.0);
		cairo_rectangle(cr, px0, top, (x1 - x0) * scale, (y1 - y0) * scale);
		cairo_stroke(cr);
		for (int i = 0; i < s->nposes; i++) {
			const struct ps_view *v = &s->poses[i].view;
			double px = px0 + (v->vp[0] - x0) * scale, py = py0 - (v->vp[1] - y0) * scale, r = 16;
			double hx = v->vd[0], hy = v->vd[1], hl = sqrt(hx * hx + hy * hy);
			uint8_t rgb[3] = { 170, 170, 170 };
			if (have[i] == 1)
				ps_falsecolor_rgb8(emax > emin ? (best[i] - emin) / (emax - emin) : 0.0, rgb);
			/* tilted poses sit beside the ones at the same point */
			if (hl > 1e-6) {
				px += 3.2 * r * hx / hl;
				py -= 3.2 * r * hy / hl;
			}
			cairo_set_source_rgb(cr, rgb[0] / 255.0, rgb[1] / 255.0, rgb[2] / 255.0);
			cairo_arc(cr, px, py, r, 0, 2 * M_PI);
			cairo_fill_preserve(cr);
			cairo_set_source_rgb(cr, 0, 0, 0);
			cairo_set_line_width(cr, s->nc && s->c[0].pose == i ? 4.0 : 1.0);
			cairo_stroke(cr);
			if (hl > 1e-6) {
				cairo_set_line_width(cr, 2.0);
				cairo_move_to(cr, px, py);
				cairo_line_to(cr, px + 1.5 * r * hx / hl, py - 1.5 * r * hy / hl);
				cairo_stroke(cr);
			}
			snprintf(buf, sizeof buf, "%s %s", s->poses[i].id, have[i] ? "" : "(no year)");
			if (have[i])
				snprintf(buf, sizeof buf, "%s %.1f%%", s->poses[i].id, best[i]);
			ps_canvas_label(&cv, px, py + r + 9, 10, 0, ink, 0, buf);
		}
	}
	ps_canvas_label(&cv, 10, 16, 13, -1, ink, 0, "psplace: candidate poses, plan (x across, y up; metres)");
	snprintf(buf, sizeof buf, "colour: the pose's best energy, blue %.1f %% to red %.1f %%; grey: under-lit; ringed: the best",
	         emin < 1e29 ? emin : 0.0, emax > -1e29 ? emax : 0.0);
	ps_canvas_label(&cv, 10, 34, 10, -1, ink, 0, buf);
	snprintf(buf, sizeof buf, "x %.2f to %.2f m, y %.2f to %.2f m", x0, x1, y0, y1);
	ps_canvas_label(&cv, 10, H - 14, 10, -1, ink, 0, buf);
	free(best);
	free(have);
	if (ps_canvas_save_png(&cv, path, &e) != 0) {
		ps_canvas_free(&cv);
		return snprintf(err, errlen, "%s", e.msg), -1;
	}
	ps_canvas_free(&cv);
	ps_canvas_shutdown();
	return 0;
}

/* ---- main ---------------------------------------------------------- */

static int parse_law(const char *name)
{
	for (int i = 0; psd_control_algorithm_names[i]; i++)
		if (!strcmp(name, psd_control_algorithm_names[i]))
			return i;
	return -1;
}

static int positive_int(const char *v, int lo, int hi, int *out)
{
	char *end;
	long x = strtol(v, &end, 10);
	if (end == v || *end || x < lo || x > hi)
		return -1;
	*out = (int)x;
	return 0;
}

static void search_free(struct search *s)
{
	for (int i = 0; i < s->nposes; i++) {
		free(s->poses[i].row);
		free(s->poses[i].elec);
	}
	free(s->poses);
	for (int k = 0; s->sens && k < s->o->nsens; k++)
		ps_sensor_free(&s->sens[k]);
	free(s->sens);
	free(s->hrs.h);
	free(s->hrs.sky);
	free(s->hrs.task);
	free(s->c);
}

int main(int argc, char **argv)
{
	static struct psd_config cf;
	static const struct option longopts[] = { PS_CLI_LONGOPTS, { NULL, 0, NULL, 0 } };
	struct opts o = { .stat = "mean", .nrot = 36, .rot_step = 10, .top = 3, .threads = 2, .cell_theta = 2.0,
	                  .dir = ".", .max_below = -1 };
	struct search s;
	struct ps_gridmtx g;
	char err[1024], what[256];
	double t0 = psd_time_mono(), t_sky, t_proj, t_run;
	int ch, status = 1;
	while ((ch = getopt_long(argc, argv, "f:z:c:d:g:e:w:s:a:r:t:T:n:p:u:k:jo:x:E:y:Z:P:qhV", longopts, NULL)) != -1) {
		switch (ch) {
		case 'f': o.conf = optarg; break;
		case 'z': o.zone = optarg; break;
		case 'c': o.cands = optarg; break;
		case 'd': o.dir = optarg; break;
		case 'g': o.grid = optarg; break;
		case 'e': o.elec = optarg; break;
		case 'w': o.weather = optarg; break;
		case 's':
			if (o.nsens == MAX_LIST) {
				fprintf(stderr, "psplace: -s: at most %d sensors\n", MAX_LIST);
				return 2;
			}
			o.sens[o.nsens++] = optarg;
			break;
		case 'a': {
			int a = parse_law(optarg);
			if (a < 0 || o.nlaws == PSD_ALG_COUNT) {
				fprintf(stderr, "psplace: -a %s: a law is one of setpoint, closed-proportional, "
				                "open-proportional, integral-reset, switching\n", optarg);
				return 2;
			}
			o.laws[o.nlaws++] = a;
			break;
		}
		case 'r': {
			char *end;
			double v = strtod(optarg, &end), n = v > 0 ? 360.0 / v : 0;
			if (end == optarg || *end || !(v > 0) || v > 360 || fabs(n - round(n)) > 1e-9) {
				fprintf(stderr, "psplace: -r %s: a rotation step that divides 360 degrees\n", optarg);
				return 2;
			}
			o.rot_step = v;
			o.nrot = (int)round(n);
			break;
		}
		case 't': o.stat = optarg; break;
		case 'T':
			if (positive_int(optarg, 0, 1000, &o.top) != 0) {
				fprintf(stderr, "psplace: -T %s: 0 to 1000\n", optarg);
				return 2;
			}
			break;
		case 'n':
			if (positive_int(optarg, 1, 256, &o.threads) != 0) {
				fprintf(stderr, "psplace: -n %s: 1 to 256 threads\n", optarg);
				return 2;
			}
			break;
		case 'p':
		case 'u':
		case 'k': {
			char *end;
			double v = strtod(optarg, &end);
			if (end == optarg || *end || !(v > 0) || v > 86400) {
				fprintf(stderr, "psplace: -%c %s: a positive number\n", ch, optarg);
				return 2;
			}
			if (ch == 'p')
				o.period = v;
			else if (ch == 'u')
				o.max_below = v;
			else
				o.cell_theta = v;
			break;
		}
		case 'j': o.json = 1; break;
		case 'o': o.json_out = optarg; break;
		case 'x': o.results_out = optarg; break;
		case 'E': o.schedule = optarg; break;
		case 'y': o.csv = optarg; break;
		case 'Z': o.zone_out = optarg; break;
		case 'P': o.plan = optarg; break;
		case 'q': o.quiet = 1; break;
		case 'h': usage(stdout); return 0;
		case 'V': return ps_cli_version("psplace");
		default: usage(stderr); return 2;
		}
	}
	if (optind != argc || !o.conf || !o.cands || !o.grid || !o.elec || !o.weather) {
		usage(stderr);
		return 2;
	}
	if (!o.nsens)
		o.sens[o.nsens++] = "builtin:cosine";
	if (!o.nlaws)
		for (int a = 0; a < PSD_ALG_COUNT; a++)
			o.laws[o.nlaws++] = a;
	psd_log_init(1, 6, "psplace");
	memset(&s, 0, sizeof s);
	memset(&g, 0, sizeof g);
	s.o = &o;
	s.cf = &cf;
	pthread_mutex_init(&s.lock, NULL);
	if (psd_config_load_keys(&cf, o.conf) != 0) {
		for (size_t i = 0; i < cf.conf.nerrors; i++)
			fprintf(stderr, "psplace: %s\n", cf.conf.errors[i]);
		psd_config_free(&cf);
		return 1;
	}
	{
		int zi = o.zone ? psd_config_zone(&cf, o.zone) : cf.nzone ? 0 : -1;
		if (zi < 0) {
			fprintf(stderr, "psplace: %s: no zone %s\n", o.conf, o.zone ? o.zone : "at all");
			goto out;
		}
		s.zc = &cf.zone[zi];
	}
	if (o.max_below < 0)
		o.max_below = 0.01 * (cf.occ_to - cf.occ_from) / 3600.0 * 365;   /* 1 % of the occupied hours */
	s.ao.period = o.period > 0 ? o.period : s.zc->period;
	s.ao.occ_start = cf.occ_from;
	s.ao.occ_end = cf.occ_to;
	s.ao.dated = 1;
	s.ao.no_estimate = 1;   /* the estimate's error statistics are not scored */
	if (psd_annual_devices(&cf, s.zc, &s.ao, what, sizeof what, err, sizeof err) != 0) {
		fprintf(stderr, "psplace: zone %s: %s\n", s.zc->name, err);
		goto out;
	}
	s.sens = calloc((size_t)o.nsens, sizeof *s.sens);
	if (!s.sens)
		goto oom;
	for (int k = 0; k < o.nsens; k++) {
		struct ps_err e;
		if (ps_sensor_open(&s.sens[k], o.sens[k], &e) != 0) {
			fprintf(stderr, "psplace: -s %s: %s\n", o.sens[k], e.msg);
			goto out;
		}
	}
	/* cells in polar angle no coarser than half a table's finest step (a
	 * scan spreads each cell ring over two rows of every table step) */
	s.cell_theta = o.cell_theta;
	s.theta_max = 0;
	for (int k = 0; k < o.nsens; k++)
		if (ps_sensor_extent(&s.sens[k]) * 180.0 / M_PI > s.theta_max)
			s.theta_max = ps_sensor_extent(&s.sens[k]) * 180.0 / M_PI;
	s.theta_max = s.theta_max + o.cell_theta > 180 ? 180 : s.theta_max + o.cell_theta;
	for (int k = 0; k < o.nsens; k++)
		if (s.sens[k].kind == PS_SENS_TABLE)
			for (int i = 0; i < s.sens[k].nt; i++) {
				double half = 0.5 * (s.sens[k].tb[i + 1] - s.sens[k].tb[i]) * 180.0 / M_PI;
				if (half > 0 && half < s.cell_theta)
					s.cell_theta = half;
			}
	{
		struct ps_err e;
		double *lux, *scratch;
		if (ps_gridmtx_read(&g, o.grid, &e) != 0) {
			fprintf(stderr, "psplace: %s\n", e.msg);
			goto out;
		}
		if (check_stat(o.stat, g.npoints, err, sizeof err) != 0) {
			fprintf(stderr, "psplace: %s\n", err);
			goto out;
		}
		lux = malloc((size_t)g.npoints * sizeof *lux);
		scratch = malloc((size_t)g.npoints * sizeof *scratch);
		if (!lux || !scratch) {
			free(lux);
			free(scratch);
			goto oom;
		}
		if (ps_gridmtx_elec_read(o.elec, g.npoints, lux, &e) != 0) {
			fprintf(stderr, "psplace: %s\n", e.msg);
			free(lux);
			free(scratch);
			goto out;
		}
		s.elec_task = grid_stat(o.stat, lux, g.npoints, scratch);
		free(lux);
		free(scratch);
		s.npatch = g.npatch;
		s.mf = g.mf;
	}
	if (read_candidates(&s, err, sizeof err) != 0) {
		fprintf(stderr, "psplace: %s\n", err);
		goto out;
	}
	if (make_hours(&s, &g, err, sizeof err) != 0) {
		fprintf(stderr, "psplace: %s\n", err);
		goto out;
	}
	t_sky = psd_time_mono();
	for (int i = 0; i < s.nposes; i++)
		if (project_pose(&s, &s.poses[i], err, sizeof err) != 0) {
			fprintf(stderr, "psplace: %s\n", err);
			goto out;
		}
	t_proj = psd_time_mono();
	s.nc = (size_t)s.nposes * (size_t)o.nrot * (size_t)o.nsens * (size_t)o.nlaws;
	s.c = calloc(s.nc, sizeof *s.c);
	if (!s.c)
		goto oom;
	{
		size_t i = 0;
		for (int p = 0; p < s.nposes; p++)
			for (int r = 0; r < o.nrot; r++)
				for (int k = 0; k < o.nsens; k++)
					for (int a = 0; a < o.nlaws; a++)
						s.c[i++] = (struct combo){ .pose = p, .rot = r, .sens = k, .law = a };
	}
	{
		pthread_t th[256];
		int n = 0;
		for (int i = 1; i < o.threads; i++)
			if (pthread_create(&th[n], NULL, worker, &s) == 0)
				n++;
		worker(&s);
		for (int i = 0; i < n; i++)
			pthread_join(th[i], NULL);
	}
	t_run = psd_time_mono();
	rank_s = &s;
	qsort(s.c, s.nc, sizeof *s.c, rank_cmp);
	pareto(&s);
	/* the best again by the exact route */
	for (size_t i = 0; i < (size_t)o.top && i < s.nc; i++) {
		struct combo *k = &s.c[i], x;
		double *row = malloc((size_t)s.npatch * 3 * sizeof *row), elec;
		if (!row)
			goto oom;
		if (k->fail || exact_row(&s, &s.poses[k->pose], k->sens, rot_deg(&s, k->rot), row, &elec, err,
		                         sizeof err) != 0) {
			if (!k->fail)
				fprintf(stderr, "psplace: %s\n", err);
			free(row);
			continue;
		}
		x = *k;
		if (run_row(&s, &x, 1, row, elec, NULL) == 0) {
			k->exact = 1;
			k->exact_sensor_err = 100 * (k->sensor_sum / x.sensor_sum - 1);
			k->exact_energy_err = 100 * (k->a.energy_h - x.a.energy_h) / k->a.occ_h;
		}
		free(row);
	}
	{
		double t_end = psd_time_mono();
		if (o.json_out) {
			FILE *fp = fopen(o.json_out, "w");
			if (!fp || write_json(&s, fp, t_end - t0) != 0 || fclose(fp) != 0) {
				fprintf(stderr, "psplace: %s: %s\n", o.json_out, strerror(errno));
				goto out;
			}
		}
		if (o.json) {
			if (write_json(&s, stdout, t_end - t0) != 0)
				goto out;
		} else {
			printf("psplace: zone %s, %d poses x %d rotations x %d sensors x %d laws = %zu combinations,\n"
			       "  %zu hours with light of %s, the grid's %s (%d points; %.1f lx at full output),\n"
			       "  target %g lx, %s, a step every %g s\n",
			       s.zc->name, s.nposes, o.nrot, o.nsens, o.nlaws, s.nc, s.hrs.n, o.weather, o.stat, g.npoints,
			       s.elec_task, s.zc->ctl.target_lux, what, s.ao.period);
			print_table(&s, o.quiet ? 10 : 40);
			for (size_t i = 0; i < (size_t)o.top && i < s.nc; i++)
				if (s.c[i].exact)
					printf("exact route, rank %zu: the year's sensor signal %+.3f %% by the projection, "
					       "energy %+.3f points\n", i + 1, s.c[i].exact_sensor_err, s.c[i].exact_energy_err);
			printf("time: %.3f s: sky and grid %.3f s, projections %.3f s, %zu years %.3f s (%.3f ms each "
			       "on %d threads), exact re-checks %.3f s\n", t_end - t0, t_sky - t0, t_proj - t_sky, s.nc,
			       t_run - t_proj, 1000 * (t_run - t_proj) / (double)s.nc, o.threads, t_end - t_run);
		}
	}
	if (s.failed)
		fprintf(stderr, "psplace: %d combination(s) could not run the year\n", s.failed);
	if (s.nc && !s.c[0].fail && exports(&s, &s.c[0], err, sizeof err) != 0) {
		fprintf(stderr, "psplace: %s\n", err);
		goto out;
	}
	if (o.plan && plan_png(&s, o.plan, err, sizeof err) != 0) {
		fprintf(stderr, "psplace: %s\n", err);
		goto out;
	}
	status = 0;
	goto out;
oom:
	fprintf(stderr, "psplace: out of memory\n");
out:
	ps_gridmtx_free(&g);
	search_free(&s);
	psd_config_free(&cf);
	return status;
}
