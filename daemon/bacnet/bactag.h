/* SPDX-License-Identifier: ISC */
/* BACnet's tagged encoding (ANSI/ASHRAE 135, clause 20.2): the tag octet
 * (tag number, class, length/value/type), extended tag numbers and lengths,
 * opening and closing tags, and the primitive values a lighting controller
 * reads and writes: null, boolean, unsigned, signed, real, character string
 * (UTF-8), bit string, enumerated and object identifier.
 *
 * Decoding reads from a bounded buffer and never past its end; encoding
 * writes into a bounded buffer and marks it overflowed instead of writing
 * past its end, so a reply too long for the asker is found and answered
 * with an Abort, not cut. */
#ifndef PSD_BACTAG_H
#define PSD_BACTAG_H

#include <stddef.h>
#include <stdint.h>

/* application tag numbers (20.2.1.4) */
enum {
	PSD_BACTAG_NULL = 0,
	PSD_BACTAG_BOOLEAN = 1,
	PSD_BACTAG_UNSIGNED = 2,
	PSD_BACTAG_SIGNED = 3,
	PSD_BACTAG_REAL = 4,
	PSD_BACTAG_DOUBLE = 5,
	PSD_BACTAG_OCTETS = 6,
	PSD_BACTAG_CHARSTRING = 7,
	PSD_BACTAG_BITSTRING = 8,
	PSD_BACTAG_ENUM = 9,
	PSD_BACTAG_DATE = 10,
	PSD_BACTAG_TIME = 11,
	PSD_BACTAG_OBJECTID = 12
};

/* One decoded tag.  For an application boolean `len` is its value (0 or 1)
 * and `data` points at nothing. */
struct psd_bactag {
	uint32_t number;      /* tag number (0-254) */
	int context;          /* 1: context-specific class */
	int opening, closing; /* an opening or a closing tag (context class only) */
	uint32_t len;         /* content octets (or the boolean's value) */
	const uint8_t *data;  /* the content */
};

/* Read the tag at *pos of buf[0..n) and step *pos over it and its content.
 * -1 when it is malformed or runs past n. */
int psd_bactag_read(const uint8_t *buf, size_t n, size_t *pos, struct psd_bactag *t);
/* Read the tag at *pos without moving. */
int psd_bactag_peek(const uint8_t *buf, size_t n, size_t pos, struct psd_bactag *t);

/* A tag's content as a value: -1 when its length does not fit the type. */
int psd_bactag_unsigned(const struct psd_bactag *t, uint32_t *v);
int psd_bactag_signed(const struct psd_bactag *t, int32_t *v);
int psd_bactag_real(const struct psd_bactag *t, float *v);
int psd_bactag_objectid(const struct psd_bactag *t, uint32_t *type, uint32_t *instance);

/* An encoding buffer: `overflow` is set (and nothing more is written) when a
 * write would pass `cap`. */
struct psd_bacbuf {
	uint8_t *p;
	size_t cap, len;
	int overflow;
};

void psd_bactag_put_raw(struct psd_bacbuf *b, const void *data, size_t n);
void psd_bactag_put_tag(struct psd_bacbuf *b, uint32_t number, int context, uint32_t len);
void psd_bactag_open(struct psd_bacbuf *b, uint32_t number);
void psd_bactag_close(struct psd_bacbuf *b, uint32_t number);
/* ctx < 0: an application tag; else a context tag of that number. */
void psd_bactag_put_null(struct psd_bacbuf *b, int ctx);
void psd_bactag_put_bool(struct psd_bacbuf *b, int ctx, int v);
void psd_bactag_put_unsigned(struct psd_bacbuf *b, int ctx, uint32_t v);
void psd_bactag_put_enum(struct psd_bacbuf *b, int ctx, uint32_t v);
void psd_bactag_put_real(struct psd_bacbuf *b, int ctx, float v);
void psd_bactag_put_objectid(struct psd_bacbuf *b, int ctx, uint32_t type, uint32_t instance);
/* A character string in ANSI X3.4/UTF-8 (character set 0). */
void psd_bactag_put_string(struct psd_bacbuf *b, int ctx, const char *s);
/* nbits bits, bit 0 first (the most significant bit of the first octet). */
void psd_bactag_put_bits(struct psd_bacbuf *b, int ctx, const uint8_t *bits, unsigned nbits);

#endif
