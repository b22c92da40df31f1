/* SPDX-License-Identifier: ISC */
/* The GPIO driver (libgpiod 1.6, the kernel's v1 character-device
 * interface): relays, buttons and occupancy inputs, and light-to-frequency
 * sensors of the TSL230R kind.  See psensd-gpio(7).
 *
 * Its keys are in gpio_options below: the chip and consumer for a device;
 * for a relay its line, active_low and initial state; for an input its line,
 * active_low, edge, bias and debounce; for a sensor kind = frequency, its
 * line, gate, factor, max_rate, gap, the divider pins s2 and s3 and the
 * sensitivity pins s0 and s1 with sensitivity.
 *
 * All edge events of a device are gathered in one epoll descriptor (fd());
 * service() drains them, debounces inputs and closes gates; deadline() is
 * the next debounce or gate end.  Nothing here sleeps. */
#include <errno.h>
#include <gpiod.h>
#include <math.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/epoll.h>
#include <unistd.h>

#include "driver.h"
#include "freq.h"
#include "gpio.h"

enum { GPIO_MAX_POINTS = 32 };

struct gpio_point {
	struct ps_point *pt;
	int role, kind;           /* kind: 1 frequency sensor */
	struct gpiod_line *line;
	int offset, active_low;
	/* input */
	double debounce;
	int edge;                 /* 0 both, 1 rising, 2 falling: which changes are events */
	int state;                /* last delivered (-1 none) */
	int pending;              /* value waiting for its debounce (-1 none) */
	double pending_until;
	/* frequency sensor */
	double gate, factor, max_rate, gap;
	double full_scale_hz;     /* the sensor's output saturation, divider 1 */
	struct gpiod_line *s2, *s3;
	int div;                  /* index into ps_freq_dividers */
	int settle;               /* gates to skip after a divider change */
	struct ps_freq_gate g;
	double gate_end;
	double value;             /* the last complete gate's signal */
	int have_value, overran;
	double overrun_hz;
	int overrun_div;          /* the divider of the gate that overran */
};

struct gpio_dev {
	struct gpiod_chip *chip;
	char chipname[64];
	char consumer[32];
	int epfd;
	struct gpio_point p[GPIO_MAX_POINTS];
	int np;
	double now;               /* the last time service() ran */
};

static const char *const onoff[] = { "off", "on", NULL };
static const char *const edges[] = { "both", "rising", "falling", NULL };
static const char *const biases[] = { "as-is", "pull-up", "pull-down", "disable", NULL };
static const char *const kinds[] = { "frequency", NULL };
static const char *const sensitivities[] = { "1", "10", "100", NULL };

