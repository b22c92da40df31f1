/* SPDX-License-Identifier: ISC */
/* The web console's HTTP server (web.h): routes, login, the live stream. */
#include "web.h"

#include <arpa/inet.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <microhttpd.h>
#include <netinet/in.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>

#include "canvas.h"
#include "ctlsock.h"
#include "config.h"
#include "engine.h"
#include "errbuf.h"
#include "json.h"
#include "log.h"
#include "time.h"
#include "webasset.h"
#include "webdoc.h"
#include "webhist.h"
#include "webreq.h"
#include "websess.h"

/* The connections: CONN_MAX at once, PER_ADDR from one address, CONN_IDLE
 * s without a byte; a request must arrive whole (its headers and body)
 * within REQUEST_MAX s of its first byte however often its bytes come,
 * and past ROOM connections the slowest request still arriving is closed,
 * so that a new client always finds a place (psensd.conf(5) [web]). */
enum { BODY_MAX = 4096, CONN_MAX = 64, PER_ADDR = 16, CONN_IDLE = 30, REQUEST_MAX = 10, ROOM = CONN_MAX - 4 };
static const char cookie_name[] = "psd_session";

/* A TCP connection: by when its request must have arrived. */
struct conn {
	struct conn *next, **pprev;
	struct MHD_Connection *mc;
	double deadline;   /* monotonic s; 0 while its request is answered */
	int shut;       /* closed by us, waiting for MHD to see it */
};

/* A live stream (GET /api/events): what is still to be sent. */
struct sse {
	struct sse *next, **pprev;
	struct psd_web *w;
	struct MHD_Connection *conn;
	char *buf;
	size_t len, off;
	int suspended;
	double expiry;   /* wall s: its login's end, when the stream ends too */
	int ended;
};

/* The thread that checks the passwords (PBKDF2, tens of ms each): so that
 * logins never hold the loop, the control and the other front ends. */
struct checker {
	pthread_t thread;
	pthread_mutex_t lock;
	pthread_cond_t wake;
	struct req *head, **tail;
	int stop, running;
	const char *hash;
};

struct psd_web {
	struct psd_web_conf c;
	struct psd_engine *e;
	psd_frontend_request_fn fn;
	void *user;
	struct MHD_Daemon *mhd;
	struct psd_websess sess;
	struct sse *streams;
	struct conn *conns;
	int nconns;
	int closing;
	int drew;             /* a record was drawn: cairo's and fontconfig's caches are filled */
	double next_update;   /* monotonic s */
	struct psd_webhist hist;
	struct psd_ctl_reply reply;   /* the last control request's, kept for its buffer */
	struct checker chk;
};

/* A request's state across MHD's calls: its body so far, and a login's
 * password check while the worker runs it. */
struct req {
	char body[BODY_MAX];
	size_t len;
	int too_long;
	struct req *next_check;   /* the worker's queue */
	struct MHD_Connection *conn;
	char pw[256];
	enum { CHECK_NONE, CHECK_QUEUED, CHECK_DONE } check;
	int ok;   /* the password matched (CHECK_DONE) */
};


static enum MHD_Result send_text(struct MHD_Connection *conn, unsigned status, const char *type, const char *text,
                                 const char *cookie)
{
	struct MHD_Response *r = MHD_create_response_from_buffer(strlen(text), (void *)text, MHD_RESPMEM_MUST_COPY);
	enum MHD_Result rc;
	if (!r)
		return MHD_NO;
	MHD_add_response_header(r, "Content-Type", type);
	MHD_add_response_header(r, "Cache-Control", "no-store");
	MHD_add_response_header(r, "X-Content-Type-Options", "nosniff");
	MHD_add_response_header(r, "X-Frame-Options", "DENY");
	if (cookie)
		MHD_add_response_header(r, "Set-Cookie", cookie);
	rc = MHD_queue_response(conn, status, r);
	MHD_destroy_response(r);
	return rc;
}

/* {"ok":false,"error":msg} */
static enum MHD_Result send_error(struct MHD_Connection *conn, unsigned status, const char *msg)
{
	json_object *o = json_object_new_object();
	enum MHD_Result rc;
	json_object_object_add(o, "ok", json_object_new_boolean(0));
	psd_json_str(o, "error", msg);
	rc = send_text(conn, status, "application/json", psd_json_text(o, 10), NULL);
	json_object_put(o);
	return rc;
}

