/* SPDX-License-Identifier: ISC */
/* psvirt's virtual DALI bus: control gear (IEC 62386-102) and DALI-2 input
 * devices (IEC 62386-103 with a 303 occupancy and a 304 light-sensor
 * instance), written from the standards' facts as doc/hardware.md and
 * psvirt(1) restate them, not from psensd's drivers.
 *
 * A pure state machine: a forward frame in (8, 16 or 24 bits, sent once or
 * twice), what the bus answers out (a backward frame, nothing, a garbled
 * answer when devices answering differently collide, no power); the time
 * is the caller's (seconds, monotonic).  It knows nothing of rooms or
 * sockets: psvirt sets each zone's sensor value and occupancy and reads
 * each zone's light output; daliserve.c frames it for an interface.
 *
 * Gear i lights zone gear[i].zone; device k is zone k's multisensor
 * (instance 0: type 3 occupancy, instance 1: type 4 light sensor). */
#ifndef PSD_DALIBUS_H
#define PSD_DALIBUS_H

#include <stdint.h>

enum {
	PSD_DALIBUS_MAX_GEAR = 64,
	PSD_DALIBUS_MAX_DEV = 10,
	PSD_DALIBUS_NINST = 2,
	PSD_DALIBUS_MAX_EVENTS = 8,
};

/* What the bus did with a frame. */
enum { PSD_DALIBUS_NONE, PSD_DALIBUS_ANSWER, PSD_DALIBUS_GARBLED, PSD_DALIBUS_NOPOWER };

/* Faults on demand (psvirt(1), DALI FAULTS). */
enum { PSD_DALIBUS_OK, PSD_DALIBUS_SILENT, PSD_DALIBUS_COLLIDE, PSD_DALIBUS_SHORT, PSD_DALIBUS_NFAULT };
/* A fault's target: a gear short address 0-63, a control device
 * PSD_DALIBUS_DEVICE + its short address, or every device. */
enum { PSD_DALIBUS_DEVICE = 100, PSD_DALIBUS_EVERY = 255 };

struct psd_dalibus_gear {
	int zone;               /* the room it lights */
	int addr;               /* short address 0-63, -1 none */
	int from, target;       /* a fade: arc level from, to */
	double fade_t0, fade_len;
	int min, max, phys_min, sfl, pol, fade_time, fade_rate;
	uint16_t groups;
	uint8_t scene[16];      /* 255: not in the scene */
	uint32_t random;        /* 24 bits */
	int selected, withdrawn;   /* INITIALISE, WITHDRAW */
	int reset_state;
};

struct psd_dalibus_inst {
	int type;               /* 3 occupancy, 4 light sensor */
	int enabled, scheme, filter, priority, group;
	int t_report, t_deadtime, hysteresis, hysteresis_min, t_hold;   /* timers as set */
	unsigned value;         /* the input value now (resolution bits) */
	int resolution;
	unsigned reported;      /* the last value in an event */
	double last_event;
};

struct psd_dalibus_dev {
	int zone, addr;         /* addr 0-63, -1 none */
	uint32_t random;
	int selected, withdrawn;
	uint32_t groups;
	uint8_t latch;          /* QUERY INPUT VALUE's next byte */
	int app_enabled;
	struct psd_dalibus_inst inst[PSD_DALIBUS_NINST];
};

struct psd_dalibus {
	struct psd_dalibus_gear gear[PSD_DALIBUS_MAX_GEAR];
	struct psd_dalibus_dev dev[PSD_DALIBUS_MAX_DEV];
	int ngear, ndev;
	uint8_t dtr[3];          /* gear's DTR0-2 */
	uint8_t ddtr[3];         /* control devices' DTR0-2 */
	uint32_t search, dsearch;
	int init_left;           /* gear initialised (an INITIALISE runs) */
	int dinit_left;
	uint32_t prev_frame;     /* send-twice: the previous frame and when */
	int prev_bits;
	double prev_t;
	uint32_t rng;
	int fault, target;       /* PSD_DALIBUS_OK ... */
	long frames;
};
/* The bus lost its power: every gear to its system failure level. */
void psd_dalibus_power_lost(struct psd_dalibus *b, double now);

/* ngear gear spread over nzone zones (gear i lights zone i * nzone / ngear),
 * nzone devices; addressed: gear i at short i, device k at short k, else
 * none (to be commissioned).  seed makes the random addresses. */
void psd_dalibus_init(struct psd_dalibus *b, int ngear, int nzone, int addressed, uint32_t seed);
/* One forward frame at time now; *answer is the backward frame when
 * PSD_DALIBUS_ANSWER. */
int psd_dalibus_frame(struct psd_dalibus *b, double now, int bits, uint32_t frame, int twice, uint8_t *answer);
/* Zone z's sensor inputs now: the light sensor's 10-bit value and the
 * occupancy (1 occupied). */
void psd_dalibus_sense(struct psd_dalibus *b, int z, unsigned light10, int occupied);
/* The event frames (24 bits) the enabled instances send by now; returns
 * how many (at most PSD_DALIBUS_MAX_EVENTS). */
int psd_dalibus_events(struct psd_dalibus *b, double now, uint32_t *ev);
/* Zone z's light output now, 0..1: the mean of its gear's arc power. */
double psd_dalibus_output(const struct psd_dalibus *b, int z, double now);
/* Gear i's arc level now (a running fade included). */
int psd_dalibus_level(const struct psd_dalibus_gear *g, double now);
/* Arc power level n (0..254) as a fraction of full: 0 off, else
 * 10^((n-1)/(253/3) - 3). */
double psd_dalibus_arc(int n);

#endif
