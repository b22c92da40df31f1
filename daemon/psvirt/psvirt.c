/* SPDX-License-Identifier: ISC */
/* psvirt: the loopback virtual room served as a Modbus device, so psensd's
 * real Modbus driver runs the whole control loop with no hardware; one room
 * per zone for a whole site.
 *
 * The parts: virtroom.c builds each zone's room as psensd builds it (the
 * only part that knows the room); virtmap.c lays the zones out as an
 * ADAM-6024-style 0-10 V module with a lux meter per zone; mbpdu.c answers
 * the Modbus requests from that map; mbframe.c and mbserve.c frame them on
 * TCP or RTU and serve every client without blocking; dalibus.c (the gear
 * and the DALI-2 multisensors), daliserve.c (a Foxtron or AtxLED interface
 * on TCP or a pty) and virtdali.c (joining them to the rooms) serve the same
 * rooms as a DALI bus, beside Modbus or alone.  This file reads the
 * options and the configuration, and misbehaves on request (late reply,
 * exception, garbage, disconnect: the fault registers 900-903).  psvirt(1)
 * has the register map.  Time: the rooms' clock is --start plus --speed
 * times the real seconds since psvirt started (--speed 0 freezes it).
 *
 * libmodbus opens and configures the serial line (termios, RS-485); its
 * server API (modbus_receive, modbus_reply) is not used: it reads one
 * client at a time with a byte timeout that restarts on every byte, sleeps
 * its response timeout before flushing after an exception reply, cannot
 * answer an unknown function with an exception and does not check the MBAP
 * header, all of which psvirt must do for several clients at once. */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <modbus.h>

#include "cli.h"
#include "clock.h"
#include "config.h"
#include "virtdali.h"
#include "refresh.h"
#include "time.h"
#include "log.h"
#include "mbpdu.h"
#include "mbserve.h"
#include "results.h"
#include "replace.h"
#include "roomsetup.h"
#include "virtmap.h"
#include "virtroom.h"

enum {
	REG_FAULT = PSD_VIRT_FAULT,   /* 0 none, 1 late, 2 exception, 3 garbage, 4 disconnect */
	REG_FAULT_COUNT = 901,        /* requests to affect, 0: until cleared */
	REG_LATE_MS = 902,
	REG_EXCEPTION = 903,
	REG_DALI_FAULT = 904,         /* the DALI bus's fault: 0 none, 1 silent, 2 collision, 3 short */
	REG_DALI_TARGET = 905,        /* its target: gear short address, 100 + device, 255 every */
};
enum { FAULT_NONE, FAULT_LATE, FAULT_EXCEPTION, FAULT_GARBAGE, FAULT_DISCONNECT, FAULT_COUNT };
static const char *const fault_names[] = { "none", "late", "exception", "garbage", "disconnect", NULL };
static const char *const dali_fault_names[] = { "none", "silent", "collision", "short", NULL };
#define DALI_WAIT 0.02     /* s: the DALI bus's wait when it is alone */
#define BOTH_WAIT 0.002    /* s: each server's wait when Modbus and DALI share the loop */

#define MAX_OPTS 64
#define FRAME_TIMEOUT 1.0   /* s, from a frame's first byte (psvirt(1)) */

struct virt {
	struct psd_virtmap map;
	struct psd_mbmap mb;
	struct psd_virtroom *room[PSD_VIRT_MAX_ZONES];
	char zone[PSD_VIRT_MAX_ZONES][48];
	int nzone, rtu;
	unsigned unit;
	double start, speed, t0;
	long requests, faulted;
	struct psd_virtdali dali;   /* the DALI bus (psvirt(1), DALI BUS), dali.serve NULL when off */
	int dali_fault;             /* the fault SIGUSR1 arms */
};

static volatile sig_atomic_t stop, dali_armed = -1;

static void on_signal(int sig)
{
	if (sig == SIGUSR1 || sig == SIGUSR2)
		dali_armed = sig == SIGUSR1;
	else
		stop = 1;
}

static double room_now(const struct virt *v)
{
	return v->start + v->speed * (psd_time_mono() - v->t0);
}

/* Requests that only touch 900-905 always get through (psvirt(1)). */
static int fault_registers_only(const struct psd_mbspan *sp, int nsp)
{
	for (int i = 0; i < nsp; i++)
		if (sp[i].table != PSD_MB_HOLDING || sp[i].addr < REG_FAULT ||
		    (unsigned long)sp[i].addr + sp[i].count > REG_DALI_TARGET + 1)
			return 0;
	return nsp > 0;
}

/* A reply that is not the reply: TCP, one to another transaction; RTU, a
 * frame with a bad CRC. */
