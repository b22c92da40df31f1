/* SPDX-License-Identifier: ISC */
/* Sensors that change with azimuth beside symmetric ones.
 *
 * 1. The weights alone (library, every core), an 8 x 6 table that changes
 *    with azimuth on a 180-degree angular fisheye: the exact edge route
 *    (both readings, cold) and the cell reading's route from the
 *    solid-angle map (sim/weights/cellmap.h), with the solid angles built
 *    (an empty cache) and given (a warm one), and the linear reading's
 *    route from the solid angles and the pixels' moments.  Error: the largest
 *    difference of a weight from the exact route's, over the largest
 *    weight, at 1000 x 1000; at 4000 x 4000 the map's total against the
 *    sensitivity's integral over the sphere (the table ends inside the
 *    picture, so the two are equal analytically).
 * 2. psens end to end on a uniform 4000 x 4000 picture: empty cache (cold)
 *    and the cache it leaves (warm), five runs each, the median wall time
 *    and the median CPU time (user + system); error: the r channel (full
 *    precision, -od) against the decoded radiance times the sensitivity's
 *    integral.  Each warm row is compared with the cold one of the same
 *    run (cold / warm, CPU seconds): Radiance is not installed here, so no
 *    ratio against its pipeline is made; part 1 sets the exact route
 *    beside the cell and linear routes in the same way.
 * On whatever else the machine is doing (the load average is printed). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "cellmap.h"
#include "picture.h"
#include "sensor.h"
#include "time.h"
#include "view.h"
#include "weights.h"

/* CPU seconds of this process, every thread */
static double cpu_now(void)
{
	struct rusage ru;
	getrusage(RUSAGE_SELF, &ru);
	return ru.ru_utime.tv_sec + ru.ru_stime.tv_sec + 1e-6 * (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

#define DECODED_ONE 1.00390625   /* RGBE's 1 as Radiance decodes it */

static const char table[] = "Elevation field 90\n"
                            "degrees 0 45 90 135 180 225 270 315\n"
                            "0 1 1 1 1 1 1 1 1\n"
                            "20 0.95 0.9 0.7 0.6 0.8 0.9 0.85 0.9\n"
                            "40 0.8 0.6 0.4 0.3 0.5 0.7 0.7 0.75\n"
                            "60 0.5 0.3 0.2 0.1 0.2 0.4 0.45 0.5\n"
                            "80 0.1 0.05 0.02 0.01 0.03 0.08 0.1 0.1\n"
                            "90 0 0 0 0 0 0 0 0\n";

static double max_diff(const struct ps_weights *a, const struct ps_weights *b)
{
	double wmax = 0, d = 0;
	if (a->nw != b->nw)
		return INFINITY;
	for (size_t i = 0; i < a->nw; i++) {
		wmax = fmax(wmax, fabs(b->w[i]));
		d = fmax(d, fabs(a->w[i] - b->w[i]));
	}
	return d / wmax;
}

static void weights_part(struct ps_sensor *s, const struct ps_view *v)
{
	static const int sizes[] = { 1000, 4000 };
	struct ps_err e;
	struct ps_sensor uni;
	printf("exact weights of a sensor that changes with azimuth (8 x 6 table), 180-degree\n"
	       "angular fisheye, every core; error: at 1000 the largest weight's difference from\n"
	       "the exact route over the largest weight, at 4000 the total against the integral\n");
	printf("%-52s %10s %10s %10s\n", "route", "error", "wall ms", "cpu ms");
	if (ps_sensor_builtin(&uni, PS_SENS_UNIFORM, &e) != 0)
		exit(1);
	for (int k = 0; k < 2; k++) {
		int n = sizes[k];
		struct ps_weights ex[2], om, fast;
		char name[96];
		for (int r = 0; r < 2; r++) {
			double t0 = psd_time_mono(), c0 = cpu_now(), ms;
			if (ps_sensor_set_reading(s, r == 0 ? PS_READ_LINEAR : PS_READ_CELL, &e) != 0 ||
			    ps_weights_build(&ex[r], s, 10.0, v, n, n, PS_W_EXACT, &e) != 0)
				exit(1);
			ms = 1e3 * (psd_time_mono() - t0);
			snprintf(name, sizeof name, "%dx%d exact route, %s reading, cold", n, n,
			         r == 0 ? "linear" : "cell");
			printf("%-52s %10.2e %10.1f %10.1f\n", name, ex[r].sens_sum / ex[r].sens_full - 1, ms,
			       1e3 * (cpu_now() - c0));
		}
		/* the cell reading is in force now */
		{
			double t0 = psd_time_mono(), t1, t2, c0 = cpu_now(), c1, c2;
			if (ps_weights_build_ex(&om, &uni, 0.0, v, n, n, PS_W_EXACT, PS_WB_COMPACT, &e) != 0)
				exit(1);
			t1 = psd_time_mono();
			c1 = cpu_now();
			if (ps_cellmap_build(&fast, s, 10.0, v, n, n, &om, &e) != 0)
				exit(1);
			t2 = psd_time_mono();
			c2 = cpu_now();
			snprintf(name, sizeof name, "%dx%d cell route, solid angles built (cold)", n, n);
			printf("%-52s %10.2e %10.1f %10.1f\n", name,
			       n <= 1000 ? max_diff(&fast, &ex[1]) : fast.sens_sum / fast.sens_full - 1,
			       1e3 * (t2 - t0), 1e3 * (c2 - c0));
			snprintf(name, sizeof name, "%dx%d cell route, solid angles given (warm)", n, n);
			printf("%-52s %10s %10.1f %10.1f\n", name, "same", 1e3 * (t2 - t1), 1e3 * (c2 - c1));
		}
		ps_weights_free(&fast);
		ps_weights_free(&om);
		/* the linear reading from the solid angles and the moments */
		{
			double t0 = psd_time_mono(), t1, t2, c0 = cpu_now(), c1, c2;
			if (ps_sensor_set_reading(s, PS_READ_LINEAR, &e) != 0 ||
			    ps_weights_build_ex(&om, &uni, 0.0, v, n, n, PS_W_EXACT, PS_WB_COMPACT, &e) != 0)
				exit(1);
			t1 = psd_time_mono();
			c1 = cpu_now();
			if (ps_cellmap_build(&fast, s, 10.0, v, n, n, &om, &e) != 0)
				exit(1);
			t2 = psd_time_mono();
			c2 = cpu_now();
			snprintf(name, sizeof name, "%dx%d linear route, solid angles built (cold)", n, n);
			printf("%-52s %10.2e %10.1f %10.1f\n", name,
			       n <= 1000 ? max_diff(&fast, &ex[0]) : fast.sens_sum / fast.sens_full - 1,
			       1e3 * (t2 - t0), 1e3 * (c2 - c0));
			snprintf(name, sizeof name, "%dx%d linear route, solid angles given", n, n);
			printf("%-52s %10s %10.1f %10.1f\n", name, "same", 1e3 * (t2 - t1), 1e3 * (c2 - c1));
		}
		ps_weights_free(&fast);
		ps_weights_free(&om);
		ps_weights_free(&ex[0]);
		ps_weights_free(&ex[1]);
	}
	ps_sensor_free(&uni);
}

/* Run psens once (argv after "psens"); wall and CPU seconds, its r channel. */
static int run(const char *bin, char *const *args, double *wall, double *cpu, double *r)
{
	char out[] = "/tmp/psbench-azXXXXXX";
	char *argv[16];
	int fd = mkstemp(out), status, na = 0;
	struct rusage ru;
	double t0;
	pid_t pid;
	if (fd < 0)
		return -1;
	argv[na++] = "psens";
	for (int i = 0; args[i] && na < 15; i++)
		argv[na++] = args[i];
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
	*wall = psd_time_mono() - t0;
	*cpu = ru.ru_utime.tv_sec + ru.ru_stime.tv_sec + 1e-6 * (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
	{
		/* -od: a Radiance header, a blank line, r g b as doubles */
		char buf[4096];
		ssize_t n = pread(fd, buf, sizeof buf, 0);
		char *p = n > 0 ? memmem(buf, (size_t)n, "\n\n", 2) : NULL;
		*r = NAN;
		if (p && buf + n - (p + 2) >= 24)
			memcpy(r, p + 2, sizeof *r);
	}
	close(fd);
	unlink(out);
	return 0;
}

static int cmp(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return x < y ? -1 : x > y;
}

static void psens_part(const char *bin, const char *dir, const char *pic, const char *sen)
{
	static const struct {
		const char *name, *sensor, *reading;
	} cases[] = {
		{ "builtin:cosine (symmetric)", "builtin:cosine", "linear" },
		{ "8 x 6 table, cell reading", NULL, "cell" },
		{ "8 x 6 table, linear reading", NULL, "linear" },
	};
	enum { RUNS = 5 };
	printf("\npsens on a uniform 4000x4000 180-degree picture, %d runs each: median wall and\n"
	       "CPU (user + system) seconds; cold / warm: the cold row's median CPU over the warm\n"
	       "row's, both measured here; error: r channel against the decoded radiance times\n"
	       "the sensitivity's integral\n", RUNS);
	printf("%-30s %-5s %10s %8s %8s %11s\n", "sensor", "cache", "error", "wall s", "cpu s",
	       "cold / warm");
	for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
		struct ps_sensor s;
		struct ps_err e;
		const char *sname = cases[c].sensor ? cases[c].sensor : sen;
		double integral;
		char cache[600];
		if (ps_sensor_open(&s, sname, &e) != 0 ||
		    ps_sensor_set_reading(&s, ps_sensor_reading_parse(cases[c].reading), &e) != 0)
			exit(1);
		integral = ps_sensor_integral(&s);
		ps_sensor_free(&s);
		snprintf(cache, sizeof cache, "%s/cache-%zu", dir, c);
		double cold_cpu = NAN;
		for (int warm = 0; warm < 2; warm++) {
			double wall[RUNS], cpu[RUNS], r = NAN;
			char ratio[16] = "";
			char *args[] = { "-q", "-od", "-C", cache, "-m", (char *)cases[c].reading, "-s",
			                 (char *)sname, (char *)pic, NULL };
			for (int k = 0; k < RUNS; k++) {
				if (!warm) {
					char cmd[700];
					snprintf(cmd, sizeof cmd, "rm -rf '%s'", cache);
					if (system(cmd) != 0)
						exit(1);
				} else if (k == 0) {
					double w0, c0, r0;   /* the cache as a cold run leaves it */
					if (run(bin, args, &w0, &c0, &r0) != 0)
						exit(1);
				}
				if (run(bin, args, &wall[k], &cpu[k], &r) != 0) {
					fprintf(stderr, "bench_weights_azimuth: %s failed\n", bin);
					exit(1);
				}
			}
			qsort(wall, RUNS, sizeof *wall, cmp);
			qsort(cpu, RUNS, sizeof *cpu, cmp);
			if (warm)
				snprintf(ratio, sizeof ratio, "%.1fx", cold_cpu / cpu[RUNS / 2]);
			else
				cold_cpu = cpu[RUNS / 2];
			printf("%-30s %-5s %10.2e %8.3f %8.3f %11s\n", cases[c].name, warm ? "warm" : "cold",
			       r / (DECODED_ONE * integral) - 1, wall[RUNS / 2], cpu[RUNS / 2], ratio);
		}
	}
}

int main(void)
{
	struct ps_sensor s;
	struct ps_view v;
	struct ps_err e;
	const char *build = getenv("BUILD");
	char bin[512], dir[] = "/tmp/psbench-azdXXXXXX", pic[600], sen[600], cmd[700];
	double load[3] = { 0, 0, 0 };
	ps_view_default_fisheye(&v);
	if (ps_sensor_parse(&s, table, sizeof table - 1, "table", &e) != 0)
		return 1;
	if (getloadavg(load, 3) < 0)
		load[0] = NAN;
	printf("load average %.2f at the start\n", load[0]);
	weights_part(&s, &v);
	ps_sensor_free(&s);
	snprintf(bin, sizeof bin, "%s/bin/psens", build ? build : "build");
	if (access(bin, X_OK) != 0 || !mkdtemp(dir)) {
		printf("(no %s: psens's part skipped)\n", bin);
		return 0;
	}
	snprintf(pic, sizeof pic, "%s/u4000.hdr", dir);
	snprintf(sen, sizeof sen, "%s/az.sen", dir);
	{
		FILE *fp = fopen(sen, "w");
		double *rgb = malloc(sizeof(double) * 3 * 4000 * 4000);
		if (!fp || !rgb || fwrite(table, 1, sizeof table - 1, fp) != sizeof table - 1)
			return 1;
		fclose(fp);
		for (size_t i = 0; i < (size_t)3 * 4000 * 4000; i++)
			rgb[i] = 1.0;
		if (ps_picture_write(pic, 4000, 4000, rgb, "-vta -vd 0 0 -1 -vu 0 1 0 -vh 180 -vv 180", NULL,
		                     &e) != 0)
			return 1;
		free(rgb);
	}
	psens_part(bin, dir, pic, sen);
	if (getloadavg(load, 3) < 0)
		load[0] = NAN;
	printf("load average %.2f at the end\n", load[0]);
	snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
	return system(cmd) != 0;
}
