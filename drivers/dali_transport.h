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

#include "dali_frame.h"

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
	/* Encode "report your firmware version" (answered by an INFO event with
	 * the version as major << 8 | minor), or NULL when the interface has no
	 * such request.  Returns the report length, -1 if it cannot. */
	int (*encode_version)(uint8_t *out, size_t cap, int seq);
};

#endif
