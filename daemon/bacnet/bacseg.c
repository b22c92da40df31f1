/* SPDX-License-Identifier: ISC */
/* Segmented transmission of a ComplexACK (bacseg.h).  Numbers from
 * ANSI/ASHRAE 135: the PDUs of clause 20.1.5 (BACnet-ComplexACK-PDU) and
 * 20.1.6 (BACnet-SegmentACK-PDU), the state machine of clause 5.4.5. */
#include "bacseg.h"

#include <stdlib.h>
#include <string.h>

/* The largest APDU the asker accepts (20.1.2.5); reserved codes: the least. */
static size_t max_apdu(uint8_t accepts)
{
	static const size_t len[6] = { 50, 128, 206, 480, 1024, 1476 };
	unsigned code = accepts & 15u;
	return code < 6 ? len[code] : 50;
}

/* The most segments the asker accepts (20.1.2.4): 0 for no stated limit
 * (unspecified, or more than 64). */
static uint32_t max_segments(uint8_t accepts)
{
	unsigned code = (unsigned)(accepts >> 4) & 7u;
	return code == 0 || code == 7 ? 0 : 1u << code;
}

static struct psd_bacseg_tx *find(struct psd_bacseg *s, const uint8_t addr[6], const uint8_t *npdu,
                                  size_t npdu_len, uint8_t invoke)
{
	for (size_t i = 0; i < PSD_BACSEG_MAX_TX; i++) {
		struct psd_bacseg_tx *t = &s->tx[i];
		if (t->used && t->invoke == invoke && memcmp(t->addr, addr, 6) == 0 && t->npdu_len == npdu_len &&
		    memcmp(t->npdu, npdu, npdu_len) == 0)
			return t;
	}
	return NULL;
}

static void end_tx(struct psd_bacseg_tx *t)
{
	free(t->data);
	memset(t, 0, sizeof *t);
}

/* Queue the window starting at t->initial (FillWindow) and restart the
 * segment timer. */
static void fill_window(struct psd_bacseg_tx *t, double now)
{
	t->next = t->initial;
	t->end = t->initial + t->window < t->nseg ? t->initial + t->window : t->nseg;
	t->timer = now + PSD_BACSEG_TIMEOUT_MS / 1000.0;
}

uint8_t *psd_bacseg_scratch(struct psd_bacseg *s)
{
	if (!s->scratch)
		s->scratch = malloc(PSD_BACSEG_MAX_LEN);
	return s->scratch;
}

int psd_bacseg_busy(const struct psd_bacseg *s, const uint8_t addr[6], const uint8_t *npdu, size_t npdu_len,
                    uint8_t invoke)
{
	return find((struct psd_bacseg *)s, addr, npdu, npdu_len, invoke) != NULL;
}

int psd_bacseg_start(struct psd_bacseg *s, const uint8_t addr[6], const uint8_t *npdu, size_t npdu_len,
                     uint8_t accepts, const uint8_t *apdu, size_t n, double now)
{
	struct psd_bacseg_tx *t = NULL;
	size_t seglen = max_apdu(accepts) - 5; /* a segment's header: type, invoke, sequence, window, service */
	uint32_t nseg, most = max_segments(accepts);
	size_t mine = 0;
	if (n < 3 || npdu_len > PSD_BACSEG_NPDU)
		return PSD_BACSEG_APDU_TOO_LONG;
	if (n > PSD_BACSEG_MAX_LEN)
		return PSD_BACSEG_APDU_TOO_LONG;
	nseg = (uint32_t)((n - 3 + seglen - 1) / seglen);
	if (nseg == 0)
		nseg = 1;
	if (most && nseg > most) {
		s->refused++;
		return PSD_BACSEG_BUFFER_OVERFLOW;
	}
	for (size_t i = 0; i < PSD_BACSEG_MAX_TX; i++) {
		if (!s->tx[i].used && !t)
			t = &s->tx[i];
		/* the host's share: its IPv4 address, whichever port it asks from */
		mine += s->tx[i].used && memcmp(s->tx[i].addr, addr, 4) == 0;
	}
	if (!t || mine >= PSD_BACSEG_PER_SOURCE) {
		s->refused++;
		return PSD_BACSEG_OUT_OF_RESOURCES;
	}
	if (!(t->data = malloc(n - 3 ? n - 3 : 1))) {
		s->refused++;
		return PSD_BACSEG_OUT_OF_RESOURCES;
	}
	memcpy(t->data, apdu + 3, n - 3);
	t->used = 1;
	memcpy(t->addr, addr, 6);
	memcpy(t->npdu, npdu, npdu_len);
	t->npdu_len = npdu_len;
	t->invoke = apdu[1], t->service = apdu[2];
	t->len = n - 3, t->seglen = seglen, t->nseg = nseg;
	/* the first segment alone, then the window the asker answers with */
	t->initial = 0, t->window = 1, t->retries = 0;
	fill_window(t, now);
	s->started++;
	return 0;
}

