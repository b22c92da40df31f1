/* SPDX-License-Identifier: ISC */
/* psensctl: talk to psensd over its control socket, and export its log.
 *
 *   psensctl [-s socket] [-j] status [ZONE] | target ZONE LUX |
 *            override ZONE LEVEL SECONDS | off ZONE | release ZONE | ratios | log |
 *            reload | ping | help |
 *            calibrate ZONE night|day [LEVEL]|lux N|finish|status|accept|abort |
 *            dali DEVICE scan|address [new|all]|group ADDRESS add|remove GROUP|
 *                 identify SHORT [SECONDS]|verify ZONE|status|abort
 *   psensctl [-s socket | -d database] export --csv
 *   psensctl [-s socket | -d database] report [ZONE] [-o file.pdf|.png|.svg]
 *            [--format pdf|png|svg] [-t percent] [-c config] [--site TEXT] [--page N]
 *   psensctl [-s socket | -d database] accept-test ZONE [--since YYYY-MM-DD] [--samples N]
 *
 * Replies are JSON lines; -j prints them as they come, otherwise they are
 * shown for a person.  See psensctl(1). */
#include <errno.h>
#include <getopt.h>
#include <json-c/json.h>
#include <math.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"
#include "ctlsock.h"
#include "cmdtab.h"
#include "db.h"
#include "canvas.h"
#include "config.h"
#include "replace.h"
#include "report.h"
#include "accept.h"
#include "clock.h"
#include "sampleout.h"
#include "time.h"
#include "web.h"

static void usage(FILE *fp)
{
	fprintf(fp, "usage: psensctl [-s socket] [-j] [-w seconds] command [arguments]\n"
	            "       psensctl [-s socket | -d database] export [--zone ZONE] [--since T] [--until T]\n"
	            "                [--format csv|json]   (T: 2026-03-18T12:05[:SS][Z], 2026-03-18 or Unix s)\n"
	            "       psensctl [-s socket | -d database] log [ZONE] [-n count]\n"
	            "       psensctl [-s socket | -d database] report [ZONE] [-o file.pdf|.png|.svg]\n"
	            "                [--format pdf|png|svg] [-t percent] [-c config] [--site TEXT] [--page N]\n"
	            "                [--boxes FILE]\n"
	            "       psensctl [-s socket | -d database] accept-test ZONE [--since YYYY-MM-DD] [--samples N]\n"
	            "       psensctl [-s socket] watch [ZONE] [-n count]\n"
	            "       psensctl web-passwd FILE   (the web console's password, read from stdin, hashed)\n"
	            "commands: status [ZONE], target ZONE LUX, override ZONE LEVEL SECONDS,\n"
	            "          off ZONE, release ZONE, ratios, reload, ping, help,\n"
	            "          calibrate ZONE night|day [LEVEL]|lux N|finish|status|accept|abort,\n"
	            "          dali DEVICE scan|address [new|all]|group ADDRESS add|remove GROUP|\n"
	            "                      identify SHORT [SECONDS]|verify ZONE|status|abort\n"
	            "  -s FILE     psensd's control socket (default $PSENSD_SOCKET, /run/psensd/psensd.sock\n"
	            "              or $XDG_RUNTIME_DIR/psensd.sock)\n"
	            "  -d FILE     the database, for export, report, log and accept-test (default: the one psensd names)\n"
	            "  -j          replies as JSON lines\n"
	            "  -w SECONDS  how long to wait for a reply (default 5)\n"
	            "  -h, --help  this help;  -V, --version  the version\n");
}

/* One line of standard input into pw (without its newline), without echo
 * on a terminal, after prompt there. */
static void read_password(int tty, const char *prompt, char *pw, size_t n)
{
	struct termios t0, t1;
	/* echo off before the prompt: TCSAFLUSH drops what was typed before it,
	 * so a password typed at the prompt must come after it */
	if (tty) {
		tcgetattr(0, &t0);
		t1 = t0;
		t1.c_lflag &= ~(tcflag_t)ECHO;
		tcsetattr(0, TCSAFLUSH, &t1);
		fprintf(stderr, "%s", prompt);
	}
	if (!fgets(pw, (int)n, stdin))
		pw[0] = 0;
	if (tty) {
		tcsetattr(0, TCSAFLUSH, &t0);
		fputc('\n', stderr);
	}
	pw[strcspn(pw, "\r\n")] = 0;
}

/* web-passwd FILE: the web console's password (psensd.conf(5) [web]),
 * read from standard input (without echo on a terminal, and asked twice
 * there: a typing mistake unseen would lock the agent out), written to
 * FILE as a salted hash, mode 0600, through a temporary file renamed over
 * it. */
static int web_passwd(int argc, char **argv)
{
	char pw[256], again[256], line[PSD_WEBPASS_LINE], text[PSD_WEBPASS_LINE + 1];
	struct ps_err e;
	int tty = isatty(0), len, same;
	size_t n;
	if (argc != 1) {
		fprintf(stderr, "usage: psensctl web-passwd FILE\n");
		return 2;
	}
	read_password(tty, "the web console's password: ", pw, sizeof pw);
	if (tty) {
		read_password(tty, "the same password again: ", again, sizeof again);
		same = strcmp(pw, again) == 0;
		memset(again, 0, sizeof again);
		if (!same) {
			memset(pw, 0, sizeof pw);
			fprintf(stderr, "psensctl: web-passwd: the two passwords differ: %s left as it was\n", argv[0]);
			return 1;
		}
	}
	n = strlen(pw);
	if (n < 8) {
		fprintf(stderr, "psensctl: web-passwd: the password is %zu characters: give at least 8\n", n);
		return 1;
	}
	if (psd_webpass_make(pw, PSD_WEBPASS_ITER, line, sizeof line) != 0) {
		fprintf(stderr, "psensctl: web-passwd: %s\n", strerror(errno));
		return 1;
	}
	memset(pw, 0, sizeof pw);
	/* mode 0600: the hash stays the owner's; the old file whole until the new one is */
	len = snprintf(text, sizeof text, "%s\n", line);
	if (ps_replace_file(argv[0], 0600, text, (size_t)len, &e) != 0) {
		fprintf(stderr, "psensctl: web-passwd: %s\n", e.msg);
		return 1;
	}
	printf("%s: the web console's password hash (mode 0600); psensd reads it when it starts\n", argv[0]);
	return 0;
}

