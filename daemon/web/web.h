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

#include "frontend.h"

/* The room's row in the front-end table (frontend.h): [web] wanted, the
 * server listening on the configured address for the engine's zones, every
 * request answered in the loop's turn. */
extern const struct psd_frontend psd_web_frontend;

#endif
