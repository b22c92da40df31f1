/* SPDX-License-Identifier: ISC */
/* BACnet's tagged encoding (bactag.h; ANSI/ASHRAE 135 clause 20.2). */
#include "bactag.h"

#include <string.h>

int psd_bactag_read(const uint8_t *buf, size_t n, size_t *pos, struct psd_bactag *t)
{
	size_t i = *pos;
	uint8_t o;
	uint32_t lvt;
	if (i >= n)
		return -1;
	o = buf[i++];
	memset(t, 0, sizeof *t);
	t->number = o >> 4;
	t->context = (o >> 3) & 1;
	lvt = o & 7u;
	if (t->number == 15) { /* extended tag number: the next octet, 255 reserved */
		if (i >= n || buf[i] == 255)
			return -1;
		t->number = buf[i++];
	}
	if (lvt == 6 || lvt == 7) {
		if (!t->context) /* an application tag cannot open or close */
			return -1;
		t->opening = lvt == 6;
		t->closing = lvt == 7;
		*pos = i;
		return 0;
	}
	if (!t->context && t->number == PSD_BACTAG_BOOLEAN) { /* the value is in the tag */
		if (lvt > 1)
			return -1;
		t->len = lvt;
		*pos = i;
		return 0;
	}
	if (lvt == 5) { /* extended length */
		if (i >= n)
			return -1;
		lvt = buf[i++];
		if (lvt == 254) {
			if (n - i < 2)
				return -1;
			lvt = (uint32_t)buf[i] << 8 | buf[i + 1];
			i += 2;
		} else if (lvt == 255) {
			if (n - i < 4)
				return -1;
			lvt = (uint32_t)buf[i] << 24 | (uint32_t)buf[i + 1] << 16 |
			      (uint32_t)buf[i + 2] << 8 | buf[i + 3];
			i += 4;
		}
	}
	if (lvt > n - i)
		return -1;
	t->len = lvt;
	t->data = buf + i;
	*pos = i + lvt;
	return 0;
}

int psd_bactag_peek(const uint8_t *buf, size_t n, size_t pos, struct psd_bactag *t)
{
	return psd_bactag_read(buf, n, &pos, t);
}

int psd_bactag_unsigned(const struct psd_bactag *t, uint32_t *v)
{
	uint32_t x = 0;
	if (t->opening || t->closing || t->len < 1 || t->len > 4)
		return -1;
	for (uint32_t i = 0; i < t->len; i++)
		x = x << 8 | t->data[i];
	*v = x;
	return 0;
}

int psd_bactag_signed(const struct psd_bactag *t, int32_t *v)
{
	uint32_t x;
	if (psd_bactag_unsigned(t, &x) != 0)
		return -1;
	if (t->len < 4 && (t->data[0] & 0x80)) /* sign-extend */
		x |= ~0u << (8 * t->len);
	memcpy(v, &x, sizeof x);
	return 0;
}

int psd_bactag_real(const struct psd_bactag *t, float *v)
{
	uint32_t x;
	if (t->len != 4 || psd_bactag_unsigned(t, &x) != 0)
		return -1;
	memcpy(v, &x, sizeof *v);
	return 0;
}

int psd_bactag_objectid(const struct psd_bactag *t, uint32_t *type, uint32_t *instance)
{
	uint32_t x;
	if (t->len != 4 || psd_bactag_unsigned(t, &x) != 0)
		return -1;
	*type = x >> 22;
	*instance = x & 0x3fffffu;
	return 0;
}

void psd_bactag_put_raw(struct psd_bacbuf *b, const void *data, size_t n)
{
	if (b->overflow || n > b->cap - b->len) {
		b->overflow = 1;
		return;
	}
	memcpy(b->p + b->len, data, n);
	b->len += n;
}

static void put1(struct psd_bacbuf *b, uint8_t o)
{
	psd_bactag_put_raw(b, &o, 1);
}

static void tag_octets(struct psd_bacbuf *b, uint32_t number, int context, uint32_t lvt)
{
	if (number < 15) {
		put1(b, (uint8_t)(number << 4 | (context ? 8u : 0u) | lvt));
	} else {
		put1(b, (uint8_t)(0xf0 | (context ? 8u : 0u) | lvt));
		put1(b, (uint8_t)number);
	}
}

