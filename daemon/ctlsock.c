/* SPDX-License-Identifier: ISC */
#include "ctlsock.h"

#include <errno.h>
#include <fcntl.h>
#include <grp.h>
#include <pwd.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

#include "errbuf.h"
#include "log.h"
#include "pidlock.h"
#include "time.h"

int psd_ctlsock_split(char *line, char **argv, char *err, size_t errlen)
{
	int n = 0;
	char *p = line;
	for (char *q = line; *q; q++)
		if (((unsigned char)*q < 0x20 && *q != '\t') || (unsigned char)*q == 0x7f)
			return psd_errbuf(err, errlen, "control character 0x%02x at byte %d", (unsigned char)*q,
			                (int)(q - line));
	for (;;) {
		while (*p == ' ' || *p == '\t')
			p++;
		if (!*p)
			break;
		if (n == PSD_CTL_MAX_WORDS)
			return psd_errbuf(err, errlen, "more than %d words", PSD_CTL_MAX_WORDS);
		argv[n++] = p;
		while (*p && *p != ' ' && *p != '\t')
			p++;
		if (*p)
			*p++ = '\0';
	}
	return n;
}

/* A socket file that answers a connect is someone's live socket: -1 with
 * its server's pid in err.  0 when nobody listens (ECONNREFUSED). */
static int live_peer(const struct sockaddr_un *sa, char *err, size_t errlen)
{
	int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0), rc;
	struct ucred cr = { 0, 0, 0 };
	socklen_t len = sizeof cr;
	if (fd < 0)
		return psd_errbuf(err, errlen, "%s: %s", sa->sun_path, strerror(errno));
	rc = connect(fd, (const struct sockaddr *)sa, sizeof *sa);
	if (rc != 0 && errno != EAGAIN && errno != EINPROGRESS) {
		close(fd);
		return 0;   /* refused: dead */
	}
	/* accepted, or a full backlog (EAGAIN): someone listens */
	if (rc == 0 && getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &cr, &len) == 0 && cr.pid > 0)
		psd_errbuf(err, errlen, "%s is in use: pid %ld serves it: not started", sa->sun_path, (long)cr.pid);
	else
		psd_errbuf(err, errlen, "%s is in use: a process serves it: not started", sa->sun_path);
	close(fd);
	return -1;
}

