/* SPDX-License-Identifier: ISC */
/* The event loop: one poll() over the signals, the control socket, the
 * drivers' descriptors and the front ends' (frontend.h, walked as one
 * table), with the timeout set by the next deadline.  A
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

#include "loop.h"
#include "cmdtab.h"
#include "refresh.h"
#include "reload.h"
#include "dated.h"
#include "log.h"
#include "time.h"


/* Unix time of local midnight of the clock's day: today on a real clock, the
 * [simulate] date (MM-DD) this year on a simulated one; NAN if unknown. */
static double utc_of_day(const char *mmdd)
{
	time_t now;
	struct tm tm;
	int m, dd;
	if (psd_time_local(psd_time_wall(), &tm) != 0)
		return NAN;
	if (mmdd && sscanf(mmdd, "%d-%d", &m, &dd) == 2) {
		tm.tm_mon = m - 1;
		tm.tm_mday = dd;
	}
	tm.tm_hour = tm.tm_min = tm.tm_sec = 0;
	tm.tm_isdst = -1;
	now = mktime(&tm);
	return now == (time_t)-1 ? NAN : (double)now;
}
/* The process's signals: one signalfd per process by nature (a signal
 * mask is the process's), so it is the one state kept outside the daemon. */
static int sigfd = -1;

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
	if (cf->socket_path)
		return cf->socket_path;
	return psd_ctlsock_default_path(1, buf, n);
}

void psd_loop_config_errors(const struct psd_config *cf)
{
	for (size_t i = 0; i < cf->conf.nerrors; i++)
		psd_log_errx("%s", cf->conf.errors[i]);
}

/* A run that starts before the last sample on record would interleave its
 * rows with those logged from its start on: refused (-1) on a date given
 * with -d, warned on the wall clock (set back: the lights are controlled
 * all the same); the overlap named either way. */
static int set_back(struct psd_daemon *d, double now, double last)
{
	char from[24], to[24];
	if (!isfinite(d->clock.epoch0) || !isfinite(last) || last < d->clock.epoch0 + now)
		return 0;
	psd_clock_stamp(d->clock.epoch0, now, from, sizeof from);
	psd_clock_stamp(last, 0, to, sizeof to);
	if (d->wall_dated) {
		psd_log_warnx("the wall clock is behind the log: this run starts %s, before the last sample on record (%s); "
		          "the samples from %s to %s will interleave", from, to, from, to);
		return 0;
	}
	psd_log_errx("this run would start %s, before the last sample on record (%s): its samples would interleave "
	         "with those logged from %s to %s; give a later date (-d) or another database", from, to, from, to);
	return -1;
}

/* The run's date: a set date the database already holds moves to the next
 * day it does not (a second simulated run appends a day, never overdraws
 * the first); a date given that the log holds from the run's start on is
 * refused (set_back); then every row and log line carries it. */
static int date_run(struct psd_daemon *d, double now)
{
	double last = d->engine.db ? psd_db_last_utc(d->engine.db) : NAN;
	char was[24], is[24];
	if (d->advance_date && isfinite(d->clock.epoch0) && isfinite(last) && last >= d->clock.epoch0 + now) {
		psd_clock_stamp(d->clock.epoch0, now, was, sizeof was);
		while (last >= d->clock.epoch0 + now) {
			/* the next local midnight: a day and a half on, back to 00:00 */
			struct tm tm;
			if (psd_time_local(d->clock.epoch0 + 36 * 3600.0, &tm) != 0 ||
			    psd_clock_midnight(tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday, &d->clock.epoch0) != 0)
				break;
		}
		psd_clock_stamp(d->clock.epoch0, now, is, sizeof is);
		psd_log_info("the database holds samples up to that date already: this run starts %s, not %s", is, was);
	} else if (set_back(d, now, last) != 0) {
		return -1;
	}
	psd_engine_set_epoch(&d->engine, d->clock.epoch0);
	psd_clock_stamp(d->clock.epoch0, now, is, sizeof is);
	psd_log_info("the run starts %s (local time)", is);
	{
		char text[300];
		snprintf(text, sizeof text, "%s on a %s clock", d->config_path, d->clock.simulated ? "simulated" : "real-time");
		psd_engine_event(&d->engine, now, NULL, "start", text);
		/* the record tells a simulated zone from a real one by this */
		for (size_t i = 0; i < d->engine.cf->nzone; i++) {
			const struct psd_zone_conf *zc = &d->engine.cf->zone[i];
			const char *sim = psd_config_zone_simulated(d->engine.cf, zc);
			if (sim) {
				snprintf(text, sizeof text, "the zone's devices are simulated (%s)", sim);
				psd_engine_event(&d->engine, now, zc->name, "simulated", text);
			}
		}
	}
	return 0;
}

