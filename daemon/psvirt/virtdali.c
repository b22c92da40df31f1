/* SPDX-License-Identifier: ISC */
/* psvirt's rooms as a DALI bus (virtdali.h). */
#include "virtdali.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "log.h"
#include "replace.h"
#include "time.h"

#define SENSE_EVERY 0.02   /* s: the 304s and 303s follow the rooms this often */

int psd_virtdali_occupancy(struct psd_virtdali *d, const char *spec)
{
	char buf[256], *save = NULL, *tok;
	d->nocc = 0;
	if (strcmp(spec, "never") == 0)
		return 0;
	if (strcmp(spec, "always") == 0) {
		d->occ[0][0] = 0;
		d->occ[0][1] = 86400;
		d->nocc = 1;
		return 0;
	}
	snprintf(buf, sizeof buf, "%s", spec);
	for (tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
		char *dash = strchr(tok, '-');
		if (!dash || d->nocc >= PSD_VIRTDALI_MAX_OCC)
			goto bad;
		*dash = 0;
		if (psd_time_hhmm(tok, &d->occ[d->nocc][0]) != 0 || psd_time_hhmm(dash + 1, &d->occ[d->nocc][1]) != 0 ||
		    d->occ[d->nocc][1] <= d->occ[d->nocc][0])
			goto bad;
		d->nocc++;
	}
	if (d->nocc)
		return 0;
bad:
	psd_log_errx("--dali-occupancy: '%s' is not always, never or up to %d HH:MM-HH:MM spans", spec,
	             PSD_VIRTDALI_MAX_OCC);
	return -1;
}

static int occupied(const struct psd_virtdali *d, double tod)
{
	for (int i = 0; i < d->nocc; i++)
		if (tod >= d->occ[i][0] && tod < d->occ[i][1])
			return 1;
	return 0;
}

/* path into FILE.tmp, then renamed: a reader sees all of it or nothing */
static int write_path(const char *file, const char *path)
{
	char line[4096];
	int len = snprintf(line, sizeof line, "%s\n", path);
	return ps_replace_file(file, 0644, line, (size_t)len < sizeof line ? (size_t)len : sizeof line - 1, NULL);
}

int psd_virtdali_open(struct psd_virtdali *d, const struct psd_virtdali_opts *o, struct psd_virtroom *const *room,
                      int nzone, char *where, size_t wlen)
{
	char err[512], path[256];
	size_t k = strlen(where);
	d->nzone = nzone;
	for (int z = 0; z < nzone; z++) {
		d->room[z] = room[z];
		d->out[z] = 1;   /* the rooms start at full output, as the gear do */
	}
	d->power_on = 1;
	psd_dalibus_init(&d->bus, o->gear * nzone, nzone, !o->unaddressed, (uint32_t)getpid());
	if (!(d->serve = psd_daliserve_new(&d->bus, o->trace))) {
		psd_log_errx("out of memory");
		return -1;
	}
	if (o->tcp) {
		char host[256];
		const char *colon = strrchr(o->tcp, ':');
		int port;
		snprintf(host, sizeof host, "%.*s", colon ? (int)(colon - o->tcp) : 0, o->tcp);
		if (!colon || (port = psd_daliserve_tcp(d->serve, host, colon + 1, err, sizeof err)) < 0) {
			psd_log_errx("--dali-tcp: cannot listen: %s", colon ? err : "not ADDR:PORT");
			return -1;
		}
		printf("psvirt: DALI bus (Foxtron DALInet) on port %d\n", port);
		k += (size_t)snprintf(where + k, wlen - k, "%sdali-tcp %d", k ? "\n" : "", port);
	}
	if (o->pty) {
		const char *proto = o->protocol == PSD_DALISERVE_ATX ? "AtxLED HAT" : "Foxtron DALI232";
		if (psd_daliserve_pty(d->serve, o->protocol, path, sizeof path, err, sizeof err) != 0) {
			psd_log_errx("--dali-pty %s: %s", o->pty, err);
			return -1;
		}
		if (write_path(o->pty, path) != 0) {
			psd_log_err("--dali-pty %s", o->pty);
			return -1;
		}
		printf("psvirt: DALI bus (%s) on %s\n", proto, path);
		k += (size_t)snprintf(where + k, wlen - k, "%sdali-pty %s", k ? "\n" : "", path);
	}
	fflush(stdout);
	return 0;
}

static double room_now(const struct psd_virtdali *d)
{
	return d->start + d->speed * (psd_time_mono() - d->t0);
}

int psd_virtdali_turn(struct psd_virtdali *d, int fault, int target, double max_wait)
{
	double mono = psd_time_mono(), now = room_now(d);
	d->bus.fault = fault >= 0 && fault < PSD_DALIBUS_NFAULT ? fault : PSD_DALIBUS_OK;
	d->bus.target = target;
	if (d->power_on != (d->bus.fault != PSD_DALIBUS_SHORT)) {
		d->power_on = !d->power_on;
		psd_log_info("DALI bus power %s", d->power_on ? "back" : "lost (a short)");
		psd_daliserve_power(d->serve, d->power_on);
		if (!d->power_on)
			psd_dalibus_power_lost(&d->bus, mono);
	}
	if (mono - d->sensed >= SENSE_EVERY) {
		d->sensed = mono;
		for (int z = 0; z < d->nzone; z++) {
			double volts, x;
			int state;
			if (psd_virtroom_sensor(d->room[z], now, &volts, &state) != 0)
				continue;   /* the room dropped or delayed it: the last value stays */
			x = volts / 10 * 1023;
			psd_dalibus_sense(&d->bus, z, x <= 0 ? 0 : x >= 1023 ? 1023 : (unsigned)lround(x),
			                  occupied(d, psd_virtroom_tod(now)));
		}
	}
	if (psd_daliserve_step(d->serve, mono, max_wait) != 0)
		return -1;
	mono = psd_time_mono();
	for (int z = 0; z < d->nzone; z++) {
		double out = psd_dalibus_output(&d->bus, z, mono);
		if (out != d->out[z]) {
			d->out[z] = out;
			psd_virtroom_command(d->room[z], room_now(d), out);
		}
	}
	return 0;
}

void psd_virtdali_free(struct psd_virtdali *d)
{
	psd_daliserve_free(d->serve);
	d->serve = NULL;
}
