/* SPDX-License-Identifier: ISC */
/* psens's routes against their goals: error and wall time for
 * one-shot runs of the psens binary (cold and warm weight cache), the
 * library's decoding against its integration, batches of many pictures
 * after the weights, a rotation scan, and the peak memory of a 4000 x 4000
 * run (getrusage of the child, ru_maxrss).  Every picture is uniform, so
 * the error is against the analytic answer (cosine sensor: pi times the
 * decoded radiance).  Times are wall clock on whatever else the machine is
 * doing: one run each, no repetition.  No goal is asserted; the table says
 * which are met. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "batch.h"
#include "cache.h"
#include "fileio.h"
#include "integrate.h"
#include "picture.h"
#include "rescan.h"
#include "scancheck.h"
#include "rowsum.h"
#include "sensor.h"
#include "stream.h"
#include "view.h"
#include "wcache.h"
#include "time.h"
#include "weights.h"

#define VIEW "-vta -vd 0 0 -1 -vu 0 1 0 -vh 180 -vv 180"
#define DECODED_ONE 1.00390625   /* RGBE's 1 as Radiance decodes it */

static void row(const char *route, double err, double ms, double goal_ms, const char *note)
{
	char g[32] = "-", e[32] = "-";
	if (goal_ms > 0)
		snprintf(g, sizeof g, "%.0f", goal_ms);
	if (!isnan(err))
		snprintf(e, sizeof e, "%.2e", err);
	printf("%-46s %10s %10.1f %8s %5s  %s\n", route, e, ms, g,
	       goal_ms > 0 ? (ms <= goal_ms ? "yes" : "no") : "", note ? note : "");
}

/* A row callback that keeps nothing: decoding alone. */
static int no_row(void *ctx, int y, const uint8_t *rgbe)
{
	(void)ctx;
	(void)y;
	(void)rgbe;
	return 0;
}

static int uniform(const char *path, int n, double value)
{
	double *rgb = malloc(sizeof(double) * 3 * (size_t)n * n);
	struct ps_err e;
	int rc;
	if (!rgb)
		return -1;
	for (size_t i = 0; i < (size_t)n * n * 3; i++)
		rgb[i] = value;
	rc = ps_picture_write(path, n, n, rgb, VIEW, NULL, &e);
	free(rgb);
	return rc;
}

/* Run psens once; wall time, its response, and its peak resident size. */
static int run_psens(const char *bin, const char *cache, const char *pic, double *ms,
                     double *resp, long *maxrss_kb)
{
	char out[] = "/tmp/psbench-outXXXXXX";
	int fd = mkstemp(out), status;
	struct rusage ru;
	double t0 = psd_time_mono();
	pid_t pid = fork();
	if (pid == 0) {
		dup2(fd, 1);
		if (cache)
			execl(bin, "psens", "-q", "-C", cache, "-s", "builtin:cosine", pic, (char *)NULL);
		else
			execl(bin, "psens", "-q", "-N", "-s", "builtin:cosine", pic, (char *)NULL);
		_exit(127);
	}
	if (pid < 0 || wait4(pid, &status, 0, &ru) != pid || !WIFEXITED(status) ||
	    WEXITSTATUS(status) != 0) {
		close(fd);
		unlink(out);
		return -1;
	}
	*ms = 1e3 * (psd_time_mono() - t0);
	*maxrss_kb = ru.ru_maxrss;
	{
		char buf[256] = "";
		FILE *fp = fdopen(fd, "r");
		rewind(fp);
		if (!fgets(buf, sizeof buf, fp) || !strstr(buf, "Response: "))
			*resp = NAN;
		else
			*resp = strtod(strstr(buf, "Response: ") + 10, NULL);
		fclose(fp);
	}
	unlink(out);
	return 0;
}

/* Run psens with these arguments (after "psens"); wall ms, peak RSS and up
 * to nmax responses in the order printed; the number found, -1 on failure. */
