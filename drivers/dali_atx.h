/* SPDX-License-Identifier: ISC */
/* The AtxLED DALI HAT (a Raspberry Pi UART at 19200 8N1) as a stream codec
 * (dali_frame.h). */
#ifndef PS_DALI_ATX_H
#define PS_DALI_ATX_H

#include "dali_frame.h"

extern const struct ps_dali_codec ps_dali_atx;

#endif