int psd_ctlsock_open(struct psd_ctlsock *s, const char *path, int mode, int max_clients, psd_ctl_handler h,
                 void *user, char *err, size_t errlen)
{
	struct sockaddr_un sa = { .sun_family = AF_UNIX };
	struct stat st;
	int inuse = 0;
	memset(s, 0, sizeof *s);
	s->lfd = -1;
	s->lockfd = -1;
	if (strlen(path) >= sizeof sa.sun_path)
		return psd_errbuf(err, errlen, "%s: a socket path is at most %zu bytes", path,
		                sizeof sa.sun_path - 1);
	s->cl = calloc((size_t)max_clients, sizeof *s->cl);
	if (!s->cl)
		return psd_errbuf(err, errlen, "%s: out of memory", path);
	s->max = max_clients;
	s->handler = h;
	s->user = user;
	snprintf(s->path, sizeof s->path, "%s", path);
	snprintf(sa.sun_path, sizeof sa.sun_path, "%s", path);
	/* one daemon per socket: the lock first, then a socket no lock
	 * guards (another program's, or an older daemon's) must not answer */
	{
		char lock[sizeof s->path + 8];
		pid_t holder;
		snprintf(lock, sizeof lock, "%s.lock", path);
		if ((s->lockfd = psd_pidlock_take(lock, &holder)) < 0) {
			inuse = errno == EWOULDBLOCK;
			if (errno == EWOULDBLOCK && holder > 0)
				psd_errbuf(err, errlen, "%s is in use by psensd pid %ld (it holds %s): not started", path,
				         (long)holder, lock);
			else if (errno == EWOULDBLOCK)
				psd_errbuf(err, errlen, "%s is in use: another process holds %s: not started", path, lock);
			else
				psd_errbuf(err, errlen, "%s: %s", lock, strerror(errno));
			goto bad;
		}
	}
	if (lstat(path, &st) == 0) {
		if (!S_ISSOCK(st.st_mode)) {
			psd_errbuf(err, errlen, "%s exists and is not a socket", path);
			goto bad;
		}
		if (live_peer(&sa, err, errlen) != 0) {
			inuse = 1;
			goto bad;
		}
		unlink(path);   /* left by a killed daemon: nobody answers it */
	}
	/* The backlog is the kernel's maximum: a crowd of clients connecting
	 * between two turns of the poll loop queues rather than being refused
	 * (non-blocking clients see EAGAIN on a full AF_UNIX backlog).  The
	 * max_clients cap is applied after accept, with an error reply. */
	s->lfd = socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
	if (s->lfd < 0 || bind(s->lfd, (struct sockaddr *)&sa, sizeof sa) != 0 ||
	    chmod(path, (mode_t)mode) != 0 || listen(s->lfd, SOMAXCONN) != 0) {
		psd_errbuf(err, errlen, "%s: %s", path, strerror(errno));
		goto bad;
	}
	return 0;
bad:
	if (s->lfd >= 0)
		close(s->lfd);
	psd_pidlock_release(s->lockfd);
	s->lockfd = -1;
	free(s->cl);
	s->cl = NULL;
	s->lfd = -1;
	s->path[0] = 0;
	errno = inuse ? EADDRINUSE : EINVAL;
	return -1;
}

int psd_ctlsock_pollfds(const struct psd_ctlsock *s, struct pollfd *fds, int max)
{
	int n = 0;
	if (s->lfd < 0 || max < 1)
		return 0;
	fds[n++] = (struct pollfd){ s->lfd, POLLIN, 0 };
	for (int i = 0; i < s->ncl && n < max; i++)
		fds[n++] = (struct pollfd){ s->cl[i].fd, (short)(POLLIN | (s->cl[i].nout ? POLLOUT : 0)), 0 };
	return n;
}

static void drop(struct psd_ctlsock *s, int i)
{
	close(s->cl[i].fd);
	free(s->cl[i].out);
	s->cl[i] = s->cl[--s->ncl];
	memset(&s->cl[s->ncl], 0, sizeof s->cl[s->ncl]);
}

int psd_ctlsock_reply_set(struct psd_ctl_reply *r, const char *text)
{
	static const char too_long[] = "{\"ok\":false,\"error\":\"reply too long\"}";
	static const char no_mem[] = "{\"ok\":false,\"error\":\"out of memory\"}";
	size_t n = strlen(text);
	if (n >= PSD_CTL_MAX_REPLY) {
		psd_ctlsock_reply_free(r);
		r->text = (char *)too_long;
		return -1;
	}
	if (n + 1 > r->cap) {
		char *grown = realloc(r->cap ? r->text : NULL, n + 1);
		if (!grown) {
			psd_ctlsock_reply_free(r);
			r->text = (char *)no_mem;
			return -1;
		}
		r->text = grown;
		r->cap = n + 1;
	}
	memcpy(r->text, text, n + 1);
	return 0;
}

void psd_ctlsock_reply_free(struct psd_ctl_reply *r)
{
	if (r->cap)
		free(r->text);
	r->text = NULL;
	r->cap = 0;
}

/* Queue text and a newline; a client that stops reading is dropped. */
static int queue(struct psd_ctl_client *c, const char *text)
{
	size_t n = strlen(text);
	if (c->nout + n + 1 > PSD_CTL_MAX_OUT)
		return -1;
	if (c->nout + n + 1 > c->outcap) {
		size_t cap = c->outcap ? c->outcap : 4096;
		char *grown;
		while (cap < c->nout + n + 1)
			cap *= 2;
		if (!(grown = realloc(c->out, cap)))
			return -1;
		c->out = grown;
		c->outcap = cap;
	}
	memcpy(c->out + c->nout, text, n);
	c->out[c->nout + n] = '\n';
	c->nout += n + 1;
	return 0;
}

