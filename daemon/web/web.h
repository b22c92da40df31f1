/* SPDX-License-Identifier: ISC */
/* The on-site web console (psensd.conf(5) [web], doc/console.md): a small
 * web application for the commissioning agent's phone: every zone live,
 * charts of the last hours, override and release, the calibration sessions
 * step by step, the acceptance tests.
 *
 * One job: the HTTP server.  libmicrohttpd runs in its external mode on
 * one epoll descriptor, one more in psensd's poll() (no thread): every
 * request is answered in the loop's turn, on the loop's thread.  Every
 * action a page asks for is a control request line given to the same
 * function as the control socket's (psd_cmdtab_request), judged and
 * answered alike; the live updates (server-sent events) are its `status`
 * reply.  Built only WITH_WEB; daemon/web/web_off.c otherwise. */
#ifndef PSD_WEB_H
#define PSD_WEB_H

#include <poll.h>
#include <stddef.h>

/* The room's public face is this header: the [web] section the core's
 * configuration holds and judges comes with it. */
#include "webconf.h"

struct psd_engine;
struct psd_web;
struct psd_ctl_reply;

/* A control request: what psd_cmdtab_request does (the reply grows as it
 * needs, up to the control socket's PSD_CTL_MAX_REPLY). */
typedef void (*psd_web_request_fn)(void *user, char *line, struct psd_ctl_reply *reply);

/* Listen on the configured address for the engine's zones.  NULL with a
 * message in err. */
struct psd_web *psd_web_open(const struct psd_web_conf *c, struct psd_engine *e, psd_web_request_fn fn, void *user,
                             char *err, size_t errlen);
/* The server's descriptor for poll(): 1 written. */
int psd_web_pollfd(struct psd_web *w, struct pollfd *pfd);
/* Answer what is due (pfd from psd_web_pollfd, or NULL), keep the charts'
 * history, send the live update when one is due. */
void psd_web_service(struct psd_web *w, const struct pollfd *pfd);
/* Wall milliseconds until the server wants a turn, -1 none. */
int psd_web_wait_ms(const struct psd_web *w);
/* Close every connection and the socket, free. */
void psd_web_close(struct psd_web *w);

#endif