static int run_args(const char *bin, char *const *args, double *ms, long *maxrss_kb,
                    double *resp, int nmax)
{
	char out[] = "/tmp/psbench-outXXXXXX", *argv[32];
	int fd = mkstemp(out), status, n = 0, na = 0;
	struct rusage ru;
	double t0;
	pid_t pid;
	argv[na++] = "psens";
	while (args[na - 1] && na < 31) {
		argv[na] = args[na - 1];
		na++;
	}
	argv[na] = NULL;
	t0 = psd_time_mono();
	pid = fork();
	if (pid == 0) {
		dup2(fd, 1);
		execv(bin, argv);
		_exit(127);
	}
	if (pid < 0 || wait4(pid, &status, 0, &ru) != pid || !WIFEXITED(status) ||
	    WEXITSTATUS(status) != 0) {
		close(fd);
		unlink(out);
		return -1;
	}
	*ms = 1e3 * (psd_time_mono() - t0);
	*maxrss_kb = ru.ru_maxrss;
	{
		char buf[512];
		FILE *fp = fdopen(fd, "r");
		rewind(fp);
		while (n < nmax && fgets(buf, sizeof buf, fp))
			if (strstr(buf, "Response: "))
				resp[n++] = strtod(strstr(buf, "Response: ") + 10, NULL);
		fclose(fp);
	}
	unlink(out);
	return n;
}

static double batch_ms(const struct ps_batch *b, const char *const *paths, size_t n,
                       double value0, double *maxerr)
{
	struct ps_batch_result *res = malloc(n * sizeof *res);
	struct ps_err e;
	double t0 = psd_time_mono(), t;
	long bad = ps_batch_run_files(b, paths, n, res, &e);
	t = psd_time_mono() - t0;
	*maxerr = 0;
	for (size_t i = 0; i < n; i++) {
		/* picture i holds value0 (1 + i / 64) before encoding: compare with
		 * what the file decodes to */
		uint8_t px[4];
		double rgb[3], want;
		double v = value0 * (1 + (double)i / 64);
		ps_picture_rgbe_encode((double[3]){ v, v, v }, px);
		ps_picture_rgbe_decode(px, rgb);
		want = rgb[0] * M_PI;
		if (res[i].status != PS_BATCH_OK)
			*maxerr = INFINITY;
		else if (fabs(res[i].r.response / want - 1) > *maxerr)
			*maxerr = fabs(res[i].r.response / want - 1);
	}
	free(res);
	return bad ? NAN : 1e3 * t;
}

