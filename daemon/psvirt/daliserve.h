/* SPDX-License-Identifier: ISC */
/* psvirt's DALI interfaces: the virtual bus (dalibus.h) behind the host
 * protocols of two real interfaces, written from their descriptions in
 * doc/hardware.md (sections 5 and 6), the server's side:
 *
 *   foxtron  a Foxtron DALI232 / DALInet: SOH, the message's bytes as hex,
 *            the checksum (one's complement of their sum), ETB; a send
 *            (0x0B) answered 0x0D (an answer, or answer length 0: answers
 *            collided) or 0x0E (none); events 0x05 (0 bus power back, 1
 *            lost, 5 a wrong checksum, 6 an invalid message); the input
 *            devices' event frames as other masters' frames (0x04); the
 *            configuration query 0x06 answered 0x07
 *   atx      the AtxLED DALI HAT: lines 'h'/'t'/'j'/'l' + hex answered
 *            'J' + hex, 'N' or 'X'; a frame sent twice ('t') answered
 *            once per sending; event frames as 'l' + 6 hex lines
 *
 * on a pseudo-terminal (posix_openpt: psensd opens its slave as a serial
 * port) and on TCP (foxtron, as a DALInet).  Never blocks: one poll over
 * every descriptor; TCP clients silent for 30 s are closed, as a DALInet
 * closes them. */
#ifndef PSD_DALISERVE_H
#define PSD_DALISERVE_H

#include <stddef.h>

#include "dalibus.h"

enum { PSD_DALISERVE_FOXTRON, PSD_DALISERVE_ATX };

struct psd_daliserve;

/* A server of bus b (owned by the caller); NULL when out of memory. */
struct psd_daliserve *psd_daliserve_new(struct psd_dalibus *b, int trace);
/* Listen on host:port for Foxtron clients (port "0": the kernel picks);
 * the port, or -1 with the reason in err. */
int psd_daliserve_tcp(struct psd_daliserve *s, const char *host, const char *port, char *err, size_t n);
/* A pseudo-terminal speaking protocol (PSD_DALISERVE_FOXTRON or _ATX); its
 * slave's path in path.  0, or -1 with the reason in err. */
int psd_daliserve_pty(struct psd_daliserve *s, int protocol, char *path, size_t pathlen, char *err, size_t n);
/* Serve an open descriptor (a socketpair's end, in tests) speaking
 * protocol; the server closes it.  0, or -1 when it has no room. */
int psd_daliserve_fd(struct psd_daliserve *s, int fd, int protocol);
/* One turn at time now (monotonic seconds): wait at most max_wait for
 * traffic, answer it, send the devices' events.  0, or -1 when poll
 * failed. */
int psd_daliserve_step(struct psd_daliserve *s, double now, double max_wait);
/* Tell every Foxtron client the bus power went (on 0) or came back. */
void psd_daliserve_power(struct psd_daliserve *s, int on);
void psd_daliserve_free(struct psd_daliserve *s);

#endif