void psd_bactag_put_tag(struct psd_bacbuf *b, uint32_t number, int context, uint32_t len)
{
	if (len <= 4) {
		tag_octets(b, number, context, len);
		return;
	}
	tag_octets(b, number, context, 5);
	if (len <= 253) {
		put1(b, (uint8_t)len);
	} else if (len <= 65535) {
		uint8_t o[3] = { 254, (uint8_t)(len >> 8), (uint8_t)len };
		psd_bactag_put_raw(b, o, 3);
	} else {
		uint8_t o[5] = { 255, (uint8_t)(len >> 24), (uint8_t)(len >> 16), (uint8_t)(len >> 8),
			         (uint8_t)len };
		psd_bactag_put_raw(b, o, 5);
	}
}

void psd_bactag_open(struct psd_bacbuf *b, uint32_t number)
{
	tag_octets(b, number, 1, 6);
}

void psd_bactag_close(struct psd_bacbuf *b, uint32_t number)
{
	tag_octets(b, number, 1, 7);
}

static void put_tag_for(struct psd_bacbuf *b, int ctx, uint32_t app, uint32_t len)
{
	if (ctx < 0)
		psd_bactag_put_tag(b, app, 0, len);
	else
		psd_bactag_put_tag(b, (uint32_t)ctx, 1, len);
}

void psd_bactag_put_null(struct psd_bacbuf *b, int ctx)
{
	put_tag_for(b, ctx, PSD_BACTAG_NULL, 0);
}

void psd_bactag_put_bool(struct psd_bacbuf *b, int ctx, int v)
{
	if (ctx < 0) { /* the value in the tag (20.2.3) */
		psd_bactag_put_tag(b, PSD_BACTAG_BOOLEAN, 0, v ? 1 : 0);
	} else {
		psd_bactag_put_tag(b, (uint32_t)ctx, 1, 1);
		put1(b, v ? 1 : 0);
	}
}

/* the fewest octets, most significant first (20.2.4) */
static void put_uint(struct psd_bacbuf *b, int ctx, uint32_t app, uint32_t v)
{
	uint32_t n = v > 0xffffffu ? 4 : v > 0xffffu ? 3 : v > 0xffu ? 2 : 1;
	put_tag_for(b, ctx, app, n);
	for (uint32_t i = n; i-- > 0;)
		put1(b, (uint8_t)(v >> (8 * i)));
}

void psd_bactag_put_unsigned(struct psd_bacbuf *b, int ctx, uint32_t v)
{
	put_uint(b, ctx, PSD_BACTAG_UNSIGNED, v);
}

void psd_bactag_put_enum(struct psd_bacbuf *b, int ctx, uint32_t v)
{
	put_uint(b, ctx, PSD_BACTAG_ENUM, v);
}

void psd_bactag_put_real(struct psd_bacbuf *b, int ctx, float v)
{
	uint32_t x;
	uint8_t o[4];
	memcpy(&x, &v, sizeof x);
	o[0] = (uint8_t)(x >> 24), o[1] = (uint8_t)(x >> 16), o[2] = (uint8_t)(x >> 8), o[3] = (uint8_t)x;
	put_tag_for(b, ctx, PSD_BACTAG_REAL, 4);
	psd_bactag_put_raw(b, o, 4);
}

void psd_bactag_put_objectid(struct psd_bacbuf *b, int ctx, uint32_t type, uint32_t instance)
{
	uint32_t x = (type & 0x3ffu) << 22 | (instance & 0x3fffffu);
	uint8_t o[4] = { (uint8_t)(x >> 24), (uint8_t)(x >> 16), (uint8_t)(x >> 8), (uint8_t)x };
	put_tag_for(b, ctx, PSD_BACTAG_OBJECTID, 4);
	psd_bactag_put_raw(b, o, 4);
}

void psd_bactag_put_string(struct psd_bacbuf *b, int ctx, const char *s)
{
	size_t n = strlen(s);
	put_tag_for(b, ctx, PSD_BACTAG_CHARSTRING, (uint32_t)n + 1);
	put1(b, 0); /* character set: ISO 10646 (UTF-8) */
	psd_bactag_put_raw(b, s, n);
}

void psd_bactag_put_bits(struct psd_bacbuf *b, int ctx, const uint8_t *bits, unsigned nbits)
{
	unsigned n = (nbits + 7) / 8;
	put_tag_for(b, ctx, PSD_BACTAG_BITSTRING, n + 1);
	put1(b, (uint8_t)(n * 8 - nbits)); /* unused bits in the last octet */
	psd_bactag_put_raw(b, bits, n);
}
