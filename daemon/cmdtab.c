/* SPDX-License-Identifier: ISC */
/* The control commands' table, its parser and the typed entries. */
#include "cmdtab.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ctlcmd.h"
#include "ctlsock.h"
#include "engine.h"
#include "errbuf.h"
#include "loop.h"

static void run_help(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);
static void run_override(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);
static void run_release(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);

/* what psensctl and the web console may both send */
#define SOCKET_CONSOLE (PSD_CMDTAB_SOCKET | PSD_CMDTAB_CONSOLE)

static const char *const verbs_status[] = { "status", NULL };
static const char *const verbs_target[] = { "target", NULL };
static const char *const verbs_override[] = { "override", NULL };
static const char *const verbs_release[] = { "release", NULL };
/* MQTT's lux, finish, accept and abort are calibration steps by name */
static const char *const verbs_calibrate[] = { "calibrate", "lux", "finish", "accept", "abort", NULL };

/* In help's order.  An MQTT verb's row needs MQTT_ALL as well as
 * MQTT_OVERRIDE: commands = all allows what override does. */
static const struct psd_cmdtab rows[] = {
	{ .word = "ping", .help = "ping", .fronts = SOCKET_CONSOLE, .fn = psd_ctlcmd_ping },
	{ .word = "status",
	  .arg = { PSD_CMDTAB_ZONE_OPT },
	  .help = "status [ZONE]",
	  .usage = "usage: status [ZONE]",
	  .fronts = SOCKET_CONSOLE | PSD_CMDTAB_MQTT_OVERRIDE | PSD_CMDTAB_MQTT_ALL,
	  .mqtt_verbs = verbs_status,
	  .fn = psd_ctlcmd_status },
	{ .word = "target",
	  .arg = { PSD_CMDTAB_ZONE, PSD_CMDTAB_LUX },
	  .help = "target ZONE LUX",
	  .usage = "usage: target ZONE LUX",
	  .fronts = SOCKET_CONSOLE | PSD_CMDTAB_MQTT_ALL,
	  .changes = 1,
	  .mqtt_verbs = verbs_target,
	  .fn = psd_ctlcmd_target },
	{ .word = "override",
	  .arg = { PSD_CMDTAB_ZONE, PSD_CMDTAB_LEVEL, PSD_CMDTAB_SECONDS },
	  .help = "override ZONE LEVEL SECONDS",
	  .usage = "usage: override ZONE LEVEL SECONDS (level 0 to 1)",
	  .fronts = SOCKET_CONSOLE | PSD_CMDTAB_MQTT_OVERRIDE | PSD_CMDTAB_MQTT_ALL | PSD_CMDTAB_BACNET,
	  .changes = 1,
	  .mqtt_verbs = verbs_override,
	  .fn = run_override },
	{ .word = "off",
	  .arg = { PSD_CMDTAB_ZONE },
	  .help = "off ZONE",
	  .usage = "usage: off ZONE",
	  .fronts = PSD_CMDTAB_SOCKET,
	  .changes = 1,
	  .fn = psd_ctlcmd_off },
	{ .word = "release",
	  .arg = { PSD_CMDTAB_ZONE },
	  .help = "release ZONE",
	  .usage = "usage: release ZONE",
	  .fronts = SOCKET_CONSOLE | PSD_CMDTAB_MQTT_OVERRIDE | PSD_CMDTAB_MQTT_ALL | PSD_CMDTAB_BACNET,
	  .changes = 1,
	  .mqtt_verbs = verbs_release,
	  .fn = run_release },
	{ .word = "ratios",
	  .arg = { PSD_CMDTAB_ZONE_OPT },
	  .help = "ratios [ZONE]",
	  .fronts = SOCKET_CONSOLE,
	  .fn = psd_ctlcmd_ratios },
	{ .word = "log", .help = "log", .fronts = PSD_CMDTAB_SOCKET, .fn = psd_ctlcmd_log },
	{ .word = "reload", .help = "reload", .fronts = PSD_CMDTAB_SOCKET, .changes = 1, .fn = psd_ctlcmd_reload },
	{ .word = "help", .arg = { PSD_CMDTAB_WORDS }, .help = "help", .fronts = SOCKET_CONSOLE, .fn = run_help },
	{ .word = "calibrate",
	  .arg = { PSD_CMDTAB_WORDS },
	  .help = "calibrate ZONE night|day [LEVEL]|lux N|finish|status|accept|abort",
	  .fronts = SOCKET_CONSOLE | PSD_CMDTAB_MQTT_ALL,
	  .changes = 1,
	  .mqtt_verbs = verbs_calibrate,
	  .fn = psd_ctlcmd_calibrate },
	{ .word = "accept-test",
	  .arg = { PSD_CMDTAB_WORDS },
	  .help = "accept-test ZONE [--since YYYY-MM-DD] [--samples N]",
	  .fronts = SOCKET_CONSOLE,
	  .changes = 1,
	  .fn = psd_ctlcmd_accept_test },
	{ .word = "dali",
	  .arg = { PSD_CMDTAB_WORDS },
	  .help = "dali DEVICE scan|address [new|all]|group ADDRESS add|remove GROUP|identify SHORT [SECONDS]|"
	          "verify ZONE|status|abort",
	  .fronts = PSD_CMDTAB_SOCKET,
	  .changes = 1,
	  .fn = psd_ctlcmd_dali },
};

