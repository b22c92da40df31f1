/* psemu: an emulated Tridonic/Lunatone DALI USB interface (17b5:0020) with
 * DALI ballasts on its bus, behind real libusb through libumockdev (vusb.h).
 *
 * The interface model answers SEND reports as the hardware notes describe
 * (echo 0x73, then 0x71 no answer / 0x72 answer / 0x77 bus status), performs
 * send-twice and the DTR0 prefix itself, and puts each frame on the bus.
 * The ballast model (IEC 62386-102): short address, groups, actual level with
 * linear fades over FADE TIME, MIN/MAX/physical minimum, DTR0, system failure
 * level (taken when the bus goes down with the interface), configuration
 * commands executed only when received twice within 100 ms, and the queries a
 * dimming daemon uses.  Several ballasts answering one query with different
 * values collide into a framing error, as on a real bus.
 *
 * Faults, each for the next N SEND reports: no answer (echo only), garbled
 * answer (bus status 3), a malformed report, and unplug in the middle of the
 * transfer (after the echo).  Unplug/replug at any time; a replugged interface
 * gets a new device number, as after a real replug.
 *
 * Thread safety: the firmware runs in umockdev's worker thread; every public
 * function takes the emulator's lock.  One psemu per process (one testbed). */
#ifndef PS_DALI_EMU_H
#define PS_DALI_EMU_H

#include <stddef.h>

#define PSEMU_MAX_IFACES 4
#define PSEMU_MAX_BALLASTS 64

enum psemu_fault {
	PSEMU_FAULT_NONE = 0,
	PSEMU_FAULT_NO_ANSWER,    /* the frame goes out, the final report never comes */
	PSEMU_FAULT_GARBLED,      /* the answer is a framing error (bus status 3) */
	PSEMU_FAULT_MALFORMED,    /* one report of garbage instead of the echo and answer */
	PSEMU_FAULT_UNPLUG,       /* unplugged after the echo, before the answer */
};

struct psemu_ballast {
	int present;
	int level;            /* actual arc power level now (0..254) */
	int target;           /* where a running fade ends */
	int fade_time;        /* FADE TIME code 0..15 */
	int min_level, max_level, phys_min;
	int sfl;              /* SYSTEM FAILURE LEVEL (255 = MASK: stay) */
	int power_on_level;
	int dtr0;
	unsigned groups;      /* bit g: member of group g */
	unsigned config_writes;   /* configuration commands executed (EEPROM writes) */
	unsigned commands;        /* frames addressed to it */
};

struct psemu_stats {
	unsigned sends;           /* SEND reports received */
	unsigned bus_frames;      /* forward frames put on the bus (twice counts 2) */
	unsigned collisions;      /* queries answered by ballasts that disagreed */
	double min_gap;           /* shortest time from a final report to the next SEND, s */
	unsigned gap_violations;  /* SENDs sooner than 21.2 ms after the last final report */
	unsigned last_frame;      /* the last forward frame put on the bus */
	int plugged;
	int devnum;
};

struct psemu;

/* NULL with a message on failure (no preload, umockdev error). */
struct psemu *psemu_new(char *err, size_t errlen);
void psemu_free(struct psemu *e);

/* An interface at USB port 1-<port> with a serial number and n ballasts at
 * short addresses 0..n-1.  Returns the interface index, -1 on failure. */
int psemu_add(struct psemu *e, int port, const char *serial, int nballasts, char *err, size_t errlen);

/* Unplug (the bus loses power: ballasts go to their system failure level);
 * replug (a new device number). 0 ok, -1 on failure. */
int psemu_unplug(struct psemu *e, int iface);
int psemu_replug(struct psemu *e, int iface, char *err, size_t errlen);
void psemu_fault(struct psemu *e, int iface, int fault, int count);

/* The ballasts' clock for fades (seconds); default: the monotonic clock.
 * Tests set it to move fades along without waiting. */
void psemu_set_clock(struct psemu *e, double (*now)(void *user), void *user);

/* A copy of one ballast's state, levels brought up to the clock's time. */
int psemu_ballast(struct psemu *e, int iface, int addr, struct psemu_ballast *out);
/* Configure a ballast before a test: groups, physical minimum (also its MIN LEVEL). */
int psemu_ballast_setup(struct psemu *e, int iface, int addr, unsigned groups, int phys_min);
int psemu_stats(struct psemu *e, int iface, struct psemu_stats *out);

/* One line per ballast: "iface I addr A level L target T fade F sfl S min M". */
int psemu_dump(struct psemu *e, char *buf, size_t len);

#endif
