/* SPDX-License-Identifier: ISC */
/* A non-blocking Modbus TCP and RTU server loop (see mbserve.h). */
#include "mbserve.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <netdb.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>

#include "log.h"
#include "mbpdu.h"
#include "time.h"

enum {
	IN_CAP = 2 * PSD_MBFRAME_TCP_MAX,    /* a frame and the start of the next */
	OUT_CAP = 4 * PSD_MBFRAME_TCP_MAX,   /* replies the client has not read yet */
};

struct conn {
	int fd;
	unsigned id;                 /* for messages */
	uint8_t in[IN_CAP];
	size_t nin;
	uint8_t out[OUT_CAP];
	size_t nout;
	double partial_since;        /* the unfinished frame at the head of in began (0: none) */
	double active;               /* bytes last moved either way */
	double due;                  /* a deferred request is answered then (0: none) */
	uint8_t req[PSD_MBFRAME_TCP_MAX];
	size_t nreq;
};

struct psd_mbserve {
	struct psd_mbserve_opts o;
	psd_mbserve_fn fn;
	void *user;
	int rtu;
	int lfd, port;               /* TCP */
	struct conn **c;
	int nc, cap;
	unsigned next_id;
	struct conn line;            /* RTU: fd, buffers, deferral */
	double last_byte, silence, down_until;
};

/* Frames in hex at debug level, when the server traces them. */
static void hex(const struct psd_mbserve *srv, const char *what, unsigned id, const uint8_t *p, size_t n)
{
	char s[3 * PSD_MBFRAME_TCP_MAX + 1];
	size_t k = 0;
	if (!srv->o.trace)
		return;
	for (size_t i = 0; i < n && k + 4 < sizeof s; i++)
		k += (size_t)snprintf(s + k, sizeof s - k, "%s%02x", i ? " " : "", p[i]);
	s[k] = 0;
	psd_log_debug("client %u %s %s", id, what, s);
}

static struct psd_mbserve *new_server(const struct psd_mbserve_opts *o, psd_mbserve_fn fn, void *user)
{
	struct psd_mbserve *s = calloc(1, sizeof *s);
	if (!s)
		return NULL;
	s->o = *o;
	s->fn = fn;
	s->user = user;
	s->lfd = s->line.fd = -1;
	return s;
}