static const char *default_socket(void)
{
	static char buf[600];
	return psd_ctlsock_default_path(0, buf, sizeof buf);
}

/* One request, one reply line (malloc'd) or NULL after a message. */
static char *ask(const char *path, const char *request, int timeout_ms)
{
	struct sockaddr_un sa = { .sun_family = AF_UNIX };
	size_t cap = 4096, n = 0, len = strlen(request);
	char *buf = malloc(cap);
	int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0), send_errno = 0;
	if (!buf || fd < 0 || strlen(path) >= sizeof sa.sun_path) {
		fprintf(stderr, "psensctl: %s: %s\n", path, fd < 0 ? strerror(errno) : "cannot use this path");
		goto bad;
	}
	snprintf(sa.sun_path, sizeof sa.sun_path, "%s", path);
	if (connect(fd, (struct sockaddr *)&sa, sizeof sa) != 0) {
		fprintf(stderr, "psensctl: cannot reach psensd at %s: %s\n", path, strerror(errno));
		goto bad;
	}
	/* a send that fails may still leave psensd's reason to read (it
	 * refuses a peer or a crowd with one line, then closes) */
	if (send(fd, request, len, MSG_NOSIGNAL) != (ssize_t)len || send(fd, "\n", 1, MSG_NOSIGNAL) != 1)
		send_errno = errno;
	for (;;) {
		struct pollfd p = { fd, POLLIN, 0 };
		ssize_t got;
		int rc = poll(&p, 1, timeout_ms);
		if (rc == 0) {
			fprintf(stderr, "psensctl: %s: no reply in %d ms\n", path, timeout_ms);
			goto bad;
		}
		if (rc < 0 && errno == EINTR)
			continue;
		if (n + 1 >= cap) {
			char *grown = cap < (1u << 24) ? realloc(buf, cap * 2) : NULL;
			if (!grown) {
				fprintf(stderr, "psensctl: reply too long\n");
				goto bad;
			}
			buf = grown;
			cap *= 2;
		}
		got = read(fd, buf + n, cap - n - 1);
		if (got <= 0) {
			fprintf(stderr, "psensctl: %s: %s\n", path,
			        send_errno ? strerror(send_errno) : "connection closed without a reply");
			goto bad;
		}
		n += (size_t)got;
		if (memchr(buf, '\n', n)) {
			*(char *)memchr(buf, '\n', n) = '\0';
			close(fd);
			return buf;
		}
	}
bad:
	if (fd >= 0)
		close(fd);
	free(buf);
	return NULL;
}

static void show_value(json_object *v, int indent, const char *key);

static void show_object(json_object *o, int indent)
{
	json_object_object_foreach(o, key, val)
	{
		if (strcmp(key, "ok") == 0)
			continue;
		show_value(val, indent, key);
	}
}

/* A person's view of a reply: key: value, nested blocks indented. */
static void show_value(json_object *v, int indent, const char *key)
{
	enum json_type t = json_object_get_type(v);
	if (t == json_type_object) {
		printf("%*s%s:\n", indent, "", key);
		show_object(v, indent + 2);
	} else if (t == json_type_array) {
		size_t n = json_object_array_length(v);
		printf("%*s%s: (%zu)\n", indent, "", key, n);
		for (size_t i = 0; i < n; i++) {
			json_object *e = json_object_array_get_idx(v, i);
			json_object *name;
			if (json_object_get_type(e) == json_type_object) {
				const char *label = json_object_object_get_ex(e, "name", &name) ||
				                            json_object_object_get_ex(e, "label", &name)
				                    ? json_object_get_string(name) : "";
				printf("%*s- %s\n", indent + 2, "", label);
				show_object(e, indent + 4);
			} else {
				printf("%*s- %s\n", indent + 2, "", json_object_get_string(e));
			}
		}
	} else if (t == json_type_null) {
		printf("%*s%s: -\n", indent, "", key);
	} else if (t == json_type_double) {
		printf("%*s%s: %.6g\n", indent, "", key, json_object_get_double(v));
	} else {
		printf("%*s%s: %s\n", indent, "", key, json_object_get_string(v));
	}
}

/* ---- dali: commissioning jobs, followed until they end ------------------------------- */

static json_object *member(json_object *o, const char *key)
{
	json_object *v;
	return o && json_object_object_get_ex(o, key, &v) ? v : NULL;
}

static const char *text_of(json_object *o, const char *key)
{
	json_object *v = member(o, key);
	return v && json_object_get_type(v) != json_type_null ? json_object_get_string(v) : NULL;
}

/* a value for a table cell: "-" for null (no answer) */
static const char *cell(json_object *o, const char *key, char *buf, size_t len)
{
	json_object *v = member(o, key);
	if (!v || json_object_get_type(v) == json_type_null)
		return "-";
	if (json_object_get_type(v) == json_type_array) {
		size_t n = json_object_array_length(v), k = 0;
		buf[0] = 0;
		for (size_t i = 0; i < n && k < len; i++)
			k += (size_t)snprintf(buf + k, len - k, "%s%s", i ? "," : "",
			                      json_object_get_string(json_object_array_get_idx(v, i)));
		return n ? buf : "none";
	}
	snprintf(buf, len, "%s", json_object_get_string(v));
	return buf;
}

static int state_is(json_object *r, const char *state)
{
	const char *s = text_of(r, "state");
	return s && strcmp(s, state) == 0;
}

