/* SPDX-License-Identifier: ISC */
/* Replay files: a day of daylight read back from the CSV that
 * `psensctl export --csv` writes, so the loopback room can replay a real
 * site's day.  Columns are found by name in the header line; the replay
 * needs tod_s and daylight_v, and uses daylight_lux when present (else
 * daylight_v times a lux-per-volt ratio).  Rows without daylight (faults)
 * are skipped; '#' lines are comments. */
#ifndef PS_REPLAY_H
#define PS_REPLAY_H

#include <stddef.h>

#include "room.h"

/* Parse text into daypoints (malloc'd, times strictly increasing).  gain is
 * the room's volts per unit of sensor response.  -1 with "name:line: why"
 * in err. */
int ps_replay_parse(const char *text, size_t len, const char *name, double gain,
                    double lux_per_volt, struct ps_room_daypoint **out, size_t *n, char *err,
                    size_t errlen);
int ps_replay_read(const char *path, double gain, double lux_per_volt,
                   struct ps_room_daypoint **out, size_t *n, char *err, size_t errlen);

#endif
