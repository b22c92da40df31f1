/* SPDX-License-Identifier: ISC */
/* One zone's virtual room for psvirt (see virtroom.h): a loopback device
 * opened through the driver registry, as psensd opens it, with a sensor, a
 * task meter and a dim point, given its room by roomsetup.c through the
 * table's setup hook and asked what is true through its truth hook. */
#include "virtroom.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "clock.h"
#include "log.h"
#include "registry.h"
#include "roomsetup.h"

struct psd_virtroom {
	struct ps_dev dev;
	struct ps_point sensor, task, dim, rooftop;
	int failing;   /* bits: the driver calls failing now (enum call), logged once each */
};

enum call { CALL_TASK = 1, CALL_WRITE = 2, CALL_TRUTH = 4 };

/* A driver call's result: a failure is logged as an error when that call
 * starts failing (the room is asked on every request: once, not a flood),
 * and its recovery at info.  rc is passed on. */
static int checked(struct psd_virtroom *r, int call, const char *what, int rc)
{
	if (rc != 0 && !(r->failing & call))
		psd_log_errx("virtual room: %s failed: %s", what, r->dev.err[0] ? r->dev.err : "no reason given");
	else if (rc == 0 && (r->failing & call))
		psd_log_info("virtual room: %s works again", what);
	r->failing = rc != 0 ? r->failing | call : r->failing & ~call;
	return rc;
}

/* A loopback device, opened with these options; -1 with the reason in err. */
static int open_dev(struct ps_dev *dev, const struct ps_opts *opts, char *err, size_t n)
{
	memset(dev, 0, sizeof *dev);
	dev->drv = ps_registry_find("loopback");
	snprintf(dev->name, sizeof dev->name, "psvirt");
	if (!dev->drv || !dev->drv->setup || !dev->drv->truth) {
		snprintf(err, n, "this build has no simulated room (loopback driver)");
		dev->drv = NULL;
		return -1;
	}
	if (dev->drv->open(dev, opts) != 0) {
		snprintf(err, n, "%s", dev->err);
		return -1;
	}
	return 0;
}

int psd_virtroom_check(const struct ps_opts *opts, char *err, size_t n)
{
	struct ps_dev dev;
	int rc = open_dev(&dev, opts, err, n);
	if (dev.drv)
		dev.drv->close(&dev);
	return rc;
}

struct psd_virtroom *psd_virtroom_new(const struct psd_virtday *day, const struct ps_opts *opts,
                                      double start, char *err, size_t n)
{
	struct psd_virtroom *r = calloc(1, sizeof *r);
	struct ps_room_params *rp;
	if (!r) {
		snprintf(err, n, "out of memory");
		return NULL;
	}
	if (open_dev(&r->dev, opts, err, n) != 0) {
		psd_virtroom_free(r);
		return NULL;
	}
	if (!(rp = day->year ? psd_roomsetup_new_year(day->res, day->date, psd_clock_dst_shift_day(day->date, NAN))
	                     : psd_roomsetup_new(day->res, day->date, day->sunrise, day->sunset))) {
		snprintf(err, n, day->year ? "[simulate] year = yes: the results need a year and an "
		                             "electric condition"
		                           : "the results need a computed daylight and an electric condition");
		psd_virtroom_free(r);
		return NULL;
	}
	r->sensor = (struct ps_point){ "sensor", PS_ROLE_SENSOR, NULL };
	r->task = (struct ps_point){ "task", PS_ROLE_TASK_LUX, NULL };
	r->dim = (struct ps_point){ "dim", PS_ROLE_DIM, NULL };
	r->rooftop = (struct ps_point){ "rooftop", PS_ROLE_ROOFTOP, NULL };
	if (r->dev.drv->setup(&r->dev, rp, start) != 0 || r->dev.drv->add_point(&r->dev, &r->sensor, NULL) != 0 ||
	    r->dev.drv->add_point(&r->dev, &r->task, NULL) != 0 || r->dev.drv->add_point(&r->dev, &r->dim, NULL) != 0 ||
	    r->dev.drv->add_point(&r->dev, &r->rooftop, NULL) != 0) {
		snprintf(err, n, "%s", r->dev.err);
		psd_roomsetup_free(rp);
		psd_virtroom_free(r);
		return NULL;
	}
	psd_roomsetup_free(rp);
	return r;
}

void psd_virtroom_free(struct psd_virtroom *r)
{
	if (!r)
		return;
	if (r->dev.drv)
		r->dev.drv->close(&r->dev);
	free(r);
}

/* The fault the room plays now (its faults key's name), NULL for none. */
static const char *fault_now(const struct psd_virtroom *r, double now)
{
	struct ps_truth t;
	memset(&t, 0, sizeof t);
	if (r->dev.drv->truth((struct ps_dev *)&r->dev, now, &t) != 0)
		return NULL;
	return t.fault;
}

static int is(const char *fault, const char *name)
{
	return fault && strcmp(fault, name) == 0;
}

int psd_virtroom_comms(const struct psd_virtroom *r, double now)
{
	const char *f = fault_now(r, now);
	return is(f, "drop") ? PSD_VIRTROOM_DROP : is(f, "late") ? PSD_VIRTROOM_LATE : PSD_VIRTROOM_ANSWER;
}

int psd_virtroom_sensor(struct psd_virtroom *r, double now, double *volts, int *state)
{
	const char *f = fault_now(r, now);
	*state = (is(f, "open") ? PSD_VIRTROOM_OPEN : 0) | (is(f, "saturated") ? PSD_VIRTROOM_SATURATED : 0);
	return r->dev.drv->read(&r->dev, &r->sensor, now, now, volts);
}

double psd_virtroom_task(struct psd_virtroom *r, double now)
{
	double lux = 0;
	if (checked(r, CALL_TASK, "reading the task meter", r->dev.drv->read(&r->dev, &r->task, now, now, &lux)) != 0)
		lux = 0;
	return lux;
}

double psd_virtroom_rooftop(struct psd_virtroom *r, double now)
{
	double lux;
	return r->dev.drv->read(&r->dev, &r->rooftop, now, now, &lux) == 0 ? lux : 0.0;
}

void psd_virtroom_command(struct psd_virtroom *r, double now, double level)
{
	checked(r, CALL_WRITE, "setting the light level", r->dev.drv->write(&r->dev, &r->dim, now, now, level));
}

/* The truth hook never advances the room: asking cannot move its clock. */
static struct ps_truth truth(struct psd_virtroom *r, double now)
{
	struct ps_truth t;
	memset(&t, 0, sizeof t);
	if (checked(r, CALL_TRUTH, "asking the room what is true", r->dev.drv->truth(&r->dev, now, &t)) != 0)
		memset(&t, 0, sizeof t);
	return t;
}

double psd_virtroom_output(struct psd_virtroom *r, double now)
{
	return truth(r, now).output;
}

double psd_virtroom_truth(struct psd_virtroom *r, double now)
{
	return truth(r, now).task_lux;
}

double psd_virtroom_energy(struct psd_virtroom *r, double now)
{
	return truth(r, now).energy;
}

double psd_virtroom_tod(double now)
{
	double t = fmod(now, 86400.0);
	return t < 0 ? t + 86400.0 : t;
}