static size_t garbage(const struct virt *v, const struct psd_mbadu *req, uint8_t *out)
{
	uint8_t pdu[4] = { req->pdu[0], 2, 0x12, 0x34 };
	struct psd_mbadu other = *req;
	if (v->rtu) {
		size_t n = psd_mbframe_rtu_put(req->unit, pdu, sizeof pdu, out);
		out[n - 2] ^= 0x5a;
		return n;
	}
	other.tid ^= 0x5a;
	return psd_mbframe_tcp_put(&other, pdu, sizeof pdu, out);
}

/* The injected fault of registers 900-903 for one request, counted down;
 * an action of mbserve.h, or -1 for none. */
static int injected(struct virt *v, const struct psd_mbadu *req, uint8_t *out, size_t *n, double *delay)
{
	uint16_t *hr = v->map.hr;
	int fault = hr[REG_FAULT] < FAULT_COUNT ? hr[REG_FAULT] : FAULT_NONE;
	if (fault == FAULT_NONE)
		return -1;
	v->faulted++;
	if (hr[REG_FAULT_COUNT] > 0 && --hr[REG_FAULT_COUNT] == 0)
		hr[REG_FAULT] = FAULT_NONE;
	switch (fault) {
	case FAULT_LATE:
		*delay = hr[REG_LATE_MS] * 1e-3;
		return PSD_MBS_DEFER;
	case FAULT_EXCEPTION:
		*n = psd_mbpdu_exception(req->pdu[0], (uint8_t)hr[REG_EXCEPTION], out);
		return PSD_MBS_REPLY;
	case FAULT_GARBAGE:
		*n = garbage(v, req, out);
		return PSD_MBS_RAW;
	default:   /* disconnect: TCP closes, a serial line goes silent */
		return v->rtu ? PSD_MBS_SILENT : PSD_MBS_CLOSE;
	}
}

/* mbserve's handler: units, the rooms' own faults, the injected faults,
 * then the answer from the register map. */
static int on_request(void *user, const struct psd_mbadu *req, int deferred, uint8_t *out, size_t *n,
                      double *delay)
{
	struct virt *v = user;
	int broadcast = v->rtu && req->unit == 0;
	double now = room_now(v);
	if (!deferred) {
		struct psd_mbspan sp[2];
		int nsp, act;
		if (v->rtu && req->unit != v->unit && !broadcast)
			return PSD_MBS_SILENT;   /* another unit's frame on the bus */
		v->requests++;
		if (!v->rtu && req->unit != v->unit && req->unit != 0 && req->unit != 255) {
			*n = psd_mbpdu_exception(req->pdu[0], PSD_MBX_GATEWAY_TARGET, out);
			return PSD_MBS_REPLY;
		}
		nsp = psd_mbpdu_spans(req->pdu, req->npdu, sp);
		if (!broadcast && !fault_registers_only(sp, nsp)) {
			switch (psd_virtmap_comms(&v->map, psd_virtmap_zones(&v->map, sp, nsp), now)) {
			case PSD_VIRTROOM_DROP:
				return PSD_MBS_SILENT;
			case PSD_VIRTROOM_LATE:
				*delay = v->map.hr[REG_LATE_MS] * 1e-3;
				return PSD_MBS_DEFER;
			}
			if ((act = injected(v, req, out, n, delay)) >= 0)
				return act;
		}
	}
	v->map.now = now;
	*n = psd_mbpdu_reply(&v->mb, req->pdu, req->npdu, out);
	return broadcast ? PSD_MBS_SILENT : PSD_MBS_REPLY;
}

static int write_ready(const char *path, const char *what)
{
	char line[4096];
	int len = snprintf(line, sizeof line, "%s\n", what);
	return ps_replace_file(path, 0644, line, (size_t)len < sizeof line ? (size_t)len : sizeof line - 1, NULL);
}

static void usage(FILE *fp)
{
	fprintf(fp,
	        "usage: psvirt [-f psensd.conf] [--results FILE] [--date MM-DD] [--sunrise HH:MM]\n"
	        "              [--sunset HH:MM] [--start HH:MM] [--speed F] [--zones N]\n"
	        "              [-D [ZONE:]KEY=VALUE]...\n"
	        "              [--tcp ADDR:PORT | --rtu DEVICE [--baud N] [--parity none|even|odd]\n"
	        "              [--stop-bits 1|2]] [--unit N] [--ready-file FILE]\n"
	        "              [--idle-timeout S] [--max-clients N] [-v]\n"
	        "              [--fault late|exception|garbage|disconnect] [--fault-count N] [--late-ms N]\n"
	        "              [--dali-tcp ADDR:PORT] [--dali-pty FILE] [--dali-protocol foxtron|atx]\n"
	        "              [--dali-gear N] [--dali-unaddressed] [--dali-occupancy HH:MM-HH:MM,...]\n"
	        "              [--dali-fault silent|collision|short] [--dali-target N|dN|all]\n"
	        "The virtual room of each zone as one Modbus 0-10 V I/O module with a lux meter\n"
	        "per zone, and/or as a DALI bus (gear and a DALI-2 multisensor per zone) behind\n"
	        "a Foxtron or AtxLED interface; see psvirt(1).\n"
	        "  -D [ZONE:]KEY=VALUE  a room option (-o, its old spelling, goes in the next release)\n"
	        "  -h, --help  this help;  -V, --version  the version\n");
}

