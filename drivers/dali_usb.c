/* SPDX-License-Identifier: ISC */
/* The DALI USB driver: DALI ballasts through a USB interface with libusb-1.0
 * (transport tridonic or hasseb), or through a serial or TCP interface
 * (transport atx, foxtron, luba, daliserver: the
 * link in dali_serial.c, its descriptor in the same epoll set, its results
 * mapped onto the same transactions).  See psensd-dali_usb(7) for the options.
 *
 * Why asynchronous: a DALI transaction takes 30 to 50 ms on the bus and the
 * interface answers in two reports (echo, then answer or "no answer"), so a
 * synchronous exchange would hold the daemon for longer than the driver
 * contract allows.  Instead an IN transfer is always pending, the SEND report
 * goes out as an asynchronous OUT transfer, and everything else happens in
 * service(): libusb's file descriptors are gathered in one epoll descriptor
 * (fd()), timeouts and the frame rate are deadlines on the monotonic clock
 * (deadline()'s *mono): all bus timing (reply timeouts, frame gaps, retries,
 * back-off, control-device report ages and polls, commissioning waits) runs
 * on `mono`, so a bus keeps its real speed under psensd -x; only the input
 * events handed to the daemon carry the daemon's clock.  read() and write() also run service(), so a caller that only
 * writes still makes progress.
 *
 * One transaction is on the bus at a time; the next SEND waits frame_gap
 * after the last one's final report (the bus's settling time before a new
 * forward frame is at most 21.2 ms, priority 5).  Reports are matched on the
 * sequence number; reports for other numbers (another master repeating our
 * last frame, a late answer after a timeout) are ignored.  An interface
 * without the DTR0 prefix (hasseb) gets the DTR0 of a configuration command
 * as a frame of its own under its own sequence number, and the command
 * follows in the same transaction 13.5 ms after DTR0's final report.
 *
 * Unplug: any NO_DEVICE/IO error closes the interface and the driver rescans
 * with a backoff of 0.5 s doubling to 8 s from service(), read() and write();
 * meanwhile read and write fail with ENODEV (the daemon drives the lights to
 * its safe level, which the driver remembers and sends on reconnect).  With
 * the safe_level option the driver also programs each ballast's SYSTEM
 * FAILURE LEVEL at every connect, which is where the gear goes by itself
 * when the bus goes down with the interface.
 *
 * Commissioning (dali_commission.h) runs beside the control: the command
 * method starts one job at a time (scan, address, group, identify, verify),
 * whose transactions take turns with the queue's, so zones keep being
 * dimmed between the frames of a search.  While a job moves the light of
 * some ballasts (identify, verify), frames to the points that reach them
 * wait in the queue; when it ends those points get their level again.
 *
 * DALI-2 control devices (IEC 62386-103) are sensor and input points:
 * dali_input.c says which 24-bit frames each instance needs (its
 * configuration, polls) and takes the event messages the serial and TCP
 * interfaces report among the frames they see on the bus; their
 * transactions share the queue with the gear's. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/epoll.h>
#include <unistd.h>

#include <libusb.h>

#include <json-c/json.h>

#include "dali.h"
#include "dali_atx.h"
#include "dali_daliserver.h"
#include "dali_commission.h"
#include "dali_device.h"
#include "dali_foxtron.h"
#include "dali_input.h"
#include "dali_luba.h"
#include "dali_serial.h"
#include "dali_transport.h"
#include "dali_usb.h"
#include "driver.h"
#include "usb_hasseb.h"
#include "usb_tridonic.h"

#define MAX_POINTS 64
#define QCAP 256
#define MAX_FDS 32
#define BACKOFF_MIN 0.5
#define BACKOFF_MAX 8.0
#define CLOSE_WAIT 1.0      /* seconds to wait for cancelled transfers */
#define SERIAL_TIMEOUT_MS 50
#define IN_TX_GAP 0.0135    /* between the frames of one transaction (101's priority 1) */

enum { ST_DOWN = 0, ST_UP, ST_CLOSING };

enum tx_kind { TX_DAPC, TX_QUERY_ACTUAL, TX_QUERY_PHYS_MIN, TX_QUERY_SFL, TX_SET_SFL, TX_SET_FADE, TX_JOB, TX_INPUT };

struct tx {
	int kind;
	int point;             /* -1 for TX_JOB */
	int tries;
	unsigned frame;        /* TX_JOB, TX_INPUT: the transaction's frame (> 0xFFFF: 24 bits) */
	int twice;
	int answer;            /* TX_JOB, TX_INPUT: a backward frame may come */
};

struct dpoint {
	struct ps_point *pt;
	struct ps_dali_addr addr;
	int want;          /* level asked for by write(), -1 none yet */
	int sent;          /* level last acknowledged on the bus, -1 unknown */
	int phys_min;      /* QUERY PHYSICAL MINIMUM, 1 until known */
	int actual;        /* last QUERY ACTUAL LEVEL answer, -1 none */
	int actual_errno;  /* the last query's failure, 0 if it was answered */
	int dapc_pending;  /* a DAPC is queued or on the bus */
	int query_pending;
	/* The read-back rule, on the monotonic clock: an answer counts only if its
	 * query went out once the last level change was on the bus and its fade
	 * had passed; an earlier one is the level from before the command. */
	double settle_at;  /* the last level-changing DAPC's end plus the fade time */
	double asked_at;   /* when the query on the bus went out */
	double actual_at;  /* when the query that actual (or actual_errno) answers went out */
	double query_due;  /* a query to send once settled, INFINITY none */
	int read_back;     /* read() was called: each level change is read back by itself */
	int held;          /* a commissioning job held its frames back */
	int err;           /* an asynchronous failure to report on the next call */
	char errmsg[200];
	struct ps_dali_input *in;   /* a control device's input instance (sensor, input points), else NULL */
	int input_pending;          /* its transaction is queued or on the bus */
	double input_due;           /* when it has one next */
	double reported;            /* input points: the value last handed to on_event, NAN none */
	int refresh_event;          /* a refresh asked for: hand its answer to on_event, changed or not */
};

struct dali_usb {
	const struct ps_dali_transport *tp;   /* a USB interface (the one found, for transport = usb), or */
	int any_usb;                          /* transport = usb: tp is whichever is plugged in */
	const struct ps_dali_codec *codec;    /* a serial or TCP one */
	char serial[64], port[32];
	char where[256];                      /* serial, TCP: the tty or HOST:PORT */
	long baud;                            /* serial: bits per second, 0 the codec's */
	struct ps_dali_serial *ser;
	int ser_dtr0_frame;                   /* the frame to send after its DTR0, -1 none */
	int ser_twice, ser_answer;
	int ser_repeat;                       /* a 24-bit frame to send once more (the codec has no send-twice for it), -1 none */
	int usb_then, usb_then_twice;         /* USB without a DTR0 prefix: the frame after its DTR0, -1 none */
	int usb_then_go;                      /* DTR0 is through: send usb_then at cur_deadline */
	int ask_version;                      /* USB: ask for the firmware version before the next frame */
	int firmware;                         /* its last version report (major << 8 | minor), -1 none */
	double timeout, frame_gap, safe_level, fade_time;
	long retries;

	libusb_context *ctx;
	libusb_device_handle *h;
	int reattach;
	int epfd;
	int fds[MAX_FDS];
	int nfds;
	struct libusb_transfer *in, *out;
	int in_busy, out_busy;
	uint8_t inbuf[64], outbuf[64];

	int state;
	double now;            /* the monotonic clock at the last service: all bus timing */
	double clock;          /* the daemon's clock then: the time of input events */
	double next_scan, backoff, closing_until;
	char down_why[400];
	char lost_why[160];   /* why the link last went down; kept across failed rescans */

	struct tx q[QCAP];
	size_t qhead, qlen;
	struct tx cur;
	int cur_active, cur_seq, cur_garbled, cur_frame;
	double cur_deadline, next_send;
	int seq;

	struct dpoint pts[MAX_POINTS];
	int npts;
	struct ps_dali_usb_stats st;

	struct ps_dali_commission *job;   /* the last commissioning job, NULL before the first */
	int job_busy;          /* its transaction is on the bus or queued for a retry */
	int last_was_job;      /* the last SEND was the job's: the queue's turn */
	int job_held;          /* points were held back while it ran */
	int collisions;        /* our frames that collided in a row: the random wait grows */
	uint32_t rnd;          /* the random wait's generator */
};


/* The interfaces, and their names for the transport key (in that order):
 * USB ones through libusb, serial and TCP ones through dali_serial.c. */
static const struct ps_dali_transport *const transports[] = { &ps_usb_tridonic, NULL, NULL, NULL, NULL,
	                                                       &ps_usb_hasseb, NULL, NULL };
static const struct ps_dali_codec *const codecs[] = { NULL,           &ps_dali_atx, &ps_dali_foxtron, &ps_dali_luba,
                                                       &ps_dali_daliserver, NULL, NULL, NULL };
static const char *const transport_names[] = { "tridonic", "atx", "foxtron", "luba", "daliserver", "hasseb", "usb",
	                                        NULL };
enum { TRANSPORT_ANY_USB = 6 };   /* "usb": whichever USB interface is plugged in, by its VID:PID */
static const struct ps_dali_transport *const usb_transports[] = { &ps_usb_tridonic, &ps_usb_hasseb, NULL };

/* A transport name that is a USB interface (no device = key). */
static int usb_transport(const char *name)
{
	for (int i = 0; transport_names[i]; i++)
		if (strcmp(name, transport_names[i]) == 0)
			return transports[i] != NULL || i == TRANSPORT_ANY_USB;
	return 0;
}

/* The USB interface a device descriptor is, among those the transport key
 * allows (any of them for transport = usb); NULL none. */
static const struct ps_dali_transport *usb_match(const struct dali_usb *d, const struct libusb_device_descriptor *dd)
{
	for (int i = 0; usb_transports[i]; i++) {
		const struct ps_dali_transport *t = usb_transports[i];
		if ((d->any_usb || t == d->tp) && dd->idVendor == t->vid && dd->idProduct == t->pid)
			return t;
	}
	return NULL;
}

/* port: the interface's place in the USB tree, as in /sys/bus/usb/devices. */
static int valid_port(const char *v, char *why, size_t n)
{
	int bus, len = 0;
	if (sscanf(v, "%d-%*[0-9.]%n", &bus, &len) == 1 && !v[len] && strlen(v) < 32)
		return 0;
	snprintf(why, n, "is not BUS-PORT[.PORT...] (as in /sys/bus/usb/devices, e.g. 1-1.4)");
	return -1;
}

