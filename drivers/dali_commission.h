/* SPDX-License-Identifier: ISC */
/* DALI commissioning (IEC 62386-102) as step-wise jobs: a bus scan, the
 * random-address search that gives ballasts short addresses, group
 * membership, identifying a ballast by flashing it, and checking that a
 * zone's ballasts follow a command.  Pure: no USB, no clock.  A driver asks
 * a job for its next transaction (ps_dali_commission_next), puts it on the
 * bus when its frame rate allows, and hands back what came of it
 * (ps_dali_commission_result); waits (RANDOMISE's 100 ms, a fade, a flash)
 * are times the driver turns into deadlines and passes on with
 * ps_dali_commission_poll.  A search over tens of ballasts takes thousands
 * of frames: nothing here blocks.
 *
 * The search (102, 9.14): TERMINATE; INITIALISE (sent twice) for the gear
 * without a short address (or all gear, or gear at one short address);
 * RANDOMISE (twice), then 100 ms for the new addresses; then, ballast by
 * ballast, a binary search over the 24-bit random addresses with
 * SEARCHADDRH/M/L (only the bytes that change: the halves are aligned, so
 * mostly one byte a step) and COMPARE, where any backward frame means
 * "yes": one ballast's 0xFF, or the garbled frame of several answering
 * together.  A garbled "yes" also says that at least two ballasts lie in
 * that half: the search for the next ballast starts in the smallest such
 * half that still holds one, not from the top.  The lowest random address R found, QUERY
 * SHORT ADDRESS asks the ballast selected by R for its address; it keeps a
 * unique one, else PROGRAM SHORT ADDRESS gives it the lowest free one and
 * VERIFY SHORT ADDRESS checks it; WITHDRAW takes it out of the search.
 * Two ballasts that drew the same random address answer out of step, so
 * COMPARE at R, QUERY SHORT ADDRESS or VERIFY comes back garbled: they are
 * told apart by RANDOMISE and a new search.  A ballast that stops answering
 * mid-search leaves a search that ends where nobody answers: the search
 * starts again without it.  INITIALISE is sent again before its 15-minute
 * window closes. */
#ifndef PS_DALI_COMMISSION_H
#define PS_DALI_COMMISSION_H

#include <stddef.h>
#include <stdint.h>

#include "dali.h"

struct json_object;

enum ps_dali_commission_kind {
	PS_DALI_COMMISSION_SCAN = 0,
	PS_DALI_COMMISSION_ADDRESS,
	PS_DALI_COMMISSION_GROUP,
	PS_DALI_COMMISSION_IDENTIFY,
	PS_DALI_COMMISSION_VERIFY,
};

enum ps_dali_commission_state {
	PS_DALI_COMMISSION_RUNNING = 0,
	PS_DALI_COMMISSION_DONE,
	PS_DALI_COMMISSION_FAILED,
	PS_DALI_COMMISSION_ABORTED,
};

/* address: gear without a short address (and ballasts sharing one), or all gear */
enum { PS_DALI_ADDRESS_NEW = 0, PS_DALI_ADDRESS_ALL };

/* What came of a transaction. */
enum ps_dali_rx {
	PS_DALI_RX_NONE = 0,     /* no backward frame */
	PS_DALI_RX_ANSWER,       /* one clean backward frame: value */
	PS_DALI_RX_COLLISION,    /* a garbled backward frame: several answered at once */
	PS_DALI_RX_FAILED,       /* the interface gave no result (timeouts, unplugged) */
};

/* One transaction asked of the driver. */
struct ps_dali_tx {
	unsigned frame;          /* forward frame: 16 bits, or 24 (> 0xFFFF) for a control device */
	int twice;               /* send twice within 100 ms (configuration, INITIALISE, RANDOMISE) */
	int answer;              /* a backward frame may come (queries, COMPARE, VERIFY) */
};

enum { PS_DALI_NEXT_NONE = 0, PS_DALI_NEXT_TX, PS_DALI_NEXT_WAIT };

/* Unknown values in results: no answer, or answers that collided. */
#define PS_DALI_NO_ANSWER (-1)
#define PS_DALI_COLLIDED (-2)

/* One short address as a scan found it (values are raw DALI bytes). */
struct ps_dali_gear {
	int present;             /* 0 none, 1 one ballast, 2 several (their answers collide) */
	int device_type, phys_min, min_level, max_level, fade, sfl, power_on, status, actual;
	int groups;              /* bit g: member of group g; < 0 unknown */
};

/* One control device (IEC 62386-103) a scan found at a short address of
 * the device space. */
struct ps_dali_ctl_device {
	int present;             /* 0 none, 1 one device, 2 several (their answers collide) */
	int instances;           /* QUERY NUMBER OF INSTANCES */
	signed char type[32];    /* each instance's QUERY INSTANCE TYPE, -1 no answer */
};

/* One ballast the search found. */
struct ps_dali_found {
	unsigned random;         /* its random address */
	int address;             /* its short address now, -1 none (no free address) */
	int was;                 /* its short address before, -1 none */
};

#define PS_DALI_VERIFY_MAX 8

struct ps_dali_verify_target {
	char name[48];           /* the point's name */
	struct ps_dali_addr addr;
	uint64_t members;        /* bit a: short address a answers to addr */
	int ok;                  /* every member followed both levels */
};

struct ps_dali_commission {
	int kind, state;
	double started, ended;
	unsigned long frames;    /* transactions done */
	char step[96];           /* what it does now */
	char msg[256];           /* the outcome, or why it failed */

