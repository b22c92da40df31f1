/* SPDX-License-Identifier: ISC */
/* BACnet/IP: the server's socket in psensd's loop (bacnet.h). */
#include "bacnet.h"

#include <arpa/inet.h>
#include <errno.h>
#include <math.h>
#include <netinet/in.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "bacobj.h"
#include "bacserve.h"
#include "config.h"
#include "engine.h"
#include "errbuf.h"
#include "log.h"
#include "points.h"
#include "time.h"

enum { BATCH = 64 };   /* datagrams answered in one turn at most */
/* foreign-device registration: s to wait for the BBMD's BVLC-Result, and
 * the first and the longest wait before trying again */
#define FD_ANSWER_S 3.0
#define FD_BACKOFF_MIN_S 1.0
#define FD_BACKOFF_MAX_S 60.0
enum { SOURCES = 32 }; /* sources whose rate is tracked (the longest idle one makes room) */

/* A token bucket per source address: `rate` a second, as many at once. */
struct source {
	uint32_t ip;
	double tokens, last;
};

struct psd_bacnet {
	int fd;
	struct psd_bacnet_conf c;
	struct psd_engine *e;
	const struct psd_points *pts;
	psd_frontend_override_fn override;   /* the command table's typed entries */
	psd_frontend_release_fn release;
	struct psd_bacserve_zone zone[PSD_MAX_ZONES];
	double issued[PSD_MAX_ZONES]; /* clock time of the last override sent for a zone */
	struct psd_bacserve_model m;
	double now;
	struct source src[SOURCES];
	unsigned long dropped; /* datagrams over a source's rate */
	/* [bacnet] bbmd: psensd as a foreign device of that BBMD (Annex J.5.2): its registration */
	struct {
		uint8_t addr[6];    /* the BBMD's B/IP address */
		int registered;     /* its last BVLC-Result was a success, TTL not run out */
		int pending;        /* a Register-Foreign-Device awaits its result */
		double next;        /* monotonic s: the next registration */
		double answer_by;   /* the pending one's result is due */
		double expires;     /* the registration runs out */
		double backoff;     /* s before the next try after a failure */
		unsigned long fails; /* failures in a row (the first is logged, then every tenth) */
	} fdr;
};

/* 1 when a datagram from ip may be answered now (wall seconds t). */
static int within_rate(struct psd_bacnet *b, uint32_t ip, double t)
{
	struct source *s = NULL, *idle = &b->src[0];
	for (int i = 0; i < SOURCES; i++) {
		if (b->src[i].last > 0 && b->src[i].ip == ip) {
			s = &b->src[i];
			break;
		}
		if (b->src[i].last < idle->last)
			idle = &b->src[i];
	}
	if (!s) {
		s = idle;
		*s = (struct source){ ip, b->c.rate, t };
	}
	s->tokens += (t - s->last) * b->c.rate;
	if (s->tokens > b->c.rate)
		s->tokens = b->c.rate;
	s->last = t;
	if (s->tokens < 1) {
		if (b->dropped++ == 0)
			psd_log_warnx("bacnet: a source sends more than %g datagrams a second: the excess is "
			              "dropped",
			              b->c.rate);
		return 0;
	}
	s->tokens -= 1;
	return 1;
}

/* The highest priority written, or -1 when every one is relinquished. */
static int in_force(const struct psd_bacserve_zone *z)
{
	for (int i = 0; i < PSD_BACSERVE_PRIORITIES; i++)
		if (!isnan(z->prio[i]))
			return i;
	return -1;
}

/* The zone's priority array to the engine: an override at the highest
 * priority's level for `hold` seconds, or, all relinquished, release.
 * The command table's typed entries (cmdtab.h): the socket's own checks
 * and messages, with no request line between. */