struct args {
	const char *conf, *results, *date, *sunrise, *sunset, *start, *tcp, *rtu, *ready, *parity;
	const char *self;         /* argv[0]: psscene is looked for beside it */
	const char *dali_tcp, *dali_pty, *dali_occ;
	double speed, idle_timeout;
	long unit, baud, stop_bits, fault_count, late_ms, zones, max_clients, dali_gear;
	int fault, verbose, dali_protocol, dali_unaddressed, dali_fault, dali_target;
	struct ps_opt opts[MAX_OPTS];   /* -o: key may be ZONE:KEY */
	size_t nopts;
};

/* One option out of range: its name and its range only (-2: no usage after). */
static int bad_range(const char *opt, const char *range)
{
	fprintf(stderr, "psvirt: %s %s\n", opt, range);
	return -2;
}

/* --tcp's port: decimal 0 to 65535 (0 picks a free one); the resolver would
 * otherwise take 99999 modulo 65536. */
static int tcp_port_ok(const char *tcp)
{
	const char *colon = strrchr(tcp, ':');
	char *end;
	long port;
	if (!colon || colon == tcp) {
		fprintf(stderr, "psvirt: --tcp: '%s' is not ADDR:PORT\n", tcp);
		return -1;
	}
	errno = 0;
	port = strtol(colon + 1, &end, 10);
	if (!colon[1] || *end || errno || port < 0 || port > 65535 || colon[1] == '-' || colon[1] == '+') {
		fprintf(stderr, "psvirt: --tcp: port '%s' is not 0 to 65535\n", colon + 1);
		return -1;
	}
	return 0;
}

