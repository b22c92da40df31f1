/* SPDX-License-Identifier: ISC */
/* BACnet/IP (psensd.conf(5) [bacnet], doc/bacnet-pics.md): psensd's zones as
 * BACnet objects for a building's BMS.
 *
 * One job: the server's socket.  A non-blocking UDP socket is one more
 * descriptor in psensd's poll() (no thread); each turn reads at most a
 * bounded number of datagrams, answers each at once (bacserve.c) and never
 * waits to send (a reply the socket cannot take now is dropped, as UDP
 * may).  An answer in segments (bacseg.h) goes out a window at a time from
 * the same turns, its retry timer part of the loop's poll timeout.  The
 * objects are filled from the engine before each batch.  A
 * write to a zone's Lighting Output becomes the command table's typed
 * `override` or `release` (cmdtab.h), the entries the control socket's
 * requests reach too, so it is judged like one and never overrides the
 * safe level of a zone in a fault.  A write to a Value (the target lux,
 * daylight control, the vacancy hold) becomes the point model's write
 * (psd_points_write), again whenever the engine lost the value in force
 * (a reload), and likewise never moves a zone off its safe level. */
#ifndef PSD_BACNET_H
#define PSD_BACNET_H

#include <poll.h>
#include <stddef.h>

/* The room's public face is this header: the [bacnet] section the core's
 * configuration holds and judges comes with it. */
#include "bacconf.h"

struct psd_engine;
struct psd_bacnet;
struct psd_points;

/* Open the socket for the engine's zones, their points read through pts
 * (points.h).  NULL with a message in err. */
struct psd_bacnet *psd_bacnet_open(const struct psd_bacnet_conf *c, struct psd_engine *e,
                                   const struct psd_points *pts, char *err, size_t errlen);
/* The socket for poll(): 1 written. */
int psd_bacnet_pollfd(struct psd_bacnet *b, struct pollfd *pfd);
/* Answer what arrived (pfd from psd_bacnet_pollfd, or NULL), renew the
 * overrides a BMS holds.  now: the daemon's clock. */
void psd_bacnet_service(struct psd_bacnet *b, const struct pollfd *pfd, double now);
/* Wall milliseconds until the server wants a turn of its own (a
 * foreign-device registration due), -1 never. */
int psd_bacnet_wait_ms(const struct psd_bacnet *b);
void psd_bacnet_close(struct psd_bacnet *b);

#endif
