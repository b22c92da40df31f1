/* SPDX-License-Identifier: ISC */
/* Segmented transmission of a ComplexACK (ANSI/ASHRAE 135 clause 5.2 and
 * 5.4.5, the responding BACnet-user's SEGMENTED_RESPONSE state): an answer
 * longer than the asker's max-APDU, to a request whose SA bit says it
 * accepts a segmented response, is cut into segments of at most its
 * max-APDU and sent a window at a time; each SegmentACK (or negative ack)
 * from the asker starts the next window at the sequence number after the
 * one it names, in the window size the asker chose (the actual window
 * size, at most the one proposed here); a window not acknowledged within
 * APDU_Segment_Timeout is sent again, Number_Of_APDU_Retries times, then
 * the transaction is dropped silently.  Receiving segmented requests is
 * not supported (bacserve.c answers Abort segmentation-not-supported).
 *
 * One job: the transactions' state.  Pure and non-blocking: it never
 * reads a clock nor a socket (the time comes in, the segments go out one
 * datagram per call), so the control loop asks it for what is due and the
 * unit tests drive it by hand.  Bounded: at most PSD_BACSEG_MAX_TX
 * transactions at once (one more is refused with Abort out-of-resources),
 * an answer of at most PSD_BACSEG_MAX_LEN octets, each transaction's data
 * on the heap only while it lives; an acknowledgement only moves a
 * transaction forward (a repeated, reflected or forged one sends nothing
 * more than one window), so no ack can make it loop. */
#ifndef PSD_BACSEG_H
#define PSD_BACSEG_H

#include <stddef.h>
#include <stdint.h>

enum {
	PSD_BACSEG_MAX_TX = 8,          /* segmented answers in progress at once */
	/* of them to one IPv4 address (whatever its ports): one host leaving
	 * its answers unacknowledged never locks the others out */
	PSD_BACSEG_PER_SOURCE = 2,
	PSD_BACSEG_MAX_LEN = 1 << 16,   /* the longest answer (APDU octets) sent in segments */
	PSD_BACSEG_WINDOW = 16,         /* the proposed window size */
	PSD_BACSEG_TIMEOUT_MS = 2000,   /* APDU_Segment_Timeout */
	PSD_BACSEG_RETRIES = 3,         /* Number_Of_APDU_Retries (the Device object's) */
	PSD_BACSEG_NPDU = 24,           /* the reply's NPDU header, octets at most */
};

/* abort reasons (BACnetAbortReason, clause 21) */
enum {
	PSD_BACSEG_BUFFER_OVERFLOW = 1,
	PSD_BACSEG_SEGMENTATION_NOT_SUPPORTED = 4,
	PSD_BACSEG_WINDOW_SIZE_OUT_OF_RANGE = 7,
	PSD_BACSEG_OUT_OF_RESOURCES = 9,
	PSD_BACSEG_APDU_TOO_LONG = 11,
};

struct psd_bacseg_tx {
	int used;
	uint8_t addr[6];                  /* the asker's B/IP address */
	uint8_t npdu[PSD_BACSEG_NPDU];    /* the reply's NPDU header (through its router) */
	size_t npdu_len;
	uint8_t invoke, service;
	uint8_t *data;                    /* the service-ACK's octets (after the service choice) */
	size_t len, seglen;               /* octets; octets a segment */
	uint32_t nseg;                    /* segments */
	/* sequence numbers counted without wrapping (sent modulo 256) */
	uint32_t initial;                 /* the first not acknowledged */
	uint32_t window;                  /* the actual window size */
	uint32_t next, end;               /* the segments [next, end) still to send now */
	uint32_t retries;
	double timer;                     /* when the window is sent again (model seconds) */
};

struct psd_bacseg {
	struct psd_bacseg_tx tx[PSD_BACSEG_MAX_TX];
	uint8_t *scratch;                 /* PSD_BACSEG_MAX_LEN octets to build an answer in */
	unsigned long started, done, timeouts, refused;
};

/* A buffer of PSD_BACSEG_MAX_LEN octets to build a whole answer in (kept
 * until psd_bacseg_free), or NULL without memory. */
uint8_t *psd_bacseg_scratch(struct psd_bacseg *s);
/* 1 when a segmented answer to (addr, npdu, invoke) is in progress: a
 * repeated request is then dropped (clause 5.4.5.3, DuplicateRequest). */
int psd_bacseg_busy(const struct psd_bacseg *s, const uint8_t addr[6], const uint8_t *npdu, size_t npdu_len,
                    uint8_t invoke);
/* Start sending the ComplexACK apdu[0..n) (unsegmented form: 0x30, invoke,
 * service, data) in segments to a request whose second octet (max
 * segments and max-APDU) was `accepts`, from addr; the first segment is
 * queued for psd_bacseg_next.  0, or the abort reason to answer with:
 * buffer-overflow when it needs more segments than the asker accepts,
 * apdu-too-long when longer than PSD_BACSEG_MAX_LEN, out-of-resources when
 * every transaction is in use or memory ran out. */
int psd_bacseg_start(struct psd_bacseg *s, const uint8_t addr[6], const uint8_t *npdu, size_t npdu_len,
                     uint8_t accepts, const uint8_t *apdu, size_t n, double now);
/* A SegmentACK apdu[0..n) from addr (clause 20.1.6): the next window
 * queued, the transaction finished, or nothing (not ours, a duplicate).
 * 0, or an abort reason for the transaction (an actual window size of 0 or
 * over 127: window-size-out-of-range), which is then ended. */
int psd_bacseg_ack(struct psd_bacseg *s, const uint8_t addr[6], const uint8_t *npdu, size_t npdu_len,
                   const uint8_t *apdu, size_t n, double now);
/* An Abort from the asker (clause 20.1.9, server bit clear): its
 * transaction ended, if there is one. */
void psd_bacseg_cancel(struct psd_bacseg *s, const uint8_t addr[6], const uint8_t *npdu, size_t npdu_len,
                       uint8_t invoke);
/* The next datagram due at `now` (a queued segment, or a window sent again
 * after its timeout), whole with its BVLL header, into out (at least
 * 4 + PSD_BACSEG_NPDU + 1476 octets), its destination in addr: its length,
 * or 0 when nothing is due. */
size_t psd_bacseg_next(struct psd_bacseg *s, double now, uint8_t *out, uint8_t addr[6]);
/* Seconds from now until a transaction's timer runs out (0 when due),
 * -1 none. */
double psd_bacseg_due(const struct psd_bacseg *s, double now);
/* End every transaction and free the memory. */
void psd_bacseg_free(struct psd_bacseg *s);

#endif