static void dali_show(json_object *r)
{
	const char *job = text_of(r, "job"), *msg = text_of(r, "message"), *fw = text_of(r, "firmware");
	json_object *list;
	char a[64], b[64], c[64], d[64], e[64], f[64], g[64], h[64], i[64], j[64], k[64], l[64], m[64];
	if (fw)
		printf("%s: interface firmware %s\n", text_of(r, "device"), fw);
	if (!job) {
		printf("%s: no commissioning job since psensd started\n", text_of(r, "device"));
		return;
	}
	printf("%s %s %s in %s s (%s frames)%s%s\n", text_of(r, "device"), job, cell(r, "state", c, sizeof c),
	       cell(r, "elapsed_s", a, sizeof a), cell(r, "frames", b, sizeof b), msg ? ": " : "", msg ? msg : "");
	if (state_is(r, "running"))
		printf("  now: %s\n", text_of(r, "step"));
	if (strcmp(job, "scan") == 0 && (list = member(r, "ballasts"))) {
		printf("  short ballasts type phys_min min max fade_s rate groups    failure power_on status level\n");
		for (size_t n = 0; n < json_object_array_length(list); n++) {
			json_object *x = json_object_array_get_idx(list, n);
			printf("  %5s %-8s %4s %8s %3s %3s %6s %4s %-9s %7s %8s %6s %5s\n", cell(x, "address", a, sizeof a),
			       cell(x, "ballasts", b, sizeof b), cell(x, "device_type", c, sizeof c),
			       cell(x, "physical_min", d, sizeof d), cell(x, "min_level", e, sizeof e),
			       cell(x, "max_level", f, sizeof f), cell(x, "fade_time_s", g, sizeof g),
			       cell(x, "fade_rate", h, sizeof h), cell(x, "groups", i, sizeof i),
			       cell(x, "failure_level", j, sizeof j), cell(x, "power_on_level", k, sizeof k),
			       cell(x, "status", l, sizeof l), cell(x, "actual_level", m, sizeof m));
		}
		printf("  gear without a short address: %s\n", cell(r, "unaddressed", a, sizeof a));
		if ((list = member(r, "devices"))) {
			printf("  control devices (IEC 62386-103):\n  short devices instances (number: type kind)\n");
			for (size_t n = 0; n < json_object_array_length(list); n++) {
				json_object *x = json_object_array_get_idx(list, n), *in = member(x, "instances");
				printf("  %5s %-7s", cell(x, "address", a, sizeof a), cell(x, "devices", b, sizeof b));
				for (size_t q = 0; in && q < json_object_array_length(in); q++) {
					json_object *y = json_object_array_get_idx(in, q);
					const char *kind = text_of(y, "kind");
					printf(" %s: %s%s%s%s", cell(y, "number", c, sizeof c), cell(y, "type", d, sizeof d),
					       kind ? " " : "", kind ? kind : "",
					       q + 1 < json_object_array_length(in) ? ";" : "");
				}
				printf("\n");
			}
			printf("  control devices without a short address: %s\n",
			       cell(r, "devices_unaddressed", a, sizeof a));
		}
	} else if (strcmp(job, "address") == 0 && (list = member(r, "found"))) {
		printf("  random    short  was\n");
		for (size_t n = 0; n < json_object_array_length(list); n++) {
			json_object *x = json_object_array_get_idx(list, n);
			printf("  %-8s  %5s  %3s\n", cell(x, "random", a, sizeof a), cell(x, "address", b, sizeof b),
			       cell(x, "was", c, sizeof c));
		}
	} else if (strcmp(job, "group") == 0 && member(r, "control_device")) {
		printf("  control device %s: device groups %s\n", cell(r, "control_device", a, sizeof a),
		       cell(r, "device_groups", b, sizeof b));
	} else if (strcmp(job, "group") == 0) {
		printf("  %s: groups %s\n", cell(r, "address", a, sizeof a), cell(r, "groups", b, sizeof b));
	} else if (strcmp(job, "verify") == 0 && (list = member(r, "targets"))) {
		for (size_t n = 0; n < json_object_array_length(list); n++) {
			json_object *t = json_object_array_get_idx(list, n), *bl = member(t, "ballasts");
			printf("  %s (%s): %s\n", cell(t, "point", a, sizeof a), cell(t, "address", b, sizeof b),
			       json_object_get_boolean(member(t, "ok")) ? "every ballast follows" : "NOT ALL FOLLOW");
			for (size_t q = 0; bl && q < json_object_array_length(bl); q++) {
				json_object *x = json_object_array_get_idx(bl, q);
				printf("    short %-3s expected %-8s got %-8s %s\n", cell(x, "address", a, sizeof a),
				       cell(x, "expected", b, sizeof b), cell(x, "got", c, sizeof c),
				       json_object_get_boolean(member(x, "ok")) ? "ok" : "NOT FOLLOWING");
			}
		}
		if ((list = member(r, "others_following")) && json_object_array_length(list))
			printf("  outside the zone but following: %s\n", cell(r, "others_following", a, sizeof a));
	}
}

/* Start a job and follow it with "dali DEVICE status" until it ends.
 * Exit status: 0 done (and, for verify, every ballast follows), 1 else. */
static int dali_follow(const char *sock, const char *request, const char *device, int raw, int timeout_ms)
{
	char status_req[128], *reply = ask(sock, request, timeout_ms), last[128] = "";
	json_object *o = reply ? json_tokener_parse(reply) : NULL, *r, *ok;
	int rc;
	if (!reply)
		return 1;
	if (!o || !json_object_object_get_ex(o, "ok", &ok) || !json_object_get_boolean(ok)) {
		fprintf(stderr, "psensctl: %s\n", o && text_of(o, "error") ? text_of(o, "error") : reply);
		json_object_put(o);
		free(reply);
		return 1;
	}
	if (raw)
		puts(reply);
	snprintf(status_req, sizeof status_req, "dali %s status", device);
	while ((r = member(o, "dali")) && state_is(r, "running")) {
		const char *stepname = text_of(r, "step");
		if (!raw && stepname && strcmp(stepname, last) != 0) {
			fprintf(stderr, "  %s\n", stepname);
			snprintf(last, sizeof last, "%s", stepname);
		}
		poll(NULL, 0, 250);
		free(reply);
		json_object_put(o);
		if (!(reply = ask(sock, status_req, timeout_ms)))
			return 1;
		if (!(o = json_tokener_parse(reply))) {
			fprintf(stderr, "psensctl: not a JSON reply: %s\n", reply);
			free(reply);
			return 1;
		}
	}
	if (raw)
		puts(reply);
	else if (r)
		dali_show(r);
	rc = r && state_is(r, "done") &&
	     !(member(r, "ok") && json_object_get_type(member(r, "ok")) == json_type_boolean &&
	       !json_object_get_boolean(member(r, "ok"))) ? 0 : 1;
	json_object_put(o);
	free(reply);
	return rc;
}

