/* SPDX-License-Identifier: ISC */
/* mbdrive: the Modbus driver from the command line, for system tests and the
 * benchmark.  It reads [device NAME] and [point NAME] sections (the point's
 * device, role and driver keys, as in psensd-modbus(5)) and runs one command:
 *
 *   mbdrive CONF read POINT...        print "POINT = VALUE" (or the failure)
 *   mbdrive CONF write POINT VALUE
 *   mbdrive CONF poll SECONDS POINT   read every 50 ms, print each change of state
 *   mbdrive CONF control SECONDS      psensd's control law ([control] section)
 *   mbdrive CONF bench N POINT        round trips and the highest sustained poll rate
 *
 * Time for the driver is CLOCK_MONOTONIC seconds.  This is a test tool: it
 * sleeps between steps, the driver never does. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "conf.h"
#include "control.h"
#include "driver.h"
#include "registry.h"
#include "results.h"
#include "time.h"

#define MAX_DEV 4
#define MAX_PT 16
#define MAX_KV 32

struct dev {
	struct ps_dev d;
	struct ps_opt kv[MAX_KV];
	struct ps_opts o;
};

struct pt {
	struct ps_point p;
	struct dev *dev;
	struct ps_opt kv[MAX_KV];
	struct ps_opts o;
};

static struct ps_conf conf;
static struct dev devs[MAX_DEV];
static struct pt pts[MAX_PT];
static size_t ndev, npt;

static void sleep_until(double t)
{
	struct timespec ts;
	ts.tv_sec = (time_t)t;
	ts.tv_nsec = (long)((t - (double)ts.tv_sec) * 1e9);
	while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR)
		;
}

static const char *errname(int e)
{
	switch (e) {
	case EPROTO: return "EPROTO";
	case ETIMEDOUT: return "ETIMEDOUT";
	case ENODEV: return "ENODEV";
	case ERANGE: return "ERANGE";
	case EINVAL: return "EINVAL";
	case ENOTSUP: return "ENOTSUP";
	default: return "E?";
	}
}

static void copy_opts(struct ps_conf_section *s, struct ps_opt *kv, struct ps_opts *o, const char *skip1,
                      const char *skip2, const char *skip3)
{
	o->v = kv;
	o->n = 0;
	o->file = conf.path;
	for (size_t j = 0; j < s->nkv && o->n < MAX_KV; j++) {
		const char *k = s->kv[j].key;
		s->kv[j].used = 1;
		if (!strcmp(k, skip1) || (skip2 && !strcmp(k, skip2)) || (skip3 && !strcmp(k, skip3)))
			continue;
		kv[o->n++] = (struct ps_opt){ k, s->kv[j].value, s->kv[j].line, 0 };
	}
}

static int unused(const struct ps_opts *o, const char *what)
{
	for (size_t i = 0; i < o->n; i++)
		if (!o->v[i].used) {
			fprintf(stderr, "%s:%d: unknown key '%s' for %s\n", o->file, o->v[i].line, o->v[i].key, what);
			return 1;
		}
	return 0;
}

static int load(const char *path)
{
	struct ps_err e;
	if (ps_conf_load(&conf, path, &e) != 0) {
		fprintf(stderr, "%s\n", e.msg);
		return -1;
	}
	for (size_t i = 0; i < conf.nsec; i++) {
		struct ps_conf_section *s = &conf.sec[i];
		const char *name;
		if ((name = ps_conf_section_is(s, "device")) && ndev < MAX_DEV) {
			struct dev *d = &devs[ndev++];
			const char *drv = ps_conf_str(&conf, s, "driver", "");
			d->d.drv = ps_registry_find(drv);
			snprintf(d->d.name, sizeof d->d.name, "%s", name);
			copy_opts(s, d->kv, &d->o, "driver", NULL, NULL);
			if (!d->d.drv || d->d.drv->open(&d->d, &d->o) != 0) {
				fprintf(stderr, "device %s: %s\n", name, d->d.drv ? d->d.err : "no such driver");
				return -1;
			}
			if (unused(&d->o, drv))
				return -1;
		}
	}
	for (size_t i = 0; i < conf.nsec; i++) {
		struct ps_conf_section *s = &conf.sec[i];
		const char *name, *devname;
		struct pt *p;
		if (!(name = ps_conf_section_is(s, "point")) || npt >= MAX_PT)
			continue;
		p = &pts[npt++];
		snprintf(p->p.name, sizeof p->p.name, "%s", name);
		p->p.role = ps_role_parse(ps_conf_str(&conf, s, "role", ""));
		devname = ps_conf_str(&conf, s, "device", "");
		for (size_t j = 0; j < ndev; j++)
			if (!strcmp(devs[j].d.name, devname))
				p->dev = &devs[j];
		if (!p->dev || p->p.role < 0) {
			fprintf(stderr, "%s:%d: point %s needs a known device and role\n", conf.path, s->line, name);
			return -1;
		}
		copy_opts(s, p->kv, &p->o, "device", "role", NULL);
		if (p->dev->d.drv->add_point(&p->dev->d, &p->p, &p->o) != 0) {
			fprintf(stderr, "point %s: %s\n", name, p->dev->d.err);
			return -1;
		}
		if (unused(&p->o, "a modbus point"))
			return -1;
	}
	return 0;
}

static struct pt *point(const char *name)
{
	for (size_t i = 0; i < npt; i++)
		if (!strcmp(pts[i].p.name, name))
			return &pts[i];
	return NULL;
}

static int rd(struct pt *p, double now, double *v)
{
	return p->dev->d.drv->read(&p->dev->d, &p->p, now, now, v);
}

static int cmd_read(int argc, char **argv, double t0)
{
	int bad = 0;
	for (int i = 0; i < argc; i++) {
		struct pt *p = point(argv[i]);
		double v;
		if (!p) {
			fprintf(stderr, "no point %s\n", argv[i]);
			return 2;
		}
		if (rd(p, psd_time_mono() - t0, &v) != 0) {
			int e = errno;
			printf("%s: %s: %s\n", argv[i], errname(e), p->dev->d.err);
			bad = 1;
		} else {
			printf("%s = %.9g\n", argv[i], v);
		}
	}
	return bad;
}

static int cmd_write(struct pt *p, double value, double t0)
{
	if (p->dev->d.drv->write(&p->dev->d, &p->p, psd_time_mono() - t0, psd_time_mono() - t0, value) != 0) {
		int e = errno;
		printf("%s: %s: %s\n", p->p.name, errname(e), p->dev->d.err);
		return 1;
	}
	printf("%s <- %.9g\n", p->p.name, value);
	return 0;
}

static int cmd_poll(struct pt *p, double seconds, double t0)
{
	char last[320] = "", now_s[320];
	for (double t = psd_time_mono() - t0; t < seconds; t = psd_time_mono() - t0) {
		double v;
		if (rd(p, t, &v) != 0) {
			int e = errno;
			snprintf(now_s, sizeof now_s, "%s %s", errname(e), p->dev->d.err);
		} else {
			snprintf(now_s, sizeof now_s, "ok %.6g", v);
		}
		/* the state, without the countdown that changes every time */
		if (strncmp(now_s, last, strcspn(now_s, ";")) != 0 || strcspn(now_s, ";") != strcspn(last, ";")) {
			printf("%.3f %s\n", t, now_s);
			fflush(stdout);
			snprintf(last, sizeof last, "%s", now_s);
		}
		sleep_until(t0 + t + 0.05);
	}
	return 0;
}

