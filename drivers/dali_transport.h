/* SPDX-License-Identifier: ISC */
/* A USB-to-DALI interface as the DALI USB driver sees it: its USB identity and
 * endpoints, and how a DALI forward frame becomes an OUT report and an IN
 * report becomes an event.  The transports are pure byte codecs; the USB I/O,
 * sequence numbers, timeouts, retries and the frame rate live in dali_usb.c,
 * so a second interface (the hasseb DALI Master, 04cc:0802, 10-byte reports)
 * is one more table like ps_usb_tridonic, without touching the driver or
 * the DALI layer. */
#ifndef PS_DALI_TRANSPORT_H
#define PS_DALI_TRANSPORT_H

#include <stddef.h>
#include <stdint.h>

enum ps_dali_event {
	PS_DALI_EV_IGNORE = 0,   /* idle/no-op report, or not for us */
	PS_DALI_EV_ECHO,         /* our forward frame went out on the bus (not final) */
	PS_DALI_EV_NO_ANSWER,    /* final: done, no backward frame */
	PS_DALI_EV_ANSWER,       /* final: backward frame in value */
	PS_DALI_EV_BUS_ERROR,    /* final: garbled answer (collision, framing), or bus fault */
	PS_DALI_EV_OBSERVED,     /* another master's frame seen on the bus */
	PS_DALI_EV_INFO,         /* reply to an init request (firmware, serial) */
	PS_DALI_EV_MALFORMED,    /* a report that does not follow the protocol */
};

struct ps_dali_reply {
	int event;          /* enum ps_dali_event */
	int seq;            /* sequence number the report answers, -1 if none */
	unsigned value;     /* backward frame (ANSWER), forward frame (ECHO, OBSERVED), status code */
};

struct ps_dali_transport {
	const char *name;           /* "tridonic" */
	uint16_t vid, pid;
	int interface;
	uint8_t ep_in, ep_out;
	int report_len;             /* bytes per report, both directions */
	int has_echo;               /* sends an ECHO before the final report */
	/* Encode "send this 16-bit forward frame" (send_twice: the interface repeats
	 * it within the 100 ms limit; dtr0 >= 0: load DTR0 with it first, as one
	 * transaction).  Returns the report length, -1 if the interface cannot. */
	int (*encode_send)(uint8_t *out, size_t cap, int seq, unsigned frame, int send_twice, int dtr0);
	/* Decode one IN report (any length: short or long reports are MALFORMED). */
	void (*decode)(const uint8_t *in, size_t len, struct ps_dali_reply *r);
	/* Next sequence number after seq (the interface's wrap rule). */
	int (*next_seq)(int seq);
};

#endif