struct psd_mbserve *psd_mbserve_tcp(const char *host, const char *port, const struct psd_mbserve_opts *o,
                                    psd_mbserve_fn fn, void *user, char *err, size_t n)
{
	struct addrinfo hints, *ai = NULL;
	struct sockaddr_storage a;
	socklen_t alen = sizeof a;
	struct psd_mbserve *s = new_server(o, fn, user);
	int rc, one = 1;
	if (!s) {
		snprintf(err, n, "out of memory");
		return NULL;
	}
	memset(&hints, 0, sizeof hints);
	hints.ai_family = AF_UNSPEC;
	hints.ai_socktype = SOCK_STREAM;
	hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
	if ((rc = getaddrinfo(host, port, &hints, &ai)) != 0) {
		snprintf(err, n, "%s:%s: %s", host, port, gai_strerror(rc));
		free(s);
		return NULL;
	}
	s->lfd = socket(ai->ai_family, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
	if (s->lfd < 0 || setsockopt(s->lfd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) != 0 ||
	    bind(s->lfd, ai->ai_addr, ai->ai_addrlen) != 0 || listen(s->lfd, SOMAXCONN) != 0 ||
	    getsockname(s->lfd, (struct sockaddr *)&a, &alen) != 0) {
		snprintf(err, n, "%s:%s: %s", host, port, strerror(errno));
		freeaddrinfo(ai);
		psd_mbserve_free(s);
		return NULL;
	}
	freeaddrinfo(ai);
	s->port = ntohs(a.ss_family == AF_INET6 ? ((struct sockaddr_in6 *)&a)->sin6_port
	                                        : ((struct sockaddr_in *)&a)->sin_port);
	return s;
}

struct psd_mbserve *psd_mbserve_rtu(int fd, const struct psd_mbserve_opts *o, psd_mbserve_fn fn, void *user,
                                    char *err, size_t n)
{
	struct psd_mbserve *s = new_server(o, fn, user);
	if (!s) {
		snprintf(err, n, "out of memory");
		return NULL;
	}
	s->rtu = 1;
	s->line.fd = fd;
	s->silence = psd_mbframe_rtu_silence(o->baud);
	fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
	return s;
}

int psd_mbserve_port(const struct psd_mbserve *s)
{
	return s->port;
}

static void drop(struct psd_mbserve *s, int i, const char *why)
{
	psd_log_debug("client %u closed: %s", s->c[i]->id, why);
	close(s->c[i]->fd);
	free(s->c[i]);
	s->c[i] = s->c[--s->nc];
}

void psd_mbserve_free(struct psd_mbserve *s)
{
	if (!s)
		return;
	while (s->nc > 0)
		drop(s, 0, "server stops");
	free(s->c);
	if (s->lfd >= 0)
		close(s->lfd);
	free(s);
}

/* Send what is queued; -1 when the peer is gone. */
static int flush_out(struct conn *c, double now)
{
	while (c->nout > 0) {
		ssize_t w = write(c->fd, c->out, c->nout);
		if (w < 0)
			return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR ? 0 : -1;
		memmove(c->out, c->out + w, c->nout - (size_t)w);
		c->nout -= (size_t)w;
		c->active = now;
	}
	return 0;
}

/* The handler's answer to one request, queued as bytes; 1 to close. */
static int answer(struct psd_mbserve *s, struct conn *c, const struct psd_mbadu *adu, int deferred, double now)
{
	uint8_t out[PSD_MBFRAME_TCP_MAX];
	size_t n = 0;
	double delay = 0;
	int act = s->fn(s->user, adu, deferred, out, &n, &delay);
	if (act == PSD_MBS_DEFER && !deferred) {
		c->due = now + (delay > 0 ? delay : 0);
		return 0;
	}
	if (act == PSD_MBS_CLOSE)
		return 1;
	if (act == PSD_MBS_REPLY && n > 0 && n <= PSD_MBPDU_MAX) {
		uint8_t *p = c->out + c->nout;
		c->nout += s->rtu ? psd_mbframe_rtu_put(adu->unit, out, n, p) : psd_mbframe_tcp_put(adu, out, n, p);
		hex(s, "reply", c->id, p, (size_t)(c->out + c->nout - p));
	} else if (act == PSD_MBS_RAW && n <= PSD_MBFRAME_TCP_MAX) {
		memcpy(c->out + c->nout, out, n);
		c->nout += n;
		hex(s, "raw", c->id, out, n);
	}
	return 0;
}

/* Answer the complete TCP frames at the head of c->in, in order, until one
 * is deferred or the output is full; 1 to close the connection. */
static int serve_frames(struct psd_mbserve *s, struct conn *c, double now)
{
	size_t used = 0;
	int closing = 0;
	while (!c->due && c->nout + PSD_MBFRAME_TCP_MAX <= OUT_CAP) {
		struct psd_mbadu adu;
		const char *why = "";
		int len = psd_mbframe_tcp(c->in + used, c->nin - used, &adu, &why);
		if (len == 0)
			break;
		if (len < 0) {
			psd_log_debug("client %u: refused: %s", c->id, why);
			hex(s, "refused", c->id, c->in + used, c->nin - used);
			closing = 1;
			break;
		}
		hex(s, "request", c->id, c->in + used, (size_t)len);
		if (answer(s, c, &adu, 0, now)) {
			closing = 1;
			break;
		}
		if (c->due) {   /* keep the frame for its deferred answer */
			memcpy(c->req, c->in + used, (size_t)len);
			c->nreq = (size_t)len;
		}
		used += (size_t)len;
	}
	if (used > 0) {
		memmove(c->in, c->in + used, c->nin - used);
		c->nin -= used;
		c->partial_since = c->nin > 0 ? now : 0;
	}
	return closing;
}

/* Close the client silent the longest, to make room for a new one. */
static void drop_oldest(struct psd_mbserve *s, const char *why)
{
	int old = 0;
	for (int i = 1; i < s->nc; i++)
		if (s->c[i]->active < s->c[old]->active)
			old = i;
	drop(s, old, why);
}

static void accept_all(struct psd_mbserve *s, double now)
{
	for (;;) {
		int fd = accept4(s->lfd, NULL, NULL, SOCK_NONBLOCK | SOCK_CLOEXEC), one = 1;
		struct conn *c;
		if (fd < 0 && (errno == EMFILE || errno == ENFILE) && s->nc > 0) {
			/* out of descriptors: the oldest client makes room, or the
			 * pending connection would wake every turn */
			drop_oldest(s, "its place taken by a new client (no descriptors left)");
			continue;
		}
		if (fd < 0)
			return;   /* EAGAIN: no more; anything else: try again next turn */
		if (s->nc >= s->o.max_clients)
			drop_oldest(s, "its place taken by a new client (max clients)");
		if (s->nc == s->cap) {
			int cap = s->cap ? 2 * s->cap : 16;
			struct conn **p = realloc(s->c, (size_t)cap * sizeof *p);
			if (!p) {
				close(fd);
				return;
			}
			s->c = p;
			s->cap = cap;
		}
		if (!(c = calloc(1, sizeof *c))) {
			close(fd);
			return;
		}
		setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
		c->fd = fd;
		c->id = ++s->next_id;
		c->active = now;
		s->c[s->nc++] = c;
		psd_log_debug("client %u connected (%d clients)", c->id, s->nc);
	}
}

/* Read what the client sent; 1 when the connection is broken, 2 when the
 * client has closed its side (what it sent before is in c->in). */
static int read_in(struct conn *c, double now, const char **why)
{
	while (c->nin < IN_CAP) {
		ssize_t r = read(c->fd, c->in + c->nin, IN_CAP - c->nin);
		if (r < 0) {
			if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)
				return 0;
			*why = strerror(errno);
			return 1;
		}
		if (r == 0) {
			*why = "the client closed";
			return 2;
		}
		if (c->nin == 0)
			c->partial_since = now;
		c->nin += (size_t)r;
		c->active = now;
	}
	return 0;
}