static int dali_is_job(const char *w)
{
	static const char *const jobs[] = { "scan", "address", "group", "identify", "verify", NULL };
	for (int i = 0; jobs[i]; i++)
		if (strcmp(w, jobs[i]) == 0)
			return 1;
	return 0;
}

/* The database: -d, else the one psensd names (o keeps the string). */
static const char *database(const char *sock, const char *dbpath, int timeout_ms, json_object **o)
{
	json_object *db;
	*o = NULL;
	if (!dbpath) {
		char *reply = ask(sock, "log", timeout_ms);
		if (!reply)
			return NULL;
		*o = json_tokener_parse(reply);
		free(reply);
		if (!*o || !json_object_object_get_ex(*o, "database", &db) || !json_object_get_string(db) ||
		    json_object_get_type(db) != json_type_string) {
			fprintf(stderr, "psensctl: psensd keeps no database (use -d)\n");
			json_object_put(*o);
			*o = NULL;
			return NULL;
		}
		dbpath = json_object_get_string(db);
	}
	return dbpath;
}

static int export_csv(const char *sock, const char *dbpath, int timeout_ms)
{
	char err[512];
	json_object *o;
	int rc;
	if (!(dbpath = database(sock, dbpath, timeout_ms, &o)))
		return 1;
	rc = psd_db_export_csv(dbpath, stdout, err, sizeof err);
	if (rc != 0)
		fprintf(stderr, "psensctl: %s\n", err);
	json_object_put(o);
	return rc == 0 && fflush(stdout) == 0 ? 0 : 1;
}

/* accept-test ZONE: the acceptance tests (daemon/accept.h) on the zone's
 * log, printed and stored.  Without -d psensd runs them on its own log
 * (it is the database's one writer, and its open batch holds the newest
 * samples); with -d psensctl runs them on a file no psensd holds. */
static void accept_print(const char *zone, const struct psd_accept_params *p,
                         const struct psd_accept_result r[PSD_ACCEPT_NTESTS], const struct psd_accept_summary *sum)
{
	printf("acceptance of zone %s (target %g lx, electric %.1f lx at full output, delay %g s):\n", zone,
	       p->target_lux, p->elec_task_lux, p->delay);
	for (int i = 0; i < PSD_ACCEPT_NTESTS; i++)
		if (r[i].test)
			printf("  %-14s %-10s %s\n", r[i].test, psd_accept_verdict_names[r[i].verdict + 1], r[i].measured);
	printf("zone %s: %s (%d of %d tests run, %d failed)\n", zone, psd_accept_overall(sum), sum->tested,
	       sum->count, sum->failed);
}

static int accept_exit(const struct psd_accept_summary *sum)
{
	return sum->failed ? 1 : sum->tested == sum->count ? 0 : 3;
}

static double num_or_nan(json_object *o, const char *key)
{
	json_object *v = member(o, key);
	return v && json_object_get_type(v) != json_type_null ? json_object_get_double(v) : NAN;
}

/* psensd's reply (ctlcmd.c, accept_reply) back into the results */
static int accept_from_reply(json_object *a, struct psd_accept_params *p, struct psd_accept_result r[],
                             struct psd_accept_summary *sum)
{
	json_object *tests = member(a, "tests");
	size_t n = tests && json_object_get_type(tests) == json_type_array ? json_object_array_length(tests) : 0;
	if (n < 1 || n > PSD_ACCEPT_NTESTS)
		return -1;
	p->target_lux = num_or_nan(a, "target_lux");
	p->elec_task_lux = num_or_nan(a, "elec_task_lux");
	p->delay = num_or_nan(a, "delay");
	memset(r, 0, PSD_ACCEPT_NTESTS * sizeof *r);   /* a test the zone has not: test NULL */
	for (size_t i = 0; i < n; i++) {
		json_object *t = json_object_array_get_idx(tests, i);
		const char *v = text_of(t, "verdict"), *m = text_of(t, "measured");
		r[i].test = text_of(t, "test");
		r[i].verdict = -2;
		for (int k = 0; k < 3 && v; k++)
			if (strcmp(v, psd_accept_verdict_names[k]) == 0)
				r[i].verdict = k - 1;
		if (!r[i].test || r[i].verdict == -2)
			return -1;
		snprintf(r[i].measured, sizeof r[i].measured, "%s", m ? m : "");
	}
	psd_accept_summarize(r, sum);
	return 0;
}