static int parse_args(struct args *a, int argc, char **argv)
{
	static const struct option lo[] = {
		{ "results", 1, NULL, 'r' }, { "date", 1, NULL, 'Y' }, { "sunrise", 1, NULL, 'R' },
		{ "sunset", 1, NULL, 'S' }, { "start", 1, NULL, 's' }, { "speed", 1, NULL, 'x' },
		{ "tcp", 1, NULL, 't' }, { "rtu", 1, NULL, 'u' }, { "baud", 1, NULL, 'b' },
		{ "parity", 1, NULL, 'p' }, { "stop-bits", 1, NULL, 'B' }, { "unit", 1, NULL, 'U' },
		{ "ready-file", 1, NULL, 'y' }, { "fault", 1, NULL, 'F' }, { "fault-count", 1, NULL, 'C' },
		{ "late-ms", 1, NULL, 'L' }, { "zones", 1, NULL, 'z' }, { "idle-timeout", 1, NULL, 'I' },
		{ "max-clients", 1, NULL, 'M' }, { "dali-tcp", 1, NULL, 1000 }, { "dali-pty", 1, NULL, 1001 },
		{ "dali-protocol", 1, NULL, 1002 }, { "dali-gear", 1, NULL, 1003 },
		{ "dali-unaddressed", 0, NULL, 1004 }, { "dali-occupancy", 1, NULL, 1005 },
		{ "dali-fault", 1, NULL, 1006 }, { "dali-target", 1, NULL, 1007 }, PS_CLI_LONGOPTS,
		{ NULL, 0, NULL, 0 }
	};
	int c;
	memset(a, 0, sizeof *a);
	a->speed = 1;
	a->unit = 1;
	a->baud = 9600;
	a->stop_bits = 1;
	a->late_ms = 500;
	a->parity = "none";
	a->idle_timeout = 300;
	a->max_clients = 32;
	a->dali_gear = 2;
	a->dali_target = PSD_DALIBUS_EVERY;
	a->dali_occ = "08:00-12:00,13:00-18:00";
	while ((c = getopt_long(argc, argv, "f:D:o:hVv", lo, NULL)) != -1) {
		char *end = NULL;
		switch (c) {
		case 'f': a->conf = optarg; break;
		case 'r': a->results = optarg; break;
		case 'Y': a->date = optarg; break;
		case 'R': a->sunrise = optarg; break;
		case 'S': a->sunset = optarg; break;
		case 's': a->start = optarg; break;
		case 'x': a->speed = strtod(optarg, &end); break;
		case 't': a->tcp = optarg; break;
		case 'u': a->rtu = optarg; break;
		case 'b': a->baud = strtol(optarg, &end, 10); break;
		case 'p': a->parity = optarg; break;
		case 'B': a->stop_bits = strtol(optarg, &end, 10); break;
		case 'U': a->unit = strtol(optarg, &end, 10); break;
		case 'y': a->ready = optarg; break;
		case 'C': a->fault_count = strtol(optarg, &end, 10); break;
		case 'L': a->late_ms = strtol(optarg, &end, 10); break;
		case 'z': a->zones = strtol(optarg, &end, 10); break;
		case 'I': a->idle_timeout = strtod(optarg, &end); break;
		case 'M': a->max_clients = strtol(optarg, &end, 10); break;
		case 'v': a->verbose = 1; break;
		case 1000: a->dali_tcp = optarg; break;
		case 1001: a->dali_pty = optarg; break;
		case 1002:
			if (strcmp(optarg, "foxtron") && strcmp(optarg, "atx")) {
				fprintf(stderr, "psvirt: --dali-protocol: '%s' is not foxtron or atx\n", optarg);
				return -1;
			}
			a->dali_protocol = strcmp(optarg, "atx") == 0 ? PSD_DALISERVE_ATX : PSD_DALISERVE_FOXTRON;
			break;
		case 1003: a->dali_gear = strtol(optarg, &end, 10); break;
		case 1004: a->dali_unaddressed = 1; break;
		case 1005: a->dali_occ = optarg; break;
		case 1006:
			for (a->dali_fault = 1; dali_fault_names[a->dali_fault] && strcmp(dali_fault_names[a->dali_fault], optarg);
			     a->dali_fault++)
				;
			if (!dali_fault_names[a->dali_fault]) {
				fprintf(stderr, "psvirt: --dali-fault: '%s' is not silent, collision or short\n", optarg);
				return -1;
			}
			break;
		case 1007:
			if (strcmp(optarg, "all") == 0) {
				a->dali_target = PSD_DALIBUS_EVERY;
				break;
			}
			a->dali_target = (int)strtol(optarg + (optarg[0] == 'd'), &end, 10);
			if (*end || end == optarg + (optarg[0] == 'd') || a->dali_target < 0 || a->dali_target > 63) {
				fprintf(stderr, "psvirt: --dali-target: '%s' is not a gear 0-63, a device d0-d63 or all\n", optarg);
				return -2;
			}
			a->dali_target += optarg[0] == 'd' ? PSD_DALIBUS_DEVICE : 0;
			end = NULL;
			break;
		case 'F':
			for (a->fault = 1; fault_names[a->fault] && strcmp(fault_names[a->fault], optarg); a->fault++)
				;
			if (!fault_names[a->fault]) {
				fprintf(stderr, "psvirt: --fault: '%s' is not late, exception, garbage or disconnect\n", optarg);
				return -1;
			}
			break;
		case 'o':   /* the old spelling of -D */
			ps_cli_deprecated("psvirt", "-o KEY=VALUE", "-D KEY=VALUE (-o is an output file elsewhere)");
			/* fall through */
		case 'D': {
			char *eq = strchr(optarg, '=');
			if (!eq || eq == optarg || a->nopts >= MAX_OPTS) {
				fprintf(stderr, "psvirt: -D: '%s' is not [ZONE:]KEY=VALUE\n", optarg);
				return -1;
			}
			*eq = 0;
			a->opts[a->nopts++] = (struct ps_opt){ optarg, eq + 1, (int)a->nopts + 1, 0 };
			break;
		}
		case 'h': usage(stdout); exit(0);
		case 'V': exit(ps_cli_version("psvirt"));
		default: return -1;
		}
		if (end && *end) {
			fprintf(stderr, "psvirt: '%s' is not a number\n", optarg);
			return -1;
		}
	}
	if (optind != argc || (a->tcp && a->rtu) || (!a->tcp && !a->rtu && !a->dali_tcp && !a->dali_pty)) {
		fprintf(stderr, "psvirt: give one of --tcp ADDR:PORT or --rtu DEVICE, and/or --dali-tcp or --dali-pty\n");
		return -1;
	}
	if (a->dali_gear < 1 || a->dali_gear > 6)
		return bad_range("--dali-gear", "must be 1 to 6 (gear per zone)");
	if (a->dali_tcp && tcp_port_ok(a->dali_tcp) != 0)
		return -2;
	if (!(a->speed >= 0))
		return bad_range("--speed", "must be >= 0 (0 freezes the clock)");
	if (a->unit < 1 || a->unit > 247)
		return bad_range("--unit", "must be 1 to 247");
	if (a->late_ms < 0 || a->late_ms > 60000)
		return bad_range("--late-ms", "must be 0 to 60000");
	if (a->fault_count < 0 || a->fault_count > 65535)
		return bad_range("--fault-count", "must be 0 to 65535");
	if (a->zones < 0 || a->zones > PSD_VIRT_MAX_ZONES) {
		fprintf(stderr, "psvirt: --zones must be 1 to %d\n", PSD_VIRT_MAX_ZONES);
		return -2;
	}
	if (!(a->idle_timeout > 0))
		return bad_range("--idle-timeout", "must be > 0 seconds");
	if (a->max_clients < 1 || a->max_clients > 4096)
		return bad_range("--max-clients", "must be 1 to 4096");
	if (a->tcp && tcp_port_ok(a->tcp) != 0)
		return -2;
	return 0;
}