static const char *client_addr(struct MHD_Connection *conn, char *buf, size_t n)
{
	const union MHD_ConnectionInfo *ci = MHD_get_connection_info(conn, MHD_CONNECTION_INFO_CLIENT_ADDRESS);
	const struct sockaddr *sa = ci ? ci->client_addr : NULL;
	snprintf(buf, n, "?");
	if (sa && sa->sa_family == AF_INET)
		inet_ntop(AF_INET, &((const struct sockaddr_in *)(const void *)sa)->sin_addr, buf, (socklen_t)n);
	else if (sa && sa->sa_family == AF_INET6)
		inet_ntop(AF_INET6, &((const struct sockaddr_in6 *)(const void *)sa)->sin6_addr, buf, (socklen_t)n);
	return buf;
}

/* The connection's record (NULL when MHD has none). */
static struct conn *conn_of(struct MHD_Connection *mc)
{
	const union MHD_ConnectionInfo *ci = MHD_get_connection_info(mc, MHD_CONNECTION_INFO_SOCKET_CONTEXT);
	return ci ? ci->socket_context : NULL;
}

/* Close a connection under MHD: the shut socket reads as the end, and MHD
 * closes it at its next turn. */
static void conn_shut(struct conn *c, const char *why)
{
	const union MHD_ConnectionInfo *ci = MHD_get_connection_info(c->mc, MHD_CONNECTION_INFO_CONNECTION_FD);
	char addr[64];
	if (c->shut || !ci)
		return;
	psd_log_info("web: a request from %s %s: connection closed", client_addr(c->mc, addr, sizeof addr), why);
	shutdown(ci->connect_fd, SHUT_RDWR);
	c->shut = 1;
}

/* The connection whose request is the latest against its deadline (the
 * earliest deadline), but skip. */
static struct conn *conn_slowest(struct psd_web *w, const struct conn *skip)
{
	struct conn *slow = NULL;
	for (struct conn *c = w->conns; c; c = c->next)
		if (c != skip && !c->shut && c->deadline > 0 && (!slow || c->deadline < slow->deadline))
			slow = c;
	return slow;
}

static void notify_cb(void *cls, struct MHD_Connection *mc, void **sctx, enum MHD_ConnectionNotificationCode toe)
{
	struct psd_web *w = cls;
	struct conn *c = *sctx, *slow;
	if (toe == MHD_CONNECTION_NOTIFY_CLOSED) {
		if (c) {
			*c->pprev = c->next;
			if (c->next)
				c->next->pprev = c->pprev;
			w->nconns--;
			free(c);
			*sctx = NULL;
		}
		return;
	}
	if (!(c = calloc(1, sizeof *c)))
		return;   /* not counted: MHD's own limits still hold */
	c->mc = mc;
	c->deadline = psd_time_mono() + REQUEST_MAX;
	c->next = w->conns;
	c->pprev = &w->conns;
	if (c->next)
		c->next->pprev = &c->next;
	w->conns = c;
	*sctx = c;
	if (++w->nconns > ROOM && (slow = conn_slowest(w, c)))
		conn_shut(slow, "was the slowest of too many connections");
}

/* Close every connection whose request is not in by its deadline
 * (web_wait_ms wakes the loop for the next). */
static void conn_sweep(struct psd_web *w, double now)
{
	char why[64];
	snprintf(why, sizeof why, "was not received within %d s", REQUEST_MAX);
	for (struct conn *c = w->conns; c; c = c->next)
		if (!c->shut && c->deadline > 0 && now >= c->deadline)
			conn_shut(c, why);
}

/* 1 when the request carries a valid session (its end in *expiry); else
 * 0 with why. */
static int authorized(struct psd_web *w, struct MHD_Connection *conn, const char **why, double *expiry)
{
	const char *h = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, "Cookie");
	char token[PSD_WEBSESS_TOKEN];
	*why = "not logged in";
	if (!h || psd_webreq_cookie(h, cookie_name, token, sizeof token) != 0 ||
	    !psd_websess_valid(&w->sess, token, psd_time_wall(), why))
		return 0;
	*expiry = (double)strtoll(token, NULL, 10);
	return 1;
}