static int valid_address(const char *v, char *why, size_t n)
{
	struct ps_dali_addr a;
	return ps_dali_addr_parse(v, &a, why, n);
}

#define DEV PS_OPT_DEVICE
static const struct ps_opts_spec du_options[] = {
	{ .key = "transport", .type = PS_OPT_ENUM, .scope = DEV, .def = "tridonic",
	  .names = transport_names,
	  .doc = "the interface: tridonic (Tridonic and Lunatone DALI USB, 17b5:0020), hasseb (hasseb DALI "
	         "Master, 04cc:0802), usb (whichever of these two is plugged in, by its VID:PID), atx (AtxLED DALI HAT, serial), foxtron (Foxtron DALI232 serial, DALInet "
	         "TCP), luba (Lunatone LUBA, serial), daliserver (a Tridonic DALI USB shared by daliserver, TCP)" },
	{ .key = "device", .type = PS_OPT_STRING, .scope = DEV,
	  .doc = "atx, foxtron, luba: the serial port (/dev/...) or HOST:PORT (DALInet); daliserver: HOST:PORT" },
	{ .key = "baud", .type = PS_OPT_LONG, .scope = DEV, .min = 1200, .max = 115200,
	  .doc = "atx, foxtron, luba: the serial speed, 8N1 (absent: 19200 atx, 9600 foxtron, 38400 luba)" },
	{ .key = "serial", .type = PS_OPT_STRING, .scope = DEV,
	  .doc = "the interface with this USB serial number" },
	{ .key = "port", .type = PS_OPT_STRING, .scope = DEV, .valid = valid_port,
	  .doc = "the interface at this USB port, BUS-PORT[.PORT...] (e.g. 1-1.4)" },
	{ .key = "timeout", .type = PS_OPT_DOUBLE, .scope = DEV, .def = "0.2",
	  .min = 0.01, .max = 10, .doc = "seconds for the interface's answer to a frame" },
	{ .key = "retries", .type = PS_OPT_LONG, .scope = DEV, .def = "2", .min = 0, .max = 10,
	  .doc = "further tries of a frame that got no answer" },
	{ .key = "frame_gap", .type = PS_OPT_DOUBLE, .scope = DEV, .def = "0.022",
	  .min = 0, .max = 1, .doc = "seconds between a transaction's end and the next frame" },
	{ .key = "safe_level", .type = PS_OPT_DOUBLE, .scope = DEV, .min = 0, .max = 1,
	  .doc = "program each ballast's SYSTEM FAILURE LEVEL to this output (absent: leave it)" },
	{ .key = "fade_time", .type = PS_OPT_DOUBLE, .scope = DEV, .min = 0, .max = 90.5,
	  .doc = "program each ballast's fade time, seconds (absent: leave it)" },
	{ .key = "address", .type = PS_OPT_STRING, .scope = PS_OPT_POINT, .def = "broadcast",
	  .valid = valid_address, .doc = "the ballasts: a short address 0 to 63, group N or broadcast" },
	{ .key = "device_address", .type = PS_OPT_LONG, .scope = PS_OPT_POINT, .min = 0, .max = 63,
	  .doc = "sensor, input: the DALI-2 control device's short address (0 to 63, the device space)" },
	{ .key = "instance", .type = PS_OPT_LONG, .scope = PS_OPT_POINT, .min = 0, .max = 31,
	  .doc = "sensor, input: the instance number (absent: 1 for sensor, 0 for input)" },
	{ .key = "report_time", .type = PS_OPT_DOUBLE, .scope = PS_OPT_POINT, .def = "30", .min = 1, .max = 255,
	  .doc = "sensor, input: T_report, seconds; the value is lost after 2 x report_time without one" },
	{ .key = "deadtime", .type = PS_OPT_DOUBLE, .scope = PS_OPT_POINT, .min = 0, .max = 12.75,
	  .doc = "sensor, input: T_deadtime, seconds in 50 ms steps (absent: leave it)" },
	{ .key = "hysteresis", .type = PS_OPT_LONG, .scope = PS_OPT_POINT, .min = 0, .max = 25,
	  .doc = "sensor: the light sensor's hysteresis, percent (absent: leave it)" },
	{ .key = "hysteresis_min", .type = PS_OPT_LONG, .scope = PS_OPT_POINT, .min = 0, .max = 255,
	  .doc = "sensor: the light sensor's minimum hysteresis, in reading units (absent: leave it)" },
	{ .key = "hold", .type = PS_OPT_DOUBLE, .scope = PS_OPT_POINT, .min = 10, .max = 2550,
	  .doc = "input: the occupancy sensor's hold time, seconds in 10 s steps (absent: leave it)" },
	{ .key = NULL },
};
#undef DEV

static int du_check(const struct ps_opts *o, int role, int *line, char *why, size_t n)
{
	if (role < 0) {
		const char *t = ps_opts_get(o, "transport"), *dv = ps_opts_get(o, "device");
		int serial = t && !usb_transport(t);
		if (serial && !dv) {
			*line = ps_opts_line(o, "transport");
			snprintf(why, n, "transport %s needs device = (a serial port or HOST:PORT)", t);
			return -1;
		}
		if (t && strcmp(t, "daliserver") == 0 && dv && dv[0] == '/') {
			*line = ps_opts_line(o, "device");
			snprintf(why, n, "transport daliserver is reached over TCP: device = HOST:PORT (port 55825 by default)");
			return -1;
		}
		if (t && strcmp(t, "daliserver") == 0 && (ps_opts_get(o, "safe_level") || ps_opts_get(o, "fade_time"))) {
			const char *k = ps_opts_get(o, "safe_level") ? "safe_level" : "fade_time";
			*line = ps_opts_line(o, k);
			snprintf(why, n, "%s is programmed with a frame sent twice, which daliserver cannot send", k);
			return -1;
		}
		if (!serial && dv) {
			*line = ps_opts_line(o, "device");
			snprintf(why, n, "device is for the serial and TCP transports (atx, foxtron, luba), not %s",
			         t ? t : "tridonic");
			return -1;
		}
		return 0;
	}
	if (role == PS_ROLE_DIM || role == PS_ROLE_RELAY) {
		static const char *const dev_keys[] = { "device_address", "instance", "report_time", "deadtime",
			                                "hysteresis", "hysteresis_min", "hold", NULL };
		for (int i = 0; dev_keys[i]; i++)
			if (ps_opts_get(o, dev_keys[i])) {
				*line = ps_opts_line(o, dev_keys[i]);
				snprintf(why, n, "%s is for sensor and input points (DALI-2 control devices)", dev_keys[i]);
				return -1;
			}
		return 0;
	}
	if (role == PS_ROLE_SENSOR || role == PS_ROLE_INPUT) {
		if (ps_opts_get(o, "address")) {
			*line = ps_opts_line(o, "address");
			snprintf(why, n, "address is the gear's; a control device's is device_address");
			return -1;
		}
		if (!ps_opts_get(o, "device_address")) {
			*line = o->n ? o->v[0].line : 0;   /* the key is missing: a line of the point's section */
			snprintf(why, n, "a %s point on dali_usb needs device_address = (the control device, 0 to 63)",
			         ps_role_name(role));
			return -1;
		}
		return 0;
	}
	*line = ps_opts_line(o, "address");
	snprintf(why, n, "dali_usb drives dim and relay points and reads sensor and input points, not %s",
	         ps_role_name(role));
	return -1;
}

/* ---- the epoll set that stands for libusb's descriptors ------------------ */

static void fd_added(int fd, short events, void *user)
{
	struct dali_usb *d = user;
	struct epoll_event ev = { .events = (uint32_t)events, .data.fd = fd };
	if (d->nfds < MAX_FDS && epoll_ctl(d->epfd, EPOLL_CTL_ADD, fd, &ev) == 0)
		d->fds[d->nfds++] = fd;
}

static void fd_removed(int fd, void *user)
{
	struct dali_usb *d = user;
	for (int i = 0; i < d->nfds; i++)
		if (d->fds[i] == fd) {
			epoll_ctl(d->epfd, EPOLL_CTL_DEL, fd, NULL);
			d->fds[i] = d->fds[--d->nfds];
			return;
		}
}

static void ctx_free(struct dali_usb *d)
{
	if (!d->ctx)
		return;
	libusb_set_pollfd_notifiers(d->ctx, NULL, NULL, NULL);
	for (int i = 0; i < d->nfds; i++)
		epoll_ctl(d->epfd, EPOLL_CTL_DEL, d->fds[i], NULL);
	d->nfds = 0;
	libusb_exit(d->ctx);
	d->ctx = NULL;
}

static int ctx_new(struct dali_usb *d)
{
	const struct libusb_pollfd **pf;
	int r = libusb_init(&d->ctx);
	if (r != 0) {
		d->ctx = NULL;
		snprintf(d->down_why, sizeof d->down_why, "libusb: %s", libusb_strerror(r));
		return -1;
	}
	libusb_set_pollfd_notifiers(d->ctx, fd_added, fd_removed, d);
	pf = libusb_get_pollfds(d->ctx);
	for (int i = 0; pf && pf[i]; i++)
		fd_added(pf[i]->fd, pf[i]->events, d);
	libusb_free_pollfds(pf);
	return 0;
}

static void pump_events(struct dali_usb *d)
{
	struct timeval zero = { 0, 0 };
	if (d->ctx)
		libusb_handle_events_timeout_completed(d->ctx, &zero, NULL);
}

/* ---- the transaction queue ------------------------------------------------ */

static int q_push(struct dali_usb *d, int kind, int point)
{
	if (d->qlen >= QCAP)
		return -1;
	d->q[(d->qhead + d->qlen++) % QCAP] = (struct tx){ kind, point, 0, 0, 0, 0 };
	return 0;
}

static void q_push_front(struct dali_usb *d, struct tx t)
{
	if (d->qlen >= QCAP)
		return;
	d->qhead = (d->qhead + QCAP - 1) % QCAP;
	d->q[d->qhead] = t;
	d->qlen++;
}

/* ---- connection ------------------------------------------------------------ */

static void lost(struct dali_usb *d, const char *why)
{
	if (d->state != ST_UP)
		return;
	snprintf(d->down_why, sizeof d->down_why, "%s", why);
	snprintf(d->lost_why, sizeof d->lost_why, "%s", why);
	d->state = ST_CLOSING;
	d->closing_until = d->now + CLOSE_WAIT;
	if (d->in_busy)
		libusb_cancel_transfer(d->in);
	if (d->out_busy)
		libusb_cancel_transfer(d->out);
	/* what was queued is redone from the points' state on reconnect */
	d->qlen = 0;
	d->cur_active = 0;
	if (d->job) {
		char msg[480];
		snprintf(msg, sizeof msg, "%s: %s", d->codec ? "DALI interface" : "DALI USB interface", why);
		ps_dali_commission_fail(d->job, d->now, msg);
	}
	d->job_busy = 0;
	for (int i = 0; i < d->npts; i++)
		d->pts[i].dapc_pending = d->pts[i].query_pending = d->pts[i].input_pending = 0;
}

