/* SPDX-License-Identifier: ISC */
/* The BACnet/IP server's protocol (psensd.conf(5) [bacnet], doc/bacnet-pics.md):
 * one received datagram in, at most one datagram out.  BVLL (Annex J),
 * NPDU (clause 6, no routing: a message for another network is dropped,
 * one from another network is answered through its router), APDU (clause
 * 20) and the services Who-Is/I-Am, Who-Has/I-Have, ReadProperty,
 * ReadPropertyMultiple, WriteProperty and SubscribeCOV over the objects of
 * bacobj.c (a Device; per zone a Lighting Output and an Analog Input,
 * Binary Input or Multi-state Input per read-only point of the point
 * model, daemon/points.h, and an Analog, Binary or Multi-state Value,
 * commandable, per writable one).
 * Segmentation (bacseg.h): an answer longer than the asker's max-APDU is
 * sent in segments when its request's SA bit says it takes them, within
 * its max-segments-accepted; else Abort segmentation-not-supported (SA
 * clear) or buffer-overflow (too many segments).  A segmented request is
 * refused with Abort segmentation-not-supported.
 *
 * Pure: it reads and writes only the model below, so the unit tests and
 * the fuzz target run it without a daemon; daemon/bacnet/bacnet.c fills
 * the model from the engine and does the socket's I/O.  Bounded: a
 * datagram is at most PSD_BACSERVE_MAX_PACKET octets and every loop runs
 * over its octets or the model's objects. */
#ifndef PSD_BACSERVE_H
#define PSD_BACSERVE_H

#include <stddef.h>
#include <stdint.h>

#include "bacseg.h"

enum {
	PSD_BACSERVE_MAX_APDU = 1476,   /* the largest APDU over BACnet/IP (B/IP, Annex J) */
	PSD_BACSERVE_MAX_PACKET = 1497, /* BVLL 4 + NPDU (at most 17 here) + APDU */
	PSD_BACSERVE_PRIORITIES = 16,
	PSD_BACSERVE_POINTS = 32,     /* the point model's points at most (points.h) */
	PSD_BACSERVE_STRIDE = 100,    /* a zone's objects of one type: instances 100 x zone + 1 ... */
	PSD_BACSERVE_SUBS = 64,       /* COV subscriptions at most */
	/* COV subscriptions of one IPv4 address at most (whatever its ports):
	 * one host never fills the table, so another always gets served */
	PSD_BACSERVE_SUBS_PER_SOURCE = 16,
	PSD_BACSERVE_VALUES = 4,      /* writable points other than the level (Values) at most */
};

/* object types (clause 21, BACnetObjectType) */
enum {
	PSD_BAC_AI = 0,
	PSD_BAC_AV = 2,
	PSD_BAC_BI = 3,
	PSD_BAC_BV = 5,
	PSD_BAC_DEVICE = 8,
	PSD_BAC_MSI = 13,
	PSD_BAC_MSV = 19,
	PSD_BAC_LO = 54
};

struct psd_bacserve_zone {
	char name[48];
	double level;   /* the output in force, 0-100 % (Present_Value, Tracking_Value) */
	int fault;      /* the zone is at its safe level */
	/* point i of the point model (psd_points_def(i)): has[i] the zone has
	 * it, pv[i] its value in its unit (NAN: no reading) */
	unsigned char has[PSD_BACSERVE_POINTS];
	double pv[PSD_BACSERVE_POINTS];
	double prio[PSD_BACSERVE_PRIORITIES]; /* the BACnet priority array, % (NAN: relinquished) */
	/* the last Lighting_Command taken: its operation, the level it set, its priority */
	uint32_t lc_op, lc_prio;
	double lc_target;
	/* the Values (a writable point other than the level, by its place
	 * among them, bacobj.c): priority arrays (NAN: relinquished) and
	 * Relinquish_Default, in the point's unit */
	double vprio[PSD_BACSERVE_VALUES][PSD_BACSERVE_PRIORITIES];
	double vdef[PSD_BACSERVE_VALUES];
};

