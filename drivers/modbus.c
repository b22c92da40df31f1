/* SPDX-License-Identifier: ISC */
/* The Modbus driver (libmodbus): analog input and output modules and task lux
 * meters over Modbus TCP or RTU.  psensd-modbus(5) documents every option.
 *
 * Its options, device and point keys, are the table ps_modbus_point_options in
 * modbus_point.c.
 *
 * Never a long block: every transaction is bounded by the response timeout
 * times (retries + 1), plus a TCP connect bounded by the same timeout per
 * try; after a timeout or a garbled reply a TCP connection is replaced (a
 * late reply must not be taken for the next request's); a lost connection
 * is closed and retried only when
 * `now` has passed the backoff, which doubles from backoff_min to
 * backoff_max while the device stays away.  Failures follow driver.h:
 * exceptions and garbled replies EPROTO, no reply ETIMEDOUT, connection
 * gone ENODEV, values outside their range ERANGE; dev->err names device,
 * unit, table and address ("modbus io1 unit 1 IR 0: exception 2 (illegal
 * data address)"). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <modbus.h>

#include "driver.h"
#include "modbus.h"
#include "modbus_point.h"

struct mb_point {
	struct ps_modbus_point cfg;
	struct ps_point *pt;
	/* the last poll (period > 0): its time, value or failure */
	double polled_at, next_poll;
	double value;
	int err;              /* 0, or the errno of the last poll */
	char errmsg[256];
	int have;             /* polled at least once */
};

struct mb_dev {
	modbus_t *ctx;
	char where[160];      /* "127.0.0.1:502" or "/dev/ttyUSB0" */
	int tcp;
	int unit;
	double timeout;
	long retries, lost_after;
	double backoff_min, backoff_max;
	int connected;
	double backoff;       /* the wait before the next connection attempt */
	double next_connect;  /* no attempt before this time */
	char lost_why[128];   /* why the connection is down */
	long timeouts;        /* timeouts in a row */
	struct mb_point **pts;
	size_t npts;
};

/* Exceptions by code, as the Modbus specification names them. */
static const char *exception_name(int code)
{
	static const char *const names[] = { "?", "illegal function", "illegal data address",
		"illegal data value", "server device failure", "acknowledge", "server device busy",
		"negative acknowledge", "memory parity error", "?", "gateway path unavailable",
		"gateway target device failed to respond" };
	return code > 0 && code < (int)(sizeof names / sizeof names[0]) ? names[code] : "?";
}

static void set_timeout(modbus_t *ctx, double s, int byte)
{
	uint32_t sec = (uint32_t)s, usec = (uint32_t)((s - sec) * 1e6);
	if (byte)
		modbus_set_byte_timeout(ctx, sec, usec);
	else
		modbus_set_response_timeout(ctx, sec, usec);
}

/* Close; the next attempt comes after wait seconds, and each failed attempt
 * after that doubles the wait (wait 0: try at once, then backoff_min). */
static void drop_connection(struct mb_dev *m, double now, double wait, const char *why)
{
	if (m->connected)
		modbus_close(m->ctx);
	m->connected = 0;
	m->timeouts = 0;
	m->next_connect = now + wait;
	m->backoff = wait > 0 ? fmin(2 * wait, m->backoff_max) : m->backoff_min;
	snprintf(m->lost_why, sizeof m->lost_why, "%s", why);
}

static int connect_now(struct ps_dev *dev, struct mb_dev *m, double now)
{
	int e;
	if (m->connected)
		return 0;
	if (now < m->next_connect)
		return ps_dev_fail(dev, ENODEV, "modbus %s (%s): not connected (%s); next attempt in %.1f s",
		                   dev->name, m->where, m->lost_why, m->next_connect - now);
	if (modbus_connect(m->ctx) == 0) {
		m->connected = 1;
		m->backoff = m->backoff_min;
		m->timeouts = 0;
		return 0;
	}
	e = errno;
	modbus_close(m->ctx);   /* libmodbus keeps a half-open socket or tty otherwise */
	snprintf(m->lost_why, sizeof m->lost_why, "cannot connect: %s", modbus_strerror(e));
	m->next_connect = now + m->backoff;
	ps_dev_fail(dev, ENODEV, "modbus %s (%s): %s; next attempt in %.1f s", dev->name, m->where,
	            m->lost_why, m->backoff);
	m->backoff = fmin(2 * m->backoff, m->backoff_max);
	return -1;
}

