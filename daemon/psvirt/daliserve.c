/* SPDX-License-Identifier: ISC */
/* psvirt's DALI interfaces (daliserve.h). */
#include "daliserve.h"

#include <errno.h>
#include <fcntl.h>
#include <netdb.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <unistd.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include "log.h"
#include "time.h"

#define MAX_CONN 8
#define INCAP 256
#define IDLE_CLOSE 30.0   /* s: a DALInet closes a silent connection (doc/hardware.md) */
#define SOH 0x01
#define ETB 0x17

struct conn {
	int fd, protocol, tcp;
	uint8_t in[INCAP];
	size_t len;
	double last;
};

struct psd_daliserve {
	struct psd_dalibus *bus;
	int lfd, keeper;          /* the listener; our own hold on the pty's slave */
	struct conn c[MAX_CONN];
	int nc, trace;
	double now;
};

struct psd_daliserve *psd_daliserve_new(struct psd_dalibus *b, int trace)
{
	struct psd_daliserve *s = calloc(1, sizeof *s);
	if (!s)
		return NULL;
	s->bus = b;
	s->lfd = s->keeper = -1;
	s->trace = trace;
	return s;
}

static int add_conn(struct psd_daliserve *s, int fd, int protocol, int tcp)
{
	if (s->nc >= MAX_CONN) {
		psd_log_warnx("DALI: more than %d connections: one refused", MAX_CONN);
		close(fd);
		return -1;
	}
	s->c[s->nc] = (struct conn){ .fd = fd, .protocol = protocol, .tcp = tcp, .last = s->now };
	s->nc++;
	return 0;
}

int psd_daliserve_fd(struct psd_daliserve *s, int fd, int protocol)
{
	fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
	return add_conn(s, fd, protocol, 1);
}

static void drop(struct psd_daliserve *s, int i, const char *why)
{
	psd_log_debug("DALI: connection %d closed: %s", s->c[i].fd, why);
	close(s->c[i].fd);
	s->c[i] = s->c[--s->nc];
}