/* The zone an -o key names before its colon (a channel number or a zone's
 * name), or -1 for every zone; -2 (with a message) for no such zone.
 * *key is set past the colon. */
static int opt_zone(const struct virt *v, const char *raw, const char **key)
{
	const char *colon = strchr(raw, ':');
	char *end;
	long k;
	*key = raw;
	if (!colon)
		return -1;
	*key = colon + 1;
	k = strtol(raw, &end, 10);
	if (end == colon && end != raw && k >= 0 && k < v->nzone)
		return (int)k;
	for (int z = 0; z < v->nzone; z++)
		if ((size_t)(colon - raw) == strlen(v->zone[z]) && strncmp(raw, v->zone[z], (size_t)(colon - raw)) == 0)
			return z;
	psd_log_errx("-D %s: no zone '%.*s' (%d zone(s): 0 to %d or their names)", raw,
	        (int)(colon - raw), raw, v->nzone, v->nzone - 1);
	return -2;
}

/* Zone z's options from the command line: its own (ZONE:KEY) before every
 * zone's, so the first match wins; the source -o entries' used flags are
 * set for the keys the room knows. */
static int zone_cmdline_opts(const struct virt *v, struct args *a, int z, struct ps_opt *out, size_t *n,
                             int *src)
{
	*n = 0;
	for (int pass = 0; pass < 2; pass++)
		for (size_t i = 0; i < a->nopts; i++) {
			const char *key;
			int oz = opt_zone(v, a->opts[i].key, &key);
			if (oz == -2)
				return -1;
			if ((pass == 0 && oz == z) || (pass == 1 && oz == -1)) {
				src[*n] = (int)i;
				out[(*n)++] = (struct ps_opt){ key, a->opts[i].value, a->opts[i].line, 0 };
			}
		}
	return 0;
}

/* What the rooms are built from: the configuration (-f) and the command
 * line. */
struct plan {
	struct psd_config *cf;    /* -f, or NULL */
	const char *results, *conf_path;
	char date[16];
	double rise, set;
	int year;                 /* [simulate] year = yes: the room plays the date of the results' year */
	const struct ps_opts *zone_conf[PSD_VIRT_MAX_ZONES];   /* a loopback zone's [device] keys */
};

/* -f: the zones, their names and loopback options, the results, the date
 * and the start from the configuration.  -1 after saying why. */
static int plan_from_config(struct virt *v, const struct args *a, struct plan *p)
{
	struct psd_config *cf;
	if (!(cf = p->cf = calloc(1, sizeof *cf))) {
		psd_log_errx("out of memory");
		return -1;
	}
	if (psd_config_load(cf, a->conf) != 0) {
		for (size_t i = 0; i < cf->conf.nerrors; i++)
			psd_log_errx("%s", cf->conf.errors[i]);
		return -1;
	}
	if (cf->nzone > PSD_VIRT_MAX_ZONES || (a->zones && (size_t)a->zones != cf->nzone)) {
		psd_log_errx("%s has %zu zones: psvirt serves %s", a->conf, cf->nzone,
		        a->zones ? "as many (drop --zones)" : "at most 10");
		return -1;
	}
	v->nzone = (int)cf->nzone;
	for (int z = 0; z < v->nzone; z++) {
		const struct psd_zone_conf *zc = &cf->zone[z];
		const struct psd_device_conf *dc = &cf->dev[cf->pt[zc->sensor].device];
		snprintf(v->zone[z], sizeof v->zone[z], "%s", zc->name);
		if (strcmp(dc->drv->name, "loopback") == 0)
			p->zone_conf[z] = &dc->opts;
	}
	if (!p->results)
		p->results = cf->results;
	/* zones with their own scene: their results made as psensd makes them */
	if (!a->results && psd_refresh_results(cf, a->self ? a->self : "psvirt") != 0)
		return -1;
	snprintf(p->date, sizeof p->date, "%s", cf->date);
	p->rise = cf->sunrise;
	p->set = cf->sunset;
	p->year = cf->sim_year;
	v->start = cf->start;
	return 0;
}

/* The command line over the configuration: the date, sunrise, sunset and
 * start.  -1 after saying why. */
static int plan_from_args(struct virt *v, const struct args *a, struct plan *p)
{
	if (a->date)
		snprintf(p->date, sizeof p->date, "%s", a->date);
	if (!p->results) {
		psd_log_errx("no results (--results FILE, or -f with [psensd] results)");
		return -1;
	}
	if (psd_roomsetup_day_of_year(p->date) < 0 || (a->sunrise && psd_time_hhmm(a->sunrise, &p->rise)) ||
	    (a->sunset && psd_time_hhmm(a->sunset, &p->set)) || (a->start && psd_time_hhmm(a->start, &v->start))) {
		psd_log_errx("date must be MM-DD and sunrise, sunset, start HH:MM");
		return -1;
	}
	return 0;
}