/* The worker: each queued check in turn, its connection resumed with
 * the outcome (MHD_resume_connection may be called from any thread).  At
 * a stop the rest are resumed unchecked. */
static void *checker_run(void *arg)
{
	struct checker *k = arg;
	pthread_mutex_lock(&k->lock);
	for (;;) {
		struct req *q;
		while (!k->head && !k->stop)
			pthread_cond_wait(&k->wake, &k->lock);
		if (!(q = k->head))
			break;
		if (!(k->head = q->next_check))
			k->tail = &k->head;
		pthread_mutex_unlock(&k->lock);
		q->ok = k->stop ? 0 : psd_webpass_check(k->hash, q->pw);
		memset(q->pw, 0, sizeof q->pw);
		q->check = CHECK_DONE;
		MHD_resume_connection(q->conn);
		pthread_mutex_lock(&k->lock);
	}
	pthread_mutex_unlock(&k->lock);
	return NULL;
}

static int checker_start(struct checker *k, const char *hash)
{
	*k = (struct checker){ .tail = &k->head, .hash = hash };
	if (pthread_mutex_init(&k->lock, NULL) != 0)
		return -1;
	if (pthread_cond_init(&k->wake, NULL) != 0) {
		pthread_mutex_destroy(&k->lock);
		return -1;
	}
	if ((errno = pthread_create(&k->thread, NULL, checker_run, k)) != 0) {
		pthread_cond_destroy(&k->wake);
		pthread_mutex_destroy(&k->lock);
		return -1;
	}
	k->running = 1;
	return 0;
}

static void checker_stop(struct checker *k)
{
	if (!k->running)
		return;
	pthread_mutex_lock(&k->lock);
	k->stop = 1;
	pthread_cond_signal(&k->wake);
	pthread_mutex_unlock(&k->lock);
	pthread_join(k->thread, NULL);
	pthread_cond_destroy(&k->wake);
	pthread_mutex_destroy(&k->lock);
	k->running = 0;
}

/* Queue q's password for the worker; its connection waits, suspended. */
static void checker_queue(struct checker *k, struct MHD_Connection *conn, struct req *q)
{
	q->conn = conn;
	q->check = CHECK_QUEUED;
	q->next_check = NULL;
	MHD_suspend_connection(conn);
	pthread_mutex_lock(&k->lock);
	*k->tail = q;
	k->tail = &q->next_check;
	pthread_cond_signal(&k->wake);
	pthread_mutex_unlock(&k->lock);
}

/* The answer to a checked login: a session, or the failure (already
 * counted when the check was queued). */
static enum MHD_Result login_answer(struct psd_web *w, struct MHD_Connection *conn, int ok, const char *addr,
                                    double now, char *token, char *cookie, size_t n)
{
	if (w->closing)
		return send_error(conn, MHD_HTTP_SERVICE_UNAVAILABLE, "psensd is stopping");
	if (!ok) {
		psd_log_warnx("web: a failed login from %s", addr);
		return send_error(conn, MHD_HTTP_UNAUTHORIZED, "wrong password");
	}
	psd_websess_outcome(&w->sess, addr, 1, now);
	if (psd_websess_issue(&w->sess, now, token, PSD_WEBSESS_TOKEN) != 0)
		return send_error(conn, MHD_HTTP_INTERNAL_SERVER_ERROR, "no random bytes for a session");
	psd_log_info("web: login from %s", addr);
	/* the browser keeps the cookie an hour past the session, so that a
	 * request then is told the session expired, not that there is none */
	snprintf(cookie, n, "%s=%s; Path=/; HttpOnly; SameSite=Strict; Max-Age=%.0f", cookie_name, token,
	         w->c.session + 3600);
	return send_text(conn, MHD_HTTP_OK, "application/json", "{\"ok\":true}", cookie);
}

/* POST /api/login password=...: judged in two turns.  The first queues
 * the check for the worker and counts it as a failure at once (so that
 * logins sent together are throttled as if one after the other); the
 * second, when the worker resumes the connection, answers. */
