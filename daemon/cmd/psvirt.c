/* psvirt: the loopback virtual room served as a Modbus device, so psensd's
 * real Modbus driver runs the whole control loop with no hardware.
 *
 * The room is built as psensd builds it (psd_room_from_results, the loopback
 * driver with its options); psvirt only maps it onto the registers of an
 * ADAM-6024-style 0-10 V I/O module with a lux meter, and misbehaves on
 * request (late reply, exception, garbage, disconnect).  The register map is
 * in psvirt(1).  Time: the room's clock is --start plus --speed times the
 * real seconds since psvirt started (--speed 0 freezes it). */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <modbus.h>

#include "conf.h"
#include "driver.h"
#include "loopback.h"
#include "results.h"
#include "room.h"
#include "roomsetup.h"

/* The register map (holding registers; 0..29 also as input registers). */
enum {
	REG_AI0 = 0,          /* photosensor, 0..65535 = 0..10 V */
	REG_AO0 = 10,         /* dimming output, 0..4095 = 0..10 V = light output 0..1 */
	REG_AO1 = 11,
	REG_AI0_STATUS = 20,  /* bit 1 over-range, bit 3 open circuit */
	REG_LUX = 100,        /* task lux, u32 high word first */
	REG_LUX_STATUS = 102,
	REG_LUX_F32 = 104,    /* task lux, f32 ABCD */
	REG_LUX_F32_CDAB = 106,
	REG_TOD = 200,        /* the room's time of day, u32 seconds */
	REG_OUTPUT = 202,     /* light output x 10000 */
	REG_TRUE_LUX = 203,   /* task lux without noise or faults, f32 ABCD */
	REG_FAULT = 900,      /* 0 none, 1 late, 2 exception, 3 garbage, 4 disconnect */
	REG_FAULT_COUNT = 901,/* requests to affect, 0: until cleared */
	REG_LATE_MS = 902,
	REG_EXCEPTION = 903,
	NREGS = 1000
};
enum { FAULT_NONE, FAULT_LATE, FAULT_EXCEPTION, FAULT_GARBAGE, FAULT_DISCONNECT, FAULT_COUNT };
static const char *const fault_names[] = { "none", "late", "exception", "garbage", "disconnect", NULL };

#define MAX_CLIENTS 8
#define MAX_OPTS 32

struct virt {
	modbus_t *ctx;
	modbus_mapping_t *map;
	int rtu;
	struct ps_dev dev;
	struct ps_point sensor, task, dim;
	uint16_t last_ao0;
	double start, speed, t0;
	long requests, faulted;
};

static volatile sig_atomic_t stop;

static void on_signal(int sig)
{
	(void)sig;
	stop = 1;
}