static int accept_test(const char *sock, const char *dbpath, int raw, int timeout_ms, int argc, char **argv)
{
	struct psd_accept_params p;
	struct psd_accept_result r[PSD_ACCEPT_NTESTS];
	struct psd_accept_summary sum;
	struct psd_db *db;
	const char *zone = NULL, *since = NULL, *samples = NULL;
	char err[512];
	psd_accept_defaults(&p);
	for (int i = 0; i < argc; i++) {
		int rc = i + 1 < argc ? psd_accept_option(&p, argv[i], argv[i + 1], err, sizeof err) : 0;
		if (rc < 0) {
			fprintf(stderr, "psensctl: %s\n", err);
			return 2;
		} else if (rc > 0) {
			/* kept to pass on to psensd as given */
			if (strcmp(argv[i], "--since") == 0)
				since = argv[i + 1];
			else
				samples = argv[i + 1];
			i++;
		} else if (!zone && argv[i][0] != '-') {
			zone = argv[i];
		} else {
			usage(stderr);
			return 2;
		}
	}
	if (!zone) {
		usage(stderr);
		return 2;
	}
	if (!dbpath) {
		char request[PSD_CTL_MAX_LINE];
		char *reply;
		json_object *o, *a;
		int n = snprintf(request, sizeof request, "accept-test %s%s%s%s%s", zone, since ? " --since " : "",
		                 since ? since : "", samples ? " --samples " : "", samples ? samples : "");
		if (n < 0 || (size_t)n >= sizeof request) {
			fprintf(stderr, "psensctl: request longer than %zu bytes\n", sizeof request - 1);
			return 2;
		}
		if (!(reply = ask(sock, request, timeout_ms)))
			return 1;
		o = json_tokener_parse(reply);
		if (raw)
			puts(reply);
		if (!o || !json_object_get_boolean(member(o, "ok"))) {
			if (!raw)
				fprintf(stderr, "psensctl: %s\n", o ? text_of(o, "error") : reply);
			json_object_put(o);
			free(reply);
			return 1;
		}
		a = member(o, "accept");
		if (accept_from_reply(a, &p, r, &sum) != 0) {
			fprintf(stderr, "psensctl: accept-test: a reply psensctl cannot read: %s\n", reply);
			json_object_put(o);
			free(reply);
			return 1;
		}
		if (!raw)
			accept_print(zone, &p, r, &sum);
		json_object_put(o);
		free(reply);
		return accept_exit(&sum);
	}
	if (!(db = psd_db_open_existing(dbpath, err, sizeof err))) {
		/* psensd holds it: its socket is the way in */
		fprintf(stderr, "psensctl: %s%s\n", err,
		        strstr(err, "in use by psensd") ? "; without -d, psensctl asks psensd to run the tests" : "");
		return 1;
	}
	if (psd_accept_zone(db, zone, &p, floor(psd_time_wall()), r, &sum, err, sizeof err) != 0) {
		if (sum.unstored)
			accept_print(zone, &p, r, &sum);
		fprintf(stderr, "psensctl: %s: %s\n", dbpath, err);
		psd_db_close(db);
		return 1;
	}
	psd_db_close(db);
	accept_print(zone, &p, r, &sum);
	return accept_exit(&sum);
}

/* report [ZONE] [-o FILE] [--format pdf|png|svg] [-t PERCENT] [-c CONFIG]
 * [--site TEXT] [--page N]: the commissioning record (daemon/report/report.c). */
static int report(const char *sock, const char *dbpath, int timeout_ms, int argc, char **argv)
{
	struct psd_report_opts ro = { .tolerance_pct = 25, .format = -1 };
	struct psd_report_out res = { 0 };
	struct psd_config *cf = NULL;
	const char *out = NULL, *boxes = NULL;
	char err[1024], *end, *cfgpath = NULL;
	json_object *o;
	int rc = 0;
	for (int i = 0; i < argc; i++) {
		const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
		if (strcmp(a, "-o") == 0 && v)
			out = argv[++i];
		else if (strcmp(a, "-t") == 0 && v) {
			ro.tolerance_pct = strtod(argv[++i], &end);
			if (*end || !(ro.tolerance_pct >= 0)) {
				fprintf(stderr, "psensctl: report -t %s: a percentage\n", argv[i]);
				return 2;
			}
		} else if ((strcmp(a, "-f") == 0 || strcmp(a, "--format") == 0) && v) {
			char name[8];
			snprintf(name, sizeof name, "x.%s", argv[++i]);
			if ((ro.format = psd_report_format_of(name)) < 0) {
				fprintf(stderr, "psensctl: report --format %s: one of pdf, png, svg\n", argv[i]);
				return 2;
			}
		} else if (strcmp(a, "-c") == 0 && v)
			ro.config_path = argv[++i];
		else if (strcmp(a, "--site") == 0 && v)
			ro.site = argv[++i];
		else if (strcmp(a, "--boxes") == 0 && v)
			boxes = argv[++i];
		else if (strcmp(a, "--page") == 0 && v) {
			long p = strtol(argv[++i], &end, 10);
			if (*end || p < 1 || p > 1000) {
				fprintf(stderr, "psensctl: report --page %s: a page number from 1\n", argv[i]);
				return 2;
			}
			ro.page = (int)p;
		} else if (!ro.zone && a[0] != '-')
			ro.zone = a;
		else {
			usage(stderr);
			return 2;
		}
	}
	if (ro.format < 0 && out && (ro.format = psd_report_format_of(out)) < 0) {
		fprintf(stderr, "psensctl: report -o %s: name a .pdf, .png or .svg file, or give --format\n", out);
		return 2;
	}
	if (ro.format < 0)
		ro.format = PSD_REPORT_PDF;
	if (!out && isatty(STDOUT_FILENO)) {
		fprintf(stderr, "psensctl: report: give -o FILE (the report is not text)\n");
		return 2;
	}
	if (!(ro.dbpath = database(sock, dbpath, timeout_ms, &o)))
		return 1;
	/* asking psensd: its own configuration, when it is a path readable here */
	if (!ro.config_path && !dbpath) {
		char *reply = ask(sock, "status", timeout_ms);
		json_object *st = reply ? json_tokener_parse(reply) : NULL, *c;
		if (st && json_object_object_get_ex(st, "config", &c) && json_object_is_type(c, json_type_string) &&
		    json_object_get_string(c)[0] == '/' && access(json_object_get_string(c), R_OK) == 0)
			ro.config_path = cfgpath = strdup(json_object_get_string(c));
		json_object_put(st);
		free(reply);
	}
	if (ro.config_path) {
		if (!(cf = calloc(1, sizeof *cf))) {
			fprintf(stderr, "psensctl: out of memory\n");
			rc = 1;
			goto done;
		}
		if (psd_config_load_keys(cf, ro.config_path) != 0) {
			for (size_t k = 0; k < cf->conf.nerrors; k++)
				fprintf(stderr, "psensctl: %s\n", cf->conf.errors[k]);
			if (!cf->conf.nerrors)
				fprintf(stderr, "psensctl: %s: cannot be read\n", ro.config_path);
			rc = 1;
			goto done;
		}
		ro.cf = cf;
	}
	ro.written = time(NULL);
	if (psd_report_write(&ro, out, &res, err, sizeof err) != 0) {
		fprintf(stderr, "psensctl: report: %s\n", err);
		rc = 1;
	} else {
		if (boxes) {
			/* every text's box: page x0 y0 x1 y1 text (points, y down) */
			FILE *bf = fopen(boxes, "w");
			for (size_t i = 0; bf && i < res.boxes.n; i++)
				fprintf(bf, "%d %.2f %.2f %.2f %.2f %s\n", res.boxes.box[i].page, res.boxes.box[i].x0,
				        res.boxes.box[i].y0, res.boxes.box[i].x1, res.boxes.box[i].y1, res.boxes.box[i].text);
			if (!bf || fclose(bf) != 0) {
				fprintf(stderr, "psensctl: %s: %s\n", boxes, strerror(errno));
				rc = 1;
			}
		}
		for (int i = 0; out && i < res.nzones; i++)
			printf("%s: zone %s: %s\n", out, res.zone[i].name, res.zone[i].verdict == 1 ? "PASS" :
			       res.zone[i].verdict == 2 ? "calibrated, not acceptance-tested (psensctl accept-test)" :
			       res.zone[i].verdict < 0 ? "FAIL" : "not calibrated");
	}
	psd_report_out_free(&res);
	/* cairo's and fontconfig's font caches: nothing left for leak checkers */
	ps_canvas_shutdown();
done:
	json_object_put(o);
	if (cf)
		psd_config_free(cf);
	free(cf);
	free(cfgpath);
	return rc;
}

