/* SPDX-License-Identifier: ISC */
#include "devio.h"

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/eventfd.h>
#include <time.h>
#include <unistd.h>

#include "log.h"
#include "time.h"

enum { DEVIO_MAX_EVENTS = 64 };

struct slot {
	int read_want, read_busy, have;   /* a read asked, under way, its result ready */
	int rc, err;                      /* the result */
	double value, asked_at;
	char msg[256];
	int write_want;                   /* a value waits to be written */
	double write_value;
	int wdone, wrc, werr;             /* the last finished write */
	char wmsg[256];
};

struct event {
	struct ps_point *pt;
	double now, value;
};

struct psd_devio {
	struct ps_dev *dev;
	struct ps_point *pts;
	size_t npts;
	struct psd_clock clock;   /* the worker's own copy (psd_clock_now writes it) */
	pthread_t th;
	pthread_mutex_t mu;
	pthread_cond_t cv;
	int efd, stop;
	struct slot *s;
	struct event ev[DEVIO_MAX_EVENTS];
	int nev;
	unsigned long ev_lost;
	ps_event_fn saved_fn;
	void *saved_user;
	double busy_since;        /* CLOCK_MONOTONIC seconds, 0 idle */
};

int psd_devio_wanted(const struct ps_driver *drv)
{
	/* libmodbus blocks for each transaction; the other drivers run
	 * step-wise through fd/deadline/service (DALI USB, GPIO) or touch no
	 * wire (loopback, file, replay) */
	return drv && drv->compiled_in && strcmp(drv->name, "modbus") == 0;
}

static void wake_loop(struct psd_devio *io)
{
	uint64_t one = 1;
	(void)!write(io->efd, &one, sizeof one);
}

/* on_event from inside service(), on the worker: queued for the loop. */
static void queue_event(void *user, struct ps_dev *dev, struct ps_point *pt, double now, double value)
{
	struct psd_devio *io = user;
	(void)dev;
	pthread_mutex_lock(&io->mu);
	if (io->nev < DEVIO_MAX_EVENTS)
		io->ev[io->nev++] = (struct event){ pt, now, value };
	else
		io->ev_lost++;
	pthread_mutex_unlock(&io->mu);
	wake_loop(io);
}

/* Wait on the condition until the clock reaches deadline or the monotonic
 * clock mono_deadline (at most 1 s). */
static void wait_until(struct psd_devio *io, double deadline, double now, double mono_deadline, double mono)
{
	struct timespec ts;
	double wall = 1.0, t;
	if (isfinite(deadline) && deadline > now)
		wall = fmin(1.0, (deadline - now) / io->clock.speed);
	if (mono_deadline < mono + wall)
		wall = fmax(0, mono_deadline - mono);
	clock_gettime(CLOCK_MONOTONIC, &ts);
	t = (double)ts.tv_nsec * 1e-9 + wall;
	ts.tv_sec += (time_t)t;
	ts.tv_nsec = (long)((t - floor(t)) * 1e9);
	pthread_cond_timedwait(&io->cv, &io->mu, &ts);
}

static void *worker(void *arg)
{
	struct psd_devio *io = arg;
	struct ps_dev *dev = io->dev;
	pthread_mutex_lock(&io->mu);
	while (!io->stop) {
		double now = psd_clock_now(&io->clock), mono = psd_time_mono(), v = NAN, dl, m = INFINITY;
		size_t i, w = io->npts, r = io->npts;
		int rc, e;
		for (i = 0; i < io->npts && w == io->npts; i++)
			if (io->s[i].write_want)
				w = i;
		for (i = 0; i < io->npts && r == io->npts; i++)
			if (io->s[i].read_want && !io->s[i].read_busy)
				r = i;
		if (w < io->npts) {   /* writes first: the lights */
			struct slot *s = &io->s[w];
			double value = s->write_value;
			s->write_want = 0;
			io->busy_since = psd_time_mono();
			pthread_mutex_unlock(&io->mu);
			rc = dev->drv->write(dev, &io->pts[w], now, mono, value);
			e = errno;
			pthread_mutex_lock(&io->mu);
			s->wdone = 1;
			s->wrc = rc;
			s->werr = rc ? e : 0;
			snprintf(s->wmsg, sizeof s->wmsg, "%s", rc ? dev->err : "");
		} else if (r < io->npts) {
			struct slot *s = &io->s[r];
			s->read_want = 0;
			s->read_busy = 1;
			io->busy_since = psd_time_mono();
			pthread_mutex_unlock(&io->mu);
			rc = dev->drv->read(dev, &io->pts[r], now, mono, &v);
			e = errno;
			pthread_mutex_lock(&io->mu);
			s->read_busy = 0;
			s->have = 1;
			s->rc = rc;
			s->err = rc ? e : 0;
			s->value = v;
			snprintf(s->msg, sizeof s->msg, "%s", rc ? dev->err : "");
		} else if (dev->drv->service &&
		           ((dl = dev->drv->deadline ? dev->drv->deadline(dev, &m) : INFINITY) <= now || m <= mono)) {
			char msg[256];
			io->busy_since = psd_time_mono();
			pthread_mutex_unlock(&io->mu);
			rc = dev->drv->service(dev, now, mono);
			snprintf(msg, sizeof msg, "%s", rc ? dev->err : "");
			pthread_mutex_lock(&io->mu);
			if (rc)
				psd_log_debug("device %s: %s", dev->name, msg);
		} else {
			m = INFINITY;
			dl = dev->drv->deadline ? dev->drv->deadline(dev, &m) : INFINITY;
			wait_until(io, dl, now, m, mono);
			continue;
		}
		io->busy_since = 0;
		wake_loop(io);
	}
	pthread_mutex_unlock(&io->mu);
	return NULL;
}