/* Root, the daemon's own user, or anyone in the daemon's group. */
static int peer_allowed(uid_t uid, gid_t gid)
{
	struct passwd pw, *res = NULL;
	char buf[4096];
	gid_t groups[64];
	int ng = 64;
	if (uid == 0 || uid == geteuid() || gid == getegid())
		return 1;
	if (getpwuid_r(uid, &pw, buf, sizeof buf, &res) != 0 || !res)
		return 0;
	if (getgrouplist(pw.pw_name, pw.pw_gid, groups, &ng) < 0)
		return 0;
	for (int i = 0; i < ng; i++)
		if (groups[i] == getegid())
			return 1;
	return 0;
}

static void accept_all(struct psd_ctlsock *s)
{
	for (;;) {
		struct ucred cr;
		socklen_t len = sizeof cr;
		int fd = accept4(s->lfd, NULL, NULL, SOCK_NONBLOCK | SOCK_CLOEXEC);
		if (fd < 0)
			return;
		if (getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &cr, &len) != 0 || !peer_allowed(cr.uid, cr.gid)) {
			static const char no[] = "{\"ok\":false,\"error\":\"permission denied\"}\n";
			s->rejected++;
			psd_log_warnx("control socket: refused uid %d pid %d (not in the daemon's group)", (int)cr.uid,
			          (int)cr.pid);
			(void)!write(fd, no, sizeof no - 1);
			close(fd);
			continue;
		}
		if (s->ncl >= s->max) {
			static const char busy[] = "{\"ok\":false,\"error\":\"too many clients\"}\n";
			s->rejected++;
			(void)!write(fd, busy, sizeof busy - 1);
			close(fd);
			continue;
		}
		s->cl[s->ncl] = (struct psd_ctl_client){ .fd = fd, .uid = cr.uid, .pid = cr.pid, .last = psd_time_mono() };
		s->ncl++;
	}
}

/* Handle every complete line in the input buffer. */
static void lines(struct psd_ctlsock *s, struct psd_ctl_client *c)
{
	struct psd_ctl_reply reply = { 0 };
	char *nl;
	while (!c->closing && (nl = memchr(c->in, '\n', c->nin))) {
		size_t len = (size_t)(nl - c->in), eff = len;
		*nl = '\0';
		if (eff && c->in[eff - 1] == '\r')
			c->in[--eff] = '\0';
		s->requests++;
		if (strlen(c->in) != eff)
			psd_ctlsock_reply_set(&reply, "{\"ok\":false,\"error\":\"NUL byte in the request\"}");
		else
			s->handler(s->user, c, c->in, &reply);
		if (queue(c, reply.text ? reply.text : "{\"ok\":false,\"error\":\"no reply\"}") != 0)
			c->closing = 1;
		psd_ctlsock_reply_free(&reply);
		memmove(c->in, nl + 1, c->nin - len - 1);
		c->nin -= len + 1;
	}
}

static int read_client(struct psd_ctlsock *s, struct psd_ctl_client *c)
{
	for (;;) {
		ssize_t n = read(c->fd, c->in + c->nin, sizeof c->in - 1 - c->nin);
		if (n == 0)
			return c->nout ? (c->closing = 1, 0) : -1;
		if (n < 0)
			return errno == EAGAIN || errno == EINTR ? 0 : -1;
		c->nin += (size_t)n;
		c->last = psd_time_mono();
		lines(s, c);
		if (c->nin == sizeof c->in - 1 && !memchr(c->in, '\n', c->nin)) {
			char msg[128];
			snprintf(msg, sizeof msg, "{\"ok\":false,\"error\":\"request longer than %d bytes\"}",
			         PSD_CTL_MAX_LINE - 1);
			s->rejected++;
			queue(c, msg);
			c->nin = 0;
			c->closing = 1;
		}
		if (c->closing)
			return 0;
	}
}

