/* SPDX-License-Identifier: ISC */
/* psvirt's register map (psvirt(1), REGISTER MAP): the rooms of up to ten
 * zones on one ADAM-6024-style 0-10 V module with a lux meter per zone.
 * Zone k (0 to 9) is channel k:
 *
 *   k          AIk, the zone's photosensor: 0..65535 = 0..10 V
 *   10 + k     AOk, the zone's dimming output: 0..4095 = light output 0..1
 *   20 + k     AIk status: bit 1 over-range, bit 3 open circuit
 *   100 + 10k  the zone's task lux, u32 (high word first); +2 meter status,
 *              +4 f32 ABCD, +6 f32 CDAB
 *   300 + 10k  the zone's light output x 10000; +1 true task lux f32 ABCD
 *   200        the room's time of day, u32 seconds
 *   202, 203   zone 0's light output and true task lux (its 300 and 301)
 *   210        the site's rooftop global horizontal lux (zone 0's room: the
 *              hour of the year it plays, 0 without a year), u32; 212 f32 ABCD
 *   900-903    the fault registers (psvirt.c gives them their meaning)
 *
 * Holding registers 0-999 (the rest is plain memory), input registers 0-29
 * (the same values as holding 0-29), coils 0-31 and discrete inputs 0-7
 * (plain memory).  Values are computed from the rooms when a request reads
 * them; a write to AOk commands zone k's ballast. */
#ifndef PSD_VIRTMAP_H
#define PSD_VIRTMAP_H

#include <stdint.h>

#include "mbpdu.h"
#include "virtroom.h"

enum {
	PSD_VIRT_MAX_ZONES = 10,
	PSD_VIRT_HOLDING = 1000,       /* table sizes */
	PSD_VIRT_INPUT = 30,
	PSD_VIRT_COILS = 32,
	PSD_VIRT_DISCRETE = 8,
	PSD_VIRT_AI = 0,               /* + zone */
	PSD_VIRT_AO = 10,
	PSD_VIRT_AI_STATUS = 20,
	PSD_VIRT_METER = 100,          /* + 10 zone */
	PSD_VIRT_TOD = 200,
	PSD_VIRT_OUTPUT0 = 202,
	PSD_VIRT_TRUTH0 = 203,
	PSD_VIRT_ROOFTOP = 210,        /* the site's rooftop lux: u32 210-211, f32 212-213 */
	PSD_VIRT_ZONE = 300,           /* + 10 zone */
	PSD_VIRT_FAULT = 900,          /* the fault registers 900 to 903 */
	PSD_VIRT_FAULT_LAST = 903,
	PSD_VIRT_AO_MAX = 4095,
};

struct psd_virtmap {
	uint16_t hr[PSD_VIRT_HOLDING];
	uint16_t coil[PSD_VIRT_COILS], di[PSD_VIRT_DISCRETE];
	struct psd_virtroom *room[PSD_VIRT_MAX_ZONES];   /* owned by the caller */
	int nzone;
	double now;                    /* the rooms' time for the request being answered */
};

/* Set up the map for nzone rooms (all at full output, as the rooms start)
 * and fill the table callbacks of mb. */
void psd_virtmap_init(struct psd_virtmap *m, struct psd_virtroom *const *room, int nzone,
                      struct psd_mbmap *mb);
/* The zones whose registers these runs touch, one bit per zone. */
unsigned psd_virtmap_zones(const struct psd_virtmap *m, const struct psd_mbspan *sp, int nsp);
/* What the touched zones' rooms do with a request now: PSD_VIRTROOM_ANSWER,
 * or _DROP or _LATE when any of them drops or delays it. */
int psd_virtmap_comms(const struct psd_virtmap *m, unsigned zones, double now);
/* Every register of every zone from the rooms now (start-up, tests). */
void psd_virtmap_refresh(struct psd_virtmap *m, double now);

#endif