struct psd_devio *psd_devio_start(struct ps_dev *dev, struct ps_point *pts, size_t npts,
                                  const struct psd_clock *clock)
{
	struct psd_devio *io = calloc(1, sizeof *io);
	pthread_condattr_t ca;
	int e;
	if (!io)
		return NULL;
	io->s = calloc(npts ? npts : 1, sizeof *io->s);
	io->efd = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
	if (!io->s || io->efd < 0) {
		e = errno;
		goto bad;
	}
	io->dev = dev;
	io->pts = pts;
	io->npts = npts;
	io->clock = *clock;
	pthread_mutex_init(&io->mu, NULL);
	pthread_condattr_init(&ca);
	pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
	pthread_cond_init(&io->cv, &ca);
	pthread_condattr_destroy(&ca);
	io->saved_fn = dev->on_event;
	io->saved_user = dev->event_user;
	dev->on_event = queue_event;
	dev->event_user = io;
	if ((e = pthread_create(&io->th, NULL, worker, io)) != 0) {
		dev->on_event = io->saved_fn;
		dev->event_user = io->saved_user;
		pthread_cond_destroy(&io->cv);
		pthread_mutex_destroy(&io->mu);
		goto bad;
	}
	return io;
bad:
	if (io->efd >= 0)
		close(io->efd);
	free(io->s);
	free(io);
	errno = e;
	return NULL;
}

void psd_devio_stop(struct psd_devio *io)
{
	if (!io)
		return;
	pthread_mutex_lock(&io->mu);
	io->stop = 1;
	pthread_cond_signal(&io->cv);
	pthread_mutex_unlock(&io->mu);
	pthread_join(io->th, NULL);
	io->dev->on_event = io->saved_fn;
	io->dev->event_user = io->saved_user;
	pthread_cond_destroy(&io->cv);
	pthread_mutex_destroy(&io->mu);
	close(io->efd);
	free(io->s);
	free(io);
}

int psd_devio_fd(const struct psd_devio *io)
{
	return io->efd;
}

void psd_devio_drain(struct psd_devio *io)
{
	struct event ev[DEVIO_MAX_EVENTS];
	uint64_t n;
	int nev;
	unsigned long lost;
	(void)!read(io->efd, &n, sizeof n);
	pthread_mutex_lock(&io->mu);
	nev = io->nev;
	memcpy(ev, io->ev, (size_t)nev * sizeof ev[0]);
	io->nev = 0;
	lost = io->ev_lost;
	io->ev_lost = 0;
	pthread_mutex_unlock(&io->mu);
	if (lost)
		psd_log_warnx("device %s: %lu input event(s) lost (more than %d between two turns)", io->dev->name, lost,
		          DEVIO_MAX_EVENTS);
	for (int i = 0; i < nev && io->saved_fn; i++)
		io->saved_fn(io->saved_user, io->dev, ev[i].pt, ev[i].now, ev[i].value);
}

int psd_devio_ask(struct psd_devio *io, size_t pt, double now)
{
	struct slot *s = &io->s[pt];
	int rc = 1;
	pthread_mutex_lock(&io->mu);
	if (s->have)
		rc = 0;
	else if (!s->read_want && !s->read_busy) {
		s->read_want = 1;
		s->asked_at = now;
		pthread_cond_signal(&io->cv);
	}
	pthread_mutex_unlock(&io->mu);
	return rc;
}

int psd_devio_take(struct psd_devio *io, size_t pt, double now, double *value, char *err, size_t errlen)
{
	struct slot *s = &io->s[pt];
	int rc, e;
	pthread_mutex_lock(&io->mu);
	if (!s->have) {
		snprintf(err, errlen, "%s %s: %s: no reply for %.1f s (its I/O thread is still in a transaction)",
		         io->dev->drv->name, io->dev->name, io->pts[pt].name,
		         s->read_want || s->read_busy ? now - s->asked_at : 0.0);
		pthread_mutex_unlock(&io->mu);
		errno = ETIMEDOUT;
		return -1;
	}
	s->have = 0;
	rc = s->rc;
	e = s->err;
	if (rc == 0)
		*value = s->value;
	else
		snprintf(err, errlen, "%s", s->msg);
	pthread_mutex_unlock(&io->mu);
	errno = e;
	return rc;
}

int psd_devio_write(struct psd_devio *io, size_t pt, double now, double value, char *err, size_t errlen)
{
	struct slot *s = &io->s[pt];
	int rc = 0, e = 0;
	(void)now;
	pthread_mutex_lock(&io->mu);
	s->write_want = 1;
	s->write_value = value;
	pthread_cond_signal(&io->cv);
	if (s->wdone && s->wrc != 0) {
		rc = -1;
		e = s->werr;
		snprintf(err, errlen, "%s", s->wmsg);
	}
	pthread_mutex_unlock(&io->mu);
	errno = e;
	return rc;
}

double psd_devio_busy(const struct psd_devio *io)
{
	double since;
	pthread_mutex_lock((pthread_mutex_t *)&io->mu);
	since = io->busy_since;
	pthread_mutex_unlock((pthread_mutex_t *)&io->mu);
	return since > 0 ? psd_time_mono() - since : 0;
}