/* Zone z's room options in merged[1..]: its command line options (cmd,
 * judged alone first, so that their messages name it), then its
 * configuration's keys (all: both, with a seed in merged[0] when z's must
 * differ from the others').  -1 after saying why. */
static int zone_options(struct virt *v, struct args *a, const struct plan *p, int z, struct ps_opt *merged,
                        char *seed, size_t seedlen, struct ps_opts *cmd, struct ps_opts *all)
{
	int src[MAX_OPTS];
	size_t n, nconf = p->zone_conf[z] ? p->zone_conf[z]->n : 0;
	char err[512], *end = NULL;
	const char *s;
	*cmd = (struct ps_opts){ merged, 0, "psvirt -D" };
	*all = (struct ps_opts){ merged, 0, "psvirt -D" };
	if (zone_cmdline_opts(v, a, z, merged + 1, &n, src) != 0)
		return -1;
	if (n + nconf > 2 * MAX_OPTS) {
		psd_log_errx("zone %s: more than %d room options", v->zone[z], 2 * MAX_OPTS);
		return -1;
	}
	/* the command line alone first, so its messages name it */
	cmd->v = merged + 1;
	cmd->n = n;
	if (psd_virtroom_check(cmd, err, sizeof err) != 0) {
		psd_log_errx("zone %s: %s", v->zone[z], err);
		return -1;
	}
	for (size_t i = 0; i < n; i++)
		a->opts[src[i]].used |= merged[1 + i].used;
	for (size_t i = 0; i < nconf; i++)
		merged[1 + n + i] = p->zone_conf[z]->v[i];
	if (nconf)
		all->file = p->conf_path;
	/* zones sharing their options must not share their noise: zone
	 * k's seed is its seed option (1) plus k */
	all->v = merged + 1;
	all->n = n + nconf;
	s = ps_opts_get(all, "seed");
	if (z > 0 && (!s || (strtol(s, &end, 10) >= 0 && !*end && *s))) {
		snprintf(seed, seedlen, "%ld", (s ? strtol(s, NULL, 10) : 1) + z);
		merged[0] = (struct ps_opt){ "seed", seed, 0, 0 };
		all->v = merged;
		all->n++;
	}
	return 0;
}

/* Zone z's room from its options: a zone with its own simulation (scene =
 * or results = in its [zone]) plays its own room.  NULL after saying why. */
static struct psd_virtroom *zone_room(const struct virt *v, const struct args *a, const struct plan *p,
                                      const struct psd_virtday *day, int z, const struct ps_opts *all)
{
	struct ps_results zr;
	struct psd_virtday zday = *day;
	struct psd_virtroom *room;
	struct ps_err e;
	char err[512];
	const char *zp = p->cf && !a->results ? psd_config_zone_results(p->cf, &p->cf->zone[z]) : NULL;
	int own = zp && strcmp(zp, p->results) != 0;
	if (own) {
		if (ps_results_read(&zr, zp, &e) != 0) {
			psd_log_errx("zone %s: %s", v->zone[z], e.msg);
			return NULL;
		}
		zday.res = &zr;
	}
	room = psd_virtroom_new(&zday, all, v->start, err, sizeof err);
	if (own)
		ps_results_free(&zr);
	if (!room)
		psd_log_errx("zone %s: %s", v->zone[z], err);
	return room;
}

/* Zone z's room, every key of its configuration taken.  -1 after saying
 * why. */
static int build_zone(struct virt *v, struct args *a, const struct plan *p, const struct psd_virtday *day, int z)
{
	struct ps_opt merged[2 * MAX_OPTS + 1];
	struct ps_opts cmd, all;
	size_t nconf = p->zone_conf[z] ? p->zone_conf[z]->n : 0;
	char seed[32];
	if (zone_options(v, a, p, z, merged, seed, sizeof seed, &cmd, &all) != 0)
		return -1;
	if (!(v->room[z] = zone_room(v, a, p, day, z, &all)))
		return -1;
	for (size_t i = all.n - nconf; i < all.n; i++)
		if (!all.v[i].used && !ps_opts_get(&cmd, all.v[i].key)) {
			psd_log_errx("%s:%d: unknown key '%s' for driver loopback", p->conf_path,
			        all.v[i].line, all.v[i].key);
			return -1;
		}
	return 0;
}

/* A key no zone took is not a room option (one every zone overrides with
 * its own is).  -1 after saying which. */
static int every_option_taken(const struct virt *v, const struct args *a)
{
	for (size_t i = 0; i < a->nopts; i++) {
		const char *key, *other;
		int known = 0;
		opt_zone(v, a->opts[i].key, &key);
		for (size_t j = 0; j < a->nopts && !known; j++)
			known = a->opts[j].used && (opt_zone(v, a->opts[j].key, &other), strcmp(key, other) == 0);
		if (!known) {
			psd_log_errx("-D %s: not a loopback room option (see psensd.conf(5))", key);
			return -1;
		}
	}
	return 0;
}