/* ---- log and export: the sample log, read from the database ------------------------------- */

/* The zones a log holds, joined ", " into names (sorted by the reader). */
struct zone_names {
	const char *want;
	int found;
	char list[512];
};

static void add_zone_name(void *user, const char *name)
{
	struct zone_names *zn = user;
	size_t n = strlen(zn->list);
	if (strcmp(name, zn->want) == 0)
		zn->found = 1;
	snprintf(zn->list + n, sizeof zn->list - n, "%s%s", n ? ", " : "", name);
}

/* A --zone the log does not hold is a typo, not an empty export: 0 when
 * the zone is there, else -1 with the message naming the zones that are. */
static int zone_known(const char *dbpath, const char *zone, char *err, size_t errlen)
{
	struct zone_names zn = { .want = zone, .found = 0, .list = "" };
	struct psd_db *db = psd_db_open_readonly(dbpath, err, errlen);
	int rc;
	if (!db)
		return -1;
	rc = psd_db_zones(db, add_zone_name, &zn, err, errlen);
	psd_db_close(db);
	if (rc != 0)
		return -1;
	if (zn.found)
		return 0;
	snprintf(err, errlen, "export --zone: no zone '%s' in %s: its zones are %s", zone, dbpath,
	         zn.list[0] ? zn.list : "none (no samples logged)");
	return -1;
}

/* export --zone Z --since T --until T --format csv|json (or the old --csv) */
static int export_samples(const char *sock, const char *dbpath, int timeout_ms, int argc, char **argv)
{
	const char *zone = NULL;
	double since = NAN, until = NAN;
	int format = PSD_OUT_CSV, rc;
	struct psd_sampleout out;
	char err[512];
	json_object *o;
	if (argc == 1 && strcmp(argv[0], "--csv") == 0)
		return export_csv(sock, dbpath, timeout_ms);
	for (int i = 0; i < argc; i++) {
		const char *opt = argv[i], *val = i + 1 < argc ? argv[i + 1] : NULL;
		if (!val) {
			fprintf(stderr, "psensctl: export %s: needs a value\n", opt);
			return 2;
		}
		i++;
		if (strcmp(opt, "--zone") == 0) {
			zone = val;
		} else if (strcmp(opt, "--since") == 0 || strcmp(opt, "--until") == 0) {
			if (psd_sampleout_time_parse(val, opt[2] == 's' ? &since : &until) != 0) {
				fprintf(stderr, "psensctl: export %s '%s': not an ISO date-time (2026-03-18T12:05[:SS][Z], "
				        "2026-03-18) or Unix seconds\n", opt, val);
				return 2;
			}
		} else if (strcmp(opt, "--format") == 0) {
			if (strcmp(val, "csv") == 0)
				format = PSD_OUT_CSV;
			else if (strcmp(val, "json") == 0)
				format = PSD_OUT_JSON;
			else {
				fprintf(stderr, "psensctl: export --format '%s': csv or json\n", val);
				return 2;
			}
		} else {
			fprintf(stderr, "psensctl: export: '%s' is not --zone, --since, --until or --format\n", opt);
			return 2;
		}
	}
	if (isfinite(since) && isfinite(until) && since > until) {
		fprintf(stderr, "psensctl: export: --since is after --until\n");
		return 2;
	}
	if (!(dbpath = database(sock, dbpath, timeout_ms, &o)))
		return 1;
	if (zone && zone_known(dbpath, zone, err, sizeof err) != 0) {
		fprintf(stderr, "psensctl: %s\n", err);
		json_object_put(o);
		return 1;
	}
	psd_sampleout_begin(&out, stdout, format);
	rc = psd_db_select(dbpath, zone, since, until, 0, psd_sampleout_row, &out, err, sizeof err);
	if (rc == 0 && psd_sampleout_end(&out) != 0) {
		snprintf(err, sizeof err, "standard output: write error");
		rc = -1;
	}
	if (rc != 0)
		fprintf(stderr, "psensctl: %s\n", err);
	json_object_put(o);
	return rc == 0 ? 0 : 1;
}

/* The arguments [ZONE] [-n N] of log and watch: 0, or -1 with the
 * message given (the caller exits 2). */
