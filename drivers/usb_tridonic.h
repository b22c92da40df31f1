/* SPDX-License-Identifier: ISC */
/* The Tridonic / Lunatone DALI USB interface (17b5:0020) as a DALI
 * transport (dali_transport.h). */
#ifndef PS_USB_TRIDONIC_H
#define PS_USB_TRIDONIC_H

#include "dali_transport.h"

extern const struct ps_dali_transport ps_usb_tridonic;

#endif