static void teardown(struct dali_usb *d)
{
	if (d->ser) {
		epoll_ctl(d->epfd, EPOLL_CTL_DEL, ps_dali_serial_fd(d->ser), NULL);
		ps_dali_serial_close(d->ser);
		d->ser = NULL;
	}
	if (d->h) {
		libusb_release_interface(d->h, d->tp->interface);
		if (d->reattach)
			libusb_attach_kernel_driver(d->h, d->tp->interface);
		libusb_close(d->h);
		d->h = NULL;
	}
	/* transfers still in flight after CLOSE_WAIT are leaked, not freed under libusb */
	if (!d->in_busy && d->in)
		libusb_free_transfer(d->in);
	if (!d->out_busy && d->out)
		libusb_free_transfer(d->out);
	d->in = d->out = NULL;
	d->in_busy = d->out_busy = 0;
	ctx_free(d);
	d->state = ST_DOWN;
}

static void in_done(struct libusb_transfer *t);

static int submit_in(struct dali_usb *d)
{
	int r;
	libusb_fill_interrupt_transfer(d->in, d->h, d->tp->ep_in, d->inbuf, d->tp->report_len, in_done, d, 0);
	r = libusb_submit_transfer(d->in);
	if (r == 0)
		d->in_busy = 1;
	return r;
}

static int read_serial(libusb_device_handle *h, int idx, char *out, size_t len)
{
	unsigned char buf[256];
	int n, j = 0;
	if (idx == 0)
		return -1;
	/* language 0x0409; a short timeout: this runs inside a daemon call */
	n = libusb_control_transfer(h, LIBUSB_ENDPOINT_IN, LIBUSB_REQUEST_GET_DESCRIPTOR,
	                            (uint16_t)(LIBUSB_DT_STRING << 8 | idx), 0x0409, buf, sizeof buf,
	                            SERIAL_TIMEOUT_MS);
	if (n < 2 || buf[1] != LIBUSB_DT_STRING)
		return -1;
	for (int i = 2; i + 1 < n && i < buf[0] && (size_t)j + 1 < len; i += 2)
		out[j++] = buf[i + 1] ? '?' : (char)buf[i];
	out[j] = 0;
	return 0;
}

static void port_path(libusb_device *dev, char *out, size_t len)
{
	uint8_t ports[8];
	int n = libusb_get_port_numbers(dev, ports, 8), k;
	k = snprintf(out, len, "%d-", libusb_get_bus_number(dev));
	for (int i = 0; i < n && k > 0 && (size_t)k < len; i++)
		k += snprintf(out + k, len - (size_t)k, i ? ".%d" : "%d", ports[i]);
}

/* A rescan after a loss that finds nothing keeps the loss's cause in front:
 * "interface unplugged; rescan: no ... found" tells the log what happened,
 * the rescan's words alone would not. */
static void keep_cause(struct dali_usb *d)
{
	char scan[sizeof d->down_why];
	if (!d->lost_why[0])
		return;
	snprintf(scan, sizeof scan, "%s", d->down_why);
	snprintf(d->down_why, sizeof d->down_why, "%.159s; rescan: %.230s", d->lost_why, scan);
}

static void connected(struct dali_usb *d);

/* Find, open and claim the interface.  0 ok; -1 with d->down_why. */
static int connect_usb(struct dali_usb *d)
{
	libusb_device **list = NULL;
	libusb_device_handle *found = NULL;
	const struct ps_dali_transport *found_tp = NULL, *other_tp = NULL;
	char where[64] = "", other[64] = "";
	ssize_t n;
	int r, matches = 0;
	if (!d->ctx && ctx_new(d) != 0) {
		errno = ENODEV;
		return -1;
	}
	n = libusb_get_device_list(d->ctx, &list);
	for (ssize_t i = 0; i < n; i++) {
		struct libusb_device_descriptor dd;
		const struct ps_dali_transport *tp;
		libusb_device_handle *h;
		char path[64], serial[64];
		if (libusb_get_device_descriptor(list[i], &dd) != 0 || !(tp = usb_match(d, &dd)))
			continue;
		port_path(list[i], path, sizeof path);
		if (d->port[0] && strcmp(path, d->port) != 0)
			continue;
		if (libusb_open(list[i], &h) != 0)
			continue;
		if (d->serial[0] && (read_serial(h, dd.iSerialNumber, serial, sizeof serial) != 0 ||
		                     strcmp(serial, d->serial) != 0)) {
			libusb_close(h);
			continue;
		}
		if (++matches == 1) {
			found = h;
			found_tp = tp;
			snprintf(where, sizeof where, "%s", path);
		} else {
			other_tp = tp;
			snprintf(other, sizeof other, "%s", path);
			libusb_close(h);
		}
	}
	if (n >= 0 && list)
		libusb_free_device_list(list, 1);   /* allocated even when empty */
	if (matches != 1) {
		if (found)
			libusb_close(found);
		if (matches == 0 && d->any_usb)
			snprintf(d->down_why, sizeof d->down_why,
			         "no DALI USB interface (tridonic %04x:%04x, hasseb %04x:%04x)%s%s%s%s found",
			         ps_usb_tridonic.vid, ps_usb_tridonic.pid, ps_usb_hasseb.vid, ps_usb_hasseb.pid,
			         d->port[0] ? " at port " : "", d->port, d->serial[0] ? " with serial " : "", d->serial);
		else if (matches == 0)
			snprintf(d->down_why, sizeof d->down_why, "no %s DALI USB interface %04x:%04x%s%s%s%s found",
			         d->tp->name, d->tp->vid, d->tp->pid, d->port[0] ? " at port " : "", d->port,
			         d->serial[0] ? " with serial " : "", d->serial);
		else if (found_tp != other_tp)
			snprintf(d->down_why, sizeof d->down_why,
			         "%d DALI USB interfaces found (%s at %s, %s at %s): choose one with transport =, port = or serial =",
			         matches, found_tp->name, where, other_tp->name, other);
		else
			snprintf(d->down_why, sizeof d->down_why,
			         "%d %s interfaces found (at %s and %s): choose one with port = or serial =",
			         matches, found_tp->name, where, other);
		keep_cause(d);
		ctx_free(d);
		errno = matches ? EINVAL : ENODEV;
		return -1;
	}
	d->h = found;
	d->tp = found_tp;
	d->reattach = 0;
	/* the interface enumerates as HID: usbhid holds it until we detach it */
	if (libusb_kernel_driver_active(d->h, d->tp->interface) == 1) {
		r = libusb_detach_kernel_driver(d->h, d->tp->interface);
		if (r == 0)
			d->reattach = 1;
	}
	r = libusb_claim_interface(d->h, d->tp->interface);
	d->in = libusb_alloc_transfer(0);
	d->out = libusb_alloc_transfer(0);
	if (r != 0 || !d->in || !d->out || (r = submit_in(d)) != 0) {
		snprintf(d->down_why, sizeof d->down_why, "interface at %s: cannot claim it: %s", where,
		         libusb_strerror(r ? r : LIBUSB_ERROR_NO_MEM));
		keep_cause(d);
		d->state = ST_UP;   /* so that teardown releases everything */
		teardown(d);
		errno = ENODEV;
		return -1;
	}
	connected(d);
	return 0;
}

/* The link is up: redo each point's setup and last level. */
static void connected(struct dali_usb *d)
{
	d->state = ST_UP;
	d->lost_why[0] = 0;
	d->st.connects++;
	d->backoff = BACKOFF_MIN;
	d->cur_active = 0;
	d->next_send = d->now;
	/* the interface may have been swapped: its version is asked again */
	d->firmware = -1;
	d->ask_version = !d->codec && d->tp->encode_version;
	/* redo each point's setup and last level on every connect */
	for (int i = 0; i < d->npts; i++) {
		struct dpoint *p = &d->pts[i];
		p->sent = -1;
		p->dapc_pending = p->query_pending = p->input_pending = 0;
		p->query_due = INFINITY;
		if (p->in) {
			ps_dali_input_connected(p->in, d->now);
			p->input_due = d->now;
			continue;
		}
		if (p->addr.kind == PS_DALI_SHORT)
			q_push(d, TX_QUERY_PHYS_MIN, i);
		if (d->fade_time >= 0)
			q_push(d, TX_SET_FADE, i);
		if (d->safe_level >= 0)
			q_push(d, TX_QUERY_SFL, i);
		if (p->want >= 0) {
			q_push(d, TX_DAPC, i);
			p->dapc_pending = 1;
		}
	}
}

/* Open the serial port or connect to the gateway.  0 ok; -1 with d->down_why. */
static int connect_serial(struct dali_usb *d)
{
	struct epoll_event ev = { .events = EPOLLIN };
	char err[300];
	d->ser = ps_dali_serial_open(d->codec, d->where, d->baud, err, sizeof err);
	if (!d->ser) {
		int e = errno;
		snprintf(d->down_why, sizeof d->down_why, "%s", err);
		keep_cause(d);
		errno = e == EINVAL ? EINVAL : ENODEV;
		return -1;
	}
	ev.data.fd = ps_dali_serial_fd(d->ser);
	epoll_ctl(d->epfd, EPOLL_CTL_ADD, ev.data.fd, &ev);
	d->ser_dtr0_frame = -1;
	connected(d);
	return 0;
}

static int connect_link(struct dali_usb *d)
{
	return d->codec ? connect_serial(d) : connect_usb(d);
}

/* ---- one transaction ------------------------------------------------------- */

static void out_done(struct libusb_transfer *t)
{
	struct dali_usb *d = t->user_data;
	d->out_busy = 0;
	if (d->state != ST_UP)
		return;
	if (t->status == LIBUSB_TRANSFER_NO_DEVICE)
		lost(d, "interface unplugged");
	else if (t->status == LIBUSB_TRANSFER_ERROR || t->status == LIBUSB_TRANSFER_STALL)
		lost(d, "interface gone (sending)");
	else if (t->status == LIBUSB_TRANSFER_TIMED_OUT && d->cur_active)
		d->cur_deadline = d->now;   /* the interface did not take the report: retry */
}