#define PT PS_OPT_POINT
#define RELAY PS_ROLE_BIT(PS_ROLE_RELAY)
#define INPUT PS_ROLE_BIT(PS_ROLE_INPUT)
#define SENSOR PS_ROLE_BIT(PS_ROLE_SENSOR)
static const struct ps_opts_spec gpio_options[] = {
	{ .key = "chip", .type = PS_OPT_STRING, .scope = PS_OPT_DEVICE, .def = "gpiochip0",
	  .doc = "the chip: a path, name, label or number" },
	{ .key = "consumer", .type = PS_OPT_STRING, .scope = PS_OPT_DEVICE, .def = "psensd",
	  .doc = "the label the kernel shows for the lines psensd holds" },
	{ .key = "line", .type = PS_OPT_LONG, .scope = PT, .roles = RELAY | INPUT | SENSOR,
	  .min = 0, .max = 1023, .doc = "the line's offset on the chip (required)" },
	{ .key = "active_low", .type = PS_OPT_BOOL, .scope = PT, .roles = RELAY | INPUT,
	  .def = "no", .doc = "the line is active low" },
	{ .key = "initial", .type = PS_OPT_ENUM, .scope = PT, .roles = RELAY, .def = "off",
	  .names = onoff, .doc = "the relay's state from the request until psensd's first command" },
	{ .key = "edge", .type = PS_OPT_ENUM, .scope = PT, .roles = INPUT, .def = "both",
	  .names = edges, .doc = "which changes of an input are events" },
	{ .key = "bias", .type = PS_OPT_ENUM, .scope = PT, .roles = INPUT, .def = "as-is",
	  .names = biases, .doc = "the input's bias" },
	{ .key = "debounce", .type = PS_OPT_DOUBLE, .scope = PT, .roles = INPUT, .def = "0.02",
	  .min = 0, .max = 10, .doc = "seconds an input must hold still before its level counts" },
	{ .key = "kind", .type = PS_OPT_ENUM, .scope = PT, .roles = SENSOR, .names = kinds,
	  .doc = "frequency: a light-to-frequency sensor (required on a sensor)" },
	{ .key = "gate", .type = PS_OPT_DOUBLE, .scope = PT, .roles = SENSOR, .def = "1",
	  .min = 0.01, .max = 3600, .doc = "seconds per measurement" },
	{ .key = "factor", .type = PS_OPT_DOUBLE, .scope = PT, .roles = SENSOR, .def = "1",
	  .min = 1e-12, .max = 1e12, .doc = "signal units per hertz" },
	{ .key = "max_rate", .type = PS_OPT_DOUBLE, .scope = PT, .roles = SENSOR, .def = "2000",
	  .min = 1, .max = 1e7, .doc = "edges per second the driver takes before it raises the divider" },
	{ .key = "full_scale_hz", .type = PS_OPT_DOUBLE, .scope = PT, .roles = SENSOR, .def = "1100000",
	  .min = 1, .max = 1e9,
	  .doc = "the sensor's output saturation at divider 1 (default about 1 MHz, unconfirmed: set it from the datasheet): a reading "
	         "at it times factor is saturation" },
	{ .key = "gap", .type = PS_OPT_DOUBLE, .scope = PT, .roles = SENSOR, .def = "3",
	  .min = 1.1, .max = 1000,
	  .doc = "an interval this many times the shortest in a gate means lost edges" },
	{ .key = "s0", .type = PS_OPT_LONG, .scope = PT, .roles = SENSOR, .min = 0, .max = 1023,
	  .doc = "the sensitivity pin S0's line" },
	{ .key = "s1", .type = PS_OPT_LONG, .scope = PT, .roles = SENSOR, .min = 0, .max = 1023,
	  .doc = "the sensitivity pin S1's line" },
	{ .key = "s2", .type = PS_OPT_LONG, .scope = PT, .roles = SENSOR, .min = 0, .max = 1023,
	  .doc = "the divider pin S2's line (with s3)" },
	{ .key = "s3", .type = PS_OPT_LONG, .scope = PT, .roles = SENSOR, .min = 0, .max = 1023,
	  .doc = "the divider pin S3's line (with s2)" },
	{ .key = "sensitivity", .type = PS_OPT_LONG, .scope = PT, .roles = SENSOR, .def = "1",
	  .names = sensitivities, .doc = "the sensitivity set on s0 and s1" },
	{ .key = NULL },
};
#undef PT
#undef RELAY
#undef INPUT
#undef SENSOR

/* The rules across a point's keys; errors through the reader. */
static int check_point(const struct ps_opts_reader *r, int role)
{
	const struct ps_opts *o = r->opts;
	if (role != PS_ROLE_RELAY && role != PS_ROLE_INPUT && role != PS_ROLE_SENSOR)
		return ps_opts_fail(r, "line", "gpio: no %s points (relay, input and frequency sensors)", ps_role_name(role));
	if (!ps_opts_get(o, "line"))
		return ps_opts_fail(r, "line", "gpio: 'line' (the line's offset on the chip) is required");
	if (role == PS_ROLE_SENSOR && !ps_opts_get(o, "kind"))
		return ps_opts_fail(r, "kind", "gpio: a sensor point needs kind = frequency (a light-to-frequency sensor)");
	if (!ps_opts_get(o, "s2") != !ps_opts_get(o, "s3"))
		return ps_opts_fail(r, ps_opts_get(o, "s2") ? "s2" : "s3", "gpio: the divider needs both s2 and s3");
	return 0;
}

