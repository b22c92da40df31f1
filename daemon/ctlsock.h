/* SPDX-License-Identifier: ISC */
/* The control socket: a Unix stream socket, one request per line, one reply
 * line per request (JSON; psensctl(1) and socat(1) both speak it).
 *
 * It guards the daemon: requests longer than PSD_CTL_MAX_LINE get an error
 * reply and the connection is closed; at most max_clients connections
 * (one more is told "too many clients" and closed); a client idle for
 * PSD_CTL_IDLE_S or not reading its replies (more than PSD_CTL_MAX_OUT
 * queued) is dropped; a reply grows as it needs, up to PSD_CTL_MAX_REPLY
 * bytes (1 MiB: the status of 128 zones is some 95 kB), past which it is
 * an error reply; peers are checked by SO_PEERCRED: root, the daemon's
 * user, or members of the daemon's group. */
#ifndef PSD_CTLSOCK_H
#define PSD_CTLSOCK_H

#include <poll.h>
#include <stddef.h>
#include <sys/types.h>

enum { PSD_CTL_MAX_LINE = 1024, PSD_CTL_MAX_REPLY = 1 << 20, PSD_CTL_MAX_OUT = 2 * PSD_CTL_MAX_REPLY,
       PSD_CTL_IDLE_S = 120 };

/* One reply line (without its newline), on the heap, grown as it needs:
 * text is never NULL once set (an error reply when memory or the limit
 * runs out).  Zero-initialise; free with psd_ctlsock_reply_free. */
struct psd_ctl_reply {
	char *text;
	size_t cap;           /* bytes allocated for text, 0 when text is static */
};

/* Set the reply to text (a copy).  A text of PSD_CTL_MAX_REPLY bytes or
 * more becomes the error reply "reply too long"; without memory, "out of
 * memory".  0, or -1 when the reply is one of those errors. */
int psd_ctlsock_reply_set(struct psd_ctl_reply *r, const char *text);
/* Free the text; the reply is empty again. */
void psd_ctlsock_reply_free(struct psd_ctl_reply *r);

struct psd_ctl_client {
	int fd;
	uid_t uid;
	pid_t pid;
	char in[PSD_CTL_MAX_LINE + 1];
	size_t nin;
	char *out;
	size_t nout, outcap;
	double last;          /* wall seconds of the last activity */
	int closing;          /* close once out is written */
};

/* handler: reply (a line without its newline) for one request line. */
typedef void (*psd_ctl_handler)(void *user, const struct psd_ctl_client *c, char *line,
                                struct psd_ctl_reply *reply);

struct psd_ctlsock {
	int lfd;
	int lockfd;           /* the flock on path.lock (daemon/pidlock.h), -1 none */
	char path[108];
	struct psd_ctl_client *cl;
	int ncl, max;
	unsigned long requests, rejected;
	psd_ctl_handler handler;
	void *user;
};

/* Create the socket at path with the permission bits mode, holding the
 * lock path.lock (with our pid) while it is open.  A socket that another
 * process holds the lock of, or that answers a connect, is live and is
 * refused, naming the pid; a dead one (left by a killed daemon) is
 * replaced.  -1 with a message in err and errno EADDRINUSE when the
 * socket is in use. */
int psd_ctlsock_open(struct psd_ctlsock *s, const char *path, int mode, int max_clients, psd_ctl_handler h,
                 void *user, char *err, size_t errlen);
/* Descriptors to poll; returns the count written (at most max). */
int psd_ctlsock_pollfds(const struct psd_ctlsock *s, struct pollfd *fds, int max);
/* Serve what poll() found on the descriptors psd_ctlsock_pollfds gave. */
void psd_ctlsock_service(struct psd_ctlsock *s, const struct pollfd *fds, int nfds);
/* Close every connection and the socket, and remove the file. */
void psd_ctlsock_close(struct psd_ctlsock *s);

/* The control socket when the configuration names none, one rule for
 * psensd (serve 1) and its clients (serve 0): $RUNTIME_DIRECTORY
 * (systemd's RuntimeDirectory=, psensd only), then /run/psensd when psensd
 * can write it, else $XDG_RUNTIME_DIR (a user who is not root); a client
 * takes $PSENSD_SOCKET, then whichever of the two holds a socket.  The
 * path, in buf. */
const char *psd_ctlsock_default_path(int serve, char *buf, size_t n);

/* Split a request into words (spaces and tabs); words are at most
 * PSD_CTL_MAX_WORDS.  Returns the count, or -1 with a message in err for
 * control characters or too many words. */
enum { PSD_CTL_MAX_WORDS = 8 };
int psd_ctlsock_split(char *line, char **argv, char *err, size_t errlen);

#endif