/* Send the OUT report of len bytes in outbuf.  0 ok; -1 the link is lost. */
static int usb_submit(struct dali_usb *d, int len)
{
	int r;
	libusb_fill_interrupt_transfer(d->out, d->h, d->tp->ep_out, d->outbuf, len, out_done, d,
	                               (unsigned)(d->timeout * 1000 + 0.5));
	r = libusb_submit_transfer(d->out);
	if (r != 0) {
		lost(d, r == LIBUSB_ERROR_NO_DEVICE ? "interface unplugged" : "interface gone (submit)");
		return -1;
	}
	d->out_busy = 1;
	return 0;
}

/* A USB interface: encode the frame under the next sequence number; one
 * without a DTR0 prefix (hasseb) gets DTR0 as a frame of its own first and
 * the frame is kept for usb_then_send.  The report's length, -1 if the
 * interface cannot carry it. */
static int usb_encode(struct dali_usb *d, int frame, int twice, int dtr0)
{
	int len;
	d->usb_then = -1;
	d->usb_then_go = 0;
	d->seq = d->tp->next_seq(d->seq);
	if (frame < 0)
		return -1;
	len = d->tp->encode_send(d->outbuf, sizeof d->outbuf, d->seq, (unsigned)frame, twice, dtr0);
	if (len >= 0 || dtr0 < 0 || frame > 0xFFFF)
		return len;
	len = d->tp->encode_send(d->outbuf, sizeof d->outbuf, d->seq, (unsigned)ps_dali_dtr0(dtr0), 0, -1);
	if (len >= 0) {
		d->usb_then = frame;
		d->usb_then_twice = twice;
	}
	return len;
}

/* DTR0 went out: now the command that uses it, under a sequence number of its own. */
static void usb_then_send(struct dali_usb *d)
{
	int len;
	d->usb_then_go = 0;
	d->seq = d->tp->next_seq(d->seq);
	len = d->tp->encode_send(d->outbuf, sizeof d->outbuf, d->seq, (unsigned)d->usb_then, d->usb_then_twice, -1);
	d->usb_then = -1;
	if (len < 0 || usb_submit(d, len) != 0)
		return;   /* cannot happen for a frame whose DTR0 was encoded; or the link is gone */
	d->cur_seq = d->seq;
	d->cur_garbled = 0;
	d->cur_deadline = d->now + d->timeout;
	d->st.frames++;
}

static int frame_for(struct dali_usb *d, const struct tx *t, int *twice, int *dtr0)
{
	struct dpoint *p = t->kind == TX_JOB ? NULL : &d->pts[t->point];
	int level;
	*twice = 0;
	*dtr0 = -1;
	if (!p || t->kind == TX_INPUT) {
		*twice = t->twice;
		return (int)t->frame;
	}
	switch (t->kind) {
	case TX_DAPC:
		level = ps_dali_clamp_physical_min(p->want, p->phys_min);
		if (level > PS_DALI_MAX_LEVEL && level != PS_DALI_MASK)
			level = PS_DALI_MAX_LEVEL;
		if (p->pt->role == PS_ROLE_RELAY)
			return ps_dali_cmd(&p->addr, p->want ? PS_DALI_RECALL_MAX : PS_DALI_OFF);
		return ps_dali_dapc(&p->addr, level);
	case TX_QUERY_ACTUAL:
		return ps_dali_cmd(&p->addr, PS_DALI_QUERY_ACTUAL_LEVEL);
	case TX_QUERY_PHYS_MIN:
		return ps_dali_cmd(&p->addr, PS_DALI_QUERY_PHYSICAL_MINIMUM);
	case TX_QUERY_SFL:
		return ps_dali_cmd(&p->addr, PS_DALI_QUERY_SYSTEM_FAILURE_LEVEL);
	case TX_SET_SFL:
		*twice = 1;
		*dtr0 = ps_dali_fraction_to_level(d->safe_level);
		return ps_dali_cmd(&p->addr, PS_DALI_SET_SYSTEM_FAILURE_LEVEL);
	case TX_SET_FADE:
		*twice = 1;
		*dtr0 = ps_dali_fade_time_code(d->fade_time);
		return ps_dali_cmd(&p->addr, PS_DALI_SET_FADE_TIME);
	}
	return -1;
}

static const char *tx_name(int kind)
{
	static const char *const names[] = { "DAPC", "QUERY ACTUAL LEVEL", "QUERY PHYSICAL MINIMUM",
		                             "QUERY SYSTEM FAILURE LEVEL", "SET SYSTEM FAILURE LEVEL",
		                             "SET FADE TIME", "commissioning", "control device" };
	return names[kind];
}

/* Index in the queue of the first transaction that may go now: not one to a
 * point whose light a commissioning job is moving.  -1 if none. */
static int sendable(struct dali_usb *d)
{
	for (size_t i = 0; i < d->qlen; i++) {
		const struct tx *t = &d->q[(d->qhead + i) % QCAP];
		if (t->kind == TX_JOB || t->kind == TX_INPUT || !d->job ||
		    !ps_dali_commission_holds(d->job, &d->pts[t->point].addr))
			return (int)i;
	}
	return -1;
}

/* Take the i-th queued transaction out, keeping the order of the rest. */
static struct tx q_take(struct dali_usb *d, size_t i)
{
	struct tx t = d->q[(d->qhead + i) % QCAP];
	for (size_t k = i; k > 0; k--)
		d->q[(d->qhead + k) % QCAP] = d->q[(d->qhead + k - 1) % QCAP];
	d->qhead = (d->qhead + 1) % QCAP;
	d->qlen--;
	return t;
}

/* The job's next transaction, if it has one and none is under way. */
static int job_ready(const struct dali_usb *d, struct ps_dali_tx *tx)
{
	double until;
	return d->job && !d->job_busy && ps_dali_commission_next(d->job, tx, &until) == PS_DALI_NEXT_TX;
}

/* A job's transaction ended (rx: enum ps_dali_rx). */
static void job_done(struct dali_usb *d, int rx, unsigned value, const char *why)
{
	d->job_busy = 0;
	if (d->job)
		ps_dali_commission_result(d->job, d->now, rx, value, why);
}

static void finish(struct dali_usb *d, int answer);
static void failed_try(struct dali_usb *d, int err, const char *why);

/* After our frame collided: a random wait of 0 to 2^k priority-window
 * widths (1.6 ms, the spacing of 101's priorities 2 to 5), k the
 * collisions in a row (at most 4), so that two masters that collided
 * do not start together again. */
static double collision_wait(struct dali_usb *d)
{
	int k = d->collisions < 4 ? d->collisions : 4;
	d->collisions++;
	d->rnd = d->rnd * 1664525u + 1013904223u;
	return (double)(d->rnd >> 8) / (double)(1u << 24) * 0.0016 * (double)(1 << k);
}

/* A serial or TCP interface: send the frame, or first its DTR0 (the
 * Tridonic interface does both in one report; these take two frames).
 * 0 sent, -1 the codec cannot carry it, -2 the link is gone. */
static int serial_start(struct dali_usb *d, int frame, int twice, int dtr0)
{
	struct ps_dali_frame f = { .bits = frame > 0xFFFF ? 24 : 16, .data = (uint32_t)frame, .twice = twice };
	if (frame < 0)
		return -1;
	f.expect_answer = d->cur.kind == TX_JOB || d->cur.kind == TX_INPUT ? d->cur.answer
	                                                                   : ps_dali_expects_answer((unsigned)frame);
	d->ser_answer = f.expect_answer;
	d->ser_dtr0_frame = -1;
	if (dtr0 >= 0) {
		d->ser_dtr0_frame = frame;
		d->ser_twice = twice;
		f.data = (uint32_t)ps_dali_dtr0(dtr0);
		f.twice = 0;
		f.expect_answer = 0;
	}
	d->ser_repeat = -1;
	if (ps_dali_serial_send(d->ser, &f, d->now, d->timeout) == 0)
		return 0;
	if (errno == EINVAL && f.twice && f.bits == 24) {
		/* an interface with send-twice for 16-bit frames only: two frames,
		 * each a transaction of about 30 ms, well inside the 100 ms */
		f.twice = 0;
		d->ser_repeat = frame;
		if (ps_dali_serial_send(d->ser, &f, d->now, d->timeout) == 0)
			return 0;
	}
	if (errno == EINVAL)
		return -1;
	lost(d, "interface gone (sending)");
	return -2;
}

/* A serial or TCP interface's transaction ended. */
static void on_serial_result(struct dali_usb *d, const struct ps_dali_serial_result *res)
{
	char why[200];
	if (!d->cur_active) {
		d->st.stray++;
		return;
	}
	if (res->err == 0 && d->ser_dtr0_frame >= 0) {
		/* DTR0 is loaded: now the command that uses it */
		struct ps_dali_frame f = { .bits = d->ser_dtr0_frame > 0xFFFF ? 24 : 16,
			                   .data = (uint32_t)d->ser_dtr0_frame, .twice = d->ser_twice,
			                   .expect_answer = d->ser_answer };
		d->ser_dtr0_frame = -1;
		if (ps_dali_serial_send(d->ser, &f, d->now, d->timeout) != 0) {
			lost(d, "interface gone (sending)");
			return;
		}
		d->cur_deadline = d->now + d->timeout;
		d->st.frames++;
		return;
	}
	d->ser_dtr0_frame = -1;
	if (res->err == 0 && d->ser_repeat >= 0) {
		struct ps_dali_frame f = { .bits = 24, .data = (uint32_t)d->ser_repeat, .expect_answer = d->ser_answer };
		d->ser_repeat = -1;
		if (ps_dali_serial_send(d->ser, &f, d->now, d->timeout) != 0) {
			lost(d, "interface gone (sending)");
			return;
		}
		d->cur_deadline = d->now + d->timeout;
		d->st.frames++;
		return;
	}
	d->ser_repeat = -1;
	if (res->err == 0) {
		finish(d, res->event == PS_DALI_EV_ANSWER ? (int)res->value : -1);
		return;
	}
	snprintf(why, sizeof why, "%s: %s", d->codec->name, res->why);
	if (res->err == ETIMEDOUT) {
		d->st.timeouts++;
		failed_try(d, ETIMEDOUT, why);
		return;
	}
	d->st.garbled++;
	if (res->event == PS_DALI_EV_BUS_ERROR && res->value == PS_DALI_BUS_SEND_COLLISION) {
		/* another master sent at the same moment: both stop; waiting the same
		 * settling time again would collide again, so wait a random part of
		 * the priority windows on top (IEC 62386-101's collision recovery) */
		d->st.collisions++;
		failed_try(d, res->err, res->why);
		d->next_send += collision_wait(d);
		return;
	}
	d->collisions = 0;
	if (res->event == PS_DALI_EV_BUS_ERROR && d->cur.kind == TX_JOB &&
	    (res->value == PS_DALI_BUS_FRAMING || res->value == PS_DALI_BUS_CHECKSUM)) {
		/* commissioning reads a garbled backward frame: several answered */
		d->cur_active = 0;
		d->next_send = d->now + d->frame_gap;
		job_done(d, PS_DALI_RX_COLLISION, 0, NULL);
		return;
	}
	failed_try(d, res->err, why);
}