static enum MHD_Result login(struct psd_web *w, struct MHD_Connection *conn, struct req *q)
{
	char addr[64], msg[160], token[PSD_WEBSESS_TOKEN], cookie[PSD_WEBSESS_TOKEN + 128];
	double now = psd_time_wall(), wait;
	client_addr(conn, addr, sizeof addr);
	if (q->check == CHECK_DONE)
		return login_answer(w, conn, q->ok, addr, now, token, cookie, sizeof cookie);
	if (q->check == CHECK_QUEUED)   /* not resumed by the worker: cannot happen */
		return MHD_NO;
	if ((wait = psd_websess_wait(&w->sess, addr, now)) > 0) {
		snprintf(msg, sizeof msg, "too many failed logins from this address: try again in %.0f s", ceil(wait));
		return send_error(conn, MHD_HTTP_TOO_MANY_REQUESTS, msg);
	}
	if ((wait = psd_websess_wait_all(&w->sess, now)) > 0) {
		snprintf(msg, sizeof msg, "too many failed logins from every address: try again in %.0f s", ceil(wait));
		return send_error(conn, MHD_HTTP_TOO_MANY_REQUESTS, msg);
	}
	if (psd_webreq_form(q->body, "password", q->pw, sizeof q->pw) != 0)
		return send_error(conn, MHD_HTTP_BAD_REQUEST, "no password given");
	psd_websess_outcome(&w->sess, addr, 0, now);
	psd_log_debug("web: checking a login from %s", addr);
	checker_queue(&w->chk, conn, q);
	return MHD_YES;
}

static enum MHD_Result logout(struct psd_web *w, struct MHD_Connection *conn)
{
	const char *h = MHD_lookup_connection_value(conn, MHD_HEADER_KIND, "Cookie");
	char token[PSD_WEBSESS_TOKEN], cookie[128];
	if (h && psd_webreq_cookie(h, cookie_name, token, sizeof token) == 0 &&
	    psd_websess_revoke(&w->sess, token, psd_time_wall()) == 1)
		psd_log_warnx("web: %d logouts within a session's lifetime fill the table of logged-out sessions: "
		              "the session key changed, every login has ended", PSD_WEBSESS_REVOKED + 1);
	snprintf(cookie, sizeof cookie, "%s=; Path=/; HttpOnly; SameSite=Strict; Max-Age=0", cookie_name);
	return send_text(conn, MHD_HTTP_OK, "application/json", "{\"ok\":true}", cookie);
}

/* POST /api/request line=...: the control request, answered as the socket
 * answers it. */
static enum MHD_Result request(struct psd_web *w, struct MHD_Connection *conn, const struct req *q)
{
	char line[PSD_CTL_MAX_LINE], err[200], addr[64];
	if (psd_webreq_form(q->body, "line", line, sizeof line) != 0)
		return send_error(conn, MHD_HTTP_BAD_REQUEST, "no request line given (or longer than the control socket takes)");
	if (psd_webreq_line_ok(line, err, sizeof err) != 0)
		return send_error(conn, MHD_HTTP_OK, err);
	if (strncmp(line, "status", 6) != 0)
		psd_log_info("web: %s asks: %s", client_addr(conn, addr, sizeof addr), line);
	w->fn(w->user, line, &w->reply);
	return send_text(conn, MHD_HTTP_OK, "application/json", w->reply.text, NULL);
}

/* GET /api/history?zone=Z: the zone's chart (webhist.h). */
static enum MHD_Result history(struct psd_web *w, struct MHD_Connection *conn)
{
	const char *zone = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "zone");
	char *text = zone ? psd_webhist_json(&w->hist, zone) : NULL;
	enum MHD_Result rc;
	if (!text)
		return send_error(conn, MHD_HTTP_NOT_FOUND, "no such zone");
	rc = send_text(conn, MHD_HTTP_OK, "application/json", text, NULL);
	free(text);
	return rc;
}

/* The live stream: MHD asks for more; what is queued goes, else the
 * connection waits (suspended) for the next update. */
static ssize_t sse_read(void *cls, uint64_t pos, char *buf, size_t max)
{
	struct sse *s = cls;
	size_t n;
	(void)pos;
	if (s->w->closing || (s->ended && s->off >= s->len))
		return MHD_CONTENT_READER_END_OF_STREAM;
	if (s->off >= s->len) {
		MHD_suspend_connection(s->conn);
		s->suspended = 1;
		return 0;
	}
	n = s->len - s->off < max ? s->len - s->off : max;
	memcpy(buf, s->buf + s->off, n);
	s->off += n;
	return (ssize_t)n;
}