static int mb_open(struct ps_dev *dev, const struct ps_opts *o)
{
	struct mb_dev *m = calloc(1, sizeof *m);
	struct ps_opts_reader r = { o, ps_modbus_point_options, PS_OPT_DEVICE, dev->err, sizeof dev->err, NULL };
	const char *host = NULL, *device = NULL;
	long port, unit, baud, bits, stop;
	int parity;
	double byte_timeout;
	if (!m)
		return ps_dev_fail(dev, ENOMEM, "out of memory");
	dev->priv = m;
	if (ps_modbus_point_check_device(o, dev->err, sizeof dev->err) != 0 || ps_opts_string(&r, "host", &host) ||
	    ps_opts_string(&r, "device", &device) || ps_opts_long(&r, "unit", &unit) ||
	    ps_opts_double(&r, "timeout", &m->timeout) || ps_opts_double(&r, "byte_timeout", &byte_timeout) ||
	    ps_opts_long(&r, "retries", &m->retries) || ps_opts_double(&r, "backoff_min", &m->backoff_min) ||
	    ps_opts_double(&r, "backoff_max", &m->backoff_max) || ps_opts_long(&r, "lost_after", &m->lost_after))
		return -1;
	if (host) {
		char portstr[16];
		if (ps_opts_long(&r, "port", &port))
			return -1;
		snprintf(portstr, sizeof portstr, "%ld", port);
		snprintf(m->where, sizeof m->where, "%s:%ld", host, port);
		m->tcp = 1;
		m->ctx = modbus_new_tcp_pi(host, portstr);
	} else {
		if (ps_opts_long(&r, "baud", &baud) || ps_opts_choice(&r, "parity", &parity) ||
		    ps_opts_long(&r, "data_bits", &bits) || ps_opts_long(&r, "stop_bits", &stop))
			return -1;
		snprintf(m->where, sizeof m->where, "%s", device);
		m->ctx = modbus_new_rtu(device, (int)baud, "NEO"[parity], (int)bits, (int)stop);
	}
	if (!m->ctx)
		return ps_dev_fail(dev, errno ? errno : ENOMEM, "modbus %s (%s): %s", dev->name, m->where,
		                   modbus_strerror(errno));
	m->unit = (int)unit;
	set_timeout(m->ctx, m->timeout, 0);
	if (byte_timeout > 0)
		set_timeout(m->ctx, byte_timeout, 1);
	else
		modbus_set_byte_timeout(m->ctx, 0, 0);   /* only the response timeout */
	modbus_set_error_recovery(m->ctx, MODBUS_ERROR_RECOVERY_NONE);   /* we recover, without sleeping */
	m->backoff = m->backoff_min;
	m->next_connect = -INFINITY;
	snprintf(m->lost_why, sizeof m->lost_why, "never connected");
	/* the first connection is tried now; a device that is not there yet is
	 * tried again by the first read or write, and from then on with backoff */
	if (modbus_connect(m->ctx) == 0)
		m->connected = 1;
	else
		modbus_close(m->ctx);
	return 0;
}

static int mb_add_point(struct ps_dev *dev, struct ps_point *pt, const struct ps_opts *o)
{
	struct mb_dev *m = dev->priv;
	struct mb_point *p, **grown;
	if (!m)
		return ps_dev_fail(dev, EINVAL, "modbus: device not open");
	p = calloc(1, sizeof *p);
	if (!p)
		return ps_dev_fail(dev, ENOMEM, "out of memory");
	if (ps_modbus_point_parse(&p->cfg, pt->role, o, dev->err, sizeof dev->err) != 0) {
		free(p);
		return -1;
	}
	grown = realloc(m->pts, (m->npts + 1) * sizeof *grown);
	if (!grown) {
		free(p);
		return ps_dev_fail(dev, ENOMEM, "out of memory");
	}
	m->pts = grown;
	m->pts[m->npts++] = p;
	p->pt = pt;
	p->next_poll = -INFINITY;
	pt->priv = p;
	return 0;
}

/* Turn a failed libmodbus call into driver.h's errno and a message, and
 * decide about the connection.  Returns 1 when another try makes sense. */