/* A COV subscription (SubscribeCOV): who, what, until when, what was sent. */
struct psd_bacserve_sub {
	int used;
	uint8_t addr[6];  /* the subscriber's B/IP address */
	uint8_t npdu[16]; /* the NPDU header that reaches it (through its router) */
	size_t npdu_len;
	uint32_t pid;            /* its subscriber process identifier */
	uint32_t type, instance; /* the monitored object */
	int confirmed;           /* confirmed notifications */
	double expires;          /* model time; 0: no lifetime */
	int sent;                /* a notification went out (the first is due at once) */
	float last_pv;
	int last_fault;
};

/* The result of applying a zone's priority array: 0 done, -1 refused. */
typedef int (*psd_bacserve_apply_fn)(void *user, size_t zone);
/* The same for the priority array of a zone's Value of point `point`. */
typedef int (*psd_bacserve_apply_value_fn)(void *user, size_t zone, size_t point);

struct psd_bacserve_model {
	uint32_t device;  /* the Device object's instance (0 - 4194302) */
	const char *name; /* its Object_Name */
	uint16_t vendor_id;
	/* the target lux a BMS may write ([bacnet] target_min, target_max),
	 * within the point's range; both 0: the point's range */
	double target_min, target_max;
	int writes; /* bits (bacconf.h): 1 a Lighting Output's Present_Value is writable; 2, 4, 8 the
	               target's, daylighting's, vacancy hold's Value */
	uint32_t database_revision;
	size_t nzone;
	struct psd_bacserve_zone *zone;
	psd_bacserve_apply_fn apply; /* after a write changed a zone's priority array */
	psd_bacserve_apply_value_fn apply_value; /* after a write changed a Value's */
	void *user;
	double now; /* seconds on a monotonic clock: subscriptions' lifetimes */
	struct psd_bacserve_sub sub[PSD_BACSERVE_SUBS];
	uint8_t invoke; /* the next confirmed notification's invoke ID */
	struct psd_bacseg seg; /* segmented answers in progress (free with psd_bacseg_free) */
};

/* Where the reply goes. */
enum { PSD_BACSERVE_NONE = 0, PSD_BACSERVE_TO_SENDER = 1, PSD_BACSERVE_TO_ADDRESS = 2 };

struct psd_bacserve_reply {
	int to;          /* PSD_BACSERVE_* */
	uint8_t addr[6]; /* TO_ADDRESS: the B/IP address (IPv4, port), network order */
	size_t len;      /* octets in out */
};

/* Judge one datagram in[0..n) from B/IP address src (IPv4 and port, network
 * order) and write the reply, if any, into out (at least
 * PSD_BACSERVE_MAX_PACKET octets).  `broadcast`: it came to a broadcast
 * address (then only Who-Is is answered).  An answer sent in segments is
 * not in out: it is queued in m->seg, its datagrams from psd_bacseg_next
 * (m->now is the segment timers' clock). */
void psd_bacserve_handle(struct psd_bacserve_model *m, const uint8_t *in, size_t n, const uint8_t src[6],
                         int broadcast, uint8_t *out, struct psd_bacserve_reply *r);
/* An I-Am of this device, whole with its BVLL function fn (0x0b
 * Original-Broadcast-NPDU, 0x09 Distribute-Broadcast-To-Network): its
 * length in out (at least PSD_BACSERVE_MAX_PACKET octets). */
size_t psd_bacserve_i_am(const struct psd_bacserve_model *m, uint8_t fn, uint8_t *out);
/* The next COV notification due (a new subscription's first, or a value
 * moved by its increment or a fault flag changed), into out and r (to an
 * address): 1, or 0 when none is due.  Drops subscriptions whose lifetime
 * ended.  Each call looks at each subscription at most once. */
int psd_bacserve_cov(struct psd_bacserve_model *m, uint8_t *out, struct psd_bacserve_reply *r);

#endif