static int apply(void *user, size_t i)
{
	struct psd_bacnet *b = user;
	struct psd_bacserve_zone *z = &b->zone[i];
	char err[512];
	int p = in_force(z), rc;
	if (p >= 0)
		rc = b->override(b->e, z->name, z->prio[p] / 100, b->c.hold, b->now, err, sizeof err);
	else
		rc = b->release(b->e, z->name, err, sizeof err);
	b->issued[i] = b->now; /* a refusal too: tried again at the next renewal, not every turn */
	if (rc != 0) {
		if (p >= 0)
			psd_log_warnx("bacnet: zone %s: override %s %.17g %.17g refused: %s", z->name, z->name,
			              z->prio[p] / 100, b->c.hold, err);
		else
			psd_log_warnx("bacnet: zone %s: release %s refused: %s", z->name, z->name, err);
		return -1;
	}
	if (p >= 0)
		psd_log_info("bacnet: zone %s: level %.1f %% at priority %d", z->name, z->prio[p], p + 1);
	else
		psd_log_info("bacnet: zone %s: every priority relinquished: daylight control resumes",
		             z->name);
	return 0;
}

/* The value a Value's priority array gives: the highest priority written,
 * else Relinquish_Default; *p its priority (0: the default). */
static double value_in_force(const struct psd_bacserve_zone *z, int slot, int *p)
{
	for (int i = 0; i < PSD_BACSERVE_PRIORITIES; i++)
		if (!isnan(z->vprio[slot][i])) {
			*p = i + 1;
			return z->vprio[slot][i];
		}
	*p = 0;
	return z->vdef[slot];
}

/* A Value's priority array to the engine (psd_points_write): the value in
 * force, logged with its priority. */
static int apply_value(void *user, size_t i, size_t point)
{
	struct psd_bacnet *b = user;
	struct psd_bacserve_zone *z = &b->zone[i];
	int slot = psd_bacobj_value_slot(point), p;
	double v;
	char err[256];
	if (slot < 0 || i >= b->e->nzone)
		return -1;
	v = value_in_force(z, slot, &p);
	if (psd_points_write(b->e, i, point, v, err, sizeof err) != 0) {
		psd_log_warnx("bacnet: zone %s: %s %g refused: %s", z->name, psd_points_def(point)->key, v, err);
		return -1;
	}
	z->pv[point] = v;
	if (p)
		psd_log_info("bacnet: zone %s: %s %g at priority %d", z->name, psd_points_def(point)->key, v, p);
	else
		psd_log_info("bacnet: zone %s: %s: every priority relinquished: %g (the configured value)",
		             z->name, psd_points_def(point)->key, v);
	return 0;
}

/* The objects from the engine: a zone whose name changed (a reload) starts
 * with its priority array relinquished. */
static void refresh(struct psd_bacnet *b)
{
	struct psd_engine *e = b->e;
	b->m.nzone = e->nzone;
	for (size_t i = 0; i < e->nzone; i++) {
		const struct psd_zone *z = &e->zone[i];
		struct psd_bacserve_zone *s = &b->zone[i];
		if (strcmp(s->name, z->zc->name) != 0) {
			snprintf(s->name, sizeof s->name, "%s", z->zc->name);
			for (int k = 0; k < PSD_BACSERVE_PRIORITIES; k++) {
				s->prio[k] = NAN;
				for (int v = 0; v < PSD_BACSERVE_VALUES; v++)
					s->vprio[v][k] = NAN;
			}
			s->lc_op = 0;
		}
		s->level = 100 * z->level;
		if (!(s->level >= 0 && s->level <= 100))
			s->level = 0;
		s->fault = z->in_fault;
		for (size_t k = 0; k < PSD_BACSERVE_POINTS; k++) {
			int slot = psd_bacobj_value_slot(k), p;
			s->has[k] = k < psd_points_count() &&
			            psd_points_value(b->pts, e, i, k, b->now, &s->pv[k]) == 0;
			if (slot < 0 || !s->has[k] || psd_points_default(e, i, k, &s->vdef[slot]) != 0)
				continue;
			/* a written value the engine lost (a reload, another front
			 * end): the priority array still rules */
			value_in_force(s, slot, &p);
			if (p && b->m.apply_value && s->pv[k] != s->vprio[slot][p - 1])
				apply_value(b, i, k);
		}
	}
}