int psd_daliserve_tcp(struct psd_daliserve *s, const char *host, const char *port, char *err, size_t n)
{
	struct addrinfo hints, *ai = NULL;
	struct sockaddr_storage a;
	socklen_t alen = sizeof a;
	int rc, one = 1;
	memset(&hints, 0, sizeof hints);
	hints.ai_family = AF_UNSPEC;
	hints.ai_socktype = SOCK_STREAM;
	hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
	if ((rc = getaddrinfo(host, port, &hints, &ai)) != 0) {
		snprintf(err, n, "%s:%s: %s", host, port, gai_strerror(rc));
		return -1;
	}
	s->lfd = socket(ai->ai_family, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
	if (s->lfd < 0 || setsockopt(s->lfd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) != 0 ||
	    bind(s->lfd, ai->ai_addr, ai->ai_addrlen) != 0 || listen(s->lfd, 8) != 0 ||
	    getsockname(s->lfd, (struct sockaddr *)&a, &alen) != 0) {
		snprintf(err, n, "%s:%s: %s", host, port, strerror(errno));
		freeaddrinfo(ai);
		return -1;
	}
	freeaddrinfo(ai);
	return ntohs(a.ss_family == AF_INET6 ? ((struct sockaddr_in6 *)&a)->sin6_port
	                                     : ((struct sockaddr_in *)&a)->sin_port);
}

int psd_daliserve_pty(struct psd_daliserve *s, int protocol, char *path, size_t pathlen, char *err, size_t n)
{
	struct termios t;
	const char *name;
	int fd = posix_openpt(O_RDWR | O_NOCTTY);
	if (fd < 0 || grantpt(fd) != 0 || unlockpt(fd) != 0 || !(name = ptsname(fd))) {
		snprintf(err, n, "a pseudo-terminal: %s", strerror(errno));
		if (fd >= 0)
			close(fd);
		return -1;
	}
	snprintf(path, pathlen, "%s", name);
	/* raw both ways (no echo, no line editing) until psensd sets its own,
	 * and our own hold on the slave, so the master never hangs up between
	 * psensd's runs */
	if (tcgetattr(fd, &t) == 0) {
		cfmakeraw(&t);
		tcsetattr(fd, TCSANOW, &t);
	}
	fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
	fcntl(fd, F_SETFD, FD_CLOEXEC);
	s->keeper = open(path, O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
	add_conn(s, fd, protocol, 0);
	return 0;
}

static void trace(const struct psd_daliserve *s, const struct conn *c, const char *dir, const uint8_t *p, size_t n)
{
	char buf[200];
	size_t k = 0;
	if (!s->trace)
		return;
	for (size_t i = 0; i < n && k + 4 < sizeof buf; i++)
		k += (size_t)snprintf(buf + k, sizeof buf - k, p[i] >= 0x20 && p[i] < 0x7F ? "%c" : "<%02x>", p[i]);
	buf[k] = 0;
	psd_log_debug("DALI %d %s %s", c->fd, dir, buf);
}

static void put(const struct psd_daliserve *s, struct conn *c, const uint8_t *p, size_t n)
{
	ssize_t w;
	trace(s, c, ">", p, n);
	w = write(c->fd, p, n);
	if (w != (ssize_t)n && !(w < 0 && errno == EIO))
		psd_log_debug("DALI %d: %zd of %zu bytes written", c->fd, w, n);
}

/* ------------------------------------------------------------ foxtron */

static void fox_put(const struct psd_daliserve *s, struct conn *c, const uint8_t *msg, size_t n)
{
	uint8_t out[80];
	size_t k = 0;
	unsigned sum = 0;
	out[k++] = SOH;
	for (size_t i = 0; i < n; i++) {
		sum += msg[i];
		k += (size_t)snprintf((char *)out + k, 3, "%02X", msg[i]);
	}
	k += (size_t)snprintf((char *)out + k, 3, "%02X", ~sum & 0xFF);
	out[k++] = ETB;
	put(s, c, out, k);
}

static void fox_event(const struct psd_daliserve *s, struct conn *c, uint8_t code)
{
	uint8_t m[2] = { 0x05, code };
	fox_put(s, c, m, 2);
}

static int unhex(int ch)
{
	return ch >= '0' && ch <= '9' ? ch - '0' : ch >= 'A' && ch <= 'F' ? ch - 'A' + 10 :
	       ch >= 'a' && ch <= 'f' ? ch - 'a' + 10 : -1;
}

/* A client's forward frame onto the bus; traced with the monotonic time it
 * reached the bus, so a trace gives the time from an event to the frame it
 * caused. */
static int bus_frame(struct psd_daliserve *s, int bits, uint32_t frame, int twice, uint8_t *answer)
{
	if (s->trace)
		psd_log_debug("DALI %.6f forward %d-bit %0*X%s", psd_time_mono(), bits, bits / 4, (unsigned)frame,
		              twice ? " twice" : "");
	return psd_dalibus_frame(s->bus, s->now, bits, frame, twice, answer);
}

/* Send frame on the bus and say what came back, as 0x0D/0x0E; a bus
 * without power says so instead. */
static void fox_send(struct psd_daliserve *s, struct conn *c, int bits, uint32_t frame, int twice)
{
	uint8_t m[8], ans;
	int n = 0, nb = bits / 8;
	int r = bus_frame(s, bits, frame, twice, &ans);
	if (r == PSD_DALIBUS_NOPOWER) {
		fox_event(s, c, 1);
		return;
	}
	m[n++] = r == PSD_DALIBUS_NONE ? 0x0E : 0x0D;
	m[n++] = (uint8_t)bits;
	if (r != PSD_DALIBUS_NONE)
		m[n++] = r == PSD_DALIBUS_ANSWER ? 8 : 0;
	for (int i = nb - 1; i >= 0; i--)
		m[n++] = (uint8_t)(frame >> (8 * i));
	if (r == PSD_DALIBUS_ANSWER)
		m[n++] = ans;
	fox_put(s, c, m, (size_t)n);
}

static void fox_message(struct psd_daliserve *s, struct conn *c, const uint8_t *p, size_t n)
{
	uint8_t m[32];
	size_t nm = n / 2;
	unsigned sum = 0;
	if (n % 2 || nm < 2 || nm > sizeof m) {
		fox_event(s, c, 6);
		return;
	}
	for (size_t i = 0; i < nm; i++) {
		int hi = unhex(p[2 * i]), lo = unhex(p[2 * i + 1]);
		if (hi < 0 || lo < 0) {
			fox_event(s, c, 6);
			return;
		}
		m[i] = (uint8_t)(hi << 4 | lo);
	}
	for (size_t i = 0; i + 1 < nm; i++)
		sum += m[i];
	if ((~sum & 0xFF) != m[nm - 1]) {
		fox_event(s, c, 5);
		return;
	}
	nm--;
	if (m[0] == 0x0B && nm >= 4) {
		/* type, priority, length in bits, the frame, param */
		int bits = m[2], nb = bits / 8;
		uint32_t f = 0;
		if ((bits != 8 && bits != 16 && bits != 24) || nm != (size_t)(4 + nb)) {
			fox_event(s, c, 6);
			return;
		}
		for (int i = 0; i < nb; i++)
			f = f << 8 | m[3 + i];
		fox_send(s, c, bits, f, m[3 + nb] & 1);
		return;
	}
	if (m[0] == 0x06 && nm == 2) {
		uint8_t r[4] = { 0x07, m[1], 0x01, 0x00 };   /* item, version 1.0 */
		fox_put(s, c, r, 4);
		return;
	}
	fox_event(s, c, 6);
}

/* The complete messages in c's buffer; bytes outside a message dropped. */
static void fox_input(struct psd_daliserve *s, struct conn *c)
{
	size_t i = 0;
	while (i < c->len) {
		size_t j;
		if (c->in[i] != SOH) {
			i++;
			continue;
		}
		for (j = i + 1; j < c->len && c->in[j] != ETB && c->in[j] != SOH; j++)
			;
		if (j == c->len)
			break;   /* not complete yet */
		if (c->in[j] == SOH) {
			fox_event(s, c, 6);   /* cut short by a new message */
			i = j;
			continue;
		}
		trace(s, c, "<", c->in + i, j + 1 - i);
		fox_message(s, c, c->in + i + 1, j - i - 1);
		i = j + 1;
	}
	if (i == 0 && c->len == INCAP) {
		fox_event(s, c, 6);   /* a message longer than the buffer */
		i = c->len;
	}
	memmove(c->in, c->in + i, c->len - i);
	c->len -= i;
}

/* ------------------------------------------------------------ atx */

static void atx_reply(const struct psd_daliserve *s, struct conn *c, int r, uint8_t ans)
{
	char out[8];
	int n = r == PSD_DALIBUS_ANSWER ? snprintf(out, sizeof out, "J%02X\n", ans) :
	        r == PSD_DALIBUS_GARBLED ? snprintf(out, sizeof out, "X\n") : snprintf(out, sizeof out, "N\n");
	put(s, c, (const uint8_t *)out, (size_t)n);
}

static void atx_line(struct psd_daliserve *s, struct conn *c, const uint8_t *p, size_t n)
{
	int digits = 0, bits = 0, twice = 0;
	uint32_t f = 0;
	uint8_t ans = 0;
	int r;
	switch (n ? p[0] : 0) {
	case 'j': digits = 2; bits = 8; break;
	case 'h': digits = 4; bits = 16; break;
	case 't': digits = 4; bits = 16; twice = 1; break;
	case 'l': digits = 6; bits = 24; break;
	}
	if (!bits || n != (size_t)(1 + digits)) {
		put(s, c, (const uint8_t *)"N\n", 2);
		return;
	}
	for (int i = 0; i < digits; i++) {
		int h = unhex(p[1 + i]);
		if (h < 0) {
			put(s, c, (const uint8_t *)"N\n", 2);
			return;
		}
		f = f << 4 | (uint32_t)h;
	}
	/* a frame sent twice: two sendings, each answered */
	for (int k = 0; k <= twice; k++) {
		r = bus_frame(s, bits, f, twice, &ans);
		atx_reply(s, c, r == PSD_DALIBUS_NOPOWER ? PSD_DALIBUS_NONE : r, ans);
	}
}

static void atx_input(struct psd_daliserve *s, struct conn *c)
{
	size_t i = 0, start = 0;
	for (i = 0; i < c->len; i++)
		if (c->in[i] == '\n') {
			size_t end = i;
			if (end > start && c->in[end - 1] == '\r')
				end--;
			trace(s, c, "<", c->in + start, end - start);
			if (end > start)
				atx_line(s, c, c->in + start, end - start);
			start = i + 1;
		}
	if (start == 0 && c->len == INCAP)
		start = c->len;   /* a line longer than any frame: dropped */
	memmove(c->in, c->in + start, c->len - start);
	c->len -= start;
}

/* ------------------------------------------------------------ the loop */

static void broadcast_events(struct psd_daliserve *s)
{
	uint32_t ev[PSD_DALIBUS_MAX_EVENTS];
	int n = psd_dalibus_events(s->bus, s->now, ev);
	for (int k = 0; k < n; k++) {
		if (s->trace)
			psd_log_debug("DALI %.6f event 24-bit %06X", psd_time_mono(), (unsigned)ev[k]);
		for (int i = 0; i < s->nc; i++) {
			struct conn *c = &s->c[i];
			if (c->protocol == PSD_DALISERVE_FOXTRON) {
				uint8_t m[5] = { 0x04, 24, (uint8_t)(ev[k] >> 16), (uint8_t)(ev[k] >> 8), (uint8_t)ev[k] };
				fox_put(s, c, m, sizeof m);
			} else {
				char line[16];
				int len = snprintf(line, sizeof line, "l%06X\n", (unsigned)ev[k]);
				put(s, c, (const uint8_t *)line, (size_t)len);
			}
		}
	}
}

void psd_daliserve_power(struct psd_daliserve *s, int on)
{
	for (int i = 0; i < s->nc; i++)
		if (s->c[i].protocol == PSD_DALISERVE_FOXTRON)
			fox_event(s, &s->c[i], on ? 0 : 1);
}

int psd_daliserve_step(struct psd_daliserve *s, double now, double max_wait)
{
	struct pollfd p[MAX_CONN + 1];
	int np = 0, first = 0, rc;
	s->now = now;
	if (s->lfd >= 0) {
		p[np++] = (struct pollfd){ s->lfd, POLLIN, 0 };
		first = 1;
	}
	for (int i = 0; i < s->nc; i++)
		p[np++] = (struct pollfd){ s->c[i].fd, POLLIN, 0 };
	rc = poll(p, (nfds_t)np, max_wait > 0 ? (int)(max_wait * 1000) : 0);
	if (rc < 0)
		return errno == EINTR ? 0 : -1;
	/* the connections first (their indices move when one closes) */
	for (int i = s->nc - 1; i >= 0; i--) {
		struct conn *c = &s->c[i];
		short re = p[first + i].revents;
		ssize_t got;
		if (!re) {
			if (c->tcp && now - c->last > IDLE_CLOSE)
				drop(s, i, "idle");
			continue;
		}
		got = read(c->fd, c->in + c->len, INCAP - c->len);
		if (got <= 0) {
			if (got < 0 && (errno == EAGAIN || errno == EINTR || (errno == EIO && !c->tcp)))
				continue;
			if (c->tcp)
				drop(s, i, got == 0 ? "closed by the client" : strerror(errno));
			continue;
		}
		c->len += (size_t)got;
		c->last = now;
		if (c->protocol == PSD_DALISERVE_FOXTRON)
			fox_input(s, c);
		else
			atx_input(s, c);
	}
	if (first && (p[0].revents & POLLIN)) {
		int fd = accept4(s->lfd, NULL, NULL, SOCK_NONBLOCK | SOCK_CLOEXEC);
		if (fd >= 0)
			add_conn(s, fd, PSD_DALISERVE_FOXTRON, 1);
	}
	broadcast_events(s);
	return 0;
}

void psd_daliserve_free(struct psd_daliserve *s)
{
	if (!s)
		return;
	for (int i = 0; i < s->nc; i++)
		close(s->c[i].fd);
	if (s->lfd >= 0)
		close(s->lfd);
	if (s->keeper >= 0)
		close(s->keeper);
	free(s);
}
