/* SPDX-License-Identifier: ISC */
/* The hasseb DALI Master (USB 04cc:0802) as a DALI transport
 * (dali_transport.h). */
#ifndef PS_USB_HASSEB_H
#define PS_USB_HASSEB_H

#include "dali_transport.h"

extern const struct ps_dali_transport ps_usb_hasseb;

#endif