static int gpio_check(const struct ps_opts *o, int role, int *line, char *why, size_t n)
{
	struct ps_opts_reader r = { o, gpio_options, PS_OPT_POINT, why, n, line };
	return role < 0 ? 0 : check_point(&r, role);
}

static int gpio_open(struct ps_dev *dev, const struct ps_opts *o)
{
	struct gpio_dev *g = calloc(1, sizeof *g);
	struct ps_opts_reader r = { o, gpio_options, PS_OPT_DEVICE, dev->err, sizeof dev->err, NULL };
	const char *chip = NULL, *consumer = NULL;
	if (!g)
		return ps_dev_fail(dev, ENOMEM, "out of memory");
	dev->priv = g;
	g->epfd = -1;
	if (ps_opts_string(&r, "chip", &chip) || ps_opts_string(&r, "consumer", &consumer))
		return -1;
	snprintf(g->chipname, sizeof g->chipname, "%s", chip);
	snprintf(g->consumer, sizeof g->consumer, "%s", consumer);
	/* by path, name, label or number; not by scanning /dev (see the man page) */
	if (!(g->chip = gpiod_chip_open_lookup(g->chipname)))
		return ps_dev_fail(dev, errno ? errno : ENODEV, "gpio: cannot open chip %s: %s", g->chipname,
		                   strerror(errno ? errno : ENODEV));
	if ((g->epfd = epoll_create1(EPOLL_CLOEXEC)) < 0)
		return ps_dev_fail(dev, errno, "gpio: epoll: %s", strerror(errno));
	return 0;
}

/* The line a key names, or NULL: absent (errno 0; the check said whether
 * it is required) or a failure (errno set, dev->err). */
static struct gpiod_line *get_line(struct ps_dev *dev, const struct ps_opts *o, const char *key, int *offset)
{
	struct gpio_dev *g = dev->priv;
	struct ps_opts_reader r = { o, gpio_options, PS_OPT_POINT, dev->err, sizeof dev->err, NULL };
	long n = -1;
	struct gpiod_line *l;
	if (ps_opts_long(&r, key, &n) != 0)
		return NULL;
	if (n < 0) {
		errno = 0;
		return NULL;
	}
	if (!(l = gpiod_chip_get_line(g->chip, (unsigned)n))) {
		ps_dev_fail(dev, EINVAL, "%s:%d: %s: %s has no line %ld (%u lines)", o->file, ps_opts_line(o, key), key,
		            g->chipname, n, gpiod_chip_num_lines(g->chip));
		return NULL;
	}
	*offset = (int)n;
	return l;
}

static int request(struct ps_dev *dev, const struct ps_opts *o, const char *key, struct gpiod_line *l, int type,
                   int flags, int value)
{
	struct gpio_dev *g = dev->priv;
	struct gpiod_line_request_config cfg = { g->consumer, type, flags };
	if (gpiod_line_request(l, &cfg, value) != 0)
		return ps_dev_fail(dev, errno, "%s:%d: %s: line %u of %s: %s%s", o->file, ps_opts_line(o, key), key,
		                   gpiod_line_offset(l), g->chipname, strerror(errno),
		                   errno == EBUSY ? " (another program holds it)" : "");
	return 0;
}

static int watch(struct ps_dev *dev, struct gpio_point *p)
{
	struct gpio_dev *g = dev->priv;
	struct epoll_event ev = { .events = EPOLLIN };
	ev.data.ptr = p;
	if (epoll_ctl(g->epfd, EPOLL_CTL_ADD, gpiod_line_event_get_fd(p->line), &ev) != 0)
		return ps_dev_fail(dev, errno, "gpio: epoll: %s", strerror(errno));
	return 0;
}