static void send_next(struct dali_usb *d)
{
	int frame, twice, dtr0, len, qi;
	struct ps_dali_tx jt;
	int have_job;
	if (d->state != ST_UP || d->cur_active || d->out_busy || d->now < d->next_send)
		return;
	if (d->ask_version) {
		/* no transaction: nothing waits for the version report, which may
		 * come at any time (on_report records it) or never */
		d->ask_version = 0;
		d->seq = d->tp->next_seq(d->seq);
		len = d->tp->encode_version(d->outbuf, sizeof d->outbuf, d->seq);
		if (len > 0)
			usb_submit(d, len);
		return;
	}
	qi = sendable(d);
	have_job = job_ready(d, &jt);
	if (qi < 0 && !have_job)
		return;
	/* the job and the queue take turns: zones are dimmed between search frames */
	if (have_job && (qi < 0 || !d->last_was_job)) {
		d->cur = (struct tx){ TX_JOB, -1, 0, jt.frame, jt.twice, jt.answer };
		d->job_busy = 1;
	} else {
		d->cur = q_take(d, (size_t)qi);
	}
	d->last_was_job = d->cur.kind == TX_JOB;
	frame = frame_for(d, &d->cur, &twice, &dtr0);
	if (d->codec) {
		len = serial_start(d, frame, twice, dtr0);
		if (len == -2)
			return;   /* the link is gone */
	} else {
		len = usb_encode(d, frame, twice, dtr0);
	}
	if (len < 0) {
		if (d->cur.kind == TX_JOB) {
			job_done(d, PS_DALI_RX_FAILED, 0, "a commissioning frame cannot be encoded for this interface");
		} else if (d->cur.kind == TX_INPUT) {
			struct dpoint *p = &d->pts[d->cur.point];
			p->input_pending = 0;
			ps_dali_input_result(p->in, d->now, PS_DALI_RX_FAILED, 0);
			snprintf(p->in->why, sizeof p->in->why, "this interface cannot send 24-bit frames");
		} else {
			struct dpoint *p = &d->pts[d->cur.point];
			p->err = EINVAL;
			snprintf(p->errmsg, sizeof p->errmsg, "%s: cannot be encoded for this interface", tx_name(d->cur.kind));
		}
		return;
	}
	if (!d->codec && usb_submit(d, len) != 0)
		return;
	d->cur_active = 1;
	d->cur_seq = d->seq;
	d->cur_garbled = 0;
	d->cur_frame = frame;
	d->cur.tries++;
	if (d->cur.kind == TX_QUERY_ACTUAL)
		d->pts[d->cur.point].asked_at = d->now;
	d->cur_deadline = d->now + d->timeout;
	d->st.frames++;
}

/* A DAPC that changes the gear's level is through: an answer counts again
 * once the fade is over.  The fade time is the one the driver programs
 * (fade_time); without it the gear's own is not known and taken as 0. */
static void level_changed(struct dali_usb *d, struct dpoint *p)
{
	p->settle_at = d->now + (d->fade_time > 0 ? ps_dali_fade_time_seconds(ps_dali_fade_time_code(d->fade_time)) : 0);
	if (p->read_back)
		p->query_due = p->settle_at;
}

/* The current transaction ended: answer >= 0, -1 no answer. */
static void finish(struct dali_usb *d, int answer)
{
	struct tx t = d->cur;
	struct dpoint *p;
	int sfl;
	d->cur_active = 0;
	d->next_send = d->now + d->frame_gap;
	if (t.kind == TX_JOB) {
		job_done(d, answer < 0 ? PS_DALI_RX_NONE : PS_DALI_RX_ANSWER, answer < 0 ? 0 : (unsigned)answer, NULL);
		return;
	}
	p = &d->pts[t.point];
	if (t.kind == TX_INPUT) {
		p->input_pending = 0;
		ps_dali_input_result(p->in, d->now, answer < 0 ? PS_DALI_RX_NONE : PS_DALI_RX_ANSWER,
		                     answer < 0 ? 0 : (unsigned)answer);
		return;
	}
	switch (t.kind) {
	case TX_DAPC: {
		int twice, dtr0;
		p->dapc_pending = 0;
		if ((d->cur_frame & 0xFF) != p->sent)
			level_changed(d, p);
		p->sent = d->cur_frame & 0xFF;
		p->err = 0;
		/* a write arrived while this frame was on the bus: send the new level */
		if (frame_for(d, &t, &twice, &dtr0) != d->cur_frame) {
			q_push_front(d, (struct tx){ .kind = TX_DAPC, .point = t.point });
			p->dapc_pending = 1;
		}
		break;
	}
	case TX_QUERY_ACTUAL:
		p->query_pending = 0;
		p->actual_at = p->asked_at;
		p->actual = answer;
		p->actual_errno = answer < 0 ? ETIMEDOUT : 0;
		if (answer < 0)
			snprintf(p->errmsg, sizeof p->errmsg, "no ballast answered QUERY ACTUAL LEVEL");
		break;
	case TX_QUERY_PHYS_MIN:
		if (answer >= 1 && answer <= PS_DALI_MAX_LEVEL)
			p->phys_min = answer;
		break;
	case TX_QUERY_SFL:
		sfl = ps_dali_fraction_to_level(d->safe_level);
		/* only write EEPROM when it differs (gear tolerates ~10^5 writes) */
		if (answer != sfl)
			q_push_front(d, (struct tx){ .kind = TX_SET_SFL, .point = t.point });
		break;
	default:
		break;
	}
}

/* The current transaction failed this try: retry or give up. */
static void failed_try(struct dali_usb *d, int err, const char *why)
{
	struct tx t = d->cur;
	struct dpoint *p;
	char desc[64];
	int twice, dtr0, f;
	d->cur_active = 0;
	d->next_send = d->now + d->frame_gap;
	if (t.tries <= d->retries) {
		d->st.retries++;
		q_push_front(d, t);
		return;
	}
	d->st.failed++;
	f = frame_for(d, &t, &twice, &dtr0);
	if (f > 0xFFFF)
		ps_dali_device_describe((uint32_t)f, desc, sizeof desc);
	else
		ps_dali_describe((unsigned)f, desc, sizeof desc);
	if (t.kind == TX_JOB) {
		char msg[200];
		snprintf(msg, sizeof msg, "%s: %s after %d tries", desc, why, t.tries);
		job_done(d, PS_DALI_RX_FAILED, 0, msg);
		return;
	}
	p = &d->pts[t.point];
	if (t.kind == TX_INPUT) {
		/* a garbled answer after every try: the device answers, badly */
		p->input_pending = 0;
		ps_dali_input_result(p->in, d->now, err == EPROTO ? PS_DALI_RX_COLLISION : PS_DALI_RX_FAILED, 0);
		return;
	}
	p->err = err;
	snprintf(p->errmsg, sizeof p->errmsg, "%s: %s after %d tries", desc, why, t.tries);
	if (t.kind == TX_DAPC) {
		p->dapc_pending = 0;
		p->sent = -1;
	} else if (t.kind == TX_QUERY_ACTUAL) {
		p->query_pending = 0;
		p->actual_at = p->asked_at;
		p->actual = -1;
		p->actual_errno = err;
	}
}

static void on_report(struct dali_usb *d, const uint8_t *buf, size_t len)
{
	struct ps_dali_reply r;
	d->tp->decode(buf, len, &r);
	if (r.event == PS_DALI_EV_MALFORMED) {
		d->st.garbled++;
		if (d->cur_active)
			d->cur_garbled = 1;
		return;
	}
	/* a version report answers no transaction, whatever its sequence
	 * number: asked at connect or not, it is recorded and matched to nothing */
	if (r.event == PS_DALI_EV_INFO && d->tp->encode_version) {
		d->firmware = (int)r.value;
		return;
	}
	if (r.event == PS_DALI_EV_IGNORE || r.event == PS_DALI_EV_OBSERVED || r.event == PS_DALI_EV_INFO)
		return;
	if (!d->cur_active || r.seq != d->cur_seq) {
		d->st.stray++;
		return;
	}
	switch (r.event) {
	case PS_DALI_EV_ECHO:
		break;
	case PS_DALI_EV_NO_ANSWER:
	case PS_DALI_EV_ANSWER:
		if (d->usb_then >= 0) {
			/* DTR0 is loaded; the command follows within the transaction */
			d->usb_then_go = 1;
			d->cur_deadline = d->now + IN_TX_GAP;
			break;
		}
		finish(d, r.event == PS_DALI_EV_ANSWER ? (int)r.value : -1);
		break;
	case PS_DALI_EV_BUS_ERROR:
		d->st.garbled++;
		if (d->cur.kind == TX_JOB && (r.value == 1 || r.value == 3)) {
			/* commissioning reads a garbled backward frame: several answered */
			d->cur_active = 0;
			d->next_send = d->now + d->frame_gap;
			job_done(d, PS_DALI_RX_COLLISION, 0, NULL);
			break;
		}
		failed_try(d, EPROTO, r.value == PS_DALI_BUS_EARLY ? "answer too early (before the settling time)" :
		                      r.value == 3 ? "garbled answer (framing error)" :
		                      r.value == 2 ? "DALI bus shorted or unpowered" : "checksum error");
		break;
	}
}

/* Whichever transfer meets a vanished device first names it the same way,
 * so that the fault the zone logs says "unplugged" however the race went. */
static void resubmit_in(struct dali_usb *d)
{
	int r = submit_in(d);
	if (r != 0)
		lost(d, r == LIBUSB_ERROR_NO_DEVICE ? "interface unplugged" : "interface gone (receiving)");
}

static void in_done(struct libusb_transfer *t)
{
	struct dali_usb *d = t->user_data;
	d->in_busy = 0;
	if (d->state != ST_UP)
		return;
	switch (t->status) {
	case LIBUSB_TRANSFER_COMPLETED:
		on_report(d, t->buffer, (size_t)t->actual_length);
		if (d->state == ST_UP)
			resubmit_in(d);
		break;
	case LIBUSB_TRANSFER_TIMED_OUT:
	case LIBUSB_TRANSFER_CANCELLED:
		resubmit_in(d);
		break;
	default:
		lost(d, t->status == LIBUSB_TRANSFER_NO_DEVICE ? "interface unplugged" : "USB error on the interface");
		break;
	}
}

/* ---- commissioning ------------------------------------------------------------ */