/* ---- foreign-device registration (Annex J.5.2) ----------------------- */

static void send_to(struct psd_bacnet *b, const uint8_t *out, size_t len, const uint8_t addr[6]);

static void fd_register(struct psd_bacnet *b, double t)
{
	/* Register-Foreign-Device: BVLL 0x81 0x05, length 6, Time-to-Live */
	uint8_t req[6] = { 0x81, 0x05, 0x00, 0x06, (uint8_t)(b->c.bbmd_ttl >> 8), (uint8_t)b->c.bbmd_ttl };
	send_to(b, req, sizeof req, b->fdr.addr);
	b->fdr.pending = 1;
	b->fdr.answer_by = t + FD_ANSWER_S;
}

/* A try failed (why): again after the backoff, doubled up to its most. */
static void fd_failed(struct psd_bacnet *b, double t, const char *why)
{
	b->fdr.pending = 0;
	if (b->fdr.registered && t >= b->fdr.expires)
		b->fdr.registered = 0;
	if (b->fdr.fails++ % 10 == 0)
		psd_log_warnx("bacnet: BBMD %s:%ld: %s; registering again in %g s (%lu failure(s) in a row)",
		              b->c.bbmd_host, b->c.bbmd_port, why, b->fdr.backoff, b->fdr.fails);
	b->fdr.next = t + b->fdr.backoff;
	b->fdr.backoff = b->fdr.backoff * 2 > FD_BACKOFF_MAX_S ? FD_BACKOFF_MAX_S : b->fdr.backoff * 2;
}

/* A BVLC-Result from the BBMD. */
static void fd_result(struct psd_bacnet *b, const uint8_t *in, size_t n, double t)
{
	unsigned code;
	if (n != 6 || !b->fdr.pending)
		return;
	code = (unsigned)in[4] << 8 | in[5];
	if (code != 0) {
		char why[80];
		snprintf(why, sizeof why, "Register-Foreign-Device refused (BVLC-Result 0x%04x)", code);
		fd_failed(b, t, why);
		return;
	}
	if (!b->fdr.registered || b->fdr.fails)
		psd_log_info("bacnet: registered as a foreign device with BBMD %s:%ld for %ld s", b->c.bbmd_host,
		             b->c.bbmd_port, b->c.bbmd_ttl);
	if (!b->fdr.registered) { /* announce the device to the BBMD's networks */
		uint8_t out[PSD_BACSERVE_MAX_PACKET];
		size_t len = psd_bacserve_i_am(&b->m, 0x09, out);
		send_to(b, out, len, b->fdr.addr);
	}
	b->fdr.pending = 0;
	b->fdr.fails = 0;
	b->fdr.registered = 1;
	b->fdr.backoff = FD_BACKOFF_MIN_S;
	b->fdr.expires = t + (double)b->c.bbmd_ttl;
	b->fdr.next = t + (double)b->c.bbmd_ttl / 2; /* renewed well before the TTL runs out */
}

static void fd_service(struct psd_bacnet *b, double t)
{
	if (!b->c.bbmd)
		return;
	if (b->fdr.pending && t >= b->fdr.answer_by)
		fd_failed(b, t, "no answer to Register-Foreign-Device");
	if (b->fdr.registered && t >= b->fdr.expires)
		b->fdr.registered = 0;
	if (!b->fdr.pending && t >= b->fdr.next)
		fd_register(b, t);
}

static int bacnet_wait_ms(const struct psd_bacnet *b)
{
	double t = psd_time_mono(), due, seg = psd_bacseg_due(&b->m.seg, t);
	int ms = seg < 0 ? -1 : (int)ceil(seg * 1000);
	if (!b->c.bbmd)
		return ms;
	due = b->fdr.pending ? b->fdr.answer_by : b->fdr.next;
	due = due <= t ? 0 : ceil((due - t) * 1000);
	return ms >= 0 && ms < due ? ms : (int)due;
}