/* psensd's control law over the driver: every period read the sensor, step
 * the set-point control (or go to the safe level on any fault), command the
 * dim output; one line per step with the room's truth when the config has
 * "clock" and "truth" points (psvirt's reserved registers). */
static int cmd_control(double seconds, double t0)
{
	struct ps_conf_section *s = ps_conf_section(&conf, "control");
	struct pt *sensor = point("sensor"), *dim = point("dim"), *clock = point("clock"), *truth = point("truth");
	struct psd_control ctl;
	struct ps_results res;
	struct ps_err e;
	char *results;
	double period, safe, smin, smax, tol, steps = 0, faults = 0, below = 0, judged = 0;
	if (!s || !sensor || !dim) {
		fprintf(stderr, "control needs a [control] section and points sensor and dim\n");
		return 2;
	}
	memset(&ctl, 0, sizeof ctl);
	results = ps_conf_path(&conf, s, "results");
	ps_conf_double(&conf, s, "period", 1, 0.001, 3600, &period);
	ps_conf_double(&conf, s, "safe_level", 1, 0, 1, &safe);
	ps_conf_double(&conf, s, "sensor_min", 0.01, -100, 100, &smin);
	ps_conf_double(&conf, s, "sensor_max", 9.9, -100, 100, &smax);
	ps_conf_double(&conf, s, "tolerance", 0.02, 0, 1, &tol);
	ps_conf_double(&conf, s, "target_lux", 500, 0, 1e6, &ctl.target_lux);
	ps_conf_double(&conf, s, "min_level", 0.1, 0, 1, &ctl.min_level);
	ps_conf_double(&conf, s, "sensor_gain", 1, 1e-12, 1e12, &ctl.sensor_gain);
	if (conf.nerrors || !results || ps_results_read(&res, results, &e) != 0) {
		fprintf(stderr, "%s\n", conf.nerrors ? conf.errors[0] : results ? e.msg : "[control] needs results");
		free(results);
		return 2;
	}
	free(results);
	ctl.algorithm = PSD_ALG_SETPOINT;
	ctl.daylight_ratio = res.daylight_ratio_mean;
	ctl.elec_sensor = res.electric_sensor_response;
	ctl.elec_task_lux = res.electric_task_lux;
	ctl.level = 1;
	ps_results_free(&res);
	for (double next = psd_time_mono() - t0; next < seconds; next += period) {
		double now, volts = NAN, level, tod = NAN, lux = NAN;
		char why[300] = "";
		int fault;
		sleep_until(t0 + next);
		now = psd_time_mono() - t0;
		fault = rd(sensor, now, &volts) != 0;
		if (fault)
			snprintf(why, sizeof why, "%s %s", errname(errno), sensor->dev->d.err);
		else if (volts < smin || volts > smax) {
			snprintf(why, sizeof why, "range sensor reads %.3f V, outside %g to %g V", volts, smin, smax);
			fault = 1;
		}
		level = fault ? safe : psd_control_step(&ctl, volts, now);
		if (fault)
			ctl.level = safe;
		if (dim->dev->d.drv->write(&dim->dev->d, &dim->p, now, now, level) != 0)
			snprintf(why + strlen(why), sizeof why - strlen(why), "%swrite %s %s", *why ? "; " : "",
			         errname(errno), dim->dev->d.err);
		if (clock)
			rd(clock, now, &tod);
		if (truth && rd(truth, now, &lux) == 0 && !fault && lux > 0) {
			judged++;
			below += lux < ctl.target_lux * (1 - tol);
		}
		steps++;
		faults += fault;
		printf("tod=%02d:%02d volts=%.4f level=%.4f truth=%.1f est=%.1f%s%s\n", isnan(tod) ? 99 : (int)(tod / 3600),
		       isnan(tod) ? 99 : (int)fmod(tod / 60, 60), volts, level, lux, fault ? NAN : ctl.est_task_lux,
		       *why ? " fault=" : "", why);
		fflush(stdout);
	}
	printf("control: %.0f steps, %.0f at the safe level, %.0f of %.0f judged steps below target\n", steps,
	       faults, below, judged);
	return 0;
}

