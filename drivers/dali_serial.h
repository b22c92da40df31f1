/* SPDX-License-Identifier: ISC */
/* A DALI interface on a byte stream: a tty (RS-232, USB-serial, a Raspberry
 * Pi UART) or a TCP socket, with a stream codec (dali_frame.h) on it, one
 * transaction at a time.  Never blocks after open: send() writes the frame,
 * service() reads what has arrived and ends the transaction when its reply
 * is complete or its time is up; the caller polls fd() and deadline().
 *
 * A transaction ends in exactly one result: an answer or no answer (err 0),
 * a bus error (EPROTO; the code in value: a garbled answer, our frame
 * colliding with another master's, the converter refusing it), a reply that
 * does not follow the protocol (EPROTO), the bus without power (EIO), or no
 * reply in time (ETIMEDOUT; a reply cut short says so).  Bytes left over
 * from a transaction that timed out are discarded before the next one, so a
 * late or partial reply is never taken for the next frame's.  Other masters'
 * frames and the bus power's changes are counted and kept in the stats. */
#ifndef PS_DALI_SERIAL_H
#define PS_DALI_SERIAL_H

#include "dali_frame.h"

struct ps_dali_serial;

struct ps_dali_serial_result {
	int event;          /* enum ps_dali_event: ANSWER, NO_ANSWER, BUS_ERROR, MALFORMED, POWER, or IGNORE (timeout) */
	unsigned value;     /* the answer, the bus error's code */
	int err;            /* 0, EPROTO, EIO, ETIMEDOUT */
	char why[160];      /* what went wrong, for messages */
};

struct ps_dali_serial_stats {
	unsigned long frames;      /* frames sent */
	unsigned long answers, no_answers;
	unsigned long bus_errors;  /* garbled answers, collisions, refusals */
	unsigned long malformed;   /* messages that did not follow the protocol */
	unsigned long timeouts;
	unsigned long observed;    /* other masters' frames seen on the bus */
	unsigned long stray;       /* replies when no transaction was waiting */
	unsigned long keepalives;  /* keep-alive requests sent to an idle TCP gateway */
	unsigned last_observed;    /* the last of them */
	int power_lost;            /* the interface last said the bus has no power */
};

/* Open a tty path ("/dev/ttyAMA0", baud bits per second, 8N1, raw) or
 * connect to "HOST:PORT".  NULL with errno and err on failure. */
struct ps_dali_serial *ps_dali_serial_open(const struct ps_dali_codec *c, const char *where, long baud, char *err,
                                           size_t errlen);
int ps_dali_serial_fd(const struct ps_dali_serial *s);
/* Start a transaction.  0, or -1 with errno: EBUSY (one is under way),
 * EINVAL (the codec cannot carry this frame), EIO (the write failed). */
int ps_dali_serial_send(struct ps_dali_serial *s, const struct ps_dali_frame *f, double now, double timeout);
/* Read what has arrived and move on.  1: the transaction ended (res filled
 * in); 0: nothing ended; -1: the link is gone (errno, res->why). */
int ps_dali_serial_service(struct ps_dali_serial *s, double now, struct ps_dali_serial_result *res);
/* When service() must run next without input: the transaction's time
 * limit, the next keep-alive, or INFINITY. */
double ps_dali_serial_deadline(const struct ps_dali_serial *s);
void ps_dali_serial_stats(const struct ps_dali_serial *s, struct ps_dali_serial_stats *st);
/* Over TCP, with a codec that has one: send the keep-alive request after
 * this many idle seconds (default: the codec's; 0: never). */
void ps_dali_serial_keepalive(struct ps_dali_serial *s, double seconds);
/* Take the oldest frame seen on the bus from someone else (another
 * master's command, a control device's event message): 1 with frame and
 * its bits, 0 none.  The last 32 are kept. */
int ps_dali_serial_observed(struct ps_dali_serial *s, uint32_t *frame, int *bits);
void ps_dali_serial_close(struct ps_dali_serial *s);

#endif
