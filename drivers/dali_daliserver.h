/* SPDX-License-Identifier: ISC */
/* The daliserver daemon's network protocol (a Tridonic DALI USB shared over
 * TCP, default port 55825) as a stream codec (dali_frame.h). */
#ifndef PS_DALI_DALISERVER_H
#define PS_DALI_DALISERVER_H

#include "dali_frame.h"

extern const struct ps_dali_codec ps_dali_daliserver;

#endif