static int du_service(struct ps_dev *dev, double clock, double now);
static int gone(struct ps_dev *dev, struct dali_usb *d);

/* Move the job's waits on; while it runs, note the points it holds back;
 * once it has ended, give those points their level again (the job moved
 * their ballasts' light). */
static void job_service(struct dali_usb *d)
{
	if (!d->job)
		return;
	ps_dali_commission_poll(d->job, d->now);
	if (d->job->state == PS_DALI_COMMISSION_RUNNING) {
		for (int i = 0; i < d->npts; i++)
			if (!d->pts[i].held && ps_dali_commission_holds(d->job, &d->pts[i].addr)) {
				d->pts[i].held = 1;
				d->job_held = 1;
			}
		return;
	}
	if (!d->job_held || d->state != ST_UP)
		return;
	d->job_held = 0;
	for (int i = 0; i < d->npts; i++) {
		struct dpoint *p = &d->pts[i];
		if (!p->held)
			continue;
		p->held = 0;
		if (p->want >= 0 && !p->dapc_pending && q_push(d, TX_DAPC, i) == 0)
			p->dapc_pending = 1;
	}
}

static int dali_addr_of_word(const char *w, struct ps_dali_addr *a, char *why, size_t len)
{
	return ps_dali_addr_parse(w, a, why, len);
}

static int word_long(const char *w, long min, long max, long *out)
{
	char *end;
	long v = strtol(w, &end, 10);
	if (!*w || *end || v < min || v > max)
		return -1;
	*out = v;
	return 0;
}

static const char command_usage[] =
	"scan | address [devices] [new|all] | group ADDRESS add|remove GROUP | group device SHORT add|remove GROUP | "
	"identify SHORT [SECONDS] | identify device SHORT | verify ZONE | status | abort";

/* Whether the serial or TCP interface can send a 24-bit forward frame (a
 * control device's): daliserver, for one, carries 16-bit frames only. */
static int carries_24bit(const struct ps_dali_codec *codec)
{
	uint8_t buf[64];
	struct ps_dali_frame f = { .bits = 24, .data = 0xFFFE30, .twice = 0 };   /* a broadcast query */
	return codec && codec->encode(buf, sizeof buf, &f) >= 0;
}

/* Start a job from the request's words; 0, or -1 with errno and dev->err. */
static int start_job(struct ps_dev *dev, struct dali_usb *d, int nw, char **w, struct ps_point *const *pts, int npts,
                     double now)
{
	struct ps_dali_commission *c = d->job;
	struct ps_dali_addr a;
	char why[160];
	long n, g;
	int rc;
	if (strcmp(w[0], "scan") == 0 && nw == 1) {
		/* control devices too where the interface carries 24-bit frames */
		rc = carries_24bit(d->codec) ? ps_dali_commission_scan_devices(c, now) : ps_dali_commission_scan(c, now);
	} else if (strcmp(w[0], "address") == 0 && nw >= 2 && nw <= 3 && strcmp(w[1], "devices") == 0) {
		int all = nw == 3 && strcmp(w[2], "all") == 0;
		if (nw == 3 && !all && strcmp(w[2], "new") != 0)
			return ps_dev_fail(dev, EINVAL, "address devices new|all: '%s' is neither", w[2]);
		if (!d->codec)
			return ps_dev_fail(dev, EINVAL, "address devices: this interface carries no 24-bit frames "
			                                "(control devices need transport atx, foxtron or luba)");
		rc = ps_dali_commission_address_devices(c, all ? PS_DALI_ADDRESS_ALL : PS_DALI_ADDRESS_NEW, now);
	} else if (strcmp(w[0], "address") == 0 && nw <= 2) {
		int all = nw == 2 && strcmp(w[1], "all") == 0;
		if (nw == 2 && !all && strcmp(w[1], "new") != 0)
			return ps_dev_fail(dev, EINVAL, "address new|all: '%s' is neither", w[1]);
		rc = ps_dali_commission_address(c, all ? PS_DALI_ADDRESS_ALL : PS_DALI_ADDRESS_NEW, now);
	} else if (strcmp(w[0], "group") == 0 && nw == 5 && strcmp(w[1], "device") == 0) {
		if (word_long(w[2], 0, 63, &n) != 0)
			return ps_dev_fail(dev, EINVAL, "group device: '%s' is not a short address 0 to 63", w[2]);
		if (strcmp(w[3], "add") != 0 && strcmp(w[3], "remove") != 0)
			return ps_dev_fail(dev, EINVAL, "group device SHORT add|remove GROUP: '%s' is neither", w[3]);
		if (word_long(w[4], 0, 31, &g) != 0)
			return ps_dev_fail(dev, EINVAL, "group device: '%s' is not a device group 0 to 31", w[4]);
		if (!d->codec)
			return ps_dev_fail(dev, EINVAL, "group device: this interface carries no 24-bit frames "
			                                "(control devices need transport atx, foxtron or luba)");
		rc = ps_dali_commission_group_device(c, (int)n, (int)g, strcmp(w[3], "add") == 0, now);
	} else if (strcmp(w[0], "group") == 0 && nw == 4) {
		if (dali_addr_of_word(w[1], &a, why, sizeof why) != 0)
			return ps_dev_fail(dev, EINVAL, "group: '%s': %s", w[1], why);
		if (strcmp(w[2], "add") != 0 && strcmp(w[2], "remove") != 0)
			return ps_dev_fail(dev, EINVAL, "group ADDRESS add|remove GROUP: '%s' is neither", w[2]);
		if (word_long(w[3], 0, 15, &g) != 0)
			return ps_dev_fail(dev, EINVAL, "group: '%s' is not a group 0 to 15", w[3]);
		rc = ps_dali_commission_group(c, &a, (int)g, strcmp(w[2], "add") == 0, now);
	} else if (strcmp(w[0], "identify") == 0 && nw == 3 && strcmp(w[1], "device") == 0) {
		if (word_long(w[2], 0, 63, &n) != 0)
			return ps_dev_fail(dev, EINVAL, "identify device: '%s' is not a short address 0 to 63", w[2]);
		if (!d->codec)
			return ps_dev_fail(dev, EINVAL, "identify device: this interface carries no 24-bit frames "
			                                "(control devices need transport atx, foxtron or luba)");
		rc = ps_dali_commission_identify_device(c, (int)n, now);
	} else if (strcmp(w[0], "identify") == 0 && (nw == 2 || nw == 3)) {
		if (word_long(w[1], 0, 63, &n) != 0)
			return ps_dev_fail(dev, EINVAL, "identify: '%s' is not a short address 0 to 63", w[1]);
		g = 10;
		if (nw == 3 && word_long(w[2], 1, 600, &g) != 0)
			return ps_dev_fail(dev, EINVAL, "identify: '%s' is not 1 to 600 seconds", w[2]);
		rc = ps_dali_commission_identify(c, (int)n, (double)g, now);
	} else if (strcmp(w[0], "verify") == 0 && nw == 2) {
		struct ps_dali_addr t[PS_DALI_VERIFY_MAX];
		const char *names[PS_DALI_VERIFY_MAX];
		int nt = 0;
		for (int i = 0; i < npts && nt < PS_DALI_VERIFY_MAX; i++) {
			const struct dpoint *p = pts[i] ? pts[i]->priv : NULL;
			if (!p || p < d->pts || p >= d->pts + d->npts)
				continue;
			t[nt] = p->addr;
			names[nt++] = pts[i]->name;
		}
		if (!nt)
			return ps_dev_fail(dev, EINVAL, "verify %s: the zone has no outputs on %s", w[1], dev->name);
		/* full output, then 10 % (170): a change whichever level the zone is at */
		rc = ps_dali_commission_verify(c, t, names, nt, PS_DALI_MAX_LEVEL, ps_dali_fraction_to_level(0.1), now);
	} else {
		return ps_dev_fail(dev, EINVAL, "usage: dali %s %s", dev->name, command_usage);
	}
	if (rc != 0)
		return ps_dev_fail(dev, EINVAL, "%s", c->msg);
	return 0;
}

/* The bus counters and each control-device input's state, for psensctl. */
static void bus_json(const struct dali_usb *d, double now, json_object *o)
{
	json_object *b = json_object_new_object(), *list = json_object_new_array();
	json_object_object_add(b, "frames", json_object_new_int64((int64_t)d->st.frames));
	json_object_object_add(b, "device_transactions", json_object_new_int64((int64_t)d->st.input_frames));
	json_object_object_add(b, "events", json_object_new_int64((int64_t)d->st.events));
	json_object_object_add(b, "collisions", json_object_new_int64((int64_t)d->st.collisions));
	json_object_object_add(b, "garbled", json_object_new_int64((int64_t)d->st.garbled));
	for (int i = 0; i < d->npts; i++) {
		const struct ps_dali_input *in = d->pts[i].in;
		json_object *x;
		if (!in)
			continue;
		x = json_object_new_object();
		json_object_object_add(x, "point", json_object_new_string(d->pts[i].pt->name));
		json_object_object_add(x, "device_address", json_object_new_int(in->c.address));
		json_object_object_add(x, "instance", json_object_new_int(in->c.instance));
		json_object_object_add(x, "type", json_object_new_int(in->c.type));
		json_object_object_add(x, "value", isfinite(in->last) ? json_object_new_int64(in->value) : NULL);
		json_object_object_add(x, "age_s", isfinite(in->last) ? json_object_new_double(now - in->last) : NULL);
		json_object_object_add(x, "configured", json_object_new_boolean(in->icfg >= in->ncfg));
		json_object_object_add(x, "transactions", json_object_new_int64((int64_t)in->frames));
		json_object_object_add(x, "polls", json_object_new_int64((int64_t)in->polls));
		json_object_object_add(x, "events", json_object_new_int64((int64_t)in->events));
		json_object_array_add(list, x);
	}
	json_object_object_add(b, "inputs", list);
	json_object_object_add(o, "bus", b);
}