/* An MQTT command: the control socket's request function, the same code,
 * its reply copied into the front end's fixed buffer (an error reply when
 * it does not fit). */
static void fixed_request(void *user, char *line, char *reply, size_t len)
{
	struct psd_ctl_reply r = { 0 };
	psd_cmdtab_request(user, line, &r);
	if (strlen(r.text) >= len)
		snprintf(reply, len, "{\"ok\":false,\"error\":\"reply too long\"}");
	else
		snprintf(reply, len, "%s", r.text);
	psd_ctlsock_reply_free(&r);
}

/* A start given up: the lights to their safe level when the engine has
 * opened the devices (with the reason logged), then every front end started
 * so far stopped (in the reverse order) and the configuration freed.
 * Always -1. */
static int abandon_start(struct psd_daemon *d, struct psd_config *cf, int engine_open, const char *why)
{
	if (engine_open && why)
		psd_loop_end(d, why, 0);
	psd_frontend_stop(&d->fronts);
	if (d->have_ctl)
		psd_ctlsock_close(&d->ctl);
	d->have_ctl = 0;
	if (engine_open)
		psd_engine_close(&d->engine);
	psd_config_free(cf);
	free(cf);
	return -1;
}

/* A web console's action or live update: the same function again. */
static void web_request(void *user, char *line, struct psd_ctl_reply *reply)
{
	psd_cmdtab_request(user, line, reply);
}

/* Every front end the configuration wants (frontend.h), in the table's
 * order; at the first that cannot start, the start is given up. */
static int start_fronts(struct psd_daemon *d, struct psd_config *cf)
{
	const struct psd_frontend_env env = { .cf = cf,
		                              .engine = &d->engine,
		                              .points = &d->points,
		                              .fixed = fixed_request,
		                              .request = web_request,
		                              .grants = psd_cmdtab_verb_fronts,
		                              .override = psd_cmdtab_override,
		                              .release = psd_cmdtab_release,
		                              .user = d };
	const struct psd_frontend *failed = NULL;
	char err[1024] = "";
	if (psd_frontend_start(&d->fronts, &env, &failed, err, sizeof err) == 0)
		return 0;
	psd_log_errx("%s", err);
	return abandon_start(d, cf, 1, failed->refused);
}

int psd_loop_start(struct psd_daemon *d, const char *path)
{
	struct psd_config *cf = calloc(1, sizeof *cf);
	char err[1024] = "", sock[256];
	double now = psd_clock_now(&d->clock);
	d->config_path = path;
	if (!cf) {
		psd_log_err("config");
		return -1;
	}
	/* before any device opens: a driver's library may start threads, which
	 * inherit the mask, and a signal must reach the signalfd, not them */
	if (signals_block() != 0) {
		psd_log_err("signals");
		free(cf);
		return -1;
	}
	if (psd_config_load(cf, path) != 0) {
		psd_loop_config_errors(cf);
		return abandon_start(d, cf, 0, NULL);
	}
	/* the socket first (in real time; in a simulated day only when
	 * configured): a second daemon on the same socket is refused before it
	 * opens a device or commands a light */
	if (d->dry) {   /* -Y leaves no trace: no log, no socket */
		free(cf->database);
		cf->database = NULL;
		cf->mqtt.enabled = 0;
		cf->web.enabled = 0;
		psd_promconf_free(&cf->prom);
	} else if (!d->clock.simulated || cf->socket_path) {
		if (psd_ctlsock_open(&d->ctl, socket_path(cf, sock, sizeof sock), (int)cf->socket_mode,
		                 (int)cf->max_clients, psd_cmdtab_handle, d, err, sizeof err) != 0) {
			if (errno == EADDRINUSE)
				psd_log_errx("control socket %s", err);
			else
				psd_log_errx("control socket %s (set socket = in [psensd], or run under systemd "
				          "with RuntimeDirectory=)", err);
			return abandon_start(d, cf, 0, NULL);
		}
		d->have_ctl = 1;
	}
	/* the clock now, not when start-up began: in real time loading and
	 * checking the files took clock time, with the lights at full output */
	if (psd_refresh_results(cf, d->self) != 0 ||
	    psd_engine_open_io(&d->engine, cf, now = psd_clock_now(&d->clock), d->clock.simulated ? 500 : 1, NULL, &d->clock, err, sizeof err) != 0) {
		if (d->engine.cf == NULL && err[0])
			psd_log_errx("%s", err);
		return abandon_start(d, cf, 0, NULL);
	}
	/* one date for the clock: -d, [simulate] date or run_year, today in
	 * real time (psensd.c sets clock.epoch0); else the [simulate] date this
	 * year.  date_run moves it past the days the log holds and gives it
	 * to the engine (samples.utc = utc0 + t, and every dated row) */
	if (!isfinite(d->clock.epoch0))
		d->clock.epoch0 = utc_of_day(d->clock.simulated ? cf->date : NULL);
	if (!d->dry && date_run(d, now) != 0)
		return abandon_start(d, cf, 1, "refused start");
	if (d->have_ctl)
		psd_log_info("control socket %s", d->ctl.path);
	return start_fronts(d, cf);
}

