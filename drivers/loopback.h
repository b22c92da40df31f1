/* SPDX-License-Identifier: ISC */
/* The loopback driver: the virtual room (room.h) behind the driver table, so
 * psensd runs and is tested with no hardware. */
#ifndef PS_LOOPBACK_H
#define PS_LOOPBACK_H

#include "driver.h"
#include "room.h"

extern const struct ps_driver ps_driver_loopback;


#endif