static void sse_free(void *cls)
{
	struct sse *s = cls;
	*s->pprev = s->next;
	if (s->next)
		s->next->pprev = s->pprev;
	free(s->buf);
	free(s);
}

/* Queue text on a stream (dropped when the client has not taken the last
 * update yet: a slow client gets the newest state, not a backlog). */
static void sse_queue(struct sse *s, const char *text)
{
	size_t n = strlen(text);
	char *b;
	if (s->off < s->len)
		return;
	if (!(b = realloc(s->buf, n + 1)))
		return;
	memcpy(b, text, n + 1);
	s->buf = b;
	s->len = n;
	s->off = 0;
	if (s->suspended) {
		s->suspended = 0;
		MHD_resume_connection(s->conn);
	}
}

/* The update every stream gets: the status reply as one event. */
static char *status_event(struct psd_web *w)
{
	char line[] = "status";
	size_t n;
	char *ev;
	w->fn(w->user, line, &w->reply);
	n = strlen(w->reply.text);
	if (!(ev = malloc(n + 32)))
		return NULL;
	snprintf(ev, n + 32, "event: status\ndata: %s\n\n", w->reply.text);
	return ev;
}

static enum MHD_Result events(struct psd_web *w, struct MHD_Connection *conn, double expiry)
{
	struct sse *s = calloc(1, sizeof *s);
	struct MHD_Response *r;
	enum MHD_Result rc;
	char *ev = status_event(w);
	size_t n = ev ? strlen(ev) + 80 : 0;
	if (!s || !ev || !(s->buf = malloc(n))) {
		free(s);
		free(ev);
		return MHD_NO;
	}
	/* the reconnection delay a browser keeps, the seconds between updates
	 * (a page that hears nothing for a few of them knows psensd is not
	 * answering although the connection stays open), and the first update */
	snprintf(s->buf, n, "retry: 2000\nevent: stream\ndata: {\"update_s\":%g}\n\n%s", w->c.update, ev);
	s->len = strlen(s->buf);
	free(ev);
	s->w = w;
	s->conn = conn;
	s->expiry = expiry;
	s->next = w->streams;
	s->pprev = &w->streams;
	if (s->next)
		s->next->pprev = &s->next;
	w->streams = s;
	if (!(r = MHD_create_response_from_callback(MHD_SIZE_UNKNOWN, 16384, sse_read, s, sse_free))) {
		sse_free(s);
		return MHD_NO;
	}
	MHD_add_response_header(r, "Content-Type", "text/event-stream");
	MHD_add_response_header(r, "Cache-Control", "no-store");
	rc = MHD_queue_response(conn, MHD_HTTP_OK, r);
	MHD_destroy_response(r);
	return rc;
}

/* A document (webdoc.h) as the reply, or the error it gave. */
static enum MHD_Result send_doc(struct psd_web *w, struct MHD_Connection *conn, int rc, unsigned char *buf,
                                size_t len, const char *type, const char *disp, const char *err)
{
	struct MHD_Response *r;
	enum MHD_Result mr;
	w->drew = 1;
	if (rc != 0)
		return send_error(conn, rc == PSD_WEBDOC_NONE ? MHD_HTTP_NOT_FOUND : MHD_HTTP_INTERNAL_SERVER_ERROR, err);
	if (!(r = MHD_create_response_from_buffer(len, buf, MHD_RESPMEM_MUST_FREE))) {
		free(buf);
		return MHD_NO;
	}
	MHD_add_response_header(r, "Content-Type", type);
	if (disp)
		MHD_add_response_header(r, "Content-Disposition", disp);
	MHD_add_response_header(r, "Cache-Control", "no-store");
	mr = MHD_queue_response(conn, MHD_HTTP_OK, r);
	MHD_destroy_response(r);
	return mr;
}

/* GET /api/record.pdf[?zone=Z]: the commissioning record, as psensctl
 * report draws it.  Drawn in the loop's turn: the control waits for it
 * (doc/console.md gives the times). */