int psd_bacseg_ack(struct psd_bacseg *s, const uint8_t addr[6], const uint8_t *npdu, size_t npdu_len,
                   const uint8_t *apdu, size_t n, double now)
{
	struct psd_bacseg_tx *t;
	uint32_t seq, win, delta, acked;
	/* 0x40 SegmentACK, 0x02 negative, 0x01 sent by a server: an ack from
	 * a server (or psensd's own, reflected) is not for an answer of ours */
	if (n != 4 || (apdu[0] & 0xf0) != 0x40 || (apdu[0] & 0x01))
		return 0;
	if (!(t = find(s, addr, npdu, npdu_len, apdu[1])))
		return 0;
	seq = apdu[2], win = apdu[3];
	/* the absolute number it names: one in the window sent
	 * [initial, initial + window) (clause 5.4.5.3 NewACK_Received); any
	 * other is a duplicate, which only restarts the timer */
	delta = (seq - (t->initial & 255u)) & 255u;
	if (delta >= t->window || t->initial + delta >= t->nseg) {
		t->timer = now + PSD_BACSEG_TIMEOUT_MS / 1000.0;
		return 0;
	}
	if (win < 1 || win > 127) {
		end_tx(t);
		s->refused++;
		return PSD_BACSEG_WINDOW_SIZE_OUT_OF_RANGE;
	}
	acked = t->initial + delta;
	if (acked + 1 == t->nseg) { /* FinalACK_Received */
		end_tx(t);
		s->done++;
		return 0;
	}
	/* an ack or a negative ack alike: everything through `acked` arrived,
	 * the next window starts after it */
	t->window = win < PSD_BACSEG_WINDOW ? win : PSD_BACSEG_WINDOW;
	t->initial = acked + 1;
	t->retries = 0;
	fill_window(t, now);
	return 0;
}

void psd_bacseg_cancel(struct psd_bacseg *s, const uint8_t addr[6], const uint8_t *npdu, size_t npdu_len,
                       uint8_t invoke)
{
	struct psd_bacseg_tx *t = find(s, addr, npdu, npdu_len, invoke);
	if (t)
		end_tx(t);
}

/* Timers run out: the window again, or the transaction ended after the
 * last retry (FinalTimeout: nothing is sent). */
static void timers(struct psd_bacseg *s, double now)
{
	for (size_t i = 0; i < PSD_BACSEG_MAX_TX; i++) {
		struct psd_bacseg_tx *t = &s->tx[i];
		if (!t->used || t->next < t->end || now < t->timer)
			continue;
		if (t->retries >= PSD_BACSEG_RETRIES) {
			end_tx(t);
			s->timeouts++;
			continue;
		}
		t->retries++;
		fill_window(t, now);
	}
}

size_t psd_bacseg_next(struct psd_bacseg *s, double now, uint8_t *out, uint8_t addr[6])
{
	timers(s, now);
	for (size_t i = 0; i < PSD_BACSEG_MAX_TX; i++) {
		struct psd_bacseg_tx *t = &s->tx[i];
		size_t off, take, len, h;
		int more;
		if (!t->used || t->next >= t->end)
			continue;
		off = (size_t)t->next * t->seglen;
		take = t->len - off < t->seglen ? t->len - off : t->seglen;
		more = t->next + 1 < t->nseg;
		out[0] = 0x81, out[1] = 0x0a;
		memcpy(out + 4, t->npdu, t->npdu_len);
		h = 4 + t->npdu_len;
		out[h] = (uint8_t)(0x38 | (more ? 0x04 : 0)); /* ComplexACK, segmented, more follows */
		out[h + 1] = t->invoke;
		out[h + 2] = (uint8_t)(t->next & 255u);
		out[h + 3] = PSD_BACSEG_WINDOW; /* proposed window size */
		out[h + 4] = t->service;
		memcpy(out + h + 5, t->data + off, take);
		len = h + 5 + take;
		out[2] = (uint8_t)(len >> 8), out[3] = (uint8_t)len;
		memcpy(addr, t->addr, 6);
		t->next++;
		return len;
	}
	return 0;
}

double psd_bacseg_due(const struct psd_bacseg *s, double now)
{
	double due = -1;
	for (size_t i = 0; i < PSD_BACSEG_MAX_TX; i++) {
		const struct psd_bacseg_tx *t = &s->tx[i];
		double left;
		if (!t->used)
			continue;
		left = t->next < t->end ? 0 : t->timer - now;
		if (left < 0)
			left = 0;
		if (due < 0 || left < due)
			due = left;
	}
	return due;
}

void psd_bacseg_free(struct psd_bacseg *s)
{
	for (size_t i = 0; i < PSD_BACSEG_MAX_TX; i++)
		if (s->tx[i].used)
			end_tx(&s->tx[i]);
	free(s->scratch);
	s->scratch = NULL;
}
