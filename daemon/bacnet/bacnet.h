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

#include "frontend.h"

/* The room's row in the front-end table (frontend.h): [bacnet] wanted, the
 * socket opened for the engine's zones, their points read from the point
 * model; answers and COV notifications in the loop's turns. */
extern const struct psd_frontend psd_bacnet_frontend;

#endif