static int write_client(struct psd_ctl_client *c)
{
	while (c->nout) {
		ssize_t n = send(c->fd, c->out, c->nout, MSG_NOSIGNAL);
		if (n < 0)
			return errno == EAGAIN || errno == EINTR ? 0 : -1;
		memmove(c->out, c->out + n, c->nout - (size_t)n);
		c->nout -= (size_t)n;
	}
	return 0;
}

void psd_ctlsock_service(struct psd_ctlsock *s, const struct pollfd *fds, int nfds)
{
	double now = psd_time_mono();
	if (s->lfd < 0)
		return;
	/* clients first (by descriptor: the array shifts when one is dropped) */
	for (int k = 1; k < nfds; k++) {
		int i;
		for (i = 0; i < s->ncl && s->cl[i].fd != fds[k].fd; i++)
			;
		if (i == s->ncl)
			continue;
		if (fds[k].revents & POLLIN) {
			if (read_client(s, &s->cl[i]) != 0) {
				drop(s, i);
				continue;
			}
		} else if (fds[k].revents & (POLLERR | POLLHUP | POLLNVAL)) {
			drop(s, i);
			continue;
		}
		if (write_client(&s->cl[i]) != 0 || (s->cl[i].closing && s->cl[i].nout == 0)) {
			if (s->cl[i].closing)
				shutdown(s->cl[i].fd, SHUT_RDWR);
			drop(s, i);
		}
	}
	for (int i = 0; i < s->ncl; i++)
		if (now - s->cl[i].last > PSD_CTL_IDLE_S) {
			drop(s, i);
			i--;
		}
	if (nfds > 0 && (fds[0].revents & POLLIN)) {
		int first = s->ncl;
		accept_all(s);
		/* a new client's request is usually there already: read it in
		 * this turn rather than the next (a read with nothing is EAGAIN) */
		for (int i = first; i < s->ncl; i++)
			if (read_client(s, &s->cl[i]) != 0 || write_client(&s->cl[i]) != 0 ||
			    (s->cl[i].closing && s->cl[i].nout == 0)) {
				drop(s, i);
				i--;
			}
	}
}

void psd_ctlsock_close(struct psd_ctlsock *s)
{
	while (s->ncl)
		drop(s, s->ncl - 1);
	free(s->cl);
	s->cl = NULL;
	if (s->lfd >= 0) {
		close(s->lfd);
		unlink(s->path);
	}
	s->lfd = -1;
	psd_pidlock_release(s->lockfd);   /* after the unlink: the next daemon finds no socket */
	s->lockfd = -1;
}

const char *psd_ctlsock_default_path(int serve, char *buf, size_t n)
{
	static const char sys_dir[] = "/run/psensd";
	const char *rt = getenv("RUNTIME_DIRECTORY"), *xdg = getenv("XDG_RUNTIME_DIR"), *env = getenv("PSENSD_SOCKET");
	struct stat st;
	int have_xdg = xdg && xdg[0] == '/';
	snprintf(buf, n, "%s/psensd.sock", sys_dir);
	if (serve) {
		if (rt && *rt)
			snprintf(buf, n, "%s/psensd.sock", rt);
		else if (access(sys_dir, W_OK) != 0 && have_xdg && access(xdg, W_OK) == 0)
			snprintf(buf, n, "%s/psensd.sock", xdg);
		return buf;
	}
	if (env && *env)
		snprintf(buf, n, "%s", env);
	else if (stat(buf, &st) != 0 && have_xdg) {
		char alt[512];
		snprintf(alt, sizeof alt, "%s/psensd.sock", xdg);
		if (stat(alt, &st) == 0)
			snprintf(buf, n, "%s", alt);
	}
	return buf;
}
