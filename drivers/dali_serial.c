/* SPDX-License-Identifier: ISC */
/* A DALI interface on a tty or a TCP socket (dali_serial.h). */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <netdb.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include "dali_serial.h"

#define RXCAP 512
#define CONNECT_MS 2000

#define OBSCAP 32

struct ps_dali_serial {
	const struct ps_dali_codec *c;
	int fd;
	uint8_t rx[RXCAP];
	size_t rxlen;
	int busy;          /* a transaction waits for its reply */
	int replies_left;  /* final replies still to come (a frame the interface sends twice: one each) */
	struct ps_dali_serial_result first;   /* the first of two replies */
	double deadline;
	int expect_answer;
	int echoes_left;   /* an interface with an answer window: ECHOes still to come */
	int in_window;     /* ... all came: waiting for a backward frame until deadline */
	int stale;         /* the last transaction timed out: drop what is left before the next */
	double keepalive;  /* TCP: seconds of silence before a keep-alive, 0 none */
	double last_tx;    /* when we last wrote, -1 not yet (the first service() starts the count) */
	struct ps_dali_serial_stats st;
	/* other masters' and devices' frames not yet taken by the caller */
	uint32_t obs[OBSCAP];
	int obs_bits[OBSCAP];
	size_t obs_head, obs_len;
};

static speed_t speed_of(long baud)
{
	switch (baud) {
	case 1200: return B1200;
	case 2400: return B2400;
	case 4800: return B4800;
	case 9600: return B9600;
	case 19200: return B19200;
	case 38400: return B38400;
	case 57600: return B57600;
	case 115200: return B115200;
	}
	return 0;
}

