/* SPDX-License-Identifier: ISC */
/* The Lunatone LUBA protocol (the RS-232 / USB-serial DALI interfaces) as a
 * stream codec (dali_frame.h). */
#ifndef PS_DALI_LUBA_H
#define PS_DALI_LUBA_H

#include "dali_frame.h"

extern const struct ps_dali_codec ps_dali_luba;

#endif