/* A step of the wall clock (NTP, settimeofday): logged with its size; a
 * run dated by the wall clock moves its dates with it (the samples' utc and
 * local columns), while periods and timeouts keep to the monotonic clock. */
static void follow_wall(struct psd_daemon *d, double now)
{
	double step = psd_wallstep_check(&d->wall);
	char was[24], is[24], text[160];
	if (step == 0)
		return;
	psd_clock_stamp(d->clock.epoch0, now, was, sizeof was);
	d->clock.epoch0 += step;
	psd_engine_set_epoch(&d->engine, d->clock.epoch0);
	psd_clock_stamp(d->clock.epoch0, now, is, sizeof is);
	snprintf(text, sizeof text, "the wall clock stepped by %+.3f s: %s is now %s local time", step, was, is);
	psd_log_warnx("%s; the log's dates follow it, periods and timeouts run on", text);
	psd_engine_event(&d->engine, now, NULL, "clock_step", text);
}

/* A run on the wall clock: the dated estimate's month and day of the year
 * are the run's local date, which moves on at midnight and with the clock
 * (set once at start, they would stay the start's for a run of months;
 * the day was even the [simulate] date's). */
static void follow_date(struct psd_daemon *d, double now)
{
	time_t t = (time_t)floor(d->clock.epoch0 + now);
	struct tm tm;
	char mmdd[16];
	int month, doy;
	if (d->engine.cf->sim_year || !isfinite(d->clock.epoch0) || !localtime_r(&t, &tm))
		return;   /* a room playing the year's day: the estimate keeps that day's */
	snprintf(mmdd, sizeof mmdd, "%02d-%02d", tm.tm_mon + 1, tm.tm_mday);
	month = psd_dated_month(mmdd);
	doy = psd_dated_day(mmdd);
	if (month == d->engine.month && doy == d->engine.doy)
		return;
	d->engine.month = month;
	d->engine.doy = doy;
	psd_log_info("the dated estimate: %04d-%s, month %d, day %d of the year", tm.tm_year + 1900, mmdd, month, doy);
}

/* A poll timeout shortened to a deadline on the monotonic clock (a
 * driver's wire timing, drivers/driver.h): timeout ms (-1 infinite) or
 * less. */
static int mono_wait_ms(double mono_deadline, int timeout)
{
	double left;
	int w;
	if (mono_deadline == INFINITY)
		return timeout;
	left = mono_deadline - psd_time_mono();
	w = left <= 0 ? 0 : (int)ceil(left * 1000);
	return timeout < 0 || w < timeout ? w : timeout;
}