static int open_tty(const char *path, long baud, char *err, size_t n)
{
	struct termios t;
	speed_t sp = speed_of(baud);
	int fd;
	if (!sp) {
		snprintf(err, n, "%s: %ld is not a serial speed (1200 to 115200)", path, baud);
		errno = EINVAL;
		return -1;
	}
	fd = open(path, O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
	if (fd < 0) {
		int e = errno;
		snprintf(err, n, "%s: %s", path, strerror(e));
		errno = e == ENOENT ? ENODEV : e;
		return -1;
	}
	if (tcgetattr(fd, &t) != 0) {
		int e = errno;
		snprintf(err, n, "%s: not a serial port: %s", path, strerror(e));
		close(fd);
		errno = EINVAL;
		return -1;
	}
	cfmakeraw(&t);
	t.c_cflag |= CLOCAL | CREAD;
	t.c_cflag &= ~(tcflag_t)(CSTOPB | PARENB | CRTSCTS);
	cfsetispeed(&t, sp);
	cfsetospeed(&t, sp);
	if (tcsetattr(fd, TCSANOW, &t) != 0) {
		int e = errno;
		snprintf(err, n, "%s: cannot set %ld 8N1: %s", path, baud, strerror(e));
		close(fd);
		errno = e;
		return -1;
	}
	tcflush(fd, TCIOFLUSH);
	return fd;
}

/* HOST:PORT, connected within CONNECT_MS (the one wait: at open). */
static int open_tcp(const char *where, char *err, size_t n)
{
	char host[256];
	const char *colon = strrchr(where, ':');
	struct addrinfo hints = { .ai_family = AF_UNSPEC, .ai_socktype = SOCK_STREAM }, *ai = NULL, *a;
	int fd = -1, e = ECONNREFUSED, r;
	if (!colon || colon == where || !colon[1] || (size_t)(colon - where) >= sizeof host) {
		snprintf(err, n, "%s: neither a device path (/dev/...) nor HOST:PORT", where);
		errno = EINVAL;
		return -1;
	}
	memcpy(host, where, (size_t)(colon - where));
	host[colon - where] = 0;
	if ((r = getaddrinfo(host, colon + 1, &hints, &ai)) != 0) {
		snprintf(err, n, "%s: %s", where, gai_strerror(r));
		errno = ENODEV;
		return -1;
	}
	for (a = ai; a; a = a->ai_next) {
		struct pollfd p;
		socklen_t sl = sizeof e;
		fd = socket(a->ai_family, a->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, a->ai_protocol);
		if (fd < 0) {
			e = errno;
			continue;
		}
		if (connect(fd, a->ai_addr, a->ai_addrlen) == 0)
			break;
		e = errno;
		if (e == EINPROGRESS) {
			p = (struct pollfd){ .fd = fd, .events = POLLOUT };
			if (poll(&p, 1, CONNECT_MS) == 1 && getsockopt(fd, SOL_SOCKET, SO_ERROR, &e, &sl) == 0 && e == 0)
				break;
			if (e == EINPROGRESS)
				e = ETIMEDOUT;
		}
		close(fd);
		fd = -1;
	}
	freeaddrinfo(ai);
	if (fd < 0) {
		snprintf(err, n, "%s: %s", where, strerror(e));
		errno = ENODEV;
	}
	return fd;
}

struct ps_dali_serial *ps_dali_serial_open(const struct ps_dali_codec *c, const char *where, long baud, char *err,
                                           size_t errlen)
{
	struct ps_dali_serial *s;
	int fd = where[0] == '/' ? open_tty(where, baud > 0 ? baud : c->baud, err, errlen) : open_tcp(where, err, errlen);
	if (fd < 0)
		return NULL;
	if (!(s = calloc(1, sizeof *s))) {
		close(fd);
		snprintf(err, errlen, "out of memory");
		errno = ENOMEM;
		return NULL;
	}
	s->c = c;
	s->fd = fd;
	s->deadline = INFINITY;
	s->keepalive = where[0] != '/' && c->encode_keepalive ? c->keepalive : 0;
	s->last_tx = -1;
	return s;
}

int ps_dali_serial_fd(const struct ps_dali_serial *s)
{
	return s->fd;
}

void ps_dali_serial_keepalive(struct ps_dali_serial *s, double seconds)
{
	s->keepalive = s->c->encode_keepalive ? seconds : 0;
}

double ps_dali_serial_deadline(const struct ps_dali_serial *s)
{
	double t = s->busy ? s->deadline : INFINITY;
	if (s->keepalive > 0 && !s->busy && s->last_tx >= 0)
		t = fmin(t, s->last_tx + s->keepalive);
	return t;
}

void ps_dali_serial_stats(const struct ps_dali_serial *s, struct ps_dali_serial_stats *st)
{
	*st = s->st;
}

void ps_dali_serial_close(struct ps_dali_serial *s)
{
	if (!s)
		return;
	close(s->fd);
	free(s);
}

int ps_dali_serial_send(struct ps_dali_serial *s, const struct ps_dali_frame *f, double now, double timeout)
{
	uint8_t out[64];
	int n;
	ssize_t w;
	if (s->busy) {
		errno = EBUSY;
		return -1;
	}
	if ((n = s->c->encode(out, sizeof out, f)) < 0) {
		errno = EINVAL;
		return -1;
	}
	if (s->stale) {
		s->rxlen = 0;
		s->stale = 0;
	}
	w = write(s->fd, out, (size_t)n);
	if (w != n) {
		errno = w < 0 && errno != EAGAIN ? errno : EIO;
		return -1;
	}
	s->last_tx = now;
	s->busy = 1;
	s->replies_left = f->twice ? s->c->replies_per_twice : 1;
	s->expect_answer = f->expect_answer;
	s->echoes_left = f->twice ? 2 : 1;
	s->in_window = 0;
	s->deadline = now + timeout;
	s->st.frames++;
	return 0;
}

static int end(struct ps_dali_serial *s, struct ps_dali_serial_result *res, int event, unsigned value, int err,
               const char *why)
{
	s->busy = 0;
	res->event = event;
	res->value = value;
	res->err = err;
	snprintf(res->why, sizeof res->why, "%s", why);
	return 1;
}

/* One message: 1 when it ended the transaction. */
static int take(struct ps_dali_serial *s, const struct ps_dali_frame_rx *m, double now,
                struct ps_dali_serial_result *res)
{
	char why[160];
	switch (m->event) {
	case PS_DALI_EV_ECHO:
		/* our frame went out; without an answer window it is news only */
		if (!s->busy || s->c->answer_window <= 0 || --s->echoes_left > 0)
			return 0;
		if (!s->expect_answer) {
			s->st.no_answers++;
			return end(s, res, PS_DALI_EV_NO_ANSWER, 0, 0, "");
		}
		s->in_window = 1;
		s->deadline = now + s->c->answer_window;
		return 0;
	case PS_DALI_EV_OBSERVED:
		s->st.observed++;
		s->st.last_observed = m->value;
		if (s->obs_len == OBSCAP) {   /* the caller fell behind: the oldest goes */
			s->obs_head = (s->obs_head + 1) % OBSCAP;
			s->obs_len--;
		}
		s->obs[(s->obs_head + s->obs_len) % OBSCAP] = m->value;
		s->obs_bits[(s->obs_head + s->obs_len) % OBSCAP] = m->bits;
		s->obs_len++;
		return 0;
	case PS_DALI_EV_POWER:
		s->st.power_lost = !m->value;
		if (m->value || !s->busy)
			return 0;
		return end(s, res, PS_DALI_EV_POWER, 0, EIO, m->why);
	case PS_DALI_EV_MALFORMED:
		s->st.malformed++;
		if (!s->busy)
			return 0;
		snprintf(why, sizeof why, "malformed reply from the interface: %s", m->why);
		return end(s, res, PS_DALI_EV_MALFORMED, 0, EPROTO, why);
	case PS_DALI_EV_ANSWER:
	case PS_DALI_EV_NO_ANSWER:
	case PS_DALI_EV_BUS_ERROR:
		break;
	default:
		return 0;
	}
	/* an interface that reports what it saw: what comes before our frame
	 * went out is not our frame's */
	if (!s->busy || (s->c->answer_window > 0 && !s->in_window && m->event != PS_DALI_EV_BUS_ERROR)) {
		s->st.stray++;
		return 0;
	}
	if (s->c->answer_window > 0 && !s->in_window && m->value == PS_DALI_BUS_FRAMING) {
		s->st.stray++;
		return 0;
	}
	if (m->event == PS_DALI_EV_BUS_ERROR)
		s->st.bus_errors++;
	else if (m->event == PS_DALI_EV_ANSWER)
		s->st.answers++;
	else
		s->st.no_answers++;
	if (--s->replies_left > 0) {
		/* a frame sent twice: the first sending's reply; the second decides
		 * unless the first already failed */
		if (m->event == PS_DALI_EV_BUS_ERROR && s->first.event != PS_DALI_EV_BUS_ERROR)
			s->first = (struct ps_dali_serial_result){ .event = m->event, .value = m->value, .err = EPROTO };
		return 0;
	}
	if (s->first.event == PS_DALI_EV_BUS_ERROR) {
		struct ps_dali_serial_result f = s->first;
		s->first.event = 0;
		return end(s, res, f.event, f.value, EPROTO, "bus error on the first of the two sendings");
	}
	if (m->event == PS_DALI_EV_BUS_ERROR)
		return end(s, res, m->event, m->value, EPROTO, m->why);
	return end(s, res, m->event, m->value, 0, "");
}

int ps_dali_serial_service(struct ps_dali_serial *s, double now, struct ps_dali_serial_result *res)
{
	memset(res, 0, sizeof *res);
	for (;;) {
		ssize_t r;
		if (s->rxlen == RXCAP)
			s->rxlen = 0;   /* cannot happen with max_msg < RXCAP: every full buffer holds a message */
		r = read(s->fd, s->rx + s->rxlen, RXCAP - s->rxlen);
		if (r > 0) {
			s->rxlen += (size_t)r;
			/* decode as we go, so a long burst never fills the buffer */
			while (s->rxlen) {
				struct ps_dali_frame_rx m;
				size_t used = s->c->decode(s->rx, s->rxlen, &m);
				int done;
				if (!used)
					break;
				memmove(s->rx, s->rx + used, s->rxlen - used);
				s->rxlen -= used;
				done = take(s, &m, now, res);
				if (done)
					return 1;
			}
			continue;
		}
		if (r < 0 && (errno == EAGAIN || errno == EINTR))
			break;
		snprintf(res->why, sizeof res->why, "the interface is gone: %s", r == 0 ? "end of file" : strerror(errno));
		s->busy = 0;
		errno = ENODEV;
		return -1;
	}
	if (s->keepalive > 0 && !s->busy) {
		if (s->last_tx < 0) {
			s->last_tx = now;
		} else if (now >= s->last_tx + s->keepalive) {
			uint8_t out[32];
			int n = s->c->encode_keepalive(out, sizeof out);
			s->last_tx = now;
			if (n > 0 && write(s->fd, out, (size_t)n) == n) {
				s->st.keepalives++;
			} else {
				snprintf(res->why, sizeof res->why, "the interface is gone: the keep-alive could not be sent");
				errno = ENODEV;
				return -1;
			}
		}
	}
	if (s->busy && s->in_window && now >= s->deadline) {
		/* our frame went out and no backward frame came in the window */
		s->st.no_answers++;
		return end(s, res, PS_DALI_EV_NO_ANSWER, 0, 0, "");
	}
	if (s->busy && now >= s->deadline) {
		char why[160];
		s->st.timeouts++;
		s->stale = 1;
		if (s->rxlen)
			snprintf(why, sizeof why, "a reply cut short (%zu bytes without its end)", s->rxlen);
		else
			snprintf(why, sizeof why, "no reply from the interface");
		return end(s, res, PS_DALI_EV_IGNORE, 0, ETIMEDOUT, why);
	}
	return 0;
}

int ps_dali_serial_observed(struct ps_dali_serial *s, uint32_t *frame, int *bits)
{
	if (!s->obs_len)
		return 0;
	*frame = s->obs[s->obs_head];
	*bits = s->obs_bits[s->obs_head];
	s->obs_head = (s->obs_head + 1) % OBSCAP;
	s->obs_len--;
	return 1;
}