static int cmp(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

/* Round trips, then for rising poll rates: does every service() finish
 * before the next poll is due? */
static int cmd_bench(long n, struct pt *p, double t0)
{
	double *rt = malloc((size_t)n * sizeof *rt), v;
	static const double rates[] = { 100, 200, 500, 1000, 2000, 5000, 10000, 20000 };
	double best = 0;
	if (!rt)
		return 2;
	for (long i = 0; i < n; i++) {
		double a = psd_time_mono();
		if (rd(p, a - t0, &v) != 0) {
			fprintf(stderr, "read: %s\n", p->dev->d.err);
			free(rt);
			return 1;
		}
		rt[i] = psd_time_mono() - a;
	}
	qsort(rt, (size_t)n, sizeof *rt, cmp);
	printf("driver round trip (%ld reads): median %.1f us, 99th percentile %.1f us, max %.1f us\n", n,
	       1e6 * rt[n / 2], 1e6 * rt[(size_t)(0.99 * (double)(n - 1))], 1e6 * rt[n - 1]);
	free(rt);
	printf("%10s %10s %10s %12s\n", "rate/s", "polls", "missed", "worst late");
	for (size_t k = 0; k < sizeof rates / sizeof rates[0]; k++) {
		/* a fresh connection with the one point polled at this rate */
		struct ps_dev d;
		struct ps_point q = p->p;
		struct ps_opt kv[MAX_KV];
		struct ps_opts o;
		char per[32];
		long polls = 0, missed = 0;
		double worst = 0, end;
		size_t m = 0;
		for (size_t i = 0; i < p->o.n && m < MAX_KV - 1; i++)
			if (strcmp(p->o.v[i].key, "period") != 0)
				kv[m++] = p->o.v[i];
		snprintf(per, sizeof per, "%.9g", 1 / rates[k]);
		kv[m++] = (struct ps_opt){ "period", per, 0, 0 };
		o = (struct ps_opts){ kv, m, "bench" };
		memset(&d, 0, sizeof d);
		d.drv = p->dev->d.drv;
		snprintf(d.name, sizeof d.name, "%s", p->dev->d.name);
		if (d.drv->open(&d, &p->dev->o) != 0 || d.drv->add_point(&d, &q, &o) != 0) {
			fprintf(stderr, "bench: %s\n", d.err);
			d.drv->close(&d);
			return 1;
		}
		end = psd_time_mono() + 1.0;
		for (;;) {
			double due = d.drv->deadline(&d, &(double){ INFINITY }) + t0, after;
			if (isinf(due))
				due = psd_time_mono();   /* the first poll is due at once */
			if (due > end)
				break;
			sleep_until(due);
			d.drv->service(&d, psd_time_mono() - t0, psd_time_mono() - t0);
			after = psd_time_mono();
			polls++;
			/* finished after the next poll was due: a missed deadline */
			if (after > due + 1 / rates[k]) {
				missed++;
				worst = fmax(worst, after - due - 1 / rates[k]);
			}
		}
		d.drv->close(&d);
		printf("%10.0f %10ld %10ld %10.1f us\n", rates[k], polls, missed, 1e6 * worst);
		if (missed * 100 <= polls && polls >= rates[k] * 0.95 && best == (k ? rates[k - 1] : 0))
			best = rates[k];
	}
	printf("highest poll rate sustained (under 1 %% missed): %.0f /s\n", best);
	return 0;
}

int main(int argc, char **argv)
{
	double t0 = psd_time_mono();
	int rc = 2;
	if (argc < 3) {
		fprintf(stderr, "usage: mbdrive CONF read POINT... | write POINT VALUE | poll SECONDS POINT | "
		                "control SECONDS | bench N POINT\n");
		return 2;
	}
	if (load(argv[1]) != 0)
		rc = 2;
	else if (!strcmp(argv[2], "read"))
		rc = cmd_read(argc - 3, argv + 3, t0);
	else if (!strcmp(argv[2], "write") && argc == 5 && point(argv[3]))
		rc = cmd_write(point(argv[3]), atof(argv[4]), t0);
	else if (!strcmp(argv[2], "poll") && argc == 5 && point(argv[4]))
		rc = cmd_poll(point(argv[4]), atof(argv[3]), t0);
	else if (!strcmp(argv[2], "control") && argc == 4)
		rc = cmd_control(atof(argv[3]), t0);
	else if (!strcmp(argv[2], "bench") && argc == 5 && point(argv[4]))
		rc = cmd_bench(atol(argv[3]), point(argv[4]), t0);
	else
		fprintf(stderr, "mbdrive: bad command or unknown point\n");
	for (size_t i = 0; i < ndev; i++)
		if (devs[i].d.drv)
			devs[i].d.drv->close(&devs[i].d);
	ps_conf_free(&conf);
	return rc;
}