static struct psd_bacnet *bacnet_open(const struct psd_bacnet_conf *c, const struct psd_frontend_env *env,
                                      char *err, size_t errlen)
{
	struct psd_bacnet *b = calloc(1, sizeof *b);
	struct sockaddr_in sa = { .sin_family = AF_INET, .sin_port = htons((uint16_t)c->port) };
	int one = 1;
	if (!b) {
		psd_errbuf(err, errlen, "bacnet: %s", strerror(errno));
		return NULL;
	}
	b->fd = -1;
	b->c = *c;
	b->e = env->engine;
	b->pts = env->points;
	b->override = env->override;
	b->release = env->release;
	b->m = (struct psd_bacserve_model){ .device = (uint32_t)c->instance,
		                            .name = b->c.name,
		                            .vendor_id = (uint16_t)c->vendor_id,
		                            .writes = c->writes,
		                            .target_min = c->target_min,
		                            .target_max = c->target_max,
		                            .database_revision = 1,
		                            .zone = b->zone,
		                            .apply = apply,
		                            .apply_value = apply_value,
		                            .user = b };
	if (inet_pton(AF_INET, c->bind, &sa.sin_addr) != 1 ||
	    (b->fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0)) < 0 ||
	    setsockopt(b->fd, SOL_SOCKET, SO_BROADCAST, &one, sizeof one) != 0 ||
	    bind(b->fd, (struct sockaddr *)&sa, sizeof sa) != 0) {
		psd_errbuf(err, errlen, "bacnet: udp %s:%ld: %s", c->bind, c->port, strerror(errno));
		if (b->fd >= 0)
			close(b->fd);
		free(b);
		return NULL;
	}
	if (c->bbmd) {
		struct in_addr ba;
		uint16_t bp = htons((uint16_t)c->bbmd_port);
		inet_pton(AF_INET, c->bbmd_host, &ba);
		memcpy(b->fdr.addr, &ba, 4);
		memcpy(b->fdr.addr + 4, &bp, 2);
		b->fdr.backoff = FD_BACKOFF_MIN_S;
		b->fdr.next = 0; /* at the first turn */
	}
	refresh(b);
	psd_log_info("bacnet: device %ld '%s' on udp %s:%ld, %zu zone(s), writes %s%s%s%s%s%s%s", c->instance, c->name,
	             c->bind, c->port, b->e->nzone, !b->m.writes ? "refused" : "to:",
	             c->writes & PSD_BACCONF_LIGHTING_OUTPUT ? " the lighting outputs" : "",
	             c->writes & PSD_BACCONF_TARGET ? " the target" : "",
	             c->writes & PSD_BACCONF_DAYLIGHTING ? " daylighting" : "",
	             c->writes & PSD_BACCONF_VACANCY_HOLD ? " the vacancy hold" : "",
	             c->bbmd ? ", a foreign device of BBMD " : "", c->bbmd ? c->bbmd_host : "");
	return b;
}

static int bacnet_pollfd(struct psd_bacnet *b, struct pollfd *pfd)
{
	*pfd = (struct pollfd){ b->fd, POLLIN, 0 };
	return 1;
}

static void send_to(struct psd_bacnet *b, const uint8_t *out, size_t len, const uint8_t addr[6])
{
	struct sockaddr_in to = { .sin_family = AF_INET };
	memcpy(&to.sin_addr, addr, 4);
	memcpy(&to.sin_port, addr + 4, 2);
	if (to.sin_port == 0)
		return;
	/* a full socket buffer drops the datagram, as UDP may: never wait */
	(void)sendto(b->fd, out, len, MSG_DONTWAIT, (struct sockaddr *)&to, sizeof to);
}

