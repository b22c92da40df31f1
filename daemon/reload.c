/* SPDX-License-Identifier: ISC */
/* A reload (SIGHUP, psensctl reload): the new configuration replaces the
 * running one only when it loads and its devices open; otherwise the
 * running one stays and the reasons are logged and, for the control
 * socket, returned (each file:line when the configuration names one). */
#include <errno.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <systemd/sd-daemon.h>

#include "loop.h"
#include "refresh.h"
#include "reload.h"
#include "log.h"

/* A reason a reload was refused: logged at LOG_ERR and, when the caller
 * asked (psensctl reload), added to its list. */
static void refuse(struct psd_reload_why *w, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void refuse(struct psd_reload_why *w, const char *fmt, ...)
{
	char line[PSD_RELOAD_WHY_LEN];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(line, sizeof line, fmt, ap);
	va_end(ap);
	psd_log_errx("%s", line);
	if (w && w->n < PSD_RELOAD_WHY_MAX)
		snprintf(w->line[w->n++], sizeof w->line[0], "%s", line);
}

/* "device NAME: why" from the engine, with the section's file:line in
 * front when why does not carry one already (a driver's EINVAL does). */
static void locate(const struct psd_config *cf, const char *err, char *out, size_t n)
{
	static const char *const kinds[] = { "device ", "point ", "zone " };
	const char *path = cf->conf.path ? cf->conf.path : "?";
	size_t plen = strlen(path);
	int line = 0;
	for (int k = 0; k < 3 && !line; k++) {
		size_t kl = strlen(kinds[k]);
		const char *name = err + kl, *colon;
		if (strncmp(err, kinds[k], kl) != 0 || !(colon = strchr(name, ':')))
			continue;
		for (size_t i = 0; k == 0 && i < cf->ndev; i++)
			if (strlen(cf->dev[i].name) == (size_t)(colon - name) && !strncmp(cf->dev[i].name, name, (size_t)(colon - name)))
				line = cf->dev[i].line;
		for (size_t i = 0; k == 1 && i < cf->npt; i++)
			if (strlen(cf->pt[i].name) == (size_t)(colon - name) && !strncmp(cf->pt[i].name, name, (size_t)(colon - name)))
				line = cf->pt[i].line;
		for (size_t i = 0; k == 2 && i < cf->nzone; i++)
			if (strlen(cf->zone[i].name) == (size_t)(colon - name) && !strncmp(cf->zone[i].name, name, (size_t)(colon - name)))
				line = cf->zone[i].line;
	}
	if (strstr(err, path) && strstr(err, path)[plen] == ':')
		snprintf(out, n, "%s", err);   /* it names the file already */
	else if (line > 0)
		snprintf(out, n, "%s:%d: %s", path, line, err);
	else
		snprintf(out, n, "%s: %s", path, err);
}

/* Neither configuration opens: the running one's devices once more
 * without its database (what failed may be the database alone), only so
 * that the fault that ends the run can drive the lights to the safe
 * level.  -1 when even that fails (the outputs are then left as they are,
 * said at LOG_ERR); old is then still the caller's. */
static int reopen_outputs(struct psd_daemon *d, struct psd_config *old, double now, int batch,
                          const struct psd_engine *snap)
{
	char err[1024];
	free(old->database);    /* its own copy (config.c): the engine opens no log without it */
	old->database = NULL;
	if (psd_engine_open_io(&d->engine, old, now, batch, snap, &d->clock, err, sizeof err) == 0)
		return 0;
	psd_log_errx("reload: no output can be commanded: the lights are left as they are: %s", err);
	return -1;
}

int psd_reload(struct psd_daemon *d)
{
	return psd_reload_explain(d, NULL);
}

int psd_reload_explain(struct psd_daemon *d, struct psd_reload_why *w)
{
	struct psd_config *cf = calloc(1, sizeof *cf), *old;
	struct psd_engine *snap = malloc(sizeof *snap);
	char err[1024], where[1200];
	double now = psd_clock_now(&d->clock);
	int batch = d->engine.db_batch;
	if (w)
		w->n = 0;
	sd_notify(0, "RELOADING=1");
	if (!cf || !snap) {
		refuse(w, "reload: %s", strerror(errno));
		goto keep;
	}
	if (psd_config_load_judged(cf, d->config_path) != 0) {
		for (size_t i = 0; i < cf->conf.nerrors; i++)
			refuse(w, "%s", cf->conf.errors[i]);
		psd_log_errx("reload: %s has errors: the running configuration stays", d->config_path);
		goto keep;
	}
	if (psd_refresh_results(cf, d->self) != 0) {
		refuse(w, "%s: results %s: none for the new configuration (psscene failed: see the daemon's log)",
		       d->config_path, cf->results ? cf->results : "-");
		psd_log_errx("reload: no results for the new configuration: the running configuration stays");
		goto keep;
	}
	/* devices can be opened once (a claimed USB interface, a GPIO line):
	 * close the running ones, try the new, and reopen the old on failure */
	*snap = d->engine;
	d->engine.log = NULL;   /* the log's writer goes on: the new engine takes it (snap has it) */
	old = psd_engine_close(&d->engine);
	if (psd_engine_open_io(&d->engine, cf, now, batch, snap, &d->clock, err, sizeof err) != 0) {
		locate(cf, err, where, sizeof where);
		refuse(w, "%s", where);
		psd_log_errx("reload: the running configuration stays");
		if (psd_engine_open_io(&d->engine, old, now, batch, snap, &d->clock, err, sizeof err) != 0) {
			refuse(w, "reload: cannot reopen the running configuration either: %s", err);
			d->fault = "a reload could not reopen the running configuration";
			d->stop = SIGTERM;   /* the loop ends; d->fault says it is no planned stop */
			if (reopen_outputs(d, old, now, batch, snap) != 0) {
				psd_config_free(old);
				free(old);
			}
			psd_dbwriter_close(snap->log, 2.0);
		}
		psd_config_free(cf);
		free(cf);
		free(snap);
		d->reload_failures++;
		sd_notify(0, "READY=1");
		return -1;
	}
	if (snap->log && snap->log != d->engine.log)   /* another database: the old log's writer ends */
		psd_dbwriter_close(snap->log, 2.0);
	psd_config_free(old);
	free(old);
	free(snap);
	d->reloads++;
	psd_frontend_reload(&d->fronts, cf);
	psd_log_info("reloaded %s", d->config_path);
	psd_engine_event(&d->engine, now, NULL, "reload", d->config_path);   /* dated: the engine kept utc0 */
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
