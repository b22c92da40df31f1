/* SPDX-License-Identifier: ISC */
/* The loopback driver: the virtual room (room.h) behind the driver table, so
 * psensd runs and is tested with no hardware. */
#ifndef PS_LOOPBACK_H
#define PS_LOOPBACK_H

#include "driver.h"
#include "room.h"

extern const struct ps_driver ps_driver_loopback;

/* Give an opened loopback device its room: the daemon builds the daylight and
 * electric responses from the scene results; the device's own options
 * (noise, gain, ballast, faults) are merged in.  Call once, after open. */
int ps_loopback_set_room(struct ps_dev *dev, const struct ps_room_params *p, double now);
/* The room, for summaries (true task lux, energy); NULL before set_room. */
struct ps_room *ps_loopback_room(struct ps_dev *dev);

#endif