	/* parameters */
	int mode;                /* address */
	struct ps_dali_addr target;   /* group, identify */
	int group, add;          /* group: 0..15, 1 add / 0 remove */
	double seconds;          /* identify: how long it flashes */
	int levels[2];           /* verify: the two test levels */
	struct ps_dali_verify_target vt[PS_DALI_VERIFY_MAX];
	int nvt;

	/* results */
	struct ps_dali_gear gear[64];
	int scanned;             /* short addresses scanned */
	int unaddressed;         /* gear without a short address: 0 none, 1, 2 several, -1 not asked */
	int with_devices;        /* scan: control devices too (24-bit frames) */
	int devices_space;       /* address: among control devices, not gear */
	struct ps_dali_ctl_device devices[64];
	int dev_unaddressed;     /* control devices without a short address: 0 none, 1, 2 several */
	struct ps_dali_found found[64];
	int nfound, kept, programmed, clashes, restarts, lost, no_free, inits;
	int groups_after;        /* group: the ballast's groups afterwards, < 0 unknown */
	int on_device;           /* group: a control device's device group (0..31), not a ballast's */
	unsigned device_groups;  /* group on_device: its 32 device groups afterwards */
	int device_groups_known; /* ... all four bytes came back */
	int flashes, saved_level;     /* identify */
	int got[64][2];          /* verify: each present ballast's level after each test level */
	int ok;                  /* verify: every target followed */

	/* the machine (dali_commission.c) */
	int pc, i, k, have_tx, abort_req, reinit, was, refound, tmp;
	struct ps_dali_tx tx;
	double wait_until, init_at, t0;
	unsigned lo, hi, found_at, mid, search, want;
	int hi_rx, search_known, want_ret, addr, from_node;
	/* ranges of random addresses where COMPARE came back garbled: at least
	 * two ballasts were in each, so after the one found the next is there */
	struct ps_dali_search_node {
		unsigned base, top;   /* the half's first and last random address */
		int found;            /* ballasts found in it since */
	} node[24];
	int nnode;
	uint64_t used, dup, claimed, bad;
	int hold_groups[64];     /* groups of the ballasts it changes, for ps_dali_commission_holds */
	uint64_t hold;           /* short addresses whose light it changes */
};

/* Start a job at time now (the job is reset first).  0, or -1 with a reason
 * in c->msg for bad parameters. */
int ps_dali_commission_scan(struct ps_dali_commission *c, double now);
/* A scan that then asks the 64 short addresses of the control-device space
 * for their instances and each instance's type (24-bit frames: tx.frame >
 * 0xFFFF), and whether devices without a short address are on the bus. */
int ps_dali_commission_scan_devices(struct ps_dali_commission *c, double now);
int ps_dali_commission_address(struct ps_dali_commission *c, int mode, double now);
/* The same search among DALI-2 control devices: 103's special commands
 * (24-bit frames) and short addresses of the device space. */
int ps_dali_commission_address_devices(struct ps_dali_commission *c, int mode, double now);
int ps_dali_commission_group(struct ps_dali_commission *c, const struct ps_dali_addr *a, int group, int add,
                             double now);
/* The same for a DALI-2 control device (IEC 62386-103) at short address
 * short_addr of the device space: ADD TO / REMOVE FROM DEVICE GROUPS with
 * the group's bit in DTR2:DTR1, then QUERY DEVICE GROUPS 0-7 .. 24-31 to
 * check; group 0 to 31. */
int ps_dali_commission_group_device(struct ps_dali_commission *c, int short_addr, int group, int add, double now);
int ps_dali_commission_identify(struct ps_dali_commission *c, int short_addr, double seconds, double now);
/* A DALI-2 control device at short address short_addr of the device space:
 * QUERY DEVICE STATUS (is it there?), then IDENTIFY DEVICE (sent twice): the
 * device shows itself its own way for about 10 s (IEC 62386-103). */
int ps_dali_commission_identify_device(struct ps_dali_commission *c, int short_addr, double now);
/* targets: the addresses a zone's outputs use (names for the report);
 * level1, level2: arc levels to command in turn. */
int ps_dali_commission_verify(struct ps_dali_commission *c, const struct ps_dali_addr *targets,
                              const char *const *names, int n, int level1, int level2, double now);

/* What the job wants: PS_DALI_NEXT_TX with *tx (the same until its result
 * is given), PS_DALI_NEXT_WAIT until *until (then call poll), or
 * PS_DALI_NEXT_NONE when it has ended. */
int ps_dali_commission_next(const struct ps_dali_commission *c, struct ps_dali_tx *tx, double *until);
/* Let a wait that has run out move the job on. */
void ps_dali_commission_poll(struct ps_dali_commission *c, double now);
/* The outcome of the transaction next() gave; why names an interface
 * failure (PS_DALI_RX_FAILED). */
void ps_dali_commission_result(struct ps_dali_commission *c, double now, int rx, unsigned value, const char *why);
/* Stop: a search is closed with TERMINATE and a flashing ballast restored
 * first, so the job may still want a transaction or two. */
void ps_dali_commission_abort(struct ps_dali_commission *c, double now);
/* The interface is gone: the job fails at once with why. */
void ps_dali_commission_fail(struct ps_dali_commission *c, double now, const char *why);

/* 1 while the job moves the light of gear that address a reaches, so that
 * frames to a must wait (identify, verify); 0 otherwise. */
int ps_dali_commission_holds(const struct ps_dali_commission *c, const struct ps_dali_addr *a);

/* The job as JSON: into gets "job", "state", "step", "frames", "elapsed_s",
 * "message" and the kind's results.  Names of kinds and states: */
extern const char *const ps_dali_commission_kinds[];
void ps_dali_commission_json(const struct ps_dali_commission *c, double now, struct json_object *into);

#endif
