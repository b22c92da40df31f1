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
 * The Radiance pipeline a user types today (pcomb with a solid-angle
 * expression | pvalue | total) takes about 0.5 s at 1000 x 1000 and 8 s at
 * 4000 x 4000 on this kind of machine (the figures). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "integrate.h"
#include "picture.h"
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

int main(void)
{
	static const int sizes[] = { 64, 128, 256, 512, 1000, 1024, 2048, 4000, 4096 };
	const char *table = "config/example/ofb/sensors/cosine.sen";
	struct ps_sensor cosine, tab;
	struct ps_err e;
	char path[] = "/tmp/psbenchXXXXXX";
	int fd = mkstemp(path);
	close(fd);
	if (ps_sensor_builtin(&cosine, PS_SENS_COSINE, &e) != 0 || ps_sensor_read(&tab, table, &e) != 0) {
		fprintf(stderr, "bench_psens: %s\n", e.msg);
		return 1;
	}
	printf("psens error against run time (ms); uniform radiance, -vta -vh 180\n");
	printf("%6s %-7s %11s %11s %8s %8s %9s %9s %9s %9s %s\n", "size", "method", "err cosine",
	       "err table", "read", "decode", "weights", "integr.", "1st pic", "next pic",
	       "  Radiance/psens (1st, next)");
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
			printf("%6d %-7s %11.2e %11.2e %8.1f %8.1f %9.1f %9.1f %9.1f %9.1f", n,
			       method == PS_W_EXACT ? "exact" : "centre", ec, et, 1e3 * t_read, 1e3 * t_dec,
			       1e3 * t_w, 1e3 * t_i, 1e3 * tot, 1e3 * (tot - t_w));
			if (n == 1000 || n == 4000)
				printf("  %6.1fx %6.1fx", (n == 1000 ? 0.5 : 8.0) / tot,
				       (n == 1000 ? 0.5 : 8.0) / (tot - t_w));
			printf("\n");
			ps_weights_free(&wc);
			ps_weights_free(&wt);
		}
		ps_picture_free(&pic);
		free(file);
		free(rgb);
	}
	printf("Radiance/psens: the Radiance pipeline's time (0.5 s at 1000, 8 s at 4000) over\n"
	       "psens's, for the first picture (weights built) and for each further picture of\n"
	       "the same size and view (the weight map is reused)\n");
	unlink(path);
	ps_sensor_free(&cosine);
	ps_sensor_free(&tab);
	return 0;
}