static double mono(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static double room_now(const struct virt *v)
{
	return v->start + v->speed * (mono() - v->t0);
}

static void put_f32(uint16_t *r, double x, int cdab)
{
	float f = (float)x;
	uint32_t u;
	memcpy(&u, &f, sizeof u);
	r[cdab] = (uint16_t)(u >> 16);
	r[!cdab] = (uint16_t)u;
}

static void put_u32(uint16_t *r, double x)
{
	uint32_t u = (uint32_t)lround(fmin(fmax(x, 0), 4294967295.0));
	r[0] = (uint16_t)(u >> 16);
	r[1] = (uint16_t)u;
}

/* The room's state into the registers.  Returns -1 (errno ETIMEDOUT) when
 * the room drops or delays the sensor's reply (its drop and late faults). */
static int refresh(struct virt *v, double now)
{
	uint16_t *hr = v->map->tab_registers;
	double volts = 0, lux = 0;
	int rc = 0, fault;
	struct ps_room *room = ps_loopback_room(&v->dev);
	/* AO0 written since the last request: command the ballast */
	if (hr[REG_AO0] != v->last_ao0) {
		v->last_ao0 = hr[REG_AO0] > 4095 ? 4095 : hr[REG_AO0];
		hr[REG_AO0] = v->last_ao0;
		ps_driver_loopback.write(&v->dev, &v->dim, now, v->last_ao0 / 4095.0);
	}
	if (ps_driver_loopback.read(&v->dev, &v->sensor, now, &volts) != 0)
		rc = -1;
	fault = ps_room_fault(room, now);
	hr[REG_AI0] = (uint16_t)lround(fmin(fmax(volts, 0), 10) / 10 * 65535);
	hr[REG_AI0_STATUS] = (uint16_t)((volts >= 10 || fault == PS_ROOM_FAULT_SATURATED ? 0x0002 : 0) |
	                                (fault == PS_ROOM_FAULT_OPEN ? 0x0008 : 0));
	ps_driver_loopback.read(&v->dev, &v->task, now, &lux);
	put_u32(hr + REG_LUX, lux);
	hr[REG_LUX_STATUS] = 0;
	put_f32(hr + REG_LUX_F32, lux, 0);
	put_f32(hr + REG_LUX_F32_CDAB, lux, 1);
	put_u32(hr + REG_TOD, ps_room_tod(now));
	hr[REG_OUTPUT] = (uint16_t)lround(ps_room_output(room, now) * 10000);
	put_f32(hr + REG_TRUE_LUX, ps_room_true_task_lux(room, now), 0);
	memcpy(v->map->tab_input_registers, hr, NREGS * sizeof *hr);
	if (rc != 0)
		errno = ps_room_fault(room, now) == PS_ROOM_FAULT_LATE ? EAGAIN : ETIMEDOUT;
	return rc;
}

/* Does this request write the fault registers?  Those always get through. */
static int writes_fault_regs(const uint8_t *q, int off)
{
	int fc = q[off], addr = q[off + 1] << 8 | q[off + 2];
	return (fc == MODBUS_FC_WRITE_SINGLE_REGISTER || fc == MODBUS_FC_WRITE_MULTIPLE_REGISTERS) &&
	       addr >= REG_FAULT && addr <= REG_EXCEPTION;
}

static void send_garbage(struct virt *v, int fd, const uint8_t *q, int off)
{
	/* TCP: a reply to another transaction; RTU: a reply with a bad CRC */
	uint8_t tcp[11] = { q[0], (uint8_t)(q[1] ^ 0x5a), 0, 0, 0, 5, q[6], q[off], 2, 0x12, 0x34 };
	uint8_t rtu[7] = { q[0], q[off], 2, 0x12, 0x34, 0xde, 0xad };
	ssize_t n = v->rtu ? write(fd, rtu, sizeof rtu) : write(fd, tcp, sizeof tcp);
	(void)n;
}

/* Serve one request; returns 1 when the connection must be closed, 2 when
 * the reply is late: with *late_s set (TCP) it is deferred by that many
 * seconds and finished by reply_late(), so one slow reply does not stall the
 * other clients (nor the fault registers' writes); without (a serial line,
 * where a late reply does hold the line) psvirt sleeps. */
static int serve(struct virt *v, int fd, const uint8_t *q, int len, double *late_s)
{
	uint16_t *hr = v->map->tab_registers;
	int off = modbus_get_header_length(v->ctx), fault;
	double now = room_now(v);
	v->requests++;
	if (refresh(v, now) != 0) {
		if (errno == ETIMEDOUT)
			return 0;   /* the room drops the reply */
		if (late_s) {
			*late_s = hr[REG_LATE_MS] * 1e-3;
			return 2;
		}
		usleep((useconds_t)hr[REG_LATE_MS] * 1000);
	}
	fault = hr[REG_FAULT] < FAULT_COUNT ? hr[REG_FAULT] : FAULT_NONE;
	if (fault != FAULT_NONE && !writes_fault_regs(q, off)) {
		v->faulted++;
		if (hr[REG_FAULT_COUNT] > 0 && --hr[REG_FAULT_COUNT] == 0)
			hr[REG_FAULT] = FAULT_NONE;
		switch (fault) {
		case FAULT_LATE:
			if (late_s) {
				*late_s = hr[REG_LATE_MS] * 1e-3;
				return 2;
			}
			usleep((useconds_t)hr[REG_LATE_MS] * 1000);
			break;
		case FAULT_EXCEPTION: modbus_reply_exception(v->ctx, q, hr[REG_EXCEPTION]); return 0;
		case FAULT_GARBAGE: send_garbage(v, fd, q, off); return 0;
		default: return !v->rtu;   /* disconnect: TCP closes, a serial line goes silent */
		}
	}
	if (modbus_reply(v->ctx, q, len, v->map) < 0)
		return !v->rtu;
	refresh(v, now);   /* a write to AO0 takes effect now */
	return 0;
}

/* Finish a deferred reply with the room as it is now; 1: close the client. */
static int reply_late(struct virt *v, int fd, const uint8_t *q, int len)
{
	modbus_set_socket(v->ctx, fd);
	refresh(v, room_now(v));
	if (modbus_reply(v->ctx, q, len, v->map) < 0)
		return 1;
	refresh(v, room_now(v));
	return 0;
}

static int write_ready(const char *path, const char *what)
{
	char tmp[4096];
	FILE *fp;
	snprintf(tmp, sizeof tmp, "%s.tmp", path);
	if (!(fp = fopen(tmp, "w")))
		return -1;
	fprintf(fp, "%s\n", what);
	if (fclose(fp) != 0 || rename(tmp, path) != 0)
		return -1;
	return 0;
}

/* A TCP client and its deferred reply, if any (due > 0). */
struct client {
	int fd, len;
	double due;
	uint8_t q[MODBUS_TCP_MAX_ADU_LENGTH];
};

static int run_tcp(struct virt *v, const char *ready)
{
	int lfd = modbus_tcp_listen(v->ctx, MAX_CLIENTS), n = 0;
	struct client cl[MAX_CLIENTS];
	struct sockaddr_in a;
	socklen_t alen = sizeof a;
	char port[16];
	if (lfd < 0 || getsockname(lfd, (struct sockaddr *)&a, &alen) != 0) {
		fprintf(stderr, "psvirt: cannot listen: %s\n", modbus_strerror(errno));
		return -1;
	}
	snprintf(port, sizeof port, "%d", ntohs(a.sin_port));
	if (ready && write_ready(ready, port) != 0) {
		fprintf(stderr, "psvirt: %s: %s\n", ready, strerror(errno));
		return -1;
	}
	while (!stop) {
		struct pollfd p[MAX_CLIENTS + 1];
		double t = mono(), wait = 0.2;
		p[0] = (struct pollfd){ lfd, POLLIN, 0 };
		/* a client waiting for a late reply is not read until it has it */
		for (int i = 0; i < n; i++) {
			p[i + 1] = (struct pollfd){ cl[i].fd, cl[i].due > 0 ? 0 : POLLIN, 0 };
			if (cl[i].due > 0)
				wait = fmin(wait, fmax(cl[i].due - t, 0));
		}
		poll(p, (nfds_t)n + 1, (int)ceil(wait * 1000));
		if (p[0].revents & POLLIN) {
			int c = accept(lfd, NULL, NULL);
			if (c >= 0 && n < MAX_CLIENTS)
				cl[n++] = (struct client){ .fd = c };
			else if (c >= 0)
				close(c);
		}
		t = mono();
		for (int i = 0; i < n; i++) {
			int rc, drop = 0;
			double late = 0;
			if (cl[i].due > 0) {
				if (t >= cl[i].due) {
					cl[i].due = 0;
					drop = reply_late(v, cl[i].fd, cl[i].q, cl[i].len);
				} else if (p[i + 1].revents & (POLLHUP | POLLERR)) {
					drop = 1;
				}
			} else if (p[i + 1].revents & (POLLIN | POLLHUP | POLLERR)) {
				modbus_set_socket(v->ctx, cl[i].fd);
				rc = modbus_receive(v->ctx, cl[i].q);
				if (rc < 0)
					drop = 1;
				else if (rc > 0 && (drop = serve(v, cl[i].fd, cl[i].q, rc, &late)) == 2) {
					cl[i].len = rc;
					cl[i].due = mono() + late;
					drop = 0;
				}
			}
			if (drop) {
				close(cl[i].fd);
				/* poll results are indexed by the old positions: move the last
				 * client here only after its own turn is past */
				cl[i].fd = -1;
			}
		}
		for (int i = 0; i < n;)
			if (cl[i].fd < 0)
				cl[i] = cl[--n];
			else
				i++;
	}
	for (int i = 0; i < n; i++)
		close(cl[i].fd);
	close(lfd);
	return 0;
}

static int run_rtu(struct virt *v, const char *device, const char *ready)
{
	uint8_t q[MODBUS_RTU_MAX_ADU_LENGTH];
	int fd;
	if (modbus_connect(v->ctx) != 0) {
		fprintf(stderr, "psvirt: %s: %s\n", device, modbus_strerror(errno));
		return -1;
	}
	fd = modbus_get_socket(v->ctx);
	if (ready && write_ready(ready, device) != 0) {
		fprintf(stderr, "psvirt: %s: %s\n", ready, strerror(errno));
		return -1;
	}
	while (!stop) {
		struct pollfd p = { fd, POLLIN, 0 };
		int rc;
		if (poll(&p, 1, 200) <= 0)
			continue;
		rc = modbus_receive(v->ctx, q);
		if (rc > 0)
			serve(v, fd, q, rc, NULL);
		else if (rc < 0) {
			/* a bad frame or a line with nobody on the other end: drop what
			 * is there, and do not spin on a hung-up line */
			modbus_flush(v->ctx);
			if (errno != ETIMEDOUT && errno != EMBBADCRC && errno != EMBBADDATA)
				usleep(50000);
		}
	}
	modbus_close(v->ctx);
	return 0;
}

static int hhmm(const char *s, double *out)
{
	int h, m, n = 0;
	if (sscanf(s, "%d:%d%n", &h, &m, &n) != 2 || s[n] || h < 0 || h > 24 || m < 0 || m > 59)
		return -1;
	*out = h * 3600.0 + m * 60;
	return 0;
}

static void usage(FILE *fp)
{
	fprintf(fp,
	        "usage: psvirt [-f psensd.conf] [--results FILE] [--date MM-DD] [--sunrise HH:MM]\n"
	        "              [--sunset HH:MM] [--start HH:MM] [--speed F] [-o KEY=VALUE]...\n"
	        "              (--tcp ADDR:PORT | --rtu DEVICE [--baud N] [--parity none|even|odd]\n"
	        "              [--stop-bits 1|2]) [--unit N] [--ready-file FILE]\n"
	        "              [--fault late|exception|garbage|disconnect] [--fault-count N] [--late-ms N]\n"
	        "The virtual room as a Modbus 0-10 V I/O module with a lux meter; see psvirt(1).\n");
}

struct args {
	const char *conf, *results, *date, *sunrise, *sunset, *start, *tcp, *rtu, *ready, *parity;
	double speed;
	long unit, baud, stop_bits, fault_count, late_ms;
	int fault;
	struct ps_opt opts[MAX_OPTS];
	size_t nopts;
};

static int parse_args(struct args *a, int argc, char **argv)
{
	static const struct option lo[] = {
		{ "results", 1, NULL, 'r' }, { "date", 1, NULL, 'D' }, { "sunrise", 1, NULL, 'R' },
		{ "sunset", 1, NULL, 'S' }, { "start", 1, NULL, 's' }, { "speed", 1, NULL, 'x' },
		{ "tcp", 1, NULL, 't' }, { "rtu", 1, NULL, 'u' }, { "baud", 1, NULL, 'b' },
		{ "parity", 1, NULL, 'p' }, { "stop-bits", 1, NULL, 'B' }, { "unit", 1, NULL, 'U' },
		{ "ready-file", 1, NULL, 'y' }, { "fault", 1, NULL, 'F' }, { "fault-count", 1, NULL, 'C' },
		{ "late-ms", 1, NULL, 'L' }, { "help", 0, NULL, 'h' }, { NULL, 0, NULL, 0 }
	};
	int c;
	memset(a, 0, sizeof *a);
	a->speed = 1;
	a->unit = 1;
	a->baud = 9600;
	a->stop_bits = 1;
	a->late_ms = 500;
	a->parity = "none";
	while ((c = getopt_long(argc, argv, "f:o:h", lo, NULL)) != -1) {
		char *end = NULL;
		switch (c) {
		case 'f': a->conf = optarg; break;
		case 'r': a->results = optarg; break;
		case 'D': a->date = optarg; break;
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
		case 'F':
			for (a->fault = 1; fault_names[a->fault] && strcmp(fault_names[a->fault], optarg); a->fault++)
				;
			if (!fault_names[a->fault]) {
				fprintf(stderr, "psvirt: --fault: '%s' is not late, exception, garbage or disconnect\n", optarg);
				return -1;
			}
			break;
		case 'o': {
			char *eq = strchr(optarg, '=');
			if (!eq || a->nopts >= MAX_OPTS) {
				fprintf(stderr, "psvirt: -o: '%s' is not KEY=VALUE\n", optarg);
				return -1;
			}
			*eq = 0;
			a->opts[a->nopts++] = (struct ps_opt){ optarg, eq + 1, (int)a->nopts + 1, 0 };
			break;
		}
		case 'h': usage(stdout); exit(0);
		default: return -1;
		}
		if (end && *end) {
			fprintf(stderr, "psvirt: '%s' is not a number\n", optarg);
			return -1;
		}
	}
	if (optind != argc || !a->tcp == !a->rtu) {
		fprintf(stderr, "psvirt: give one of --tcp ADDR:PORT or --rtu DEVICE\n");
		return -1;
	}
	if (!(a->speed >= 0) || a->unit < 1 || a->unit > 247 || a->late_ms < 0 || a->late_ms > 60000 ||
	    a->fault_count < 0 || a->fault_count > 65535) {
		fprintf(stderr, "psvirt: --speed must be >= 0, --unit 1 to 247, --late-ms 0 to 60000, "
		                "--fault-count 0 to 65535\n");
		return -1;
	}
	return 0;
}

/* The day as psensd builds it: results, date, sunrise and sunset from the
 * configuration (-f) unless the command line says otherwise. */
static int build_room(struct virt *v, struct args *a)
{
	struct ps_conf conf;
	struct ps_err e;
	struct ps_results res;
	struct ps_room_daypoint day[PSD_DAY_POINTS];
	struct ps_room_params rp;
	struct ps_opts opts = { a->opts, a->nopts, "psvirt -o" };
	char *results = NULL;
	const char *date = "03-18", *sunrise = "06:00", *sunset = "18:00", *start = "06:00";
	double rise, set;
	int rc = -1;
	memset(&conf, 0, sizeof conf);
	if (a->conf) {
		struct ps_conf_section *ps, *sim;
		if (ps_conf_load(&conf, a->conf, &e) != 0) {
			fprintf(stderr, "psvirt: %s\n", e.msg);
			return -1;
		}
		ps = ps_conf_section(&conf, "psensd");
		sim = ps_conf_section(&conf, "simulate");
		results = ps_conf_path(&conf, ps, "results");
		date = ps_conf_str(&conf, sim, "date", date);
		sunrise = ps_conf_str(&conf, sim, "sunrise", sunrise);
		sunset = ps_conf_str(&conf, sim, "sunset", sunset);
		start = ps_conf_str(&conf, sim, "start", start);
	}
	if (a->results) {
		free(results);
		results = strdup(a->results);
	}
	date = a->date ? a->date : date;
	sunrise = a->sunrise ? a->sunrise : sunrise;
	sunset = a->sunset ? a->sunset : sunset;
	start = a->start ? a->start : start;
	if (!results) {
		fprintf(stderr, "psvirt: no results (--results FILE, or -f with [psensd] results)\n");
		goto out;
	}
	if (psd_day_of_year(date) < 0 || hhmm(sunrise, &rise) || hhmm(sunset, &set) || hhmm(start, &v->start)) {
		fprintf(stderr, "psvirt: date must be MM-DD and sunrise, sunset, start HH:MM\n");
		goto out;
	}
	if (ps_results_read(&res, results, &e) != 0) {
		fprintf(stderr, "psvirt: %s\n", e.msg);
		goto out;
	}
	if (psd_room_from_results(&res, psd_day_of_year(date), rise, set, day, &rp) != 0) {
		fprintf(stderr, "psvirt: %s: needs a computed daylight and an electric condition\n", results);
		ps_results_free(&res);
		goto out;
	}
	ps_results_free(&res);
	v->dev.drv = &ps_driver_loopback;
	snprintf(v->dev.name, sizeof v->dev.name, "psvirt");
	v->sensor = (struct ps_point){ "sensor", PS_ROLE_SENSOR, NULL };
	v->task = (struct ps_point){ "task", PS_ROLE_TASK_LUX, NULL };
	v->dim = (struct ps_point){ "dim", PS_ROLE_DIM, NULL };
	if (ps_driver_loopback.open(&v->dev, &opts) != 0 || ps_loopback_set_room(&v->dev, &rp, v->start) != 0 ||
	    ps_driver_loopback.add_point(&v->dev, &v->sensor, NULL) != 0 ||
	    ps_driver_loopback.add_point(&v->dev, &v->task, NULL) != 0 ||
	    ps_driver_loopback.add_point(&v->dev, &v->dim, NULL) != 0) {
		fprintf(stderr, "psvirt: room: %s\n", v->dev.err);
		goto out;
	}
	for (size_t i = 0; i < opts.n; i++)
		if (!opts.v[i].used) {
			fprintf(stderr, "psvirt: -o %s: not a loopback room option (see psensd.conf(5))\n", opts.v[i].key);
			goto out;
		}
	rc = 0;
out:
	free(results);
	ps_conf_free(&conf);
	return rc;
}

int main(int argc, char **argv)
{
	struct args a;
	struct virt v;
	struct sigaction sa;
	int rc;
	double end;
	memset(&v, 0, sizeof v);
	if (parse_args(&a, argc, argv) != 0) {
		usage(stderr);
		return 2;
	}
	if (build_room(&v, &a) != 0) {
		ps_driver_loopback.close(&v.dev);
		return 1;
	}
	v.speed = a.speed;
	if (a.tcp) {
		char host[256];
		const char *colon = strrchr(a.tcp, ':');
		if (!colon || colon == a.tcp || (size_t)(colon - a.tcp) >= sizeof host) {
			fprintf(stderr, "psvirt: --tcp: '%s' is not ADDR:PORT\n", a.tcp);
			return 2;
		}
		snprintf(host, sizeof host, "%.*s", (int)(colon - a.tcp), a.tcp);
		v.ctx = modbus_new_tcp(host, atoi(colon + 1));
	} else {
		char par = !strcmp(a.parity, "even") ? 'E' : !strcmp(a.parity, "odd") ? 'O' : 'N';
		v.ctx = modbus_new_rtu(a.rtu, (int)a.baud, par, 8, (int)a.stop_bits);
		v.rtu = 1;
	}
	v.map = modbus_mapping_new(32, 8, NREGS, NREGS);
	if (!v.ctx || !v.map) {
		fprintf(stderr, "psvirt: %s\n", modbus_strerror(errno));
		return 1;
	}
	modbus_set_slave(v.ctx, (int)a.unit);
	modbus_set_debug(v.ctx, getenv("PSVIRT_DEBUG") != NULL);
	modbus_set_indication_timeout(v.ctx, 1, 0);   /* a half-sent request cannot stall us */
	v.map->tab_registers[REG_AO0] = v.last_ao0 = 4095;   /* the room starts at full output */
	v.map->tab_registers[REG_FAULT] = (uint16_t)a.fault;
	v.map->tab_registers[REG_FAULT_COUNT] = (uint16_t)a.fault_count;
	v.map->tab_registers[REG_LATE_MS] = (uint16_t)a.late_ms;
	v.map->tab_registers[REG_EXCEPTION] = MODBUS_EXCEPTION_SLAVE_OR_SERVER_FAILURE;
	memset(&sa, 0, sizeof sa);
	sa.sa_handler = on_signal;
	sigaction(SIGTERM, &sa, NULL);
	sigaction(SIGINT, &sa, NULL);
	signal(SIGPIPE, SIG_IGN);
	v.t0 = mono();
	refresh(&v, v.start);
	rc = a.tcp ? run_tcp(&v, a.ready) : run_rtu(&v, a.rtu, a.ready);
	end = room_now(&v);
	if (rc == 0)
		printf("psvirt: %ld requests (%ld faulted); room time %02d:%02d to %02d:%02d; "
		       "light output %.1f %% of full on average\n", v.requests, v.faulted,
		       (int)(v.start / 3600), (int)fmod(v.start / 60, 60), (int)(ps_room_tod(end) / 3600),
		       (int)fmod(ps_room_tod(end) / 60, 60),
		       end > v.start ? 100 * ps_room_energy(ps_loopback_room(&v.dev), end) / (end - v.start) : 100.0);
	modbus_mapping_free(v.map);
	modbus_free(v.ctx);
	ps_driver_loopback.close(&v.dev);
	return rc == 0 ? 0 : 1;
}