static int du_command(struct ps_dev *dev, int nw, char **w, struct ps_point *const *pts, int npts, double clock,
                      double now, char *out, size_t outlen)
{
	struct dali_usb *d = dev->priv;
	json_object *o;
	const char *text;
	int fresh = 0;
	if (!d)
		return ps_dev_fail(dev, EINVAL, "dali_usb: not open");
	if (nw < 1)
		return ps_dev_fail(dev, EINVAL, "usage: dali %s %s", dev->name, command_usage);
	du_service(dev, clock, now);
	if (strcmp(w[0], "abort") == 0 && nw == 1) {
		if (!d->job || d->job->state != PS_DALI_COMMISSION_RUNNING)
			return ps_dev_fail(dev, EINVAL, "%s: no commissioning job is running", dev->name);
		ps_dali_commission_abort(d->job, now);
	} else if (strcmp(w[0], "status") != 0 || nw != 1) {
		if (d->job && d->job->state == PS_DALI_COMMISSION_RUNNING)
			return ps_dev_fail(dev, EBUSY, "%s: %s is running (%s): wait for it, or abort it", dev->name,
			                   ps_dali_commission_kinds[d->job->kind], d->job->step);
		if (d->state != ST_UP)
			return gone(dev, d);
		if (!d->job) {
			if (!(d->job = calloc(1, sizeof *d->job)))
				return ps_dev_fail(dev, ENOMEM, "out of memory");
			fresh = 1;
		}
		/* a bad request starts nothing: the last job's report stays */
		if (start_job(dev, d, nw, w, pts, npts, now) != 0) {
			if (fresh) {
				free(d->job);
				d->job = NULL;
			}
			return -1;
		}
		d->job_busy = 0;
		send_next(d);
	}
	o = json_object_new_object();
	json_object_object_add(o, "device", json_object_new_string(dev->name));
	json_object_object_add(o, "connected", json_object_new_boolean(d->state == ST_UP));
	if (d->job)
		ps_dali_commission_json(d->job, now, o);
	else
		json_object_object_add(o, "job", NULL);
	bus_json(d, now, o);
	if (d->firmware >= 0) {
		char v[16];
		snprintf(v, sizeof v, "%d.%d", d->firmware >> 8, d->firmware & 0xFF);
		json_object_object_add(o, "firmware", json_object_new_string(v));
	} else {
		json_object_object_add(o, "firmware", NULL);
	}
	json_c_set_serialization_double_format("%.10g", JSON_C_OPTION_THREAD);
	text = json_object_to_json_string_ext(o, JSON_C_TO_STRING_PLAIN | JSON_C_TO_STRING_NOSLASHESCAPE);
	if (strlen(text) >= outlen) {
		json_object_put(o);
		return ps_dev_fail(dev, ENOSPC, "%s: the report does not fit in %zu bytes", dev->name, outlen);
	}
	snprintf(out, outlen, "%s", text);
	json_object_put(o);
	return 0;
}

/* ---- the driver methods ---------------------------------------------------- */

/* Event messages among the frames seen on the bus: each to the input
 * instance it names. */
static void take_observed(struct dali_usb *d)
{
	uint32_t f;
	int bits;
	while (ps_dali_serial_observed(d->ser, &f, &bits))
		if (bits == 24)
			for (int i = 0; i < d->npts; i++)
				if (d->pts[i].in && ps_dali_input_event(d->pts[i].in, d->now, f))
					d->st.events++;
}

/* Queue the read-back queries whose level change has faded in. */
static void query_service(struct dali_usb *d)
{
	for (int i = 0; i < d->npts; i++) {
		struct dpoint *p = &d->pts[i];
		if (p->query_due > d->now)
			continue;
		p->query_due = INFINITY;
		if (!p->query_pending && q_push(d, TX_QUERY_ACTUAL, i) == 0)
			p->query_pending = 1;
	}
}

/* Queue the input instances' transactions that are due. */
static void input_service(struct dali_usb *d)
{
	for (int i = 0; i < d->npts; i++) {
		struct dpoint *p = &d->pts[i];
		struct ps_dali_input_tx tx;
		if (!p->in || p->input_pending || d->qlen >= QCAP)
			continue;
		if (ps_dali_input_next(p->in, d->now, &tx, &p->input_due)) {
			d->q[(d->qhead + d->qlen++) % QCAP] = (struct tx){ TX_INPUT, i, 0, tx.frame, tx.twice, tx.answer };
			p->input_pending = 1;
			p->input_due = INFINITY;
			d->st.input_frames++;
		}
	}
}

/* An occupancy input that changed (by an event or a poll) goes to the
 * daemon as an input event; so does a light sensor's new reading, so that
 * its zone acts on it at once (the gear's command is then the next frame
 * the driver sends). */
static void input_events(struct ps_dev *dev, struct dali_usb *d)
{
	for (int i = 0; i < d->npts; i++) {
		struct dpoint *p = &d->pts[i];
		char why[200];
		double v;
		int err;
		int answered;
		if (!p->in || (p->pt->role != PS_ROLE_INPUT && p->pt->role != PS_ROLE_SENSOR) || !dev->on_event ||
		    ps_dali_input_value(p->in, d->now, &v, &err, why, sizeof why) != 0)
			continue;
		answered = p->refresh_event && !ps_dali_input_refreshing(p->in);
		if (v == p->reported && !answered)
			continue;
		p->reported = v;
		p->refresh_event = 0;
		dev->on_event(dev->event_user, dev, p->pt, d->clock, v);
	}
}

/* now is the monotonic clock (the bus's), clock the daemon's */
static int du_service(struct ps_dev *dev, double clock, double now)
{
	struct dali_usb *d = dev->priv;
	if (!d)
		return ps_dev_fail(dev, EINVAL, "dali_usb: not open");
	d->now = now;
	d->clock = clock;
	pump_events(d);
	if (d->state == ST_CLOSING && ((!d->in_busy && !d->out_busy) || now >= d->closing_until)) {
		teardown(d);
		d->next_scan = now + d->backoff;
	}
	if (d->state == ST_DOWN && now >= d->next_scan) {
		if (connect_link(d) != 0) {
			d->next_scan = now + d->backoff;
			d->backoff = fmin(d->backoff * 2, BACKOFF_MAX);
		}
	}
	if (d->state == ST_UP && d->ser) {
		struct ps_dali_serial_result res;
		int r = ps_dali_serial_service(d->ser, now, &res);
		if (r < 0)
			lost(d, res.why);
		else if (r == 1)
			on_serial_result(d, &res);
		if (d->ser)
			take_observed(d);
	}
	if (d->state == ST_UP && !d->ser && d->cur_active && d->usb_then_go && now >= d->cur_deadline &&
	    !d->out_busy)
		usb_then_send(d);
	if (d->state == ST_UP && !d->ser && d->cur_active && now >= d->cur_deadline) {
		d->st.timeouts++;
		failed_try(d, d->cur_garbled ? EPROTO : ETIMEDOUT,
		           d->cur_garbled ? "garbled report from the interface" : "no reply from the interface");
	}
	job_service(d);
	if (d->state == ST_UP) {
		query_service(d);
		input_service(d);
	}
	send_next(d);
	input_events(dev, d);
	return 0;
}

static int du_fd(struct ps_dev *dev)
{
	struct dali_usb *d = dev->priv;
	return d ? d->epfd : -1;
}

/* The next time service() is due, on the monotonic clock. */
static double du_due(struct ps_dev *dev)
{
	struct dali_usb *d = dev->priv;
	if (!d)
		return INFINITY;
	switch (d->state) {
	case ST_DOWN:
		return d->next_scan;
	case ST_CLOSING:
		return d->closing_until;
	}
	if (d->cur_active)
		return d->cur_deadline;
	{
		double t = INFINITY, until;
		struct ps_dali_tx tx;
		if (!d->out_busy && (sendable(d) >= 0 || job_ready(d, &tx)))
			t = d->next_send;
		if (d->job && !d->job_busy && ps_dali_commission_next(d->job, &tx, &until) == PS_DALI_NEXT_WAIT)
			t = fmin(t, until);
		/* an input instance's next configuration frame or poll */
		for (int i = 0; i < d->npts; i++)
			if (d->pts[i].in && !d->pts[i].input_pending)
				t = fmin(t, d->pts[i].input_due);
		/* a read-back query after a fade */
		for (int i = 0; i < d->npts; i++)
			t = fmin(t, d->pts[i].query_due);
		/* a TCP gateway's keep-alive */
		if (d->ser)
			t = fmin(t, ps_dali_serial_deadline(d->ser));
		/* a job that ended with points held back has their levels to send */
		if (d->job_held && d->job && d->job->state != PS_DALI_COMMISSION_RUNNING)
			t = -INFINITY;
		return t;
	}
}

/* Every due time of the driver is on the monotonic clock. */
static double du_deadline(struct ps_dev *dev, double *mono)
{
	*mono = du_due(dev);
	return INFINITY;
}

static int gone(struct ps_dev *dev, struct dali_usb *d)
{
	return ps_dev_fail(dev, ENODEV, "%s%s: %s (retrying in %.1f s)", d->codec ? "DALI interface " : "DALI USB interface",
	                   d->codec ? d->codec->name : "", d->down_why,
	                   d->state == ST_DOWN ? fmax(0, d->next_scan - d->now) : d->backoff);
}

static int take_error(struct ps_dev *dev, struct dpoint *p)
{
	int err = p->err;
	p->err = 0;
	return ps_dev_fail(dev, err, "%s", p->errmsg);
}

static int du_write(struct ps_dev *dev, struct ps_point *pt, double clock, double now, double value)
{
	struct dali_usb *d = dev->priv;
	struct dpoint *p = pt ? pt->priv : NULL;
	if (!d || !p)
		return ps_dev_fail(dev, EINVAL, "dali_usb: point not added");
	if (p->in)
		return ps_dev_fail(dev, EINVAL, "%s: a control device's input cannot be written", pt->name);
	if (!(value >= 0 && value <= 1))
		return ps_dev_fail(dev, EINVAL, "%s: light output %g is outside 0 to 1", pt->name, value);
	/* remembered even while the interface is gone: sent on reconnect */
	p->want = pt->role == PS_ROLE_RELAY ? (value >= 0.5) : ps_dali_fraction_to_level(value);
	du_service(dev, clock, now);
	if (d->state != ST_UP)
		return gone(dev, d);
	if (!p->dapc_pending) {
		if (q_push(d, TX_DAPC, (int)(p - d->pts)) != 0)
			return ps_dev_fail(dev, EAGAIN, "%s: DALI queue full", pt->name);
		p->dapc_pending = 1;
		send_next(d);
	}
	if (p->err)
		return take_error(dev, p);
	return 0;
}

/* A DAPC to another level than the gear's is queued or on the bus. */
static int level_change_pending(struct dali_usb *d, const struct dpoint *p)
{
	struct tx t = { .kind = TX_DAPC, .point = (int)(p - d->pts) };
	int twice, dtr0;
	return p->dapc_pending && (frame_for(d, &t, &twice, &dtr0) & 0xFF) != p->sent;
}

