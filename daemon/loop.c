/* The event loop: one poll() over the signals, the control socket and the
 * drivers' descriptors, with the timeout set by the next deadline.  A
 * simulated clock jumps to that deadline instead of waiting, so a day runs
 * in seconds through this same loop. */
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/signalfd.h>
#include <time.h>
#include <systemd/sd-daemon.h>
#include <unistd.h>

#include "daemon.h"
#include "log.h"

/* The process's signals: one signalfd per process by nature (a signal
 * mask is the process's), so it is the one state kept outside the daemon. */
static int sigfd = -1;

static double mono(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int signals_block(void)
{
	sigset_t set;
	if (sigfd >= 0)
		return 0;
	sigemptyset(&set);
	sigaddset(&set, SIGHUP);
	sigaddset(&set, SIGTERM);
	sigaddset(&set, SIGINT);
	signal(SIGPIPE, SIG_IGN);
	if (sigprocmask(SIG_BLOCK, &set, NULL) != 0)
		return -1;
	sigfd = signalfd(-1, &set, SFD_NONBLOCK | SFD_CLOEXEC);
	return sigfd >= 0 ? 0 : -1;
}

static void signals_read(struct psd_daemon *d)
{
	struct signalfd_siginfo si;
	while (read(sigfd, &si, sizeof si) == (ssize_t)sizeof si) {
		if (si.ssi_signo == SIGHUP)
			d->reload = 1;
		else
			d->stop = (int)si.ssi_signo;
	}
}

static const char *socket_path(const struct psd_config *cf, char *buf, size_t n)
{
	const char *rt = getenv("RUNTIME_DIRECTORY");   /* set by systemd's RuntimeDirectory= */
	if (cf->socket_path)
		return cf->socket_path;
	snprintf(buf, n, "%s/psensd.sock", rt && *rt ? rt : "/run/psensd");
	return buf;
}

void psd_daemon_config_errors(const struct psd_config *cf)
{
	for (size_t i = 0; i < cf->conf.nerrors; i++)
		log_errx("%s", cf->conf.errors[i]);
}

/* The run's date: a set date the database already holds moves to the next
 * day it does not (a second simulated run appends a day, never overdraws
 * the first); then every row and log line carries it. */
static void date_run(struct psd_daemon *d, double now)
{
	double last = d->engine.db ? psd_db_last_utc(d->engine.db) : NAN;
	char was[24], is[24];
	if (d->advance_date && isfinite(d->clock.epoch0) && isfinite(last) && last >= d->clock.epoch0 + now) {
		psd_clock_stamp(d->clock.epoch0, now, was, sizeof was);
		while (last >= d->clock.epoch0 + now) {
			/* the next local midnight: a day and a half on, back to 00:00 */
			time_t t = (time_t)(d->clock.epoch0 + 36 * 3600.0);
			struct tm tm;
			localtime_r(&t, &tm);
			if (psd_clock_midnight(tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday, &d->clock.epoch0) != 0)
				break;
		}
		psd_clock_stamp(d->clock.epoch0, now, is, sizeof is);
		log_info("the database holds samples up to that date already: this run starts %s, not %s", is, was);
	}
	psd_engine_set_epoch(&d->engine, d->clock.epoch0);
	psd_clock_stamp(d->clock.epoch0, now, is, sizeof is);
	log_info("the run starts %s (local time)", is);
	if (d->engine.db) {
		char err[512], text[300];
		snprintf(text, sizeof text, "%s on a %s clock", d->config_path, d->clock.simulated ? "simulated" : "real-time");
		if (psd_db_event(d->engine.db, now, NULL, "start", text, err, sizeof err) != 0)
			log_warnx("%s", err);
	}
}

int psd_daemon_start(struct psd_daemon *d, const char *path)
{
	struct psd_config *cf = calloc(1, sizeof *cf);
	char err[1024] = "", sock[256];
	double now = psd_clock_now(&d->clock);
	d->config_path = path;
	if (!cf) {
		log_err("config");
		return -1;
	}
	/* before any device opens: a driver's library may start threads, which
	 * inherit the mask, and a signal must reach the signalfd, not them */
	if (signals_block() != 0) {
		log_err("signals");
		free(cf);
		return -1;
	}
	if (psd_config_load(cf, path) != 0) {
		psd_daemon_config_errors(cf);
		psd_config_free(cf);
		free(cf);
		return -1;
	}
	/* the clock now, not when start-up began: in real time loading and
	 * checking the files took clock time, with the lights at full output */
	if (psd_refresh_results(cf, d->self) != 0 ||
	    psd_engine_open(&d->engine, cf, now = psd_clock_now(&d->clock), d->clock.simulated ? 500 : 1, NULL, err,
	                    sizeof err) != 0) {
		if (d->engine.cf == NULL && err[0])
			log_errx("%s", err);
		psd_config_free(cf);
		free(cf);
		return -1;
	}
	date_run(d, now);
	/* the socket: always in real time; in a simulated day only when configured */
	if (!d->clock.simulated || cf->socket_path) {
		if (psd_ctl_open(&d->ctl, socket_path(cf, sock, sizeof sock), (int)cf->socket_mode,
		                 (int)cf->max_clients, psd_ctl_handle, d, err, sizeof err) != 0) {
			log_errx("control socket %s (set socket = in [psensd], or run under systemd "
			          "with RuntimeDirectory=)", err);
			psd_engine_close(&d->engine);
			psd_config_free(cf);
			free(cf);
			return -1;
		}
		d->have_ctl = 1;
		log_info("control socket %s", d->ctl.path);
	}
	return 0;
}

int psd_daemon_reload(struct psd_daemon *d)
{
	struct psd_config *cf = calloc(1, sizeof *cf), *old;
	struct psd_engine *snap = malloc(sizeof *snap);
	char err[1024];
	double now = psd_clock_now(&d->clock);
	int batch = d->engine.db_batch;
	sd_notify(0, "RELOADING=1");
	if (!cf || !snap) {
		log_err("reload");
		goto keep;
	}
	if (psd_config_load(cf, d->config_path) != 0) {
		psd_daemon_config_errors(cf);
		log_errx("reload: %s has errors: the running configuration stays", d->config_path);
		goto keep;
	}
	if (psd_refresh_results(cf, d->self) != 0) {
		log_errx("reload: no results for the new configuration: the running configuration stays");
		goto keep;
	}
	/* devices can be opened once (a claimed USB interface, a GPIO line):
	 * close the running ones, try the new, and reopen the old on failure */
	*snap = d->engine;
	old = psd_engine_close(&d->engine);
	if (psd_engine_open(&d->engine, cf, now, batch, snap, err, sizeof err) != 0) {
		log_errx("reload: %s: the running configuration stays", err);
		if (psd_engine_open(&d->engine, old, now, batch, snap, err, sizeof err) != 0) {
			log_errx("reload: cannot reopen the running configuration either: %s", err);
			d->stop = SIGTERM;
		}
		psd_config_free(cf);
		free(cf);
		free(snap);
		d->reload_failures++;
		sd_notify(0, "READY=1");
		return -1;
	}
	psd_config_free(old);
	free(old);
	free(snap);
	d->reloads++;
	log_info("reloaded %s", d->config_path);
	if (d->engine.db) {
		char dberr[512];
		if (psd_db_event(d->engine.db, now, NULL, "reload", d->config_path, dberr, sizeof dberr) != 0)
			log_warnx("%s", dberr);
	}
	sd_notify(0, "READY=1");
	return 0;
keep:
	if (cf)
		psd_config_free(cf);
	free(cf);
	free(snap);
	d->reload_failures++;
	sd_notify(0, "READY=1");
	return -1;
}

int psd_daemon_run(struct psd_daemon *d)
{
	struct pollfd *fds = d->fds;
	int *fd_dev = d->fd_dev;
	uint64_t wd_usec = 0;
	double wd_next = 0;
	if (sd_watchdog_enabled(0, &wd_usec) > 0)
		d->watchdog_ms = (int)(wd_usec / 2000);
	sd_notifyf(0, "READY=1\nSTATUS=controlling %zu zone(s)\nMAINPID=%d", d->engine.nzone, (int)getpid());
	while (!d->stop) {
		double now = psd_clock_now(&d->clock), deadline;
		int n = 0, nctl, ndev, timeout;
		if (d->clock.simulated && now >= d->end)
			break;
		psd_engine_step(&d->engine, now);
		deadline = psd_engine_deadline(&d->engine);
		if (d->clock.simulated && deadline > d->end)
			deadline = d->end;
		fds[n++] = (struct pollfd){ sigfd, POLLIN, 0 };
		nctl = d->have_ctl ? psd_ctl_pollfds(&d->ctl, fds + n, PSD_MAX_POLL - n - PSD_MAX_DEVICES) : 0;
		n += nctl;
		ndev = psd_engine_pollfds(&d->engine, fds + n, fd_dev, PSD_MAX_POLL - n);
		timeout = psd_clock_wait_ms(&d->clock, deadline, d->watchdog_ms ? d->watchdog_ms : 60000);
		if (poll(fds, (nfds_t)(n + ndev), timeout) < 0 && errno != EINTR) {
			log_err("poll");
			break;
		}
		if (fds[0].revents & POLLIN)
			signals_read(d);
		if (nctl)
			psd_ctl_service(&d->ctl, fds + 1, nctl);
		now = psd_clock_now(&d->clock);
		psd_engine_service(&d->engine, now, fds + 1 + nctl, fd_dev, ndev);
		if (d->reload) {
			d->reload = 0;
			psd_daemon_reload(d);
		}
		if (d->watchdog_ms && mono() >= wd_next) {
			sd_notify(0, "WATCHDOG=1");
			wd_next = mono() + d->watchdog_ms / 1000.0;
		}
		psd_clock_advance(&d->clock, deadline);
	}
	return 0;
}

void psd_daemon_stop(struct psd_daemon *d, const char *why)
{
	double now = psd_clock_now(&d->clock);
	sd_notify(0, "STOPPING=1");
	if (d->engine.cf) {
		if (why)
			psd_engine_safe(&d->engine, now, why);
		{
			struct psd_config *cf = psd_engine_close(&d->engine);
			psd_config_free(cf);
			free(cf);
		}
	}
	if (d->have_ctl)
		psd_ctl_close(&d->ctl);
	d->have_ctl = 0;
	if (sigfd >= 0) {
		close(sigfd);
		sigfd = -1;
	}
}