static int classify(struct ps_dev *dev, struct mb_dev *m, const struct mb_point *p, int e,
                    double now, int *out)
{
	char what[96];
	int unit = p->cfg.unit >= 0 ? p->cfg.unit : m->unit;
	snprintf(what, sizeof what, "modbus %s unit %d %s %d", dev->name, unit,
	         ps_modbus_point_table_short(p->cfg.table), p->cfg.address);
	if (e >= EMBXILFUN && e <= EMBXGTAR) {
		int code = e - MODBUS_ENOBASE;
		*out = EPROTO;
		ps_dev_fail(dev, EPROTO, "%s: exception %d (%s)", what, code, exception_name(code));
		return 0;   /* the device answered: asking again gives the same answer */
	}
	if (e == EMBBADCRC || e == EMBBADDATA || e == EMBBADEXC || e == EMBUNKEXC || e == EMBMDATA ||
	    e == EMBBADSLAVE || e == ETIMEDOUT) {
		*out = e == ETIMEDOUT ? ETIMEDOUT : EPROTO;
		if (e == ETIMEDOUT)
			ps_dev_fail(dev, ETIMEDOUT, "%s: no reply within %.3f s", what, m->timeout);
		else
			ps_dev_fail(dev, EPROTO, "%s: garbled reply (%s)", what, modbus_strerror(e));
		if (m->tcp) {
			/* a reply may still be on its way (late) or the stream is out of
			 * step: on TCP only a new connection is sure to carry nothing
			 * stale, and it costs one handshake; the next try opens it */
			drop_connection(m, now, 0, e == ETIMEDOUT ? "no reply" : "garbled reply");
			return 1;
		}
		/* a serial line: drop what has arrived; after lost_after timeouts
		 * in a row reopen the device (a USB adapter may have gone) */
		modbus_flush(m->ctx);
		if (e == ETIMEDOUT && ++m->timeouts >= m->lost_after) {
			drop_connection(m, now, 0, "no reply");
			return 0;
		}
		return 1;
	}
	/* anything else is the transport: reset, refused, broken pipe, tty gone */
	*out = ENODEV;
	ps_dev_fail(dev, ENODEV, "%s: connection lost (%s); next attempt in %.1f s", what,
	            modbus_strerror(e), m->backoff_min);
	drop_connection(m, now, m->backoff_min, modbus_strerror(e));
	return 0;
}

/* One request with its retries: read (write == NULL) or write the point's
 * registers or bit. */
static int transact(struct ps_dev *dev, struct mb_point *p, double now, uint16_t *regs,
                    int write)
{
	struct mb_dev *m = dev->priv;
	const struct ps_modbus_point *c = &p->cfg;
	int n = ps_modbus_point_count(c), err = 0;
	for (long attempt = 0; attempt <= m->retries; attempt++) {
		uint8_t bit;
		int rc, e;
		if (connect_now(dev, m, now) != 0)
			return -1;
		modbus_set_slave(m->ctx, c->unit >= 0 ? c->unit : m->unit);
		switch (c->table) {
		case PS_MB_INPUT_REGISTER: rc = modbus_read_input_registers(m->ctx, c->address, n, regs); break;
		case PS_MB_HOLDING_REGISTER:
			rc = !write ? modbus_read_registers(m->ctx, c->address, n, regs)
			   : n == 1 ? modbus_write_register(m->ctx, c->address, regs[0])
			            : modbus_write_registers(m->ctx, c->address, n, regs);
			break;
		case PS_MB_COIL:
			if (write)
				rc = modbus_write_bit(m->ctx, c->address, regs[0] != 0);
			else if ((rc = modbus_read_bits(m->ctx, c->address, 1, &bit)) >= 0)
				regs[0] = bit;
			break;
		default:
			if ((rc = modbus_read_input_bits(m->ctx, c->address, 1, &bit)) >= 0)
				regs[0] = bit;
			break;
		}
		e = errno;   /* before anything else can change it */
		if (rc >= 0) {
			m->timeouts = 0;
			return 0;
		}
		if (!classify(dev, m, p, e, now, &err))
			break;
	}
	errno = err;
	return -1;
}

static int read_now(struct ps_dev *dev, struct mb_point *p, double now, double *value)
{
	struct mb_dev *m = dev->priv;
	uint16_t regs[2] = { 0, 0 };
	char why[128];
	if (transact(dev, p, now, regs, 0) != 0)
		return -1;
	if (ps_modbus_point_value(&p->cfg, regs, value, why, sizeof why) != 0)
		return ps_dev_fail(dev, ERANGE, "modbus %s unit %d %s %d: %s", dev->name,
		                   p->cfg.unit >= 0 ? p->cfg.unit : m->unit, ps_modbus_point_table_short(p->cfg.table),
		                   p->cfg.address, why);
	return 0;
}