/* Everything one TCP client needs now; 1 to close (with why). */
static int service(struct psd_mbserve *s, struct conn *c, short revents, double now, const char **why)
{
	if (revents & (POLLERR | POLLNVAL)) {
		*why = "socket error";
		return 1;
	}
	int eof = 0;
	if (revents & (POLLIN | POLLHUP)) {
		int rc = read_in(c, now, why);
		if (rc == 1)
			return 1;
		eof = rc == 2;
	}
	if (c->due && now >= c->due) {
		struct psd_mbadu adu;
		const char *w = "";
		c->due = 0;
		if (psd_mbframe_tcp(c->req, c->nreq, &adu, &w) > 0 && answer(s, c, &adu, 1, now)) {
			*why = "closed on request";
			return 1;
		}
	}
	if (serve_frames(s, c, now)) {
		*why = "closed on request or a frame that is not Modbus";
		return 1;
	}
	if (flush_out(c, now) != 0) {
		*why = "the client is gone";
		return 1;
	}
	/* the client closed its side: it has the replies that were ready (a
	 * late one still owed goes with the connection) */
	if (eof)
		return 1;
	/* the bounds: a frame from its first byte, a client from its last */
	if (!c->due && c->nout == 0 && c->nin > 0 && now - c->partial_since > s->o.frame_timeout) {
		*why = "a frame not complete within the frame timeout of its first byte";
		return 1;
	}
	if (!c->due && now - c->active > s->o.idle_timeout) {
		*why = "idle";
		return 1;
	}
	return 0;
}

/* The next time a client needs service without any input. */
static double next_deadline(const struct psd_mbserve *s, const struct conn *c)
{
	double t = c->due ? c->due : c->active + s->o.idle_timeout;
	if (!c->due && c->nout == 0 && c->nin > 0)
		t = fmin(t, c->partial_since + s->o.frame_timeout);
	return t;
}

static int step_tcp(struct psd_mbserve *s, double max_wait)
{
	struct pollfd stack[64], *p = stack;
	double now = psd_time_mono(), until = now + max_wait;
	int n = s->nc, rc;
	if (n + 1 > 64 && !(p = malloc((size_t)(n + 1) * sizeof *p)))
		return 0;   /* try again next turn */
	p[0] = (struct pollfd){ s->lfd, POLLIN, 0 };
	for (int i = 0; i < n; i++) {
		struct conn *c = s->c[i];
		p[i + 1] = (struct pollfd){ c->fd, (short)((c->nin < IN_CAP ? POLLIN : 0) | (c->nout ? POLLOUT : 0)), 0 };
		until = fmin(until, next_deadline(s, c));
	}
	rc = poll(p, (nfds_t)n + 1, (int)ceil(fmax(until - now, 0) * 1000));
	if (rc < 0 && errno != EINTR) {
		if (p != stack)
			free(p);
		return -1;
	}
	now = psd_time_mono();
	/* clients first, by their poll slot (accepting moves none of them);
	 * one that closes is replaced by the last, whose slot is then past */
	for (int i = n - 1; i >= 0; i--) {
		const char *why = "";
		if (rc > 0 || now >= next_deadline(s, s->c[i]))
			if (service(s, s->c[i], rc > 0 ? p[i + 1].revents : 0, now, &why))
				drop(s, i, why);
	}
	if (rc > 0 && (p[0].revents & POLLIN))
		accept_all(s, now);
	if (p != stack)
		free(p);
	return 0;
}