const struct psd_cmdtab *psd_cmdtab_rows(size_t *n)
{
	*n = sizeof rows / sizeof rows[0];
	return rows;
}

const struct psd_cmdtab *psd_cmdtab_find(const char *word)
{
	for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++)
		if (strcmp(word, rows[i].word) == 0)
			return &rows[i];
	return NULL;
}

const struct psd_cmdtab *psd_cmdtab_find_verb(const char *verb)
{
	for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++)
		for (size_t k = 0; rows[i].mqtt_verbs && rows[i].mqtt_verbs[k]; k++)
			if (strcmp(verb, rows[i].mqtt_verbs[k]) == 0)
				return &rows[i];
	return NULL;
}

unsigned psd_cmdtab_verb_fronts(const char *verb)
{
	const struct psd_cmdtab *t = psd_cmdtab_find_verb(verb);
	return t ? t->fronts : 0;
}

int psd_cmdtab_allows(const char *word, unsigned front)
{
	const struct psd_cmdtab *t = psd_cmdtab_find(word);
	return t && (t->fronts & front) ? 1 : 0;
}

/* help's list of the socket's commands, " | " between entries, into out:
 * the length it needs (as snprintf). */
static size_t help_list(char *out, size_t n)
{
	size_t k = 0;
	for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
		int w;
		if (!(rows[i].fronts & PSD_CMDTAB_SOCKET))
			continue;
		w = snprintf(out + (k < n ? k : n), k < n ? n - k : 0, "%s%s", k ? " | " : "", rows[i].help);
		k += w > 0 ? (size_t)w : 0;
	}
	return k;
}

static int number(const char *text, double *out)
{
	char *end;
	errno = 0;
	*out = strtod(text, &end);
	return *text && !*end && errno == 0 && isfinite(*out) ? 0 : -1;
}

/* The words a row's arguments take: *min to *max (-1: any number). */
static void arity(const struct psd_cmdtab *t, int *min, int *max)
{
	*min = *max = 0;
	for (int i = 0; i < PSD_CMDTAB_MAX_ARGS && t->arg[i] != PSD_CMDTAB_END; i++) {
		if (t->arg[i] == PSD_CMDTAB_WORDS) {
			*max = -1;
			return;
		}
		*min += t->arg[i] != PSD_CMDTAB_ZONE_OPT;
		*max += 1;
	}
}

static int wrong_words(const struct psd_cmdtab *t, char *err, size_t errlen)
{
	if (t->usage)
		return psd_errbuf(err, errlen, "%s", t->usage);
	return psd_errbuf(err, errlen, "unknown request '%s' or wrong arguments; try help", t->word);
}

