/* The GPIO driver (libgpiod 1.6, the kernel's v1 character-device
 * interface): relays, buttons and occupancy inputs, and light-to-frequency
 * sensors of the TSL230R kind.  See psensd-gpio(7).
 *
 * Device options: chip (a path, name, label or number: gpiochip0,
 * /dev/gpiochip0, 0), consumer (the label the kernel shows, "psensd").
 * Point options:
 *   relay   line, active_low (no), initial (off)
 *   input   line, active_low, edge (both|rising|falling), debounce (0.02 s),
 *           bias (as-is|pull-up|pull-down|disable)
 *   sensor  kind = frequency, line, gate (1 s), factor (signal per Hz, 1),
 *           max_rate (edges per second the driver will take, 2000),
 *           s2, s3 (the divider pins; without them the divider is 1),
 *           s0, s1 and sensitivity (1|10|100) for the sensitivity pins,
 *           gap (3: an interval this many times the shortest is lost edges)
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

static const char *const yesno[] = { "no", "yes", NULL };

static int gpio_open(struct ps_dev *dev, const struct ps_opts *o)
{
	struct gpio_dev *g = calloc(1, sizeof *g);
	const char *chip = ps_opt_get(o, "chip"), *consumer = ps_opt_get(o, "consumer");
	if (!g)
		return ps_dev_fail(dev, ENOMEM, "out of memory");
	dev->priv = g;
	g->epfd = -1;
	snprintf(g->chipname, sizeof g->chipname, "%s", chip ? chip : "gpiochip0");
	snprintf(g->consumer, sizeof g->consumer, "%s", consumer ? consumer : "psensd");
	/* by path, name, label or number; not by scanning /dev (see the man page) */
	if (!(g->chip = gpiod_chip_open_lookup(g->chipname)))
		return ps_dev_fail(dev, errno ? errno : ENODEV, "gpio: cannot open chip %s: %s", g->chipname,
		                   strerror(errno ? errno : ENODEV));
	if ((g->epfd = epoll_create1(EPOLL_CLOEXEC)) < 0)
		return ps_dev_fail(dev, errno, "gpio: epoll: %s", strerror(errno));
	return 0;
}