static int zone_count_args(const char *cmd, int argc, char **argv, const char **zone, long *count)
{
	char *end;
	for (int i = 0; i < argc; i++) {
		if (strcmp(argv[i], "-n") == 0 && i + 1 < argc) {
			*count = strtol(argv[++i], &end, 10);
			if (*end || *count < 1) {
				fprintf(stderr, "psensctl: %s -n %s: a count of 1 or more\n", cmd, argv[i]);
				return -1;
			}
		} else if (!*zone && argv[i][0] != '-') {
			*zone = argv[i];
		} else {
			usage(stderr);
			return -1;
		}
	}
	return 0;
}

/* log [ZONE] [-n N]: where the log is, then its last N samples (20) */
static int show_log(const char *sock, const char *dbpath, int timeout_ms, int argc, char **argv)
{
	const char *zone = NULL;
	long last = 20;
	char err[512];
	struct psd_sampleout out;
	json_object *o = NULL;
	int rc;
	if (zone_count_args("log", argc, argv, &zone, &last) != 0)
		return 2;
	if (!(dbpath = database(sock, dbpath, timeout_ms, &o)))
		return 1;
	if (o)
		printf("database %s: %s samples logged by this psensd\n", dbpath, text_of(o, "logged") ?
		       text_of(o, "logged") : "-");
	psd_sampleout_begin(&out, stdout, PSD_OUT_TABLE);
	rc = psd_db_select(dbpath, zone, NAN, NAN, last, psd_sampleout_row, &out, err, sizeof err);
	if (rc == 0)
		psd_sampleout_end(&out);
	if (rc != 0)
		fprintf(stderr, "psensctl: %s\n", err);
	json_object_put(o);
	return rc == 0 ? 0 : 1;
}

/* ---- watch: a view of the zones, a block each period ------------------------------------ */

static double num_of(json_object *o, const char *key)
{
	json_object *v = member(o, key);
	return v && json_object_get_type(v) != json_type_null ? json_object_get_double(v) : NAN;
}

/* "512" or "-" for a value not known */
static const char *fmt(char *buf, size_t n, int prec, double v)
{
	if (isfinite(v) && prec < 0)
		snprintf(buf, n, "%g", v);
	else if (isfinite(v))
		snprintf(buf, n, "%.*f", prec, v);
	else
		snprintf(buf, n, "-");
	return buf;
}

static void duration(char *buf, size_t n, double s)
{
	if (!isfinite(s))
		snprintf(buf, n, "-");
	else if (s >= 3600)
		snprintf(buf, n, "%.0f h %02.0f min", floor(s / 3600), floor(fmod(s, 3600) / 60));
	else if (s >= 60)
		snprintf(buf, n, "%.0f min %02.0f s", floor(s / 60), floor(fmod(s, 60)));
	else
		snprintf(buf, n, "%.0f s", s);
}

static void watch_zone(json_object *z)
{
	json_object *s = member(z, "sample"), *cal = member(z, "calibration"), *ov = member(z, "override");
	const char *fault = text_of(z, "fault");
	char a[32], b[32], c[32], d[32], e[32], f[32];
	printf("%s: %s control, target %s lx, output now %s %%%s\n", text_of(z, "name"), text_of(z, "algorithm"),
	       fmt(a, sizeof a, -1, num_of(z, "target_lux")), fmt(b, sizeof b, 1, 100 * num_of(z, "level")),
	       ov && json_object_get_type(ov) == json_type_object ? " (override)" : "");
	if (!s || json_object_get_type(s) != json_type_object) {
		printf("  no sample yet\n");
	} else {
		printf("  sample %s: level %s %% -> %s %%, sensor %s V (daylight %s V)\n", text_of(s, "time"),
		       fmt(a, sizeof a, 1, 100 * num_of(s, "level")),
		       fmt(b, sizeof b, 1, 100 * num_of(s, "commanded")), fmt(c, sizeof c, 4, num_of(s, "sensor_v")),
		       fmt(d, sizeof d, 4, num_of(s, "daylight_v")));
		printf("  task lux: estimated %s, measured %s, simulated truth %s\n",
		       fmt(e, sizeof e, 1, num_of(s, "est_task_lux")), fmt(f, sizeof f, 1, num_of(s, "task_lux")),
		       fmt(a, sizeof a, 1, num_of(s, "true_task_lux")));
	}
	printf("  fault: %s\n", fault ? fault : "none");
	if (member(z, "occupancy")) {
		json_object *oc = member(z, "occupancy");
		const char *of = text_of(oc, "fault");
		printf("  occupancy: %s%s%s%s\n", json_object_get_boolean(member(z, "occupied")) ? "occupied" : "vacant",
		       json_object_get_boolean(member(oc, "at_vacant_level")) ? ", lights at the vacant level" : "",
		       of ? ", input fault: " : "", of ? of : "");
	}
	if (member(z, "drift"))
		printf("  drift: %s (measured ratio %s %% off the simulated one)\n",
		       json_object_get_boolean(member(z, "drift")) ? "FLAGGED" : "no",
		       fmt(a, sizeof a, 1, num_of(z, "drift_pct")));
	if (cal && json_object_get_type(cal) == json_type_object) {
		json_object *left = member(cal, "levels_left") ? member(cal, "levels_left") : member(cal, "samples_left");
		duration(b, sizeof b, num_of(cal, "remaining_s"));
		printf("  calibration: %s session running, %d %s left, about %s to go\n", text_of(cal, "kind"),
		       left ? json_object_get_int(left) : 0, member(cal, "levels_left") ? "levels" : "samples", b);
	}
}

/* Ask for status every 200 ms and show it when a zone has a new sample:
 * one block per period whatever the clock's speed.  A terminal is cleared
 * and redrawn; anything else gets the blocks one after another. */