static int mb_read(struct ps_dev *dev, struct ps_point *pt, double now, double mono, double *value)
{
	(void)mono;
	struct mb_point *p = pt->priv;
	if (!p)
		return ps_dev_fail(dev, EINVAL, "modbus %s: %s is not a point of this device", dev->name,
		                   pt->name);
	/* a polled point answers from its last poll while that is fresh */
	if (p->cfg.period > 0 && p->have && now - p->polled_at <= p->cfg.period && now >= p->polled_at) {
		if (p->err) {
			snprintf(dev->err, sizeof dev->err, "%s", p->errmsg);
			errno = p->err;
			return -1;
		}
		*value = p->value;
		return 0;
	}
	return read_now(dev, p, now, value);
}

static int mb_write(struct ps_dev *dev, struct ps_point *pt, double now, double mono, double value)
{
	(void)mono;
	struct mb_point *p = pt->priv;
	uint16_t regs[2];
	if (!p)
		return ps_dev_fail(dev, EINVAL, "modbus %s: %s is not a point of this device", dev->name,
		                   pt->name);
	if (p->cfg.role != PS_ROLE_DIM && p->cfg.role != PS_ROLE_RELAY)
		return ps_dev_fail(dev, EINVAL, "modbus %s: %s is not an output", dev->name, pt->name);
	ps_modbus_point_encode(&p->cfg, value, regs);
	return transact(dev, p, now, regs, 1);
}

/* Polled points: the earliest poll due. */
static double mb_deadline(struct ps_dev *dev, double *mono)
{
	(void)mono;
	struct mb_dev *m = dev->priv;
	double next = INFINITY;
	for (size_t i = 0; m && i < m->npts; i++)
		if (m->pts[i]->cfg.period > 0 && m->pts[i]->next_poll < next)
			next = m->pts[i]->next_poll;
	if (m && next < m->next_connect && !m->connected)
		next = m->next_connect;
	return next;
}

static int mb_service(struct ps_dev *dev, double now, double mono)
{
	(void)mono;
	struct mb_dev *m = dev->priv;
	char first[256] = "";
	int first_err = 0;
	for (size_t i = 0; m && i < m->npts; i++) {
		struct mb_point *p = m->pts[i];
		double v, old = p->value;
		int had = p->have && !p->err;
		if (p->cfg.period <= 0 || p->next_poll > now)
			continue;
		/* keep the phase; after a stall, start again from now */
		p->next_poll = p->next_poll + p->cfg.period > now ? p->next_poll + p->cfg.period
		                                                 : now + p->cfg.period;
		p->polled_at = now;
		p->have = 1;
		if (read_now(dev, p, now, &v) != 0) {
			p->err = errno;
			snprintf(p->errmsg, sizeof p->errmsg, "%s", dev->err);
			if (!first_err) {
				first_err = p->err;
				snprintf(first, sizeof first, "%s", dev->err);
			}
			continue;
		}
		p->err = 0;
		p->value = v;
		if (p->cfg.role == PS_ROLE_INPUT && dev->on_event && (!had || v != old))
			dev->on_event(dev->event_user, dev, p->pt, now, v);
	}
	if (first_err)
		return ps_dev_fail(dev, first_err, "%s", first);
	return 0;
}

static void mb_close(struct ps_dev *dev)
{
	struct mb_dev *m = dev->priv;
	if (m) {
		if (m->ctx) {
			if (m->connected)
				modbus_close(m->ctx);
			modbus_free(m->ctx);
		}
		for (size_t i = 0; i < m->npts; i++)
			free(m->pts[i]);   /* the daemon's points may be gone: not touched */
		free(m->pts);
	}
	free(m);
	dev->priv = NULL;
}

static int mb_full_scale(struct ps_dev *dev, struct ps_point *pt, double *limit)
{
	const struct mb_point *p = pt->priv;
	(void)dev;
	return p ? ps_modbus_point_full_scale(&p->cfg, limit) : -1;
}

const struct ps_driver ps_driver_modbus = {
	.name = "modbus",
	.summary = "Modbus TCP and RTU (libmodbus): analog I/O modules and lux meters",
	.compiled_in = 1,
	.options = ps_modbus_point_options,
	.check = ps_modbus_point_check,
	.open = mb_open,
	.add_point = mb_add_point,
	.read = mb_read,
	.write = mb_write,
	.deadline = mb_deadline,
	.service = mb_service,
	.close = mb_close,
	.full_scale = mb_full_scale,
};
