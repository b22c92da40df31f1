/* SPDX-License-Identifier: ISC */
/* The control commands, one table (daemon/cmdtab.c): each row is a
 * command's word, its typed arguments, its help entry, the front ends that
 * may send it and its handler.  The socket's parser and help, psensctl's
 * check of a command word, the web console's allow-list and MQTT's verbs
 * all read this table; adding a command is adding a row.  The typed
 * entries at the end are what a typed front end (BACnet) calls instead of
 * printing a request line. */
#ifndef PSD_CMDTAB_H
#define PSD_CMDTAB_H

#include <stddef.h>

struct psd_daemon;
struct psd_engine;
struct psd_zone;
struct psd_ctl_reply;
struct psd_ctl_client;

/* The front ends, one bit each: which may send a command. */
enum psd_cmdtab_front {
	PSD_CMDTAB_SOCKET = 1 << 0,         /* the control socket (psensctl) */
	PSD_CMDTAB_CONSOLE = 1 << 1,        /* the web console's pages */
	PSD_CMDTAB_MQTT_OVERRIDE = 1 << 2,  /* MQTT with [mqtt] commands = override (or all) */
	PSD_CMDTAB_MQTT_ALL = 1 << 3,       /* MQTT with [mqtt] commands = all */
	PSD_CMDTAB_BACNET = 1 << 4,         /* a BACnet write (the typed entries below) */
};

/* An argument's type: what the parser checks and converts before the
 * handler runs.  A range (a level's 0 to 1) stays the engine's to judge,
 * so that its message is the same from every front end. */
enum psd_cmdtab_arg {
	PSD_CMDTAB_END = 0,     /* no more arguments */
	PSD_CMDTAB_ZONE,        /* a zone's name, resolved (no zone: refused) */
	PSD_CMDTAB_ZONE_OPT,    /* the same, optional (last) */
	PSD_CMDTAB_LUX,         /* a finite number, lux */
	PSD_CMDTAB_LEVEL,       /* a finite number, a level 0 to 1 */
	PSD_CMDTAB_SECONDS,     /* a finite number, a duration in seconds */
	PSD_CMDTAB_WORDS,       /* any words after, the handler's to judge (last) */
};

enum { PSD_CMDTAB_MAX_ARGS = 3, PSD_CMDTAB_MAX_NUMS = 2 };

/* One request's arguments, typed. */
struct psd_cmdtab_args {
	struct psd_zone *zone;              /* a ZONE argument's zone, NULL none */
	double num[PSD_CMDTAB_MAX_NUMS];    /* the numbers, in order */
	int argc;                           /* the request's words, the command's first */
	char **argv;
};

typedef void (*psd_cmdtab_fn)(struct psd_daemon *d, const struct psd_cmdtab_args *a, struct psd_ctl_reply *reply);

struct psd_cmdtab {
	const char *word;                           /* the request's first word */
	enum psd_cmdtab_arg arg[PSD_CMDTAB_MAX_ARGS]; /* its arguments, PSD_CMDTAB_END after the last */
	const char *help;                           /* its entry in help's list */
	const char *usage;                          /* the error for wrong arguments, NULL: "unknown request" */
	unsigned fronts;                            /* PSD_CMDTAB_* bits: who may send it */
	int changes;                                /* 1: it changes what psensd does */
	const char *const *mqtt_verbs;              /* the set/<verb> topics that reach it, NULL none */
	psd_cmdtab_fn fn;                           /* its handler (ctlcmd.c; help, override, release here) */
};

/* The table's rows, *n of them. */
const struct psd_cmdtab *psd_cmdtab_rows(size_t *n);
/* The row of command word, NULL none. */
const struct psd_cmdtab *psd_cmdtab_find(const char *word);
/* The row of MQTT verb (set/<verb>), NULL none. */
const struct psd_cmdtab *psd_cmdtab_find_verb(const char *verb);
/* The PSD_CMDTAB_* bits of MQTT verb's row, 0 when no row has it: what
 * the MQTT room is handed at open (it calls no core function itself). */
unsigned psd_cmdtab_verb_fronts(const char *verb);
/* 1 when front (one PSD_CMDTAB_* bit) may send command word, else 0. */
int psd_cmdtab_allows(const char *word, unsigned front);
/* A request's words (argv[0] the command of row t) checked against the
 * row's arguments into a: 0, or -1 with the error in err (the row's usage,
 * "no zone", or "unknown request"). */
int psd_cmdtab_parse(const struct psd_cmdtab *t, struct psd_engine *e, int argc, char **argv,
                     struct psd_cmdtab_args *a, char *err, size_t errlen);

/* One request line, judged by the table and answered by its row's handler
 * (a JSON line in reply, grown as it needs up to PSD_CTL_MAX_REPLY; the
 * caller frees it with psd_ctlsock_reply_free): what the socket, the web
 * console and MQTT's set/ topics all call. */
void psd_cmdtab_request(struct psd_daemon *d, char *line, struct psd_ctl_reply *reply);
/* The control socket's handler (ctlsock.h): psd_cmdtab_request. */
void psd_cmdtab_handle(void *daemon, const struct psd_ctl_client *c, char *line, struct psd_ctl_reply *reply);

/* Typed entries, with the socket's very checks and error texts: 0, or -1
 * with the error in err.  now: the daemon's clock. */
int psd_cmdtab_override(struct psd_engine *e, const char *zone, double level, double seconds, double now, char *err,
                        size_t errlen);
int psd_cmdtab_release(struct psd_engine *e, const char *zone, char *err, size_t errlen);

#endif