static int add_frequency(struct ps_dev *dev, struct gpio_point *p, const struct ps_opts *o)
{
	struct ps_opts_reader r = { o, gpio_options, PS_OPT_POINT, dev->err, sizeof dev->err, NULL };
	long sens;
	int off;
	struct gpiod_line *s0, *s1;
	if (ps_opts_double(&r, "gate", &p->gate) || ps_opts_double(&r, "factor", &p->factor) ||
	    ps_opts_double(&r, "max_rate", &p->max_rate) || ps_opts_double(&r, "gap", &p->gap) ||
	    ps_opts_double(&r, "full_scale_hz", &p->full_scale_hz) ||
	    ps_opts_long(&r, "sensitivity", &sens))
		return -1;
	if (!(p->line = get_line(dev, o, "line", &p->offset)) ||
	    request(dev, o, "line", p->line, GPIOD_LINE_REQUEST_EVENT_RISING_EDGE, 0, 0) != 0)
		return -1;
	/* the divider pins, output, starting at /1 (the check made sure both or
	 * neither are given); the sensitivity pins fixed */
	if (!(p->s2 = get_line(dev, o, "s2", &off)) && errno)
		return -1;
	if (!(p->s3 = get_line(dev, o, "s3", &off)) && errno)
		return -1;
	if (p->s2 && (request(dev, o, "s2", p->s2, GPIOD_LINE_REQUEST_DIRECTION_OUTPUT, 0, 0) != 0 ||
	              request(dev, o, "s3", p->s3, GPIOD_LINE_REQUEST_DIRECTION_OUTPUT, 0, 0) != 0))
		return -1;
	if (!(s0 = get_line(dev, o, "s0", &off)) && errno)
		return -1;
	if (!(s1 = get_line(dev, o, "s1", &off)) && errno)
		return -1;
	/* S1 S0: 01 x1, 10 x10, 11 x100 */
	if (s0 && request(dev, o, "s0", s0, GPIOD_LINE_REQUEST_DIRECTION_OUTPUT, 0, sens != 10) != 0)
		return -1;
	if (s1 && request(dev, o, "s1", s1, GPIOD_LINE_REQUEST_DIRECTION_OUTPUT, 0, sens != 1) != 0)
		return -1;
	p->kind = 1;
	p->div = 0;
	p->gate_end = NAN;   /* the first service starts the first gate */
	ps_freq_gate_reset(&p->g);
	return watch(dev, p);
}

static int add_input(struct ps_dev *dev, struct gpio_point *p, const struct ps_opts *o, int flags)
{
	struct ps_opts_reader r = { o, gpio_options, PS_OPT_POINT, dev->err, sizeof dev->err, NULL };
	int bias;
	if (ps_opts_choice(&r, "edge", &p->edge) || ps_opts_choice(&r, "bias", &bias) ||
	    ps_opts_double(&r, "debounce", &p->debounce) || !(p->line = get_line(dev, o, "line", &p->offset)))
		return -1;
	flags |= bias == 1 ? GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_UP : bias == 2 ? GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_DOWN
	         : bias == 3 ? GPIOD_LINE_REQUEST_FLAG_BIAS_DISABLE : 0;
	/* both edges always: debouncing needs to see the bounce settle; edge
	 * chooses which changes are events */
	if (request(dev, o, "line", p->line, GPIOD_LINE_REQUEST_EVENT_BOTH_EDGES, flags, 0) != 0 || watch(dev, p) != 0)
		return -1;
	p->state = gpiod_line_get_value(p->line);
	return 0;
}

