/* SPDX-License-Identifier: ISC */
/* The DALI frame layer: what an application controller puts on the bus and
 * what comes back, whatever the interface between the host and the bus.
 *
 * A forward frame is 8, 16 or 24 bits (IEC 62386-101: 16-bit frames to
 * control gear, 24-bit frames to control devices, 8-bit frames are backward
 * frames seen from the bus side), possibly sent twice within 100 ms, and may
 * expect a backward frame.  Its outcome is one of the events below: an
 * answer, no answer, a bus error (a garbled answer when several devices
 * answer at once, our frame colliding with another master's, a framing or
 * checksum error, the bus without power), or a report that does not follow
 * the interface's protocol.  Other masters' frames seen on the bus and the
 * bus power coming and going arrive as events of their own.
 *
 * Each interface is a codec (bytes to and from frames; the USB interfaces'
 * fixed-size reports in dali_transport.h, the serial and TCP interfaces'
 * byte streams here) plus an I/O kind (libusb in dali_usb.c; a tty or a TCP
 * socket in dali_serial.c). */
#ifndef PS_DALI_FRAME_H
#define PS_DALI_FRAME_H

#include <stddef.h>
#include <stdint.h>

enum ps_dali_event {
	PS_DALI_EV_IGNORE = 0,   /* idle/no-op report, or not for us */
	PS_DALI_EV_ECHO,         /* our forward frame went out on the bus (not final) */
	PS_DALI_EV_NO_ANSWER,    /* final: done, no backward frame */
	PS_DALI_EV_ANSWER,       /* final: backward frame in value */
	PS_DALI_EV_BUS_ERROR,    /* final: garbled answer (collision, framing), or bus fault: enum ps_dali_bus */
	PS_DALI_EV_OBSERVED,     /* another master's frame seen on the bus */
	PS_DALI_EV_INFO,         /* reply to an init or configuration request (firmware, serial) */
	PS_DALI_EV_MALFORMED,    /* a report that does not follow the protocol */
	PS_DALI_EV_POWER,        /* the bus power changed: value 1 back, 0 lost (a short, no supply) */
};
#define PS_DALI_EV_COUNT (PS_DALI_EV_POWER + 1)

/* The value of a BUS_ERROR: what went wrong on the bus or in the interface.
 * 1 to 3 are the Tridonic interface's own status codes. */
enum ps_dali_bus {
	PS_DALI_BUS_CHECKSUM = 1,        /* a checksum error (the interface's or the frame's) */
	PS_DALI_BUS_SHORT = 2,           /* the bus is shorted or without power */
	PS_DALI_BUS_FRAMING = 3,         /* a garbled backward frame: several devices answered at once */
	PS_DALI_BUS_SEND_COLLISION = 8,  /* our forward frame collided with another master's: send again */
	PS_DALI_BUS_REJECTED = 9,        /* the interface refused the request (full buffer, invalid command) */
	PS_DALI_BUS_EARLY = 10,          /* a backward frame before the settling time allowed it: not an answer */
};

struct ps_dali_reply {
	int event;          /* enum ps_dali_event */
	int seq;            /* sequence number the report answers, -1 if none */
	unsigned value;     /* backward frame (ANSWER), forward frame (ECHO, OBSERVED), status code */
};

struct ps_dali_frame {
	int bits;           /* 8, 16 or 24 */
	uint32_t data;      /* the frame, right-aligned: a 16-bit frame is address << 8 | data */
	int twice;          /* send twice within 100 ms (configuration commands, INITIALISE, RANDOMISE) */
	int expect_answer;  /* a query: a backward frame may follow */
};

/* One message taken off a byte stream. */
struct ps_dali_frame_rx {
	int event;          /* enum ps_dali_event */
	unsigned value;     /* the answer, the observed frame, the bus error code, the power state */
	int bits;           /* OBSERVED: the frame's length in bits (0: a framing error on the bus) */
	char why[96];       /* MALFORMED, BUS_ERROR: what was wrong, for messages */
};

/* A serial or TCP interface's protocol as a pure codec: no I/O, no clock. */
struct ps_dali_codec {
	const char *name;       /* the transport's name in the configuration */
	long baud;              /* serial speed (8N1) */
	int replies_per_twice;  /* final replies to a frame sent twice by the interface: 1 or 2 */
	size_t max_msg;         /* longest message: more bytes without its end are malformed */
	/* 0: the interface says "no answer" itself.  > 0: it reports only what
	 * it saw on the bus (an ECHO when our frame went out, a backward frame
	 * if one came), so a query's "no answer" is no backward frame within
	 * this many seconds of the last ECHO. */
	double answer_window;
	/* TCP gateways that drop a silent connection: a harmless request to
	 * send after this many idle seconds (0: none), and its encoder. */
	double keepalive;
	int (*encode_keepalive)(uint8_t *out, size_t cap);
	/* Encode a forward frame.  Returns the length, or -1 (the interface
	 * cannot send this frame: a length or send-twice it lacks, or cap too small). */
	int (*encode)(uint8_t *out, size_t cap, const struct ps_dali_frame *f);
	/* Take the first message off buf[0..len).  Returns the bytes it used
	 * (> 0) with rx filled in, or 0 when buf holds no whole message yet.
	 * Bytes that cannot begin a message are used up as MALFORMED. */
	size_t (*decode)(const uint8_t *buf, size_t len, struct ps_dali_frame_rx *rx);
};

/* 0 when f is a frame the bus can carry (bits 8, 16 or 24, data fitting in
 * them), -1 otherwise. */
int ps_dali_frame_valid(const struct ps_dali_frame *f);
/* The event's name for messages ("answer", "no answer", ...). */
const char *ps_dali_frame_event_name(int event);
/* Uppercase hex of the low n bytes of v, most significant first, into out
 * (2n characters, no terminator).  Returns 2n. */
size_t ps_dali_frame_hex(char *out, uint32_t v, int n);
/* Parse n hex digits (either case); -1 if one is not a hex digit. */
long ps_dali_frame_unhex(const uint8_t *s, size_t n);

#endif