static struct gpiod_line *get_line(struct ps_dev *dev, const struct ps_opts *o, const char *key, int required,
                                   int *offset)
{
	struct gpio_dev *g = dev->priv;
	long n;
	struct gpiod_line *l;
	if (!ps_opt_get(o, key)) {
		if (required)
			ps_dev_fail(dev, EINVAL, "%s:%d: gpio: '%s' (the line's offset on %s) is required", o->file,
			            ps_opt_line(o, "device"), key, g->chipname);
		else
			errno = 0;
		return NULL;
	}
	if (ps_opt_long(o, key, 0, 0, 1023, &n, dev->err, sizeof dev->err) != 0)
		return NULL;
	if (!(l = gpiod_chip_get_line(g->chip, (unsigned)n))) {
		ps_dev_fail(dev, EINVAL, "%s:%d: %s: %s has no line %ld (%u lines)", o->file, ps_opt_line(o, key), key,
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
		return ps_dev_fail(dev, errno, "%s:%d: %s: line %u of %s: %s%s", o->file, ps_opt_line(o, key), key,
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
	long sens;
	int off, flags = 0;
	struct gpiod_line *s0, *s1;
	if (ps_opt_double(o, "gate", 1, 0.01, 3600, &p->gate, dev->err, sizeof dev->err) ||
	    ps_opt_double(o, "factor", 1, 1e-12, 1e12, &p->factor, dev->err, sizeof dev->err) ||
	    ps_opt_double(o, "max_rate", 2000, 1, 1e7, &p->max_rate, dev->err, sizeof dev->err) ||
	    ps_opt_double(o, "gap", 3, 1.1, 1000, &p->gap, dev->err, sizeof dev->err) ||
	    ps_opt_long(o, "sensitivity", 1, 1, 100, &sens, dev->err, sizeof dev->err))
		return -1;
	if (sens != 1 && sens != 10 && sens != 100)
		return ps_dev_fail(dev, EINVAL, "%s:%d: sensitivity: %ld is not 1, 10 or 100", o->file,
		                   ps_opt_line(o, "sensitivity"), sens);
	if (!(p->line = get_line(dev, o, "line", 1, &p->offset)))
		return -1;
	if (request(dev, o, "line", p->line, GPIOD_LINE_REQUEST_EVENT_RISING_EDGE, flags, 0) != 0)
		return -1;
	/* the divider pins, output, starting at /1; the sensitivity pins fixed */
	p->s2 = get_line(dev, o, "s2", 0, &off);
	if (!p->s2 && errno)
		return -1;
	p->s3 = get_line(dev, o, "s3", 0, &off);
	if (!p->s3 && errno)
		return -1;
	if ((p->s2 != NULL) != (p->s3 != NULL))
		return ps_dev_fail(dev, EINVAL, "%s:%d: gpio: the divider needs both s2 and s3", o->file,
		                   ps_opt_line(o, p->s2 ? "s2" : "s3"));
	if (p->s2 && (request(dev, o, "s2", p->s2, GPIOD_LINE_REQUEST_DIRECTION_OUTPUT, 0, 0) != 0 ||
	              request(dev, o, "s3", p->s3, GPIOD_LINE_REQUEST_DIRECTION_OUTPUT, 0, 0) != 0))
		return -1;
	s0 = get_line(dev, o, "s0", 0, &off);
	if (!s0 && errno)
		return -1;
	s1 = get_line(dev, o, "s1", 0, &off);
	if (!s1 && errno)
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

static int gpio_add_point(struct ps_dev *dev, struct ps_point *pt, const struct ps_opts *o)
{
	struct gpio_dev *g = dev->priv;
	struct gpio_point *p;
	int al = 0, flags, init = 0, edge = 0, bias = 0;
	static const char *const onoff[] = { "off", "on", NULL };
	static const char *const edges[] = { "both", "rising", "falling", NULL };
	static const char *const biases[] = { "as-is", "pull-up", "pull-down", "disable", NULL };
	const char *kind;
	if (g->np >= GPIO_MAX_POINTS)
		return ps_dev_fail(dev, EINVAL, "gpio: at most %d points per chip", GPIO_MAX_POINTS);
	p = &g->p[g->np];
	memset(p, 0, sizeof *p);
	p->pt = pt;
	p->role = pt->role;
	p->state = p->pending = -1;
	if (ps_opt_enum(o, "active_low", yesno, 0, &al, dev->err, sizeof dev->err) != 0)
		return -1;
	p->active_low = al;
	flags = al ? GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW : 0;
	switch (pt->role) {
	case PS_ROLE_RELAY:
		if (ps_opt_enum(o, "initial", onoff, 0, &init, dev->err, sizeof dev->err) != 0 ||
		    !(p->line = get_line(dev, o, "line", 1, &p->offset)) ||
		    request(dev, o, "line", p->line, GPIOD_LINE_REQUEST_DIRECTION_OUTPUT, flags, init) != 0)
			return -1;
		break;
	case PS_ROLE_INPUT:
		if (ps_opt_enum(o, "edge", edges, 0, &edge, dev->err, sizeof dev->err) != 0 ||
		    ps_opt_enum(o, "bias", biases, 0, &bias, dev->err, sizeof dev->err) != 0 ||
		    ps_opt_double(o, "debounce", 0.02, 0, 10, &p->debounce, dev->err, sizeof dev->err) != 0 ||
		    !(p->line = get_line(dev, o, "line", 1, &p->offset)))
			return -1;
		flags |= bias == 1 ? GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_UP : bias == 2 ? GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_DOWN
		         : bias == 3 ? GPIOD_LINE_REQUEST_FLAG_BIAS_DISABLE : 0;
		/* both edges always: debouncing needs to see the bounce settle */
		(void)edge;
		if (request(dev, o, "line", p->line, GPIOD_LINE_REQUEST_EVENT_BOTH_EDGES, flags, 0) != 0 ||
		    watch(dev, p) != 0)
			return -1;
		p->edge = edge;
		p->state = gpiod_line_get_value(p->line);
		break;
	case PS_ROLE_SENSOR:
		kind = ps_opt_get(o, "kind");
		if (!kind || strcmp(kind, "frequency") != 0)
			return ps_dev_fail(dev, EINVAL, "%s:%d: gpio: a sensor point needs kind = frequency (a "
			                   "light-to-frequency sensor)", o->file, kind ? ps_opt_line(o, "kind") : 0);
		if (add_frequency(dev, p, o) != 0)
			return -1;
		break;
	default:
		return ps_dev_fail(dev, EINVAL, "gpio: no %s points (relay, input and frequency sensors)",
		                   ps_role_name(pt->role));
	}
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

static void drain(struct ps_dev *dev, struct gpio_point *p, double now)
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
		(void)dev;
	}
}

static int gpio_service(struct ps_dev *dev, double now)
{
	struct gpio_dev *g = dev->priv;
	if (!g)
		return 0;
	g->now = now;
	for (int i = 0; i < g->np; i++) {
		struct gpio_point *p = &g->p[i];
		if (p->role == PS_ROLE_RELAY)
			continue;
		drain(dev, p, now);
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

static double gpio_deadline(struct ps_dev *dev)
{
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

static int gpio_read(struct ps_dev *dev, struct ps_point *pt, double now, double *value)
{
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

static int gpio_write(struct ps_dev *dev, struct ps_point *pt, double now, double value)
{
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
	.open = gpio_open,
	.add_point = gpio_add_point,
	.read = gpio_read,
	.write = gpio_write,
	.fd = gpio_fd,
	.deadline = gpio_deadline,
	.service = gpio_service,
	.close = gpio_close,
};