static int gpio_add_point(struct ps_dev *dev, struct ps_point *pt, const struct ps_opts *o)
{
	struct gpio_dev *g = dev->priv;
	struct ps_opts_reader r = { o, gpio_options, PS_OPT_POINT, dev->err, sizeof dev->err, NULL };
	struct gpio_point *p;
	int flags, init = 0, rc;
	if (g->np >= GPIO_MAX_POINTS)
		return ps_dev_fail(dev, EINVAL, "gpio: at most %d points per chip", GPIO_MAX_POINTS);
	if (ps_dev_check(dev, o, pt->role) != 0)
		return -1;
	p = &g->p[g->np];
	memset(p, 0, sizeof *p);
	p->pt = pt;
	p->role = pt->role;
	p->state = p->pending = -1;
	if (pt->role != PS_ROLE_SENSOR && ps_opts_choice(&r, "active_low", &p->active_low) != 0)
		return -1;
	flags = p->active_low ? GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW : 0;
	if (pt->role == PS_ROLE_RELAY)
		rc = ps_opts_choice(&r, "initial", &init) || !(p->line = get_line(dev, o, "line", &p->offset)) ||
		     request(dev, o, "line", p->line, GPIOD_LINE_REQUEST_DIRECTION_OUTPUT, flags, init) != 0 ? -1 : 0;
	else if (pt->role == PS_ROLE_INPUT)
		rc = add_input(dev, p, o, flags);
	else
		rc = add_frequency(dev, p, o);   /* a sensor (the check took no other role) */
	if (rc != 0)
		return -1;
	pt->priv = p;
	g->np++;
	return 0;
}

static void set_divider(struct gpio_point *p, int idx)
{
	int s2, s3;
	if (!p->s2 || idx == p->div)
		return;
	ps_freq_divider_pins(idx, &s2, &s3);
	gpiod_line_set_value(p->s2, s2);
	gpiod_line_set_value(p->s3, s3);
	p->div = idx;
	p->settle = 1;   /* the gate under way mixes two dividers: drop it */
}

/* A gate ends: its frequency, the overrun rule, the next divider. */
static void close_gate(struct gpio_point *p, double now)
{
	double hz = ps_freq_gate_hz(&p->g, p->gate);
	int over = ps_freq_gate_overran(&p->g, p->gap);
	int next;
	if (p->settle) {
		p->settle = 0;
	} else if (over) {
		p->overran = 1;
		p->overrun_hz = hz;
		p->overrun_div = ps_freq_dividers[p->div];
	} else {
		p->overran = 0;
		p->value = hz * ps_freq_dividers[p->div] * p->factor;
		p->have_value = 1;
	}
	next = p->s2 ? ps_freq_next_divider(p->div, hz, p->max_rate, over) : p->div;
	set_divider(p, next);
	ps_freq_gate_reset(&p->g);
	p->gate_end = now + p->gate;
}

static void drain(struct gpio_point *p, double now)
{
	struct gpiod_line_event ev[PS_FREQ_KERNEL_FIFO];
	/* Bounded: edges arriving faster than they are read would keep this
	 * loop going forever and starve the control socket and the other
	 * devices.  A line still readable afterwards brings the poll loop back
	 * at once; at such rates the kernel buffer is full at every read, so
	 * the gate counts as overrun (never as a low rate). */
	for (int reads = 0; reads < 64; reads++) {
		struct pollfd pf = { gpiod_line_event_get_fd(p->line), POLLIN, 0 };
		int n;
		if (poll(&pf, 1, 0) <= 0)
			return;
		n = gpiod_line_event_read_multiple(p->line, ev, PS_FREQ_KERNEL_FIFO);
		if (n <= 0)
			return;
		if (p->kind == 1) {
			ps_freq_gate_read(&p->g, n);
			for (int i = 0; i < n; i++)
				ps_freq_gate_edge(&p->g, (uint64_t)ev[i].ts.tv_sec * 1000000000ull + (uint64_t)ev[i].ts.tv_nsec);
		} else {
			/* an input: the last edge decides what it may settle to */
			int v = ev[n - 1].event_type == GPIOD_LINE_EVENT_RISING_EDGE;
			p->pending = v;
			p->pending_until = now + p->debounce;
		}
	}
}

static int gpio_service(struct ps_dev *dev, double now, double mono)
{
	(void)mono;
	struct gpio_dev *g = dev->priv;
	if (!g)
		return 0;
	g->now = now;
	for (int i = 0; i < g->np; i++) {
		struct gpio_point *p = &g->p[i];
		if (p->role == PS_ROLE_RELAY)
			continue;
		drain(p, now);
		if (p->kind == 1) {
			if (isnan(p->gate_end)) {
				ps_freq_gate_reset(&p->g);
				p->gate_end = now + p->gate;
			} else if (now >= p->gate_end) {
				close_gate(p, now);
			}
		} else if (p->pending >= 0 && now >= p->pending_until) {
			/* stable for the debounce time: the level now is the event */
			int v = gpiod_line_get_value(p->line);
			p->pending = -1;
			if (v >= 0 && v != p->state) {
				p->state = v;
				if ((p->edge == 0 || (p->edge == 1 && v) || (p->edge == 2 && !v)) && dev->on_event)
					dev->on_event(dev->event_user, dev, p->pt, now, v);
			}
		}
	}
	return 0;
}