static int du_read(struct ps_dev *dev, struct ps_point *pt, double clock, double now, double *value)
{
	struct dali_usb *d = dev->priv;
	struct dpoint *p = pt ? pt->priv : NULL;
	if (!d || !p)
		return ps_dev_fail(dev, EINVAL, "dali_usb: point not added");
	du_service(dev, clock, now);
	if (d->state != ST_UP)
		return gone(dev, d);
	if (p->in) {
		char why[240];
		int err;
		if (ps_dali_input_value(p->in, now, value, &err, why, sizeof why) != 0)
			return ps_dev_fail(dev, err, "%s: %s", pt->name, why);
		return 0;
	}
	p->read_back = 1;
	/* a query now, unless it would be answered mid-fade (one is due then) */
	if (!p->query_pending && now >= p->settle_at && q_push(d, TX_QUERY_ACTUAL, (int)(p - d->pts)) == 0) {
		p->query_pending = 1;
		send_next(d);
	} else if (!p->query_pending && now < p->settle_at) {
		p->query_due = p->settle_at;
	}
	if (level_change_pending(d, p) || p->actual_at < p->settle_at)
		return ps_dev_fail(dev, EAGAIN, "%s: no QUERY ACTUAL LEVEL answer since the level changed yet", pt->name);
	if (p->actual_errno)
		return ps_dev_fail(dev, p->actual_errno, "%s: %s", pt->name, p->errmsg);
	if (p->actual < 0)
		return ps_dev_fail(dev, EAGAIN, "%s: no answer to QUERY ACTUAL LEVEL yet", pt->name);
	if (p->actual == PS_DALI_MASK)
		return ps_dev_fail(dev, ERANGE, "%s: the ballast answers MASK (level unknown)", pt->name);
	*value = pt->role == PS_ROLE_RELAY ? (p->actual > 0) : ps_dali_level_to_fraction(p->actual);
	return 0;
}

static double du_age(struct ps_dev *dev, struct ps_point *pt, double now)
{
	struct dali_usb *d = dev->priv;
	struct dpoint *p = pt ? pt->priv : NULL;
	if (!d || !p)
		return INFINITY;
	return p->in ? ps_dali_input_age(p->in, now) : 0;
}

/* A control device's input: poll it at once (dali_input.h); its answer
 * goes to on_event. */
static int du_refresh(struct ps_dev *dev, struct ps_point *pt, double clock, double now)
{
	struct dali_usb *d = dev->priv;
	struct dpoint *p = pt ? pt->priv : NULL;
	if (!d || !p || !p->in)
		return ps_dev_fail(dev, EINVAL, "%s: not a control device's input", pt ? pt->name : "?");
	ps_dali_input_refresh(p->in, now);
	p->refresh_event = ps_dali_input_refreshing(p->in);
	return du_service(dev, clock, now);
}

static int du_add_point(struct ps_dev *dev, struct ps_point *pt, const struct ps_opts *o)
{
	struct dali_usb *d = dev->priv;
	struct ps_opts_reader r = { o, du_options, PS_OPT_POINT, dev->err, sizeof dev->err, NULL };
	struct dpoint *p;
	const char *a = NULL;
	char why[120];
	if (!d)
		return ps_dev_fail(dev, EINVAL, "dali_usb: not open");
	if (ps_dev_check(dev, o, pt->role) != 0 || ps_opts_string(&r, "address", &a) != 0)
		return -1;
	if (d->npts >= MAX_POINTS)
		return ps_dev_fail(dev, EINVAL, "%s: more than %d points on one interface", pt->name, MAX_POINTS);
	p = &d->pts[d->npts];
	memset(p, 0, sizeof *p);
	if (pt->role == PS_ROLE_SENSOR || pt->role == PS_ROLE_INPUT) {
		int light = pt->role == PS_ROLE_SENSOR;
		struct ps_dali_input_conf c = { .type = light ? PS_DALI_TYPE_LIGHT : PS_DALI_TYPE_OCCUPANCY,
			                        .deadtime = -1, .hold = -1, .events = d->codec != NULL };
		long addr = -1, inst = light ? 1 : 0, hyst = -1, hmin = -1;
		if (ps_opts_long(&r, "device_address", &addr) || ps_opts_long(&r, "instance", &inst) ||
		    ps_opts_double(&r, "report_time", &c.report) || ps_opts_double(&r, "deadtime", &c.deadtime) ||
		    ps_opts_long(&r, "hysteresis", &hyst) || ps_opts_long(&r, "hysteresis_min", &hmin) ||
		    ps_opts_double(&r, "hold", &c.hold))
			return -1;
		c.address = (int)addr;
		c.instance = (int)inst;
		c.hysteresis = (int)hyst;
		c.hysteresis_min = (int)hmin;
		p->in = malloc(sizeof *p->in);
		if (!p->in)
			return ps_dev_fail(dev, ENOMEM, "out of memory");
		if (ps_dali_input_init(p->in, &c, why, sizeof why) != 0) {
			free(p->in);
			p->in = NULL;
			return ps_dev_fail(dev, EINVAL, "%s: %s", pt->name, why);
		}
		p->pt = pt;
		p->want = p->sent = p->actual = -1;
		p->reported = NAN;
		p->settle_at = p->asked_at = p->actual_at = -INFINITY;
		p->query_due = INFINITY;
		pt->priv = p;
		d->npts++;
		ps_dali_input_connected(p->in, d->now);
		return 0;
	}
	if (ps_dali_addr_parse(a, &p->addr, why, sizeof why) != 0)
		return ps_dev_fail(dev, EINVAL, "%s: %s", a, why);
	p->pt = pt;
	p->want = p->sent = p->actual = -1;
	p->phys_min = 1;
	p->settle_at = p->asked_at = p->actual_at = -INFINITY;
	p->query_due = INFINITY;
	pt->priv = p;
	d->npts++;
	if (d->state == ST_UP) {
		int i = d->npts - 1;
		if (p->addr.kind == PS_DALI_SHORT)
			q_push(d, TX_QUERY_PHYS_MIN, i);
		if (d->fade_time >= 0)
			q_push(d, TX_SET_FADE, i);
		if (d->safe_level >= 0)
			q_push(d, TX_QUERY_SFL, i);
	}
	return 0;
}

static void du_close(struct ps_dev *dev)
{
	struct dali_usb *d = dev->priv;
	if (!d)
		return;
	if (d->state == ST_UP)
		lost(d, "closed");
	/* bounded: cancelled transfers complete within a few ms on a live device */
	for (int i = 0; i < 50 && (d->in_busy || d->out_busy); i++) {
		struct timeval tv = { 0, 10000 };
		libusb_handle_events_timeout_completed(d->ctx, &tv, NULL);
	}
	teardown(d);
	if (d->epfd >= 0)
		close(d->epfd);
	for (int i = 0; i < d->npts; i++)
		free(d->pts[i].in);
	free(d->job);
	free(d);
	dev->priv = NULL;
}

static int du_open(struct ps_dev *dev, const struct ps_opts *o)
{
	struct dali_usb *d = calloc(1, sizeof *d);
	struct ps_opts_reader r = { o, du_options, PS_OPT_DEVICE, dev->err, sizeof dev->err, NULL };
	const char *serial = NULL, *port = NULL, *where = NULL;
	int transport = 0;
	if (!d)
		return ps_dev_fail(dev, ENOMEM, "out of memory");
	dev->priv = d;
	d->epfd = epoll_create1(EPOLL_CLOEXEC);
	d->safe_level = d->fade_time = -1;
	d->ser_dtr0_frame = d->ser_repeat = d->usb_then = -1;
	d->backoff = BACKOFF_MIN;
	d->next_scan = -INFINITY;
	d->seq = 0;
	d->firmware = -1;
	d->rnd = (uint32_t)(uintptr_t)d ^ (uint32_t)getpid();
	if (d->epfd < 0)
		return ps_dev_fail(dev, errno, "epoll: %s", strerror(errno));
	if (ps_opts_choice(&r, "transport", &transport) || ps_opts_string(&r, "serial", &serial) ||
	    ps_opts_string(&r, "port", &port) || ps_opts_double(&r, "timeout", &d->timeout) ||
	    ps_opts_long(&r, "retries", &d->retries) || ps_opts_double(&r, "frame_gap", &d->frame_gap) ||
	    ps_opts_double(&r, "safe_level", &d->safe_level) || ps_opts_double(&r, "fade_time", &d->fade_time))
		return -1;
	d->any_usb = transport == TRANSPORT_ANY_USB;
	d->tp = d->any_usb ? usb_transports[0] : transports[transport];   /* the one found replaces it */
	d->codec = codecs[transport];
	if (ps_opts_string(&r, "device", &where) || ps_opts_long(&r, "baud", &d->baud))
		return -1;
	snprintf(d->where, sizeof d->where, "%s", where ? where : "");
	if (d->codec && !d->where[0])
		return ps_dev_fail(dev, EINVAL, "transport %s needs device = (a serial port or HOST:PORT)",
		                   transport_names[transport]);
	if (d->codec == &ps_dali_daliserver && d->where[0] == '/')
		return ps_dev_fail(dev, EINVAL, "transport daliserver is reached over TCP: device = HOST:PORT");
	snprintf(d->serial, sizeof d->serial, "%s", serial ? serial : "");
	snprintf(d->port, sizeof d->port, "%s", port ? port : "");
	/* the device may be absent: open succeeds and reads fail with ENODEV until
	 * it appears; only an ambiguous choice is a configuration error */
	d->now = 0;
	if (connect_link(d) != 0) {
		if (errno == EINVAL)
			return ps_dev_fail(dev, EINVAL, "%s", d->down_why);
		d->next_scan = -INFINITY;
	}
	return 0;
}

int ps_dali_usb_stats(struct ps_dev *dev, struct ps_dali_usb_stats *st)
{
	struct dali_usb *d = dev->priv;
	if (dev->drv != &ps_driver_dali_usb || !d)
		return ps_dev_fail(dev, EINVAL, "not a dali_usb device");
	*st = d->st;
	st->connected = d->state == ST_UP;
	st->firmware = d->firmware;
	st->pending = (int)d->qlen + d->cur_active;
	st->job_running = d->job && d->job->state == PS_DALI_COMMISSION_RUNNING;
	return 0;
}

const struct ps_dali_commission *ps_dali_usb_job(struct ps_dev *dev)
{
	struct dali_usb *d = dev->priv;
	return dev->drv == &ps_driver_dali_usb && d ? d->job : NULL;
}

const struct ps_driver ps_driver_dali_usb = {
	.name = "dali_usb",
	.summary = "DALI ballasts through a DALI USB (libusb), serial or TCP interface",
	.compiled_in = 1,
	.options = du_options,
	.check = du_check,
	.open = du_open,
	.add_point = du_add_point,
	.read = du_read,
	.write = du_write,
	.fd = du_fd,
	.deadline = du_deadline,
	.service = du_service,
	.close = du_close,
	.command = du_command,
	.age = du_age,
	.refresh = du_refresh,
};