int main(void)
{
	const char *build = getenv("BUILD") ? getenv("BUILD") : "build";
	char bin[512], dir[] = "/tmp/psbench-routesXXXXXX", p4000[600], p1000[600], p512[600];
	char cache[600], pt[600];
	struct ps_sensor cosine;
	struct ps_view v;
	struct ps_err e;
	double ms, resp, err;
	long rss;
	snprintf(bin, sizeof bin, "%s/bin/psens", build);
	if (!mkdtemp(dir) || ps_sensor_builtin(&cosine, PS_SENS_COSINE, &e) != 0) {
		fprintf(stderr, "bench_psens_routes: cannot start\n");
		return 1;
	}
	ps_view_default_fisheye(&v);
	snprintf(p4000, sizeof p4000, "%s/u4000.hdr", dir);
	snprintf(p1000, sizeof p1000, "%s/u1000.hdr", dir);
	snprintf(p512, sizeof p512, "%s/u512.hdr", dir);
	snprintf(cache, sizeof cache, "%s/cache", dir);
	if (uniform(p4000, 4000, 1.0) || uniform(p1000, 1000, 1.0) || uniform(p512, 512, 1.0)) {
		fprintf(stderr, "bench_psens_routes: cannot write pictures\n");
		return 1;
	}
	printf("psens routes against their goals: uniform pictures, cosine sensor, exact\n"
	       "weights, error against pi x the decoded radiance; wall ms, one run each on a\n"
	       "shared 2-core machine\n");
	printf("%-46s %10s %10s %8s %5s  %s\n", "route", "error", "ms", "goal ms", "met", "note");

	/* one-shot runs of the binary */
	if (run_psens(bin, cache, p4000, &ms, &resp, &rss) == 0) {
		row("psens 4000x4000, cold cache", resp / (DECODED_ONE * M_PI) - 1, ms, 350,
		    "weights built and stored");
		{
			char note[64];
			snprintf(note, sizeof note, "ru_maxrss of the cold run: %.0f MB", rss / 1024.0);
			row("  peak memory 4000x4000 (goal < 100 MB)", NAN, 0, 0, note);
		}
	}
	if (run_psens(bin, cache, p4000, &ms, &resp, &rss) == 0) {
		char note[64];
		snprintf(note, sizeof note, "weights mapped; ru_maxrss %.0f MB", rss / 1024.0);
		row("psens 4000x4000, warm cache", resp / (DECODED_ONE * M_PI) - 1, ms, 150, note);
	}
	if (run_psens(bin, NULL, p4000, &ms, &resp, &rss) == 0)
		row("psens 4000x4000, no cache (-N)", resp / (DECODED_ONE * M_PI) - 1, ms, 0, NULL);
	if (run_psens(bin, cache, p1000, &ms, &resp, &rss) == 0)
		row("psens 1000x1000, cold cache", resp / (DECODED_ONE * M_PI) - 1, ms, 25, NULL);
	if (run_psens(bin, cache, p1000, &ms, &resp, &rss) == 0)
		row("psens 1000x1000, warm cache", resp / (DECODED_ONE * M_PI) - 1, ms, 0, NULL);

	/* a picture that does not run-length encode (62 MB): the error against
	 * the whole picture decoded and integrated with the full map */
	{
		char c2[600];
		struct ps_picture pic;
		struct ps_weights w;
		struct ps_response r;
		const double coef[3] = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B };
		double *rgb = malloc(sizeof(double) * 3 * 4000 * 4000);
		snprintf(pt, sizeof pt, "%s/t4000.hdr", dir);
		snprintf(c2, sizeof c2, "%s/cache-t", dir);
		for (size_t i = 0; rgb && i < (size_t)4000 * 4000; i++)
			for (int c = 0; c < 3; c++)
				rgb[3 * i + c] = 0.5 + 0.37 * (double)((i * 7 + (size_t)c * 3) % 11);
		if (!rgb || ps_picture_write(pt, 4000, 4000, rgb, VIEW, NULL, &e) != 0 ||
		    ps_picture_read(&pic, pt, &e) != 0 ||
		    ps_weights_build(&w, &cosine, 0, &v, 4000, 4000, PS_W_EXACT, &e) != 0 ||
		    ps_integrate(&w, &pic, coef, &r, &e) != 0) {
			fprintf(stderr, "bench_psens_routes: textured picture\n");
			return 1;
		}
		free(rgb);
		ps_weights_free(&w);
		ps_picture_free(&pic);
		for (int k = 0; k < 2; k++) {
			char *args[] = { "-q", "-C", c2, "-s", "builtin:cosine", pt, NULL };
			double rr;
			if (run_args(bin, args, &ms, &rss, &rr, 1) == 1) {
				char note[96];
				snprintf(note, sizeof note, "62 MB picture, no runs; ru_maxrss %.0f MB; error: "
				         "against whole-picture route", rss / 1024.0);
				row(k ? "psens 4000x4000 textured, warm cache" :
				        "psens 4000x4000 textured, cold cache",
				    rr / r.response - 1, ms, k ? 150 : 350, note);
			}
		}
	}

	/* several sensors in one run, each picture decoded once, against one run
	 * per sensor: the cosine and a table that changes with azimuth (its
	 * full map: 2 s to build, so the cache is filled first), on the
	 * textured 4000 x 4000 (its decoding costs); error: each response
	 * against the whole-picture route's */
	{
		static const char table[] = "Elevation field 90\n"
		                            "degrees 0 45 90 135 180 225 270 315\n"
		                            "0 1 1 1 1 1 1 1 1\n"
		                            "20 0.95 0.9 0.7 0.6 0.8 0.9 0.85 0.9\n"
		                            "40 0.8 0.6 0.4 0.3 0.5 0.7 0.7 0.75\n"
		                            "60 0.5 0.3 0.2 0.1 0.2 0.4 0.45 0.5\n"
		                            "80 0.1 0.05 0.02 0.01 0.03 0.08 0.1 0.1\n"
		                            "90 0 0 0 0 0 0 0 0\n";
		char ts[600];
		struct ps_sensor tab;
		FILE *fp;
		double r2[2], r1, ms1, ms2, want[2], worst = 0;
		snprintf(ts, sizeof ts, "%s/az.sen", dir);
		fp = fopen(ts, "w");
		if (!fp || fputs(table, fp) == EOF || fclose(fp) != 0 ||
		    ps_sensor_parse(&tab, table, sizeof table - 1, "az", &e) != 0 ||
		    ps_sensor_set_reading(&tab, PS_READ_LINEAR, &e) != 0)
			return 1;
		{
			struct ps_picture pic;
			struct ps_weights w;
			struct ps_response r;
			const double coef[3] = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B };
			if (ps_picture_read(&pic, pt, &e) != 0)
				return 1;
			for (int k = 0; k < 2; k++) {
				if (ps_weights_build(&w, k ? &tab : &cosine, 0, &v, 4000, 4000, PS_W_EXACT,
				                     &e) != 0 || ps_integrate(&w, &pic, coef, &r, &e) != 0)
					return 1;
				want[k] = r.response;
				ps_weights_free(&w);
			}
			ps_picture_free(&pic);
		}
		{
			char c3[600];
			snprintf(c3, sizeof c3, "%s/cache-s", dir);
			char *a1[] = { "-q", "-C", c3, "-s", "builtin:cosine", pt, NULL };
			char *a2[] = { "-q", "-C", c3, "-s", ts, pt, NULL };
			char *ab[] = { "-q", "-C", c3, "-s", "builtin:cosine", "-s", ts, pt, NULL };
			if (run_args(bin, ab, &ms, &rss, r2, 2) != 2)   /* fills the cache */
				return 1;
			if (run_args(bin, a1, &ms1, &rss, &r1, 1) == 1 &&
			    run_args(bin, a2, &ms2, &rss, &r2[1], 1) == 1) {
				worst = fmax(fabs(r1 / want[0] - 1), fabs(r2[1] / want[1] - 1));
				row("2 sensors 4000x4000 textured, a run each", worst, ms1 + ms2, 0,
				    "cosine + azimuthal table, warm: 2 decodings");
			}
			if (run_args(bin, ab, &ms, &rss, r2, 2) == 2) {
				char note[96];
				worst = fmax(fabs(r2[0] / want[0] - 1), fabs(r2[1] / want[1] - 1));
				snprintf(note, sizeof note, "warm, one decoding; ru_maxrss %.0f MB",
				         rss / 1024.0);
				row("2 sensors 4000x4000 textured, one run", worst, ms, 0, note);
			}
		}
		ps_sensor_free(&tab);
		unlink(ts);
		/* pt stays for the decoding table below */
	}

	/* where a cold one-shot run's time goes, in the library (2 threads) */
	for (int k = 0; k < 2; k++) {
		int n = k ? 1000 : 4000;
		const char *pp = k ? p1000 : p4000;
		char cd[600], name[80];
		struct ps_weights w;
		struct ps_picture pic;
		struct ps_response r;
		struct ps_fileio_map m;
		struct ps_err warn;
		size_t off;
		int how;
		const double coef[3] = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B };
		double t0, t_b, t_bs, t_i, t_d;
		snprintf(cd, sizeof cd, "%s/cache-phase%d", dir, n);
		t0 = psd_time_mono();
		if (ps_weights_build_ex(&w, &cosine, 0, &v, n, n, PS_W_EXACT, PS_WB_COMPACT, &e) != 0)
			return 1;
		t_b = psd_time_mono() - t0;
		ps_weights_free(&w);
		t0 = psd_time_mono();
		if (ps_wcache_get(&w, &(struct ps_wcache_key){ &cosine, 0, &v, n, n, PS_W_EXACT }, &(struct ps_wcache_dir){ cd, 0 }, &how, &warn, &e) != 0)
			return 1;
		t_bs = psd_time_mono() - t0;
		if (ps_fileio_map(pp, (size_t)1 << 32, &m, &e) != 0 ||
		    ps_picture_head_mem(&pic, m.data, m.len, pp, &off, &e) != 0)
			return 1;
		t0 = psd_time_mono();
		ps_stream_integrate(&w, &pic, m.data, m.len, off, pp, coef, 2, &r, &e);
		t_i = psd_time_mono() - t0;
		ps_picture_free(&pic);
		ps_fileio_unmap(&m);
		t0 = psd_time_mono();
		if (ps_picture_read(&pic, pp, &e) != 0)
			return 1;
		t_d = psd_time_mono() - t0;
		ps_picture_free(&pic);
		snprintf(name, sizeof name, "  %d cold: compact weights (every core)", n);
		row(name, NAN, 1e3 * t_b, 0, NULL);
		snprintf(name, sizeof name, "  %d cold: storing them (checksum, write)", n);
		row(name, NAN, 1e3 * (t_bs - t_b), 0, "build + store less build");
		snprintf(name, sizeof name, "  %d cold: decode+integrate, 2 thr", n);
		row(name, r.response / (DECODED_ONE * M_PI) - 1, 1e3 * t_i, 0, NULL);
		snprintf(name, sizeof name, "  %d read + decode alone (library)", n);
		row(name, NAN, 1e3 * t_d, 0, "whole picture, 1 thread");
		ps_weights_free(&w);
	}

	/* decoding against integration, in the library, 4000 x 4000 */
	{
		struct ps_picture pic;
		struct ps_weights w;
		struct ps_response r;
		const double coef[3] = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B };
		double t0, t_dec, t_int, t_w;
		char name[96];
		/* the goals' split: reading and decoding the picture, then
		 * integrating the stored picture; each the best of three */
		t_dec = t_int = INFINITY;
		for (int k = 0; k < 3; k++) {
			double t;
			if (k)
				ps_picture_free(&pic);
			t0 = psd_time_mono();
			if (ps_picture_read(&pic, p4000, &e) != 0)
				return 1;
			if ((t = psd_time_mono() - t0) < t_dec)
				t_dec = t;
		}
		t0 = psd_time_mono();
		ps_weights_build(&w, &cosine, 0, &v, 4000, 4000, PS_W_EXACT, &e);
		t_w = psd_time_mono() - t0;
		for (int k = 0; k < 3; k++) {
			double t;
			t0 = psd_time_mono();
			ps_integrate(&w, &pic, coef, &r, &e);
			if ((t = psd_time_mono() - t0) < t_int)
				t_int = t;
		}
		row("4000x4000 read + decode (library)", NAN, 1e3 * t_dec, 0, "best of 3");
		row("4000x4000 integration, own pass (library)", r.response / (DECODED_ONE * M_PI) - 1, 1e3 * t_int, 1e3 * t_dec,
		    "over the stored picture, best of 3; goal: no more than reading + decoding it");
		row("4000x4000 weights (library, every core)", NAN, 1e3 * t_w, 0, NULL);
		/* decoding fused with integration, no picture stored: the uniform
		 * picture (long runs: its decoding is cheap) and the textured one
		 * (no runs), each decoded alone and decoded with integration */
		for (int tex = 0; tex < 2; tex++) {
			struct ps_fileio_map m;
			struct ps_picture head;
			size_t off;
			char path[600];
			const char *what = tex ? "textured" : "uniform";
			double t_scan, t_fused1 = NAN;
			char kernel_note[96];
			snprintf(kernel_note, sizeof kernel_note, "file in memory; best of 5; %s run kernel",
			         ps_rowsum_name(ps_rowsum_best()));
			if (tex)
				snprintf(path, sizeof path, "%s/t4000.hdr", dir);
			else
				snprintf(path, sizeof path, "%s", p4000);
			if (ps_fileio_map(path, (size_t)1 << 32, &m, &e) != 0 ||
			    ps_picture_head_mem(&head, m.data, m.len, path, &off, &e) != 0)
				return 1;
			/* the goal compares two times: each the best of five runs, so
			 * that another process's burst does not decide it */
			t_scan = INFINITY;
			for (int k = 0; k < 5; k++) {
				double t;
				t0 = psd_time_mono();
				if (ps_picture_scan_rows(&head, m.data, m.len, path, off, 0, 4000, NULL, no_row, NULL, &e) != 0)
					return 1;
				if ((t = psd_time_mono() - t0) < t_scan)
					t_scan = t;
			}
			snprintf(name, sizeof name, "4000x4000 %s: decode alone, 1 thr", what);
			row(name, NAN, 1e3 * t_scan, 0, "file in memory, rows not kept; best of 5");
			for (int nt = 1; nt <= 2; nt++) {
				double t;
				snprintf(name, sizeof name, "4000x4000 %s: decode+integrate, %d thr", what, nt);
				t = INFINITY;
				for (int k = 0; k < 5; k++) {
					double tk;
					t0 = psd_time_mono();
					ps_stream_integrate(&w, &head, m.data, m.len, off, path, coef, nt, &r, &e);
					if ((tk = psd_time_mono() - t0) < t)
						t = tk;
				}
				row(name, tex ? NAN : r.response / (DECODED_ONE * M_PI) - 1, 1e3 * t, 0,
				    nt == 1 ? kernel_note : "file in memory; best of 5");
				if (nt == 1)
					t_fused1 = t;
			}
			snprintf(name, sizeof name, "4000x4000 %s: its integration, 1 thr", what);
			row(name, NAN, 1e3 * (t_fused1 - t_scan), 1e3 * t_scan,
			    "decode+integrate less decode; goal: no more than decoding");
			ps_picture_free(&head);
			ps_fileio_unmap(&m);
		}
		ps_weights_free(&w);
		ps_picture_free(&pic);
	}

	/* batches after the weights: 146 and 2306 pictures of 128 x 128 */
	{
		static const size_t counts[] = { 146, 2306 };
		const size_t nmax = 2306;
		char **paths = calloc(nmax, sizeof *paths);
		struct ps_batch b;
		const double coef[3] = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B };
		for (size_t i = 0; i < nmax; i++) {
			paths[i] = malloc(600);
			snprintf(paths[i], 600, "%s/b%04zu.hdr", dir, i);
			if (uniform(paths[i], 128, 1 + (double)i / 64) != 0)
				return 1;
		}
		struct ps_batch_spec sp = { .map = { &cosine, 0, &v, 128, 128, PS_W_EXACT }, .coef = coef,
		                            .nthreads = 2 };
		if (ps_batch_init(&b, &sp, &e) != 0)
			return 1;
		for (size_t k = 0; k < 2; k++) {
			char name[64];
			snprintf(name, sizeof name, "%zu pictures 128x128 after weights, 2 thr", counts[k]);
			ms = batch_ms(&b, (const char *const *)paths, counts[k], 1.0, &err);
			row(name, err, ms, k == 0 ? 50 : 500, "read + decode + integrate");
		}
		ps_batch_free(&b);
		for (size_t i = 0; i < nmax; i++) {
			unlink(paths[i]);
			free(paths[i]);
		}
		free(paths);
	}

	/* a rotation scan of 512 x 512 with a sensor that changes with azimuth:
	 * directly (weights at each step: 10 steps measured, scaled to 360) and
	 * re-evaluated from one projection (0.25 x 1 degree cells, as psens) */
	{
		static const char table[] = "Elevation field 90\n"
		                            "degrees 0 45 90 135 180 225 270 315\n"
		                            "0 1 1 1 1 1 1 1 1\n"
		                            "20 0.95 0.9 0.7 0.6 0.8 0.9 0.85 0.9\n"
		                            "40 0.8 0.6 0.4 0.3 0.5 0.7 0.7 0.75\n"
		                            "60 0.5 0.3 0.2 0.1 0.2 0.4 0.45 0.5\n"
		                            "80 0.1 0.05 0.02 0.01 0.03 0.08 0.1 0.1\n"
		                            "90 0 0 0 0 0 0 0 0\n";
		struct ps_picture pic;
		struct ps_sensor s, uni;
		struct ps_weights om;
		struct ps_rescan rs;
		const double coef[3] = { PS_RGB_DEFAULT_R, PS_RGB_DEFAULT_G, PS_RGB_DEFAULT_B };
		double t0, direct[10], scan[360], worst = 0, t_proj, t_scan, t_om;
		char pw[600];
		/* a window, so the rotations differ */
		{
			double *rgb = malloc(sizeof(double) * 3 * 512 * 512);
			for (int y = 0; y < 512; y++)
				for (int x = 0; x < 512; x++)
					for (int c = 0; c < 3; c++)
						rgb[3 * ((size_t)y * 512 + x) + c] =
						    (x > 300 && x < 400 && y > 80 && y < 240) ? 40.0 : 0.5;
			snprintf(pw, sizeof pw, "%s/w512.hdr", dir);
			if (ps_picture_write(pw, 512, 512, rgb, VIEW, NULL, &e) != 0)
				return 1;
			free(rgb);
		}
		if (ps_picture_read(&pic, pw, &e) != 0 ||
		    ps_sensor_parse(&s, table, sizeof table - 1, "table", &e) != 0 ||
		    ps_sensor_set_reading(&s, PS_READ_LINEAR, &e) != 0 ||
		    ps_sensor_builtin(&uni, PS_SENS_UNIFORM, &e) != 0)
			return 1;
		t0 = psd_time_mono();
		for (int k = 0; k < 10; k++) {
			struct ps_weights w;
			struct ps_response r;
			ps_weights_build(&w, &s, 36.0 * k, &v, 512, 512, PS_W_EXACT, &e);
			ps_integrate(&w, &pic, coef, &r, &e);
			direct[k] = r.response;
			ps_weights_free(&w);
		}
		row("rotation scan 512x512 direct, 360 (10 x 36)", 0.0, 36e3 * (psd_time_mono() - t0), 50,
		    "exact weights at each step: the reference");
		t0 = psd_time_mono();
		ps_weights_build(&om, &uni, 0, &v, 512, 512, PS_W_EXACT, &e);
		t_om = psd_time_mono() - t0;
		t0 = psd_time_mono();
		ps_rescan_project(&rs, &om, &pic, &v, coef, 0.25, 0.25, 0, 91, &e);
		t_proj = psd_time_mono() - t0;
		t0 = psd_time_mono();
		ps_rescan_scan_mt(&rs, &s, 0, 1, 360, 2, scan, &e);
		t_scan = psd_time_mono() - t0;
		for (int k = 0; k < 10; k++)
			if (fabs(scan[36 * k] / direct[k] - 1) > worst)
				worst = fabs(scan[36 * k] / direct[k] - 1);
		row("rotation scan 512x512 rescan, 360, 2 thr", worst, 1e3 * t_scan, 50,
		    "after the projection; error: worst of 10 steps");
		{
			char note[96];
			snprintf(note, sizeof note, "once a picture (+ %.0f ms solid angles, cached)",
			         1e3 * t_om);
			row("  its projection, 0.25 x 0.25 degree cells", NAN, 1e3 * t_proj, 0, note);
		}
		{
			/* psens's scan: the same, checked against the exact route at
			 * the rotations where it is most likely off (no cache: each
			 * checked rotation's weights built) */
			struct ps_scancheck c = { .tolerance = PS_SCANCHECK_TOLERANCE };
			char note[96];
			t0 = psd_time_mono();
			ps_scancheck_scan(&rs, &om, &pic, &v, coef, &s, 0, 1, 360, 2, NULL, scan, &c, &e);
			t_scan = psd_time_mono() - t0;
			double w2 = 0;
			for (int k = 0; k < 10; k++)
				w2 = fmax(w2, fabs(scan[36 * k] / direct[k] - 1));
			snprintf(note, sizeof note, "%d rotations checked: estimate %.1e%s", c.nchecked,
			         c.estimate, c.refined ? ", refined" : "");
			row("rotation scan 512x512 checked, 360, 2 thr", w2, 1e3 * t_scan, 0, note);
		}
		ps_rescan_free(&rs);
		ps_weights_free(&om);
		ps_sensor_free(&s);
		ps_sensor_free(&uni);
		ps_picture_free(&pic);
		unlink(pw);
	}
	unlink(p4000);
	unlink(p1000);
	{
		char tp[600];
		snprintf(tp, sizeof tp, "%s/t4000.hdr", dir);
		unlink(tp);
	}
	unlink(p512);
	{
		char cmd[700];
		snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
		if (system(cmd) != 0)
			fprintf(stderr, "bench_psens_routes: %s left behind\n", dir);
	}
	ps_sensor_free(&cosine);
	return 0;
}
