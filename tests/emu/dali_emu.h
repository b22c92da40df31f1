/* SPDX-License-Identifier: ISC */
/* psemu: an emulated Tridonic/Lunatone DALI USB interface (17b5:0020), or
 * hasseb DALI Master (04cc:0802), with DALI ballasts on its bus, behind real
 * libusb through libumockdev (vusb.h).
 *
 * The interface model answers SEND reports as doc/hardware.md section 1 describes
 * (echo 0x73, then 0x71 no answer / 0x72 answer / 0x77 bus status), performs
 * send-twice and the DTR0 prefix itself, and puts each frame on the bus.
 * The ballast model (IEC 62386-102): short address, groups, actual level with
 * linear fades over FADE TIME, MIN/MAX/physical minimum, DTR0, system failure
 * level (taken when the bus goes down with the interface), configuration
 * commands executed only when received twice within 100 ms, and the queries a
 * dimming daemon uses.  Several ballasts answering one query with different
 * values collide into a framing error, as on a real bus.
 *
 * Commissioning (IEC 62386-102 special commands): each ballast has its own
 * short address (or none), a 24-bit random address (0xFFFFFF after reset;
 * RANDOMISE draws a new one, available 100 ms later), a search address and
 * the initialisation state (disabled, enabled, withdrawn) that INITIALISE
 * (all, unaddressed, or one short address; sent twice) opens for 15 minutes
 * on the ballasts' clock and TERMINATE closes.  COMPARE, WITHDRAW, PROGRAM /
 * VERIFY / QUERY SHORT ADDRESS act as the standard says; ADD TO / REMOVE FROM
 * GROUP and SET SHORT ADDRESS are configuration commands (sent twice).
 *
 * Backward frames of several ballasts at once: each ballast answers after
 * its own settling time (5.5 to 10.5 ms; 8 ms unless set).  Answers with the
 * same value whose starts lie within 83 us of each other (the slack a DALI
 * receiver allows on a 416.7 us half bit) add up to one clean frame; any
 * other overlap is a framing error (bus status 3), as on a real bus.  So two
 * ballasts saying "yes" together collide unless they answer in step.
 *
 * Bus timing: off by default (reports come at once).  On, each report comes
 * when the frames it stands for would have ended on a real bus: 15.83 ms per
 * forward frame, the ballast's settling time and 9.17 ms for a backward
 * frame, 11.33 ms of silence for "no answer", 13.5 ms between the frames of
 * a send-twice or DTR0 transaction.  Either way stats.bus_time adds those
 * durations up.
 *
 * The hasseb DALI Master (doc/hardware.md section 1.2, written from its
 * firmware's published protocol): 10-byte reports starting with 0xAA on
 * endpoints 0x81 IN and 0x01 OUT.  It takes "send" (0x07) with a sequence
 * number 1-255, the frame length in bits (16 only), an "expect an answer"
 * flag and a send-twice delay in ms; it has no echo and no DTR0 prefix, and
 * answers with one transmission report for that sequence number: status 1
 * no answer, 2 an answer, 3 invalid data (a garbled answer).  It also
 * takes "read firmware version" (0x02, with a sequence number), answered by
 * a version report: AA 02 seq major minor, zeros to 10 bytes.  Without the
 * expect-answer flag it does not listen for a backward frame (status 1
 * whatever the ballasts said): an assumption of this model, as the protocol
 * does not say.  Reports that break the protocol (sequence 0, wrong length,
 * preamble or endpoint) are dropped and counted in stats.rejected.
 *
 * Faults, each for the next N SEND reports: no answer (echo only; hasseb:
 * nothing at all), garbled answer (bus status 3; hasseb: status 3), a
 * malformed report (hasseb: a short one of 6 bytes), unplug in the middle of
 * the transfer (after the echo; hasseb: after the frame), and another
 * master's frame on the bus before ours (a query to short address 63, which
 * no ballast of the tests has), reported as another master's traffic (0x11;
 * hasseb: its two bytes sniffed, with sequence number 0), and a stale
 * report: the final report of the SEND is lost and an answer 0x55 under the
 * previous sequence number comes in its place (a late report of the
 * transaction before).  The hasseb's own: an answer too early (status 4, a
 * backward frame that began before the 5.5 ms settling time, in place of
 * the transmission report), and an unasked firmware-version report, either
 * before the transmission report or in its place (both under the SEND's
 * sequence number, the worst case for matching); the Tridonic model has no
 * such reports and ignores these three.  Unplug/replug at any time; a replugged interface
 * gets a new device number, as after a real replug.  Per ballast: dead after
 * it has answered N more backward frames (it then ignores the bus).
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
	PSEMU_FAULT_OTHER_MASTER, /* another master's frame on the bus before ours */
	PSEMU_FAULT_STALE,        /* our final report is lost; an answer 0x55 for the previous sequence number comes instead */
	PSEMU_FAULT_EARLY,        /* hasseb: a backward frame before the settling time (status 4) instead of the answer */
	PSEMU_FAULT_VERSION,      /* hasseb: an unasked firmware-version report first, under the SEND's sequence number */
	PSEMU_FAULT_VERSION_ONLY, /* hasseb: an unasked firmware-version report in place of the transmission report */
};