int psd_cmdtab_parse(const struct psd_cmdtab *t, struct psd_engine *e, int argc, char **argv,
                     struct psd_cmdtab_args *a, char *err, size_t errlen)
{
	const char *zone = NULL;
	int min, max, nnum = 0;
	*a = (struct psd_cmdtab_args){ .argc = argc, .argv = argv };
	arity(t, &min, &max);
	if (argc - 1 < min || (max >= 0 && argc - 1 > max))
		return wrong_words(t, err, errlen);
	/* every word's type first, then the zone: a malformed request reads
	 * its usage whether or not its zone exists */
	for (int i = 0; max >= 0 && i + 1 < argc; i++) {
		if (t->arg[i] == PSD_CMDTAB_ZONE || t->arg[i] == PSD_CMDTAB_ZONE_OPT)
			zone = argv[i + 1];
		else if (nnum >= PSD_CMDTAB_MAX_NUMS || number(argv[i + 1], &a->num[nnum++]) != 0)
			return wrong_words(t, err, errlen);
	}
	if (zone && !(a->zone = psd_engine_zone(e, zone)))
		return psd_errbuf(err, errlen, "no zone '%s'", zone);
	return 0;
}

static struct psd_zone *zone_of(struct psd_engine *e, const char *zone, char *err, size_t errlen)
{
	struct psd_zone *z = psd_engine_zone(e, zone);
	if (!z)
		psd_errbuf(err, errlen, "no zone '%s'", zone);
	return z;
}

int psd_cmdtab_override(struct psd_engine *e, const char *zone, double level, double seconds, double now, char *err,
                        size_t errlen)
{
	struct psd_zone *z = zone_of(e, zone, err, errlen);
	if (!z)
		return -1;
	return psd_engine_override(z, level, seconds, now, err, errlen);
}

int psd_cmdtab_release(struct psd_engine *e, const char *zone, char *err, size_t errlen)
{
	struct psd_zone *z = zone_of(e, zone, err, errlen);
	if (!z)
		return -1;
	psd_engine_release(z);
	return 0;
}

/* help, override and release: the table's own rows, the last two the
 * typed entries' socket face */
static void run_help(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply)
{
	char text[1024];
	(void)d;
	(void)a;
	help_list(text, sizeof text);
	psd_ctlcmd_ok(reply, "commands", text);
}

static void run_override(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply)
{
	char err[512];
	if (psd_cmdtab_override(&d->engine, a->argv[1], a->num[0], a->num[1], psd_clock_now(&d->clock), err,
	                        sizeof err) != 0)
		psd_ctlcmd_error(reply, "%s", err);
	else
		psd_ctlcmd_ok(reply, NULL, NULL);
}

static void run_release(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply)
{
	char err[512];
	if (psd_cmdtab_release(&d->engine, a->argv[1], err, sizeof err) != 0)
		psd_ctlcmd_error(reply, "%s", err);
	else
		psd_ctlcmd_ok(reply, NULL, NULL);
}

void psd_cmdtab_handle(void *daemon, const struct psd_ctl_client *c, char *line, struct psd_ctl_reply *reply)
{
	(void)c;
	psd_cmdtab_request(daemon, line, reply);
}

/* One request: its words split, its row found, its arguments judged by
 * the row's types, then the row's handler. */
void psd_cmdtab_request(struct psd_daemon *d, char *line, struct psd_ctl_reply *reply)
{
	const struct psd_cmdtab *t;
	struct psd_cmdtab_args a;
	char *argv[PSD_CTL_MAX_WORDS], err[512];
	int argc = psd_ctlsock_split(line, argv, err, sizeof err);
	if (argc < 0) {
		psd_ctlcmd_error(reply, "%s", err);
		return;
	}
	if (argc == 0) {
		psd_ctlcmd_error(reply, "empty request; try help");
		return;
	}
	if (!(t = psd_cmdtab_find(argv[0])) || !(t->fronts & PSD_CMDTAB_SOCKET)) {
		char shown[64];
		snprintf(shown, sizeof shown, "%s", argv[0]);
		psd_ctlcmd_error(reply, "unknown request '%s' or wrong arguments; try help", shown);
		return;
	}
	if (psd_cmdtab_parse(t, &d->engine, argc, argv, &a, err, sizeof err) != 0) {
		psd_ctlcmd_error(reply, "%s", err);
		return;
	}
	t->fn(d, &a, reply);
}
