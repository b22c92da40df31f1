/* SPDX-License-Identifier: ISC */
/* A Modbus server that never blocks: a TCP listener and its clients, or one
 * serial line, in one poll loop, each connection with its own buffers,
 * framing (mbframe.h) and deadlines, so no client can delay another.
 *
 * TCP: a request is answered as soon as its frame is complete; requests
 * sent together are answered in order; a reply may be deferred (a late
 * device), and meanwhile the client's further requests wait while every
 * other client is served.  A frame must be complete within frame_timeout of
 * its first byte (the clock does not restart with each byte), else the
 * connection is closed; a client silent for idle_timeout is closed; when
 * max_clients are connected, a new client takes the place of the one
 * silent the longest, so stale clients never lock out a new one.  A frame
 * that is not Modbus (mbframe.h) closes its connection; a client that
 * closes its side gets the replies that are ready, then is closed.
 *
 * RTU: frames end at their function's length or the line's silence (3.5
 * characters), mbframe.h; a frame not complete within frame_timeout of its
 * first byte is dropped; while a reply is deferred the line is busy and what
 * arrives is dropped.
 *
 * Time here is the monotonic clock: these are network timeouts, not the
 * room's time. */
#ifndef PSD_MBSERVE_H
#define PSD_MBSERVE_H

#include <stddef.h>
#include <stdint.h>

#include "mbframe.h"

/* What the handler wants done with a request. */
enum {
	PSD_MBS_REPLY,     /* send out[0..n) as the reply PDU */
	PSD_MBS_RAW,       /* send out[0..n) as it is (a garbled reply) */
	PSD_MBS_SILENT,    /* no reply */
	PSD_MBS_DEFER,     /* call again with deferred = 1 after *delay seconds */
	PSD_MBS_CLOSE,     /* close the connection (TCP; on RTU: no reply) */
};

/* Answer one request: out has room for PSD_MBFRAME_TCP_MAX bytes. */
typedef int (*psd_mbserve_fn)(void *user, const struct psd_mbadu *req, int deferred, uint8_t *out,
                              size_t *n, double *delay);

struct psd_mbserve_opts {
	double idle_timeout;   /* s */
	double frame_timeout;  /* s, from a frame's first byte */
	int max_clients;
	long baud;             /* RTU: for the silence that ends a frame */
	int trace;             /* every frame in hex at debug level (log.h) */
};

struct psd_mbserve;

/* Listen on host:port (port "0": the kernel chooses); NULL with the reason
 * in err. */
struct psd_mbserve *psd_mbserve_tcp(const char *host, const char *port, const struct psd_mbserve_opts *o,
                                    psd_mbserve_fn fn, void *user, char *err, size_t n);
/* Serve an open serial line (raw, configured, non-blocking); the server
 * does not close it. */
struct psd_mbserve *psd_mbserve_rtu(int fd, const struct psd_mbserve_opts *o, psd_mbserve_fn fn, void *user,
                                    char *err, size_t n);
/* The TCP port listened on (0 on a serial line). */
int psd_mbserve_port(const struct psd_mbserve *s);
/* One turn: wait at most max_wait seconds for something to do, and do all
 * of it.  Returns 0, or -1 when poll itself failed (not EINTR). */
int psd_mbserve_step(struct psd_mbserve *s, double max_wait);
void psd_mbserve_free(struct psd_mbserve *s);

#endif