enum psemu_model { PSEMU_TRIDONIC = 0, PSEMU_HASSEB };

enum psemu_init { PSEMU_INIT_DISABLED = 0, PSEMU_INIT_ENABLED, PSEMU_INIT_WITHDRAWN };

struct psemu_ballast {
	int present;
	int short_addr;       /* 0..63, -1 none */
	unsigned random;      /* 24-bit random address */
	unsigned search;      /* 24-bit search address */
	int init_state;       /* enum psemu_init, brought up to the clock (15 minutes) */
	int device_type;      /* QUERY DEVICE TYPE (6: LED) */
	int fade_rate;        /* FADE RATE code */
	double reply_ms;      /* settling time before its backward frames */
	int dead;             /* stopped answering: ignores the bus */
	unsigned level_changes;   /* commands that moved its target level */
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
	unsigned rejected;        /* OUT reports that broke the protocol (dropped) */
	unsigned last_seq;        /* the sequence number of the last SEND */
	unsigned bus_frames;      /* forward frames put on the bus (twice counts 2) */
	unsigned collisions;      /* queries answered by ballasts that disagreed */
	double min_gap;           /* shortest time from a final report to the next SEND, s */
	unsigned gap_violations;  /* SENDs sooner than 21.2 ms after the last final report
	                           * (a command after its DTR0 frame: sooner than 13.5 ms) */
	unsigned last_frame;      /* the last forward frame put on the bus */
	unsigned early_compares;  /* COMPAREs within 100 ms of a RANDOMISE */
	unsigned specials;        /* special commands (INITIALISE, COMPARE, ...) on the bus */
	unsigned version_requests;    /* hasseb: "read firmware version" requests (0x02) answered */
	double bus_time;          /* seconds the SENDs would take on a real bus */
	int plugged;
	int devnum;
};

struct psemu;

/* NULL with a message on failure (no preload, umockdev error). */
struct psemu *psemu_new(char *err, size_t errlen);
void psemu_free(struct psemu *e);

/* An interface at USB port 1-<port> with a serial number and n ballasts in
 * slots 0..n-1, each at the short address of its slot, random address
 * 0xFFFFFF.  Returns the interface index, -1 on failure. */
int psemu_add(struct psemu *e, int port, const char *serial, int nballasts, char *err, size_t errlen);
/* The same for either model (enum psemu_model). */
int psemu_add_model(struct psemu *e, int model, int port, const char *serial, int nballasts, char *err,
                    size_t errlen);

/* Unplug (the bus loses power: ballasts go to their system failure level);
 * replug (a new device number). 0 ok, -1 on failure. */
int psemu_unplug(struct psemu *e, int iface);
int psemu_replug(struct psemu *e, int iface, char *err, size_t errlen);
void psemu_fault(struct psemu *e, int iface, int fault, int count);
/* The hasseb's firmware version, major.minor (each 0..255; 2.5 unless set):
 * what its version reports carry.  0 ok, -1 no such hasseb. */
int psemu_hasseb_version(struct psemu *e, int iface, int major, int minor);

/* The ballasts' clock for fades (seconds); default: the monotonic clock.
 * Tests set it to move fades along without waiting. */
void psemu_set_clock(struct psemu *e, double (*now)(void *user), void *user);

/* Report timing of a real bus (see above): 1 on, 0 off (the default). */
void psemu_set_bus_timing(struct psemu *e, int on);

/* A copy of one ballast's state (by slot), levels brought up to the clock's time. */
int psemu_ballast(struct psemu *e, int iface, int slot, struct psemu_ballast *out);
/* Configure a ballast before a test: groups, physical minimum (also its MIN LEVEL). */
int psemu_ballast_setup(struct psemu *e, int iface, int slot, unsigned groups, int phys_min);
/* Its identity for commissioning: short address (-1 none), random address
 * (0..0xFFFFFF), settling time of its answers in ms (5.5 to 10.5). */
int psemu_ballast_identity(struct psemu *e, int iface, int slot, int short_addr, unsigned random_addr,
                           double reply_ms);
/* The values its next n RANDOMISE commands draw (then its own generator,
 * seeded from interface and slot): two ballasts given the same value collide. */
int psemu_ballast_randoms(struct psemu *e, int iface, int slot, const unsigned *values, int n);
/* It goes dead after answering n more backward frames (n < 0: never). */
int psemu_ballast_dead_after(struct psemu *e, int iface, int slot, int n);
int psemu_stats(struct psemu *e, int iface, struct psemu_stats *out);

/* One line per ballast: "iface I slot N level L target T fade F sfl S min M
 * short A groups G random R plugged P" (short -1: none; groups, random hex). */
int psemu_dump(struct psemu *e, char *buf, size_t len);

#endif