static int gpio_fd(struct ps_dev *dev)
{
	struct gpio_dev *g = dev->priv;
	return g ? g->epfd : -1;
}

static double gpio_deadline(struct ps_dev *dev, double *mono)
{
	(void)mono;
	struct gpio_dev *g = dev->priv;
	double t = INFINITY;
	for (int i = 0; g && i < g->np; i++) {
		const struct gpio_point *p = &g->p[i];
		if (p->kind == 1)
			t = isnan(p->gate_end) ? -INFINITY : fmin(t, p->gate_end);
		else if (p->pending >= 0)
			t = fmin(t, p->pending_until);
	}
	return t;
}

static int gpio_read(struct ps_dev *dev, struct ps_point *pt, double now, double mono, double *value)
{
	(void)mono;
	struct gpio_point *p = pt->priv;
	(void)now;
	if (p->role == PS_ROLE_SENSOR) {
		if (p->overran)
			return ps_dev_fail(dev, EOVERFLOW, "gpio %s line %d: edges lost at %.0f edges/s with the divider at "
			                   "/%d (the kernel keeps 16 events)%s", dev->name, p->offset, p->overrun_hz,
			                   p->overrun_div, p->s2 ? "" : "; no divider pins: set s2 and s3, or lower max_rate");
		if (!p->have_value)
			return ps_dev_fail(dev, ETIMEDOUT, "gpio %s line %d: no complete gate yet", dev->name, p->offset);
		*value = p->value;
		return 0;
	}
	*value = gpiod_line_get_value(p->line);
	if (*value < 0)
		return ps_dev_fail(dev, errno, "gpio %s line %d: %s", dev->name, p->offset, strerror(errno));
	return 0;
}

static int gpio_full_scale(struct ps_dev *dev, struct ps_point *pt, double *limit)
{
	const struct gpio_point *p = pt->priv;
	(void)dev;
	if (!p || p->role != PS_ROLE_SENSOR)
		return -1;
	*limit = p->full_scale_hz * p->factor;
	return 0;
}

static int gpio_write(struct ps_dev *dev, struct ps_point *pt, double now, double mono, double value)
{
	(void)mono;
	struct gpio_point *p = pt->priv;
	(void)now;
	if (p->role != PS_ROLE_RELAY)
		return ps_dev_fail(dev, EINVAL, "gpio: %s is not a relay", pt->name);
	if (gpiod_line_set_value(p->line, value > 0.5) != 0)
		return ps_dev_fail(dev, errno, "gpio %s line %d: %s", dev->name, p->offset, strerror(errno));
	return 0;
}

static void gpio_close(struct ps_dev *dev)
{
	struct gpio_dev *g = dev->priv;
	if (!g)
		return;
	if (g->epfd >= 0)
		close(g->epfd);
	/* closing the chip releases every line it handed out */
	if (g->chip)
		gpiod_chip_close(g->chip);
	free(g);
	dev->priv = NULL;
}

const struct ps_driver ps_driver_gpio = {
	.name = "gpio",
	.summary = "GPIO relays, buttons, occupancy and light-to-frequency sensors (libgpiod)",
	.compiled_in = 1,
	.options = gpio_options,
	.check = gpio_check,
	.open = gpio_open,
	.add_point = gpio_add_point,
	.read = gpio_read,
	.write = gpio_write,
	.fd = gpio_fd,
	.deadline = gpio_deadline,
	.service = gpio_service,
	.close = gpio_close,
	.full_scale = gpio_full_scale,
};