static enum MHD_Result record(struct psd_web *w, struct MHD_Connection *conn)
{
	const char *zone = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "zone");
	unsigned char *buf = NULL;
	size_t len = 0;
	char err[512] = "", disp[128];
	int rc = psd_webdoc_record(w->e, zone, &buf, &len, err, sizeof err);
	snprintf(disp, sizeof disp, "attachment; filename=\"psensd-record%s%.60s.pdf\"", zone ? "-" : "", zone ? zone : "");
	return send_doc(w, conn, rc, buf, len, "application/pdf", disp, err);
}

/* GET /api/year.png?zone=Z: the zone's year, as psensd -Y -P draws it;
 * in the loop's turn, as the record. */
static enum MHD_Result year(struct psd_web *w, struct MHD_Connection *conn)
{
	const char *zone = MHD_lookup_connection_value(conn, MHD_GET_ARGUMENT_KIND, "zone");
	unsigned char *buf = NULL;
	size_t len = 0;
	char err[512] = "";
	int rc = zone ? psd_webdoc_year(w->e, zone, &buf, &len, err, sizeof err) : PSD_WEBDOC_NONE;
	if (!zone)
		snprintf(err, sizeof err, "the year of which zone? (?zone=NAME)");
	return send_doc(w, conn, rc, buf, len, "image/png", NULL, err);
}

static enum MHD_Result asset(struct MHD_Connection *conn, const char *url)
{
	const struct psd_webasset *a = psd_webasset_find(strcmp(url, "/") == 0 ? "/index.html" : url);
	struct MHD_Response *r;
	enum MHD_Result rc;
	if (!a)
		return send_error(conn, MHD_HTTP_NOT_FOUND, "no such page");
	if (!(r = MHD_create_response_from_buffer(a->len, (void *)a->data, MHD_RESPMEM_PERSISTENT)))
		return MHD_NO;
	MHD_add_response_header(r, "Content-Type", a->type);
	MHD_add_response_header(r, "Cache-Control", "no-cache");
	MHD_add_response_header(r, "X-Content-Type-Options", "nosniff");
	MHD_add_response_header(r, "X-Frame-Options", "DENY");
	MHD_add_response_header(r, "Content-Security-Policy",
	                        "default-src 'self'; img-src 'self' data:; style-src 'self'; script-src 'self'");
	rc = MHD_queue_response(conn, MHD_HTTP_OK, r);
	MHD_destroy_response(r);
	return rc;
}

static enum MHD_Result route(struct psd_web *w, struct MHD_Connection *conn, const char *url, const char *method,
                             struct req *q)
{
	int post = strcmp(method, "POST") == 0, get = strcmp(method, "GET") == 0 || strcmp(method, "HEAD") == 0;
	const char *why;
	double expiry;
	if (strncmp(url, "/api/", 5) != 0)
		return get ? asset(conn, url) : send_error(conn, MHD_HTTP_METHOD_NOT_ALLOWED, "GET only");
	if (q->too_long)
		return send_error(conn, MHD_HTTP_CONTENT_TOO_LARGE, "the request's body is too long");
	/* a page of another site cannot set this header without the browser
	 * asking first (CORS), which this server never allows */
	if (post && !MHD_lookup_connection_value(conn, MHD_HEADER_KIND, "X-PSD"))
		return send_error(conn, MHD_HTTP_FORBIDDEN, "a console request carries the X-PSD header");
	if (post && strcmp(url, "/api/login") == 0)
		return login(w, conn, q);
	if (post && strcmp(url, "/api/logout") == 0)
		return logout(w, conn);
	if (!authorized(w, conn, &why, &expiry)) {
		char msg[80];
		snprintf(msg, sizeof msg, "session %s: log in", why);
		return send_error(conn, MHD_HTTP_UNAUTHORIZED, msg);
	}
	if (get && strcmp(url, "/api/session") == 0)
		return send_text(conn, MHD_HTTP_OK, "application/json", "{\"ok\":true}", NULL);
	if (post && strcmp(url, "/api/request") == 0)
		return request(w, conn, q);
	if (get && strcmp(url, "/api/events") == 0)
		return events(w, conn, expiry);
	if (get && strcmp(url, "/api/history") == 0)
		return history(w, conn);
	if (get && strcmp(url, "/api/record.pdf") == 0)
		return record(w, conn);
	if (get && strcmp(url, "/api/year.png") == 0)
		return year(w, conn);
	return send_error(conn, MHD_HTTP_NOT_FOUND, "no such request");
}

