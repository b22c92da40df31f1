/* SPDX-License-Identifier: ISC */
/* The Foxtron DALI232 / DALI232e (RS-232) and DALInet / DALI2net (TCP)
 * converters' ASCII protocol as a stream codec (dali_frame.h). */
#ifndef PS_DALI_FOXTRON_H
#define PS_DALI_FOXTRON_H

#include "dali_frame.h"

extern const struct ps_dali_codec ps_dali_foxtron;

#endif