static void bacnet_service(struct psd_bacnet *b, const struct pollfd *pfd, double now)
{
	uint8_t in[PSD_BACSERVE_MAX_PACKET + 1], out[PSD_BACSERVE_MAX_PACKET];
	struct psd_bacserve_reply r;
	b->m.now = psd_time_mono(); /* subscriptions' lifetimes: seconds of real time */
	b->now = now;
	refresh(b);
	for (int k = 0; pfd && (pfd->revents & POLLIN) && k < BATCH; k++) {
		struct sockaddr_in from;
		socklen_t fl = sizeof from;
		uint8_t src[6];
		ssize_t n = recvfrom(b->fd, in, sizeof in, MSG_DONTWAIT, (struct sockaddr *)&from, &fl);
		if (n < 0)
			break;
		if (fl != sizeof from || from.sin_family != AF_INET || from.sin_port == 0)
			continue;
		if (!within_rate(b, from.sin_addr.s_addr, b->m.now))
			continue;
		memcpy(src, &from.sin_addr, 4);
		memcpy(src + 4, &from.sin_port, 2);
		if (b->c.bbmd && memcmp(src, b->fdr.addr, 6) == 0 && n >= 4 && in[0] == 0x81 && in[1] == 0x00) {
			fd_result(b, in, (size_t)n, b->m.now);
			continue;
		}
		psd_bacserve_handle(&b->m, in, (size_t)n, src, 0, out, &r);
		if (r.to == PSD_BACSERVE_NONE || r.len == 0)
			continue;
		if (b->fdr.registered && r.len > 7 && out[1] == 0x0a && out[5] == 0 && out[6] == 0x10 && out[7] == 0x00) {
			/* an I-Am of a foreign device: broadcast through the BBMD */
			out[1] = 0x09;
			send_to(b, out, r.len, b->fdr.addr);
			continue;
		}
		send_to(b, out, r.len, r.to == PSD_BACSERVE_TO_ADDRESS ? r.addr : src);
	}
	/* an answer's segments queued by the datagrams above or due again
	 * after their timeout: at most a window a transaction */
	{
		uint8_t to[6];
		size_t len;
		while ((len = psd_bacseg_next(&b->m.seg, b->m.now, out, to)))
			send_to(b, out, len, to);
	}
	fd_service(b, b->m.now);
	/* COV notifications: at most one per subscription a turn */
	while (psd_bacserve_cov(&b->m, out, &r))
		send_to(b, out, r.len, r.addr);
	/* renew an override a BMS still holds before it runs out */
	for (size_t i = 0; i < b->m.nzone; i++)
		if (in_force(&b->zone[i]) >= 0 && now - b->issued[i] >= b->c.hold / 2)
			apply(b, i);
}

static void bacnet_close(struct psd_bacnet *b)
{
	if (!b)
		return;
	psd_bacseg_free(&b->m.seg);
	close(b->fd);
	free(b);
}

/* ---- the room's row (frontend.h) ---- */

static int wanted(const struct psd_config *cf)
{
	return cf->bacnet.enabled;
}

static void *start(const struct psd_frontend_env *env, char *err, size_t errlen)
{
	return bacnet_open(&env->cf->bacnet, env, err, errlen);
}

/* COV notifications of the levels just commanded */
static void step(void *fe, double now)
{
	bacnet_service(fe, NULL, now);
}

static int pollfds(void *fe, struct pollfd *fds, int max)
{
	return max > 0 ? bacnet_pollfd(fe, fds) : 0;
}

static int wait_ms(const void *fe)
{
	return bacnet_wait_ms(fe);
}

static void turn(void *fe, const struct pollfd *fds, int n, double now)
{
	(void)n;
	bacnet_service(fe, fds, now);
}

static void stop(void *fe)
{
	bacnet_close(fe);
}

const struct psd_frontend psd_bacnet_frontend = {
	.name = "bacnet",
	.refused = "BACnet cannot start",
	.wanted = wanted,
	.start = start,
	.step = step,
	.pollfds = pollfds,
	.wait_ms = wait_ms,
	.service = turn,
	.stop = stop,
};