/* The day, the zones and their options: from -f (psensd.conf: [psensd]
 * results, [simulate], the [zone] sections in order, each with its sensor's
 * loopback device's options) and the command line, which wins. */
static int build_rooms(struct virt *v, struct args *a)
{
	struct plan p = { .results = a->results, .conf_path = a->conf ? a->conf : "", .date = "03-18",
	                  .rise = 6 * 3600.0, .set = 18 * 3600.0 };
	struct ps_results res;
	struct ps_err e;
	struct psd_virtday day;
	int rc = -1, have_res = 0;
	v->start = 6 * 3600.0;
	v->nzone = a->zones ? (int)a->zones : 1;
	for (int z = 0; z < PSD_VIRT_MAX_ZONES; z++)
		snprintf(v->zone[z], sizeof v->zone[z], "zone%d", z);
	if (a->conf && plan_from_config(v, a, &p) != 0)
		goto out;
	if (plan_from_args(v, a, &p) != 0)
		goto out;
	if (ps_results_read(&res, p.results, &e) != 0) {
		psd_log_errx("%s", e.msg);
		goto out;
	}
	have_res = 1;
	day = (struct psd_virtday){ &res, p.date, p.rise, p.set, p.year };
	for (int z = 0; z < v->nzone; z++)
		if (build_zone(v, a, &p, &day, z) != 0)
			goto out;
	rc = every_option_taken(v, a);
out:
	if (have_res)
		ps_results_free(&res);
	if (p.cf) {
		psd_config_free(p.cf);
		free(p.cf);
	}
	return rc;
}

static void summary(struct virt *v)
{
	double end = room_now(v), sum = 0;
	char from[8], to[8];
	psd_clock_hhmm(v->start, from);
	psd_clock_hhmm(end, to);
	for (int z = 0; z < v->nzone; z++)
		sum += end > v->start ? 100 * psd_virtroom_energy(v->room[z], end) / (end - v->start) : 100.0;
	printf("psvirt: %ld requests (%ld faulted); room time %s to %s; light output %.1f %% of full on average\n",
	       v->requests, v->faulted, from, to, sum / v->nzone);
	if (v->dali.serve)
		printf("psvirt: %ld DALI frames\n", v->dali.bus.frames);
	for (int z = 0; v->nzone > 1 && z < v->nzone; z++)
		printf("psvirt: zone %d %s: light output %.1f %% of full on average\n", z, v->zone[z],
		       end > v->start ? 100 * psd_virtroom_energy(v->room[z], end) / (end - v->start) : 100.0);
}

/* One turn of the DALI bus with the fault of the signals (SIGUSR1 arms
 * --dali-fault, SIGUSR2 clears it) and registers 904 and 905. */
static int dali_turn(struct virt *v, double max_wait)
{
	if (dali_armed >= 0) {
		v->map.hr[REG_DALI_FAULT] =
		        (uint16_t)(dali_armed ? (v->dali_fault ? v->dali_fault : PSD_DALIBUS_SILENT) : PSD_DALIBUS_OK);
		dali_armed = -1;
	}
	return psd_virtdali_turn(&v->dali, v->map.hr[REG_DALI_FAULT], v->map.hr[REG_DALI_TARGET], max_wait);
}

/* The serial line, opened and configured by libmodbus; NULL on failure. */
static modbus_t *open_line(const struct args *a, int *fd)
{
	char par = !strcmp(a->parity, "even") ? 'E' : !strcmp(a->parity, "odd") ? 'O' : 'N';
	modbus_t *ctx = modbus_new_rtu(a->rtu, (int)a->baud, par, 8, (int)a->stop_bits);
	if (!ctx || modbus_connect(ctx) != 0) {
		psd_log_errx("%s: %s", a->rtu, modbus_strerror(errno));
		if (ctx)
			modbus_free(ctx);
		return NULL;
	}
	*fd = modbus_get_socket(ctx);
	return ctx;
}

static void free_rooms(struct virt *v)
{
	for (int z = 0; z < PSD_VIRT_MAX_ZONES; z++)
		psd_virtroom_free(v->room[z]);
}

