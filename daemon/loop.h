/* SPDX-License-Identifier: ISC */
/* psensd's state as a whole: the engine (devices, zones, log), the clock,
 * the control socket, and what the event loop needs to reload and stop.
 * One value, no globals: tests build and tear down as many as they like. */
#ifndef PSD_LOOP_H
#define PSD_LOOP_H

#include "clock.h"
#include "ctlsock.h"
#include "engine.h"
#include "frontend.h"
#include "points.h"
#include "wallstep.h"

/* Descriptors one turn of the loop polls: the signals, the control socket's
 * clients and listener, the drivers', the front ends'. */
enum { PSD_MAX_POLL = 8 + 1024 + PSD_MAX_DEVICES };

struct psd_daemon {
	const char *config_path;
	struct psd_engine engine;
	struct psd_clock clock;
	struct psd_ctlsock ctl;
	int have_ctl;
	struct psd_frontend_set fronts; /* the front ends running (frontend.h) */
	struct psd_points points; /* the point model's own state: energy, acceptance (points.h) */
	double end;               /* simulated: stop at this time; real: INFINITY */
	int advance_date;         /* the date is the configuration's (a set clock): when the
	                             database already holds it, the run is dated the next
	                             free day (clock.epoch0 moves), so runs never overdraw */
	int watchdog_ms;          /* systemd watchdog interval / 2, 0: none */
	struct psd_wallstep wall; /* real time: the wall clock's steps */
	int wall_dated;           /* the run's dates are the wall clock's (no -t, -d, -s):
	                             they follow its steps */
	int dry;                  /* psensd -Y: no socket, database, event, MQTT, nor a moved
	                             date; only the results and the zones */
	int stop;                 /* the signal that ends the run (SIGTERM, SIGINT), 0: none */
	const char *fault;        /* a fault that ends the run (the loop's poll failed, a
	                             reload could not reopen the devices), NULL: none;
	                             it ends at the safe level, never the stop level */
	int reload;               /* 1: SIGHUP seen */
	unsigned long reloads, reload_failures;
	const char *self;         /* argv[0], to find psscene */
	struct pollfd fds[PSD_MAX_POLL];   /* the loop's poll set, rebuilt each turn */
	int fd_dev[PSD_MAX_POLL];          /* the device of each driver descriptor */
};

/* Load path, refresh the results, open the engine at the clock's now, and
 * the control socket.  -1 after logging why. */
int psd_loop_start(struct psd_daemon *d, const char *path);
/* The event loop until d->stop or the simulated end; returns 0. */
int psd_loop_run(struct psd_daemon *d);
/* Log a refused configuration's errors, each at LOG_ERR. */
void psd_loop_config_errors(const struct psd_config *cf);
/* Shutdown: every zone to its safe level (planned 0: a fault) or its
 * stop level (planned 1: psensd(8), STOPPING), then (real time) the devices
 * that send step-wise are served until what was asked is sent (their
 * deadlines idle) or for at most PSD_SETTLE_S: a DALI frame queued behind
 * one on the bus would be lost when the interface closes.  Returns the
 * count of zones whose level cannot be commanded. */
enum { PSD_SETTLE_MS = 1000 };
int psd_loop_end(struct psd_daemon *d, const char *why, int planned);
/* Safe level (unless why is NULL: already done), close everything. */
void psd_loop_stop(struct psd_daemon *d, const char *why);

#endif