static enum MHD_Result access_cb(void *cls, struct MHD_Connection *conn, const char *url, const char *method,
                                 const char *version, const char *upload, size_t *upload_size, void **ctx)
{
	struct psd_web *w = cls;
	struct req *q = *ctx;
	struct conn *c;
	(void)version;
	if (!q) {
		if (!(q = calloc(1, sizeof *q)))
			return MHD_NO;
		*ctx = q;
		return MHD_YES;
	}
	if (*upload_size) {
		if (q->len + *upload_size < sizeof q->body) {
			memcpy(q->body + q->len, upload, *upload_size);
			q->len += *upload_size;
			q->body[q->len] = 0;
		} else {
			q->too_long = 1;
		}
		*upload_size = 0;
		return MHD_YES;
	}
	if ((c = conn_of(conn)))
		c->deadline = 0;   /* arrived whole: being answered, a stream perhaps */
	return route(w, conn, url, method, q);
}

static void done_cb(void *cls, struct MHD_Connection *conn, void **ctx, enum MHD_RequestTerminationCode toe)
{
	struct conn *c = conn_of(conn);
	(void)cls;
	(void)toe;
	/* the next request on a kept-alive connection: its wait is not its
	 * arrival (MHD does not say when it starts), so it has the idle time
	 * and the arrival's both; a connection silent that long MHD closes */
	if (c)
		c->deadline = psd_time_mono() + CONN_IDLE + REQUEST_MAX;
	free(*ctx);
	*ctx = NULL;
}

/* libmicrohttpd's own messages (a client gone mid-stream, a bad request):
 * through psensd's log, as debug messages. */
static void mhd_log(void *cls, const char *fmt, va_list ap) __attribute__((format(printf, 2, 0)));
static void mhd_log(void *cls, const char *fmt, va_list ap)
{
	char msg[300];
	size_t n;
	(void)cls;
	vsnprintf(msg, sizeof msg, fmt, ap);
	n = strcspn(msg, "\n");
	msg[n] = 0;
	psd_log_debug("web: %s", msg);
}

static struct psd_web *web_open(const struct psd_web_conf *c, struct psd_engine *e, psd_frontend_request_fn fn,
                                void *user, char *err, size_t errlen)
{
	struct psd_web *w = calloc(1, sizeof *w);
	struct sockaddr_in sa = { .sin_family = AF_INET };
	if (!w) {
		psd_errbuf(err, errlen, "[web]: out of memory");
		return NULL;
	}
	w->c = *c;
	w->e = e;
	w->fn = fn;
	w->user = user;
	psd_websess_init(&w->sess, c->hash, c->session);
	if (checker_start(&w->chk, w->c.hash) != 0) {
		psd_errbuf(err, errlen, "[web]: cannot start the password checks' thread: %s", strerror(errno));
		free(w);
		return NULL;
	}
	sa.sin_port = htons((uint16_t)c->port);
	inet_pton(AF_INET, c->addr, &sa.sin_addr);
	w->mhd = MHD_start_daemon(MHD_USE_EPOLL | MHD_ALLOW_SUSPEND_RESUME | MHD_USE_ERROR_LOG, (uint16_t)c->port, NULL,
	                          NULL, access_cb, w, MHD_OPTION_SOCK_ADDR, (struct sockaddr *)&sa,
	                          MHD_OPTION_NOTIFY_COMPLETED, done_cb, w, MHD_OPTION_NOTIFY_CONNECTION, notify_cb, w,
	                          MHD_OPTION_CONNECTION_LIMIT, (unsigned)CONN_MAX, MHD_OPTION_PER_IP_CONNECTION_LIMIT,
	                          (unsigned)PER_ADDR, MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)CONN_IDLE,
	                          MHD_OPTION_CONNECTION_MEMORY_LIMIT, (size_t)65536,
	                          MHD_OPTION_EXTERNAL_LOGGER, mhd_log, NULL, MHD_OPTION_END);
	if (!w->mhd) {
		psd_errbuf(err, errlen, "[web]: cannot listen on %s:%ld: %s", c->addr, c->port, strerror(errno));
		checker_stop(&w->chk);
		free(w);
		return NULL;
	}
	psd_log_info("web console on http://%s:%ld/", c->addr, c->port);
	return w;
}