int psd_loop_run(struct psd_daemon *d)
{
	struct pollfd *fds = d->fds;
	int *fd_dev = d->fd_dev;
	uint64_t wd_usec = 0;
	double wd_next = 0;
	if (sd_watchdog_enabled(0, &wd_usec) > 0)
		d->watchdog_ms = (int)(wd_usec / 2000);
	sd_notifyf(0, "READY=1\nSTATUS=controlling %zu zone(s)\nMAINPID=%d", d->engine.nzone, (int)getpid());
	while (!d->stop) {
		double now = psd_clock_now(&d->clock), deadline, mono_dl;
		int n = 0, nctl, ndev, nfront, timeout;
		if (d->clock.simulated && now >= d->end)
			break;
		if (d->wall_dated) {
			follow_wall(d, now);
			follow_date(d, now);
		}
		psd_engine_step(&d->engine, now);
		psd_points_update(&d->points, &d->engine, now);
		psd_frontend_step(&d->fronts, now);
		deadline = psd_engine_deadline(&d->engine, &mono_dl);
		if (d->clock.simulated && deadline > d->end)
			deadline = d->end;
		fds[n++] = (struct pollfd){ sigfd, POLLIN, 0 };
		nctl = d->have_ctl ? psd_ctlsock_pollfds(&d->ctl, fds + n, PSD_MAX_POLL - n - PSD_MAX_DEVICES) : 0;
		n += nctl;
		ndev = psd_engine_pollfds(&d->engine, fds + n, fd_dev, PSD_MAX_POLL - n - 1);
		timeout = psd_clock_wait_ms(&d->clock, deadline, d->watchdog_ms ? d->watchdog_ms : 60000);
		timeout = mono_wait_ms(mono_dl, timeout);
		nfront = psd_frontend_pollfds(&d->fronts, fds + n + ndev, PSD_MAX_POLL - n - ndev, &timeout);
		if (poll(fds, (nfds_t)(n + ndev + nfront), timeout) < 0 && errno != EINTR) {
			psd_log_err("poll");
			d->fault = "the event loop failed";
			break;
		}
		if (fds[0].revents & POLLIN)
			signals_read(d);
		if (nctl)
			psd_ctlsock_service(&d->ctl, fds + 1, nctl);
		now = psd_clock_now(&d->clock);
		psd_engine_service(&d->engine, now, fds + 1 + nctl, fd_dev, ndev);
		psd_frontend_service(&d->fronts, fds + n + ndev, now);
		if (d->reload) {
			d->reload = 0;
			psd_reload(d);
		}
		if (d->watchdog_ms && psd_time_mono() >= wd_next) {
			sd_notify(0, "WATCHDOG=1");
			wd_next = psd_time_mono() + d->watchdog_ms / 1000.0;
		}
		psd_clock_advance(&d->clock, deadline);
	}
	return 0;
}

int psd_loop_end(struct psd_daemon *d, const char *why, int planned)
{
	double now = psd_clock_now(&d->clock);
	int unsafe = planned ? psd_engine_stop(&d->engine, now, why) : psd_engine_safe(&d->engine, now, why);
	double until = psd_time_mono() + PSD_SETTLE_MS / 1000.0;
	if (d->clock.simulated)
		return unsafe;
	for (;;) {
		double mono_dl, dl = psd_engine_io_deadline(&d->engine, &mono_dl), left = until - psd_time_mono();
		int n, timeout;
		if ((!isfinite(dl) && mono_dl == INFINITY) || left <= 0)
			break;
		n = psd_engine_pollfds(&d->engine, d->fds, d->fd_dev, PSD_MAX_POLL);
		timeout = mono_wait_ms(mono_dl, psd_clock_wait_ms(&d->clock, dl, (int)(left * 1000) + 1));
		if (poll(d->fds, (nfds_t)n, timeout) < 0 && errno != EINTR)
			break;
		psd_engine_service(&d->engine, psd_clock_now(&d->clock), d->fds, d->fd_dev, n);
	}
	return unsafe;
}

void psd_loop_stop(struct psd_daemon *d, const char *why)
{
	sd_notify(0, "STOPPING=1");
	psd_frontend_stop(&d->fronts);   /* while the log is open: MQTT's last acknowledgements */
	if (d->engine.cf) {
		if (why)
			psd_loop_end(d, why, 0);
		{
			struct psd_config *cf = psd_engine_close(&d->engine);
			psd_config_free(cf);
			free(cf);
		}
	}
	if (d->have_ctl)
		psd_ctlsock_close(&d->ctl);
	d->have_ctl = 0;
	if (sigfd >= 0) {
		close(sigfd);
		sigfd = -1;
	}
}
