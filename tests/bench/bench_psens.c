/* SPDX-License-Identifier: ISC */
/* psens: error against run time, for the paper's centre-point weights and
 * the exact ones, at picture sizes 64 to 4096.
 *   error:     relative error of an ideal cosine sensor (exact answer pi) and
 *              of the shipped 2-degree cosine table (exact answer: the
 *              table's own integral) on a picture of uniform radiance 1
 *   read:      reading the file into memory (the floor any tool pays)
 *   decode:    run-length decoding to RGBE pixels
 *   weights:   building the weight map (once per sensor, view and size)
 *   integrate: applying the map to one decoded picture
 * Then the centre-point weights against the exact ones on the example
 * office's renders (config/example/ofb/img, 256 x 256), where the picture is
 * not uniform, for the cosine table and cones down to 5 degrees: a narrow
 * sensor sees few pixels, and a bright one at its rim moves the centre
 * method's answer most (`bench_psens renders`: that table alone).
 * Times only: no ratio against another tool's run (Radiance is not
 * installed where this runs); the centre and exact rows are the same run's
 * comparators. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "integrate.h"
#include "picture.h"
#include "picview.h"
#include "sensor.h"
#include "view.h"
#include "weights.h"
#include "time.h"

static uint8_t *slurp(const char *path, size_t *len)
{
	FILE *fp = fopen(path, "rb");
	uint8_t *buf;
	long n;
	if (!fp)
		return NULL;
	fseek(fp, 0, SEEK_END);
	n = ftell(fp);
	rewind(fp);
	buf = malloc((size_t)n);
	*len = fread(buf, 1, (size_t)n, fp);
	fclose(fp);
	return buf;
}

/* A cone of half-angle h degrees: sensitivity 1 to h, 0 from h + 0.5. */
static int cone(struct ps_sensor *s, double h, struct ps_err *e)
{
	char text[160];
	int n = snprintf(text, sizeof text, "Elevation field 90\ndegrees 0 90 180 270\n0 1 1 1 1\n%g 1 1 1 1\n"
	                 "%g 0 0 0 0\n90 0 0 0 0\n", h, h + 0.5);
	return ps_sensor_parse(s, text, (size_t)n, "cone", e) != 0 ? -1
	       : ps_sensor_set_reading(s, PS_READ_LINEAR, e);
}

/* The response of sensor s on pic (view v) by one method; its build time in *t. */
static double respond(const struct ps_sensor *s, const struct ps_picture *pic, const struct ps_view *v,
                      int method, double *t)
{
	static const double coef[3] = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B };
	struct ps_weights w;
	struct ps_response r;
	struct ps_err e;
	double t0 = psd_time_mono();
	if (ps_weights_build(&w, s, 0, v, pic->width, pic->height, method, &e) != 0 ||
	    ps_integrate(&w, pic, coef, &r, &e) != 0) {
		fprintf(stderr, "bench_psens: %s\n", e.msg);
		exit(1);
	}
	*t = psd_time_mono() - t0;
	ps_weights_free(&w);
	return r.response;
}

/* Centre against exact on a uniform picture and on the example renders. */
static void renders(void)
{
	static const char *const pics[] = { "day_0318_sensor", "day_0318_task", "day_0416_sensor",
	                                    "day_0416_task", "day_0517_sensor", "day_0517_task",
	                                    "elec_sensor", "elec_task" };
	static const double cones[] = { 0, 60, 30, 10, 5 };   /* 0: the cosine table */
	enum { NPIC = sizeof pics / sizeof *pics };
	struct ps_picture pic[NPIC + 1];
	struct ps_view v[NPIC + 1];
	struct ps_err e;
	double *rgb = malloc(sizeof(double) * 3 * 256 * 256);
	char *buf = NULL;
	size_t len = 0;
	FILE *fp = open_memstream(&buf, &len);
	for (size_t i = 0; i < 3 * 256 * 256; i++)
		rgb[i] = 1.0;
	ps_picture_write_fp(fp, "uniform", 256, 256, rgb, "-vta -vh 180 -vv 180", NULL, &e);
	fclose(fp);
	free(rgb);
	if (ps_picture_read_mem(&pic[NPIC], (uint8_t *)buf, len, "uniform", &e) != 0) {
		fprintf(stderr, "bench_psens: %s\n", e.msg);
		exit(1);
	}
	free(buf);
	ps_view_default_fisheye(&v[NPIC]);
	for (int i = 0; i < NPIC; i++) {
		char path[128];
		int assumed;
		snprintf(path, sizeof path, "config/example/ofb/img/%s_256.hdr", pics[i]);
		if (ps_picture_read(&pic[i], path, &e) != 0 ||
		    ps_picview_fisheye(&pic[i], path, &v[i], &assumed, &e) != 0) {
			fprintf(stderr, "bench_psens: %s\n", e.msg);
			exit(1);
		}
	}
	printf("\ncentre-point weights against the exact ones, 256 x 256: relative error on a\n"
	       "uniform picture and on the example office's %d renders (worst, and its picture);\n"
	       "ms to build and apply each map\n", NPIC);
	printf("%-14s %11s %11s  %-16s %9s %9s\n", "sensor", "uniform", "renders", "worst on",
	       "centre ms", "exact ms");
	for (size_t k = 0; k < sizeof cones / sizeof *cones; k++) {
		struct ps_sensor s;
		char name[32];
		double worst = 0, tc = 0, tx = 0, t, eu;
		int at = 0;
		if ((cones[k] == 0 ? ps_sensor_read(&s, "config/example/ofb/sensors/cosine.sen", &e)
		                   : cone(&s, cones[k], &e)) != 0) {
			fprintf(stderr, "bench_psens: %s\n", e.msg);
			exit(1);
		}
		snprintf(name, sizeof name, cones[k] == 0 ? "cosine table" : "cone %g deg", cones[k]);
		eu = respond(&s, &pic[NPIC], &v[NPIC], PS_W_CENTRE, &t) /
		     respond(&s, &pic[NPIC], &v[NPIC], PS_W_EXACT, &t) - 1;
		for (int i = 0; i < NPIC; i++) {
			double c = respond(&s, &pic[i], &v[i], PS_W_CENTRE, &t), x, d;
			tc += t;
			x = respond(&s, &pic[i], &v[i], PS_W_EXACT, &t);
			tx += t;
			d = fabs(c / x - 1);
			if (d > worst) {
				worst = d;
				at = i;
			}
		}
		printf("%-14s %11.2e %11.2e  %-16s %9.1f %9.1f\n", name, fabs(eu), worst, pics[at],
		       1e3 * tc / NPIC, 1e3 * tx / NPIC);
		ps_sensor_free(&s);
	}
	for (int i = 0; i <= NPIC; i++)
		ps_picture_free(&pic[i]);
}