static int web_pollfd(struct psd_web *w, struct pollfd *pfd)
{
	const union MHD_DaemonInfo *i = MHD_get_daemon_info(w->mhd, MHD_DAEMON_INFO_EPOLL_FD);
	if (!i)
		return 0;
	*pfd = (struct pollfd){ i->epoll_fd, POLLIN, 0 };
	return 1;
}

static void web_service(struct psd_web *w, const struct pollfd *pfd)
{
	double now = psd_time_mono();
	(void)pfd;   /* MHD_run reads its epoll set without waiting, whatever poll() said */
	psd_webhist_record(&w->hist, w->e);
	if (w->streams && now >= w->next_update) {
		char *ev = status_event(w);
		double wall = psd_time_wall();
		for (struct sse *s = w->streams; ev && s; s = s->next) {
			if (wall >= s->expiry && !s->ended) {   /* the login is over: so is its stream */
				s->ended = 1;
				if (s->suspended) {
					s->suspended = 0;
					MHD_resume_connection(s->conn);
				}
			}
			if (!s->ended)
				sse_queue(s, ev);
		}
		free(ev);
		w->next_update = now + w->c.update;
	}
	conn_sweep(w, now);
	MHD_run(w->mhd);
}

static int web_wait_ms(const struct psd_web *w)
{
	MHD_UNSIGNED_LONG_LONG t;
	int ms = -1;
	double next = -1;
	if (MHD_get_timeout(w->mhd, &t) == MHD_YES)
		ms = t > 60000 ? 60000 : (int)t;
	for (const struct conn *c = w->conns; c; c = c->next)   /* the next request to end unreceived */
		if (!c->shut && c->deadline > 0 && (next < 0 || c->deadline < next))
			next = c->deadline;
	if (next >= 0) {
		double left = (next - psd_time_mono()) * 1000;
		int u = left <= 0 ? 0 : (int)ceil(left);
		if (ms < 0 || u < ms)
			ms = u;
	}
	if (w->streams) {
		double left = (w->next_update - psd_time_mono()) * 1000;
		int u = left <= 0 ? 0 : (int)ceil(left);
		if (ms < 0 || u < ms)
			ms = u;
	}
	return ms;
}

static void web_close(struct psd_web *w)
{
	if (!w)
		return;
	w->closing = 1;
	checker_stop(&w->chk);   /* every queued login resumed, answered below */
	for (struct sse *s = w->streams; s; s = s->next)
		if (s->suspended) {
			s->suspended = 0;
			MHD_resume_connection(s->conn);
		}
	MHD_run(w->mhd);
	MHD_stop_daemon(w->mhd);
	if (w->drew)   /* the fonts' caches: nothing left for leak checkers */
		ps_canvas_shutdown();
	psd_ctlsock_reply_free(&w->reply);
	free(w);
}

/* ---- the room's row (frontend.h) ---- */

static int wanted(const struct psd_config *cf)
{
	return cf->web.enabled;
}

static void *start(const struct psd_frontend_env *env, char *err, size_t errlen)
{
	return web_open(&env->cf->web, env->engine, env->request, env->user, err, errlen);
}

static int pollfds(void *fe, struct pollfd *fds, int max)
{
	return max > 0 ? web_pollfd(fe, fds) : 0;
}

static int wait_ms(const void *fe)
{
	return web_wait_ms(fe);
}

static void turn(void *fe, const struct pollfd *fds, int n, double now)
{
	(void)n;
	(void)now;   /* the console's timers run on the monotonic clock */
	web_service(fe, fds);
}

static void stop(void *fe)
{
	web_close(fe);
}

const struct psd_frontend psd_web_frontend = {
	.name = "web",
	.refused = "the web console cannot start",
	.wanted = wanted,
	.start = start,
	.pollfds = pollfds,
	.wait_ms = wait_ms,
	.service = turn,
	.stop = stop,
};