/* RTU: one line.  Frames end at their length or the line's silence
 * (mbframe.h), an unfinished one is dropped a frame timeout after it began;
 * while a reply is deferred the device is busy and drops what arrives. */
static int step_rtu(struct psd_mbserve *s, double max_wait)
{
	struct conn *l = &s->line;
	struct pollfd p = { l->fd, POLLIN, 0 };
	double now = psd_time_mono(), until = now + max_wait;
	int rc;
	if (l->nout)
		p.events |= POLLOUT;
	if (l->nin) {   /* the silence that may end a frame, once; the frame bound */
		if (now < s->last_byte + s->silence)
			until = fmin(until, s->last_byte + s->silence);
		until = fmin(until, l->partial_since + s->o.frame_timeout);
	}
	if (l->due)
		until = fmin(until, l->due);
	if (now < s->down_until) {   /* a hung-up line: do not spin on it */
		p.fd = -1;
		until = fmin(until, s->down_until);
	}
	rc = poll(&p, 1, (int)ceil(fmax(until - now, 0) * 1000));
	if (rc < 0 && errno != EINTR)
		return -1;
	now = psd_time_mono();
	if (rc > 0 && (p.revents & (POLLIN | POLLHUP | POLLERR))) {
		uint8_t buf[PSD_MBFRAME_RTU_MAX];
		ssize_t r = read(l->fd, buf, sizeof buf);
		if (r <= 0 && !(r < 0 && (errno == EAGAIN || errno == EINTR))) {
			s->down_until = now + 0.05;
			l->nin = 0;
		} else if (r > 0 && l->due) {
			;   /* busy */
		} else if (r > 0) {
			if (l->nin + (size_t)r > sizeof l->in) {
				psd_log_debug("line: more than two frames without a frame: dropped");
				l->nin = 0;
			}
			if (l->nin == 0)
				l->partial_since = now;
			memcpy(l->in + l->nin, buf, (size_t)r);
			l->nin += (size_t)r;
			s->last_byte = now;
		}
	}
	if (l->due && now >= l->due) {
		struct psd_mbadu adu;
		const char *why;
		l->due = 0;
		if (psd_mbframe_rtu(l->req, l->nreq, 1, &adu, &why) > 0)
			answer(s, l, &adu, 1, now);
	}
	while (l->nin > 0 && !l->due) {
		struct psd_mbadu adu;
		const char *why = "";
		int len = psd_mbframe_rtu(l->in, l->nin, now - s->last_byte >= s->silence, &adu, &why);
		if (len == 0)
			break;
		if (len < 0) {   /* no frame starts here: look from the next byte */
			psd_log_debug("line: byte %02x dropped: %s", l->in[0], why);
			memmove(l->in, l->in + 1, --l->nin);
			l->partial_since = now;
			continue;
		}
		hex(s, "request", 0, l->in, (size_t)len);
		if (l->nout + PSD_MBFRAME_TCP_MAX > OUT_CAP) {
			psd_log_debug("line: replies not taken by the line: dropped");
			l->nout = 0;
		}
		answer(s, l, &adu, 0, now);
		if (l->due) {
			memcpy(l->req, l->in, (size_t)len);
			l->nreq = (size_t)len;
		}
		memmove(l->in, l->in + len, l->nin - (size_t)len);
		l->nin -= (size_t)len;
		l->partial_since = now;
	}
	/* a frame that never completes is dropped a frame timeout after it began */
	if (l->nin > 0 && now - l->partial_since > s->o.frame_timeout) {
		psd_log_debug("line: %zu bytes dropped: no frame within the frame timeout", l->nin);
		hex(s, "dropped", 0, l->in, l->nin);
		l->nin = 0;
	}
	if (flush_out(l, now) != 0) {
		l->nout = 0;
		s->down_until = now + 0.05;
	}
	return 0;
}

int psd_mbserve_step(struct psd_mbserve *s, double max_wait)
{
	return s->rtu ? step_rtu(s, max_wait) : step_tcp(s, max_wait);
}
