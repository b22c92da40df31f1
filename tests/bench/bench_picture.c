/* SPDX-License-Identifier: ISC */
/* Radiance picture decoding throughput, sizes 64 to 4096.
 * Each picture is an analytic fisheye-like scene (a smooth sky gradient,
 * flat walls that run-length encode well, and a bright disc), written with
 * ps_picture_write into a temporary directory; then, best of several runs:
 *   read:    ps_picture_read (the file read in one go plus decoding)
 *   decode:  ps_picture_read_mem on the file already in memory
 *   MB/s:    file bytes per second of decode;  Mpix/s: pixels per second
 *   touch:   malloc and first write of the 4 n^2 bytes of pixels alone: the
 *            page-fault floor under any decoder (large on some VMs)
 * A second table decodes the same pictures written flat (no run-length),
 * the form rpict -x N > 32767 or other writers may use. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "picture.h"
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
	buf = malloc((size_t)n + 1);
	if (buf)
		*len = fread(buf, 1, (size_t)n, fp);
	fclose(fp);
	return buf;
}

/* Fresh allocation of n bytes written once (what decoding must pay anyway). */
static double touch_time(size_t n)
{
	volatile uint8_t sink;
	double t0 = psd_time_mono();
	uint8_t *p = malloc(n);
	if (!p)
		return 0;
	memset(p, 1, n);
	sink = p[n - 1];
	(void)sink;
	free(p);
	return psd_time_mono() - t0;
}

static void scene(double *rgb, int n)
{
	for (int y = 0; y < n; y++)
		for (int x = 0; x < n; x++) {
			double u = (x + 0.5) / n * 2 - 1, v = 1 - (y + 0.5) / n * 2, r = hypot(u, v);
			double *p = rgb + 3 * ((size_t)y * (size_t)n + (size_t)x);
			if (r > 1) {
				p[0] = p[1] = p[2] = 0;              /* outside the fisheye circle */
			} else if (hypot(u - 0.3, v - 0.4) < 0.02) {
				p[0] = 9e6; p[1] = 8e6; p[2] = 7e6;  /* the sun */
			} else if (v < -0.2) {
				p[0] = 12.5; p[1] = 11.0; p[2] = 9.0;  /* a flat wall */
			} else {
				p[0] = 40 + 30 * u * v; p[1] = 50 + 20 * v; p[2] = 80 + 10 * u;  /* sky */
			}
		}
}

/* The same picture written flat: the header, then 4-byte pixels. */
static int write_flat(const char *path, const double *rgb, int n)
{
	FILE *fp = fopen(path, "wb");
	if (!fp)
		return -1;
	fprintf(fp, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n", n, n);
	for (size_t i = 0; i < (size_t)n * (size_t)n; i++) {
		uint8_t px[4];
		ps_picture_rgbe_encode(rgb + 3 * i, px);
		/* a flat pixel must not look like a run-length start or a repeat */
		if (i % (size_t)n == 0 && px[0] == 2 && px[1] == 2)
			px[1] = 3;
		if (px[0] == 1 && px[1] == 1 && px[2] == 1)
			px[2] = 2;
		fwrite(px, 4, 1, fp);
	}
	return fclose(fp);
}

static int run(const char *title, int flat)
{
	static const int sizes[] = { 64, 128, 256, 512, 1024, 2048, 4096 };
	char dir[] = "/tmp/psbenchpicXXXXXX", path[64];
	if (!mkdtemp(dir))
		return 1;
	snprintf(path, sizeof path, "%s/p.hdr", dir);
	printf("%s\n%6s %12s %10s %10s %10s %10s %10s\n", title, "size", "file bytes", "read ms",
	       "decode ms", "MB/s", "Mpix/s", "touch ms");
	for (size_t k = 0; k < sizeof sizes / sizeof *sizes; k++) {
		int n = sizes[k], reps = n <= 512 ? 20 : n <= 2048 ? 5 : 3;
		double *rgb = malloc(sizeof(double) * 3 * (size_t)n * (size_t)n);
		double best_read = 1e30, best_dec = 1e30, best_touch = 1e30;
		struct ps_err e;
		uint8_t *file;
		size_t len = 0;
		if (!rgb)
			return 1;
		scene(rgb, n);
		if ((flat ? write_flat(path, rgb, n) : ps_picture_write(path, n, n, rgb, NULL, NULL, &e)) != 0) {
			fprintf(stderr, "bench_picture: cannot write %s\n", path);
			return 1;
		}
		free(rgb);
		file = slurp(path, &len);
		for (int r = 0; r < reps; r++) {
			struct ps_picture pic;
			double t0 = psd_time_mono(), t1, t2;
			if (ps_picture_read(&pic, path, &e) != 0) {
				fprintf(stderr, "bench_picture: %s\n", e.msg);
				return 1;
			}
			t1 = psd_time_mono();
			ps_picture_free(&pic);
			t2 = psd_time_mono();
			if (ps_picture_read_mem(&pic, file, len, path, &e) != 0) {
				fprintf(stderr, "bench_picture: %s\n", e.msg);
				return 1;
			}
			best_dec = fmin(best_dec, psd_time_mono() - t2);
			best_read = fmin(best_read, t1 - t0);
			best_touch = fmin(best_touch, touch_time((size_t)n * (size_t)n * 4));
			ps_picture_free(&pic);
		}
		printf("%6d %12zu %10.3f %10.3f %10.0f %10.0f %10.3f\n", n, len, best_read * 1e3,
		       best_dec * 1e3, len / best_dec / 1e6, (double)n * n / best_dec / 1e6, best_touch * 1e3);
		free(file);
	}
	unlink(path);
	rmdir(dir);
	return 0;
}

int main(void)
{
	if (run("run-length encoded (as ps_picture_write and rpict write)", 0) != 0)
		return 1;
	return run("flat scanlines", 1);
}