static int watch(const char *sock, int timeout_ms, int argc, char **argv)
{
	const char *zone = NULL;
	long count = -1, shown = 0;
	double last = NAN;
	int tty = isatty(STDOUT_FILENO);
	char req[256];
	if (zone_count_args("watch", argc, argv, &zone, &count) != 0)
		return 2;
	snprintf(req, sizeof req, "status%s%s", zone ? " " : "", zone ? zone : "");
	while (count < 0 || shown < count) {
		char *reply = ask(sock, req, timeout_ms);
		json_object *o = reply ? json_tokener_parse(reply) : NULL, *zones = member(o, "zones");
		double newest = -INFINITY;
		if (!reply)
			return 1;
		if (!o || !json_object_get_boolean(member(o, "ok")) || !zones) {
			fprintf(stderr, "psensctl: %s\n", o && text_of(o, "error") ? text_of(o, "error") : reply);
			json_object_put(o);
			free(reply);
			return 1;
		}
		for (size_t i = 0; i < json_object_array_length(zones); i++) {
			double t = num_of(member(json_object_array_get_idx(zones, i), "sample"), "t");
			if (t > newest)
				newest = t;
		}
		if (!(newest == last)) {
			if (tty)
				fputs("\033[H\033[2J", stdout);
			printf("psensd %s clock %s (pid %s), %s samples logged\n", text_of(o, "clock"), text_of(o, "time"),
			       text_of(o, "pid"), text_of(o, "logged"));
			for (size_t i = 0; i < json_object_array_length(zones); i++)
				watch_zone(json_object_array_get_idx(zones, i));
			if (!tty)
				putchar('\n');
			fflush(stdout);
			last = newest;
			shown++;
		}
		json_object_put(o);
		free(reply);
		if (count < 0 || shown < count)
			poll(NULL, 0, 200);
	}
	return 0;
}

int main(int argc, char **argv)
{
	const char *sock = default_socket(), *dbpath = NULL;
	char request[PSD_CTL_MAX_LINE];
	int opt, raw = 0, timeout_ms = 5000;
	size_t used = 0;
	char *reply;
	json_object *o, *ok, *err, *dj;
	static const struct option longopts[] = { PS_CLI_LONGOPTS, { NULL, 0, NULL, 0 } };
	while ((opt = getopt_long(argc, argv, "+s:d:jw:hV", longopts, NULL)) != -1) {
		switch (opt) {
		case 's': sock = optarg; break;
		case 'd': dbpath = optarg; break;
		case 'j': raw = 1; break;
		case 'w': timeout_ms = (int)(atof(optarg) * 1000); break;
		case 'h': usage(stdout); return 0;
		case 'V': return ps_cli_version("psensctl");
		default: usage(stderr); return 2;
		}
	}
	if (optind >= argc) {
		usage(stderr);
		return 2;
	}
	/* no option is silently ignored: the database is read by export and report only */
	if (dbpath && strcmp(argv[optind], "export") != 0 && strcmp(argv[optind], "report") != 0 &&
	    strcmp(argv[optind], "log") != 0 && strcmp(argv[optind], "accept-test") != 0) {
		fprintf(stderr, "psensctl: -d is for export, report, log and accept-test; %s asks psensd (-s)\n",
		        argv[optind]);
		return 2;
	}
	if (timeout_ms <= 0)
		timeout_ms = 5000;
	if (strcmp(argv[optind], "web-passwd") == 0)
		return web_passwd(argc - optind - 1, argv + optind + 1);
	if (strcmp(argv[optind], "export") == 0)
		return export_samples(sock, dbpath, timeout_ms, argc - optind - 1, argv + optind + 1);
	if (strcmp(argv[optind], "log") == 0)
		return show_log(sock, dbpath, timeout_ms, argc - optind - 1, argv + optind + 1);
	if (strcmp(argv[optind], "watch") == 0)
		return watch(sock, timeout_ms, argc - optind - 1, argv + optind + 1);
	if (strcmp(argv[optind], "report") == 0)
		return report(sock, dbpath, timeout_ms, argc - optind - 1, argv + optind + 1);
	if (strcmp(argv[optind], "accept-test") == 0)
		return accept_test(sock, dbpath, raw, timeout_ms, argc - optind - 1, argv + optind + 1);
	if (!psd_cmdtab_allows(argv[optind], PSD_CMDTAB_SOCKET)) {
		fprintf(stderr, "psensctl: '%s' is not a command (psensctl --help lists them)\n", argv[optind]);
		return 2;
	}
	for (int i = optind; i < argc; i++) {
		int n = snprintf(request + used, sizeof request - used, "%s%s", i > optind ? " " : "", argv[i]);
		if (n < 0 || (size_t)n >= sizeof request - used) {
			fprintf(stderr, "psensctl: request longer than %zu bytes\n", sizeof request - 1);
			return 2;
		}
		used += (size_t)n;
	}
	if (strcmp(argv[optind], "dali") == 0 && optind + 2 < argc && dali_is_job(argv[optind + 2]))
		return dali_follow(sock, request, argv[optind + 1], raw, timeout_ms);
	if (!(reply = ask(sock, request, timeout_ms)))
		return 1;
	if (raw) {
		puts(reply);
		o = json_tokener_parse(reply);
	} else {
		o = json_tokener_parse(reply);
		if (!o) {
			fprintf(stderr, "psensctl: not a JSON reply: %s\n", reply);
			free(reply);
			return 1;
		}
		if (json_object_object_get_ex(o, "ok", &ok) && json_object_get_boolean(ok)) {
			if (strcmp(argv[optind], "dali") == 0 && json_object_object_get_ex(o, "dali", &dj))
				dali_show(dj);
			else
				show_object(o, 0);
		}
	}
	free(reply);
	if (!o || !json_object_object_get_ex(o, "ok", &ok) || !json_object_get_boolean(ok)) {
		if (o && json_object_object_get_ex(o, "error", &err))
			fprintf(stderr, "psensctl: %s\n", json_object_get_string(err));
		if (o && json_object_object_get_ex(o, "reasons", &err) && json_object_is_type(err, json_type_array))
			for (size_t i = 0; i < json_object_array_length(err); i++)
				fprintf(stderr, "  %s\n", json_object_get_string(json_object_array_get_idx(err, i)));
		json_object_put(o);
		return 1;
	}
	json_object_put(o);
	return 0;
}