int main(int argc, char **argv)
{
	static struct virt v;
	struct args a;
	struct sigaction sa;
	struct psd_mbserve *srv = NULL;
	struct psd_mbserve_opts so;
	modbus_t *line = NULL;
	char err[512], where[600] = "", mbwhere[300];
	int rc;
	if ((rc = parse_args(&a, argc, argv)) != 0) {
		if (rc == -1)
			usage(stderr);
		return 2;
	}
	psd_log_init(1, a.verbose || getenv("PSVIRT_DEBUG") ? PSD_LOG_DEBUG : PSD_LOG_WARN, "psvirt");
	if (a.ready)   /* a ready file left by an earlier run must not say ready now */
		unlink(a.ready);
	a.self = argv[0];
	if (build_rooms(&v, &a) != 0) {
		free_rooms(&v);
		return 1;
	}
	v.speed = a.speed;
	v.unit = (unsigned)a.unit;
	so = (struct psd_mbserve_opts){ a.idle_timeout, FRAME_TIMEOUT, (int)a.max_clients, a.baud,
	                                getenv("PSVIRT_DEBUG") != NULL };
	if (psd_virtdali_occupancy(&v.dali, a.dali_occ) != 0) {
		free_rooms(&v);
		return 2;
	}
	if (a.tcp) {
		char host[256];
		const char *colon = strrchr(a.tcp, ':');
		if (!colon || colon == a.tcp || (size_t)(colon - a.tcp) >= sizeof host) {
			psd_log_errx("--tcp: '%s' is not ADDR:PORT", a.tcp);
			free_rooms(&v);
			return 2;
		}
		snprintf(host, sizeof host, "%.*s", (int)(colon - a.tcp), a.tcp);
		srv = psd_mbserve_tcp(host, colon + 1, &so, on_request, &v, err, sizeof err);
		snprintf(where, sizeof where, "%d", srv ? psd_mbserve_port(srv) : 0);
	} else if (a.rtu) {
		int fd = -1;
		v.rtu = 1;
		srv = (line = open_line(&a, &fd)) ? psd_mbserve_rtu(fd, &so, on_request, &v, err, sizeof err) : NULL;
		snprintf(where, sizeof where, "%s", a.rtu);
	}
	if (!srv && (a.tcp || a.rtu)) {
		if (a.tcp || line)
			psd_log_errx("cannot %s: %s", a.tcp ? "listen" : "serve the line", err);
		if (line) {
			modbus_close(line);
			modbus_free(line);
		}
		free_rooms(&v);
		return 1;
	}
	psd_virtmap_init(&v.map, v.room, v.nzone, &v.mb);
	v.map.hr[REG_FAULT] = (uint16_t)a.fault;
	v.map.hr[REG_FAULT_COUNT] = (uint16_t)a.fault_count;
	v.map.hr[REG_LATE_MS] = (uint16_t)a.late_ms;
	v.map.hr[REG_EXCEPTION] = PSD_MBX_DEVICE_FAILURE;
	v.map.hr[REG_DALI_TARGET] = (uint16_t)a.dali_target;
	v.dali_fault = a.dali_fault;
	snprintf(mbwhere, sizeof mbwhere, "%s", where);
	if ((a.dali_tcp || a.dali_pty) &&
	    psd_virtdali_open(&v.dali,
	                      &(struct psd_virtdali_opts){ a.dali_tcp, a.dali_pty, a.dali_protocol, (int)a.dali_gear,
	                                                   a.dali_unaddressed, a.dali_occ, getenv("PSVIRT_DEBUG") != NULL },
	                      v.room, v.nzone, where, sizeof where) != 0) {
		psd_virtdali_free(&v.dali);
		psd_mbserve_free(srv);
		free_rooms(&v);
		return 1;
	}
	memset(&sa, 0, sizeof sa);
	sa.sa_handler = on_signal;
	sigaction(SIGTERM, &sa, NULL);
	sigaction(SIGINT, &sa, NULL);
	sigaction(SIGUSR1, &sa, NULL);
	sigaction(SIGUSR2, &sa, NULL);
	signal(SIGPIPE, SIG_IGN);
	v.t0 = psd_time_mono();
	v.dali.start = v.start;   /* the DALI bus's rooms keep the same clock */
	v.dali.speed = v.speed;
	v.dali.t0 = v.t0;
	psd_virtmap_refresh(&v.map, v.start);
	if (v.nzone > 1 && srv) {
		printf("psvirt: %d zones on %s%s, unit %u:", v.nzone, a.tcp ? "port " : "", mbwhere, v.unit);
		for (int z = 0; z < v.nzone; z++)
			printf("%s %d %s (AI%d, AO%d at %d, lux at %d)", z ? "," : "", z, v.zone[z], z, z,
			       PSD_VIRT_AO + z, PSD_VIRT_METER + 10 * z);
		printf("\n");
		fflush(stdout);
	}
	if (a.ready && write_ready(a.ready, where) != 0) {
		psd_log_err("%s", a.ready);
		psd_virtdali_free(&v.dali);
		psd_mbserve_free(srv);
		free_rooms(&v);
		return 1;
	}
	while (!stop)
		if ((srv && psd_mbserve_step(srv, v.dali.serve ? BOTH_WAIT : 1.0) != 0) ||
		    (v.dali.serve && dali_turn(&v, srv ? BOTH_WAIT : DALI_WAIT) != 0)) {
			psd_log_err("poll");
			break;
		}
	summary(&v);
	psd_virtdali_free(&v.dali);
	psd_mbserve_free(srv);
	if (line) {
		modbus_close(line);
		modbus_free(line);
	}
	free_rooms(&v);
	return stop ? 0 : 1;
}