int main(int argc, char **argv)
{
	static const int sizes[] = { 64, 128, 256, 512, 1000, 1024, 2048, 4000, 4096 };
	const char *table = "config/example/ofb/sensors/cosine.sen";
	struct ps_sensor cosine, tab;
	struct ps_err e;
	char path[] = "/tmp/psbenchXXXXXX";
	int fd;
	if (argc > 1 && strcmp(argv[1], "renders") == 0) {   /* the second table alone */
		renders();
		return 0;
	}
	fd = mkstemp(path);
	close(fd);
	if (ps_sensor_builtin(&cosine, PS_SENS_COSINE, &e) != 0 || ps_sensor_read(&tab, table, &e) != 0) {
		fprintf(stderr, "bench_psens: %s\n", e.msg);
		return 1;
	}
	printf("psens error against run time (ms); uniform radiance, -vta -vh 180\n");
	printf("%6s %-7s %11s %11s %8s %8s %9s %9s %9s %9s\n", "size", "method", "err cosine",
	       "err table", "read", "decode", "weights", "integr.", "1st pic", "next pic");
	for (size_t k = 0; k < sizeof sizes / sizeof *sizes; k++) {
		int n = sizes[k];
		double *rgb = malloc(sizeof(double) * 3 * (size_t)n * n);
		struct ps_view v;
		struct ps_picture pic;
		uint8_t *file;
		size_t len;
		double t0, t_read, t_dec;
		for (size_t i = 0; i < (size_t)n * n * 3; i++)
			rgb[i] = 1.0;
		/* a uniform picture decodes to 1.00390625: the analytic answer scales */
		ps_view_default_fisheye(&v);
		ps_picture_write(path, n, n, rgb, "-vta -vd 0 0 -1 -vu 0 1 0 -vh 180 -vv 180", NULL, &e);
		t0 = psd_time_mono();
		file = slurp(path, &len);
		t_read = psd_time_mono() - t0;
		t0 = psd_time_mono();
		if (!file || ps_picture_read_mem(&pic, file, len, path, &e) != 0) {
			fprintf(stderr, "bench_psens: %s\n", e.msg);
			return 1;
		}
		t_dec = psd_time_mono() - t0;
		for (int method = PS_W_CENTRE; method >= PS_W_EXACT; method--) {
			struct ps_weights wc, wt;
			struct ps_response rc, rt;
			double coef[3] = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B };
			double t_w, t_i, ec, et, tot;
			t0 = psd_time_mono();
			ps_weights_build(&wt, &tab, 0, &v, n, n, method, &e);
			t_w = psd_time_mono() - t0;
			ps_weights_build(&wc, &cosine, 0, &v, n, n, method, &e);
			t0 = psd_time_mono();
			ps_integrate(&wt, &pic, coef, &rt, &e);
			t_i = psd_time_mono() - t0;
			ps_integrate(&wc, &pic, coef, &rc, &e);
			ec = rc.response / (1.00390625 * M_PI) - 1;
			et = rt.response / (1.00390625 * ps_sensor_integral(&tab)) - 1;
			tot = t_read + t_dec + t_w + t_i;
			printf("%6d %-7s %11.2e %11.2e %8.1f %8.1f %9.1f %9.1f %9.1f %9.1f\n", n,
			       method == PS_W_EXACT ? "exact" : "centre", ec, et, 1e3 * t_read, 1e3 * t_dec,
			       1e3 * t_w, 1e3 * t_i, 1e3 * tot, 1e3 * (tot - t_w));
			ps_weights_free(&wc);
			ps_weights_free(&wt);
		}
		ps_picture_free(&pic);
		free(file);
		free(rgb);
	}
	printf("1st pic: the weights built; next pic: each further picture of the same size\n"
	       "and view (the weight map is reused)\n");
	unlink(path);
	ps_sensor_free(&cosine);
	ps_sensor_free(&tab);
	renders();
	return 0;
}
