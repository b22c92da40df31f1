/* SPDX-License-Identifier: ISC */
/* The segmented ComplexACK (daemon/bacnet/bacseg.c; ASHRAE 135 clause 5.4.5
 * and 20.1.5-20.1.6): the first segment alone, then windows of the size
 * the asker's SegmentACK gives; a lost SegmentACK sends the window again
 * after APDU_Segment_Timeout, Number_Of_APDU_Retries times, then the
 * transaction ends silently; a negative ack resends from the segment after
 * the one it names; duplicate, foreign and server-sent acks send nothing;
 * too few segments accepted gives buffer-overflow, a window size of 0
 * window-size-out-of-range, a ninth transaction out-of-resources.  Then,
 * through the server (bacserve.c), the Object_List of 100 zones read in one
 * ReadProperty with SA set, acked window by window as a client does, and
 * reassembled: every object identifier of the device, in order; the same
 * request with SA clear gets Abort segmentation-not-supported, with too few
 * segments accepted Abort buffer-overflow. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "bacobj.h"
#include "bacseg.h"
#include "bacserve.h"
#include "bactag.h"
#include "points.h"

static const uint8_t peer[6] = { 10, 0, 0, 7, 0xba, 0xc0 };
static const uint8_t other[6] = { 10, 0, 0, 8, 0xba, 0xc0 };
static const uint8_t npdu[2] = { 1, 0 };

/* A ComplexACK of n octets: 0x30, invoke 7, ReadProperty (12), then octet
 * i of the service-ACK is i mod 251. */
static uint8_t *answer(size_t n)
{
	uint8_t *a = malloc(n);
	assert_non_null(a);
	a[0] = 0x30, a[1] = 7, a[2] = 12;
	for (size_t i = 3; i < n; i++)
		a[i] = (uint8_t)((i - 3) % 251);
	return a;
}

/* The next datagram's segment: its sequence number (-1: none due), after
 * checking its header and that its data are the answer's at that place. */
static int segment(struct psd_bacseg *s, double now, size_t seglen, size_t total)
{
	uint8_t out[4 + PSD_BACSEG_NPDU + 1476], to[6];
	size_t len = psd_bacseg_next(s, now, out, to), off, take;
	int seq;
	if (!len)
		return -1;
	assert_memory_equal(to, peer, 6);
	assert_int_equal(out[0], 0x81);
	assert_int_equal(out[1], 0x0a);
	assert_int_equal((size_t)out[2] << 8 | out[3], len);
	assert_memory_equal(out + 4, npdu, 2);
	seq = out[8];
	off = (size_t)seq * seglen;
	take = total - off < seglen ? total - off : seglen;
	assert_int_equal(out[6] & 0xfb, 0x38);                       /* ComplexACK, segmented */
	assert_int_equal(!!(out[6] & 0x04), off + take < total);      /* more follows but on the last */
	assert_int_equal(out[7], 7);                                  /* invoke ID */
	assert_int_equal(out[9], PSD_BACSEG_WINDOW);                  /* proposed window size */
	assert_int_equal(out[10], 12);                                /* the service */
	assert_int_equal(len, 11 + take);
	for (size_t i = 0; i < take; i++)
		assert_int_equal(out[11 + i], (off + i) % 251);
	return seq;
}

static int ack(struct psd_bacseg *s, const uint8_t *from, uint8_t type, uint8_t seq, uint8_t win, double now)
{
	const uint8_t a[4] = { type, 7, seq, win };
	return psd_bacseg_ack(s, from, npdu, sizeof npdu, a, sizeof a, now);
}

/* max-APDU 480 (code 3), segments unlimited: 475 octets a segment; an
 * answer of 9500 octets of data is 20 segments */
static void windows_and_the_final_ack(void **state)
{
	struct psd_bacseg s = { 0 };
	size_t n = 3 + 9500;
	uint8_t *a = answer(n);
	(void)state;
	assert_int_equal(psd_bacseg_start(&s, peer, npdu, sizeof npdu, 0x03, a, n, 10.0), 0);
	assert_true(psd_bacseg_busy(&s, peer, npdu, sizeof npdu, 7));
	assert_false(psd_bacseg_busy(&s, other, npdu, sizeof npdu, 7));
	/* the first segment alone, until the asker answers */
	assert_int_equal(segment(&s, 10.0, 475, 9500), 0);
	assert_int_equal(segment(&s, 10.0, 475, 9500), -1);
	/* ack 0, window 4: segments 1-4 */
	assert_int_equal(ack(&s, peer, 0x40, 0, 4, 10.1), 0);
	for (int k = 1; k <= 4; k++)
		assert_int_equal(segment(&s, 10.1, 475, 9500), k);
	assert_int_equal(segment(&s, 10.1, 475, 9500), -1);
	/* an ack from another address, one sent by a server (a reflection)
	 * and a duplicate of the last: nothing */
	assert_int_equal(ack(&s, other, 0x40, 4, 4, 10.2), 0);
	assert_int_equal(ack(&s, peer, 0x41, 4, 4, 10.2), 0);
	assert_int_equal(ack(&s, peer, 0x40, 0, 4, 10.2), 0);
	assert_int_equal(segment(&s, 10.2, 475, 9500), -1);
	/* ack 4 with a window over the one proposed: the proposed one (16),
	 * segments 5-19 (the last is 19) */
	assert_int_equal(ack(&s, peer, 0x40, 4, 100, 10.3), 0);
	for (int k = 5; k <= 19; k++)
		assert_int_equal(segment(&s, 10.3, 475, 9500), k);
	assert_int_equal(segment(&s, 10.3, 475, 9500), -1);
	assert_int_equal(ack(&s, peer, 0x40, 19, 16, 10.4), 0);
	assert_false(psd_bacseg_busy(&s, peer, npdu, sizeof npdu, 7));
	assert_int_equal(s.done, 1);
	assert_true(psd_bacseg_due(&s, 10.4) < 0);
	psd_bacseg_free(&s);
	free(a);
}

/* a window not acknowledged: sent again after the segment timeout, three
 * times, then the transaction ends without a word */
static void a_lost_ack_resends_the_window(void **state)
{
	struct psd_bacseg s = { 0 };
	size_t n = 3 + 9500;
	uint8_t *a = answer(n);
	double t = 0, tseg = PSD_BACSEG_TIMEOUT_MS / 1000.0;
	(void)state;
	assert_int_equal(psd_bacseg_start(&s, peer, npdu, sizeof npdu, 0x03, a, n, t), 0);
	assert_int_equal(segment(&s, t, 475, 9500), 0);
	assert_int_equal(ack(&s, peer, 0x40, 0, 3, t), 0);
	for (int k = 1; k <= 3; k++)
		assert_int_equal(segment(&s, t, 475, 9500), k);
	assert_true(fabs(psd_bacseg_due(&s, t) - tseg) < 1e-9);
	assert_int_equal(segment(&s, t + tseg - 0.01, 475, 9500), -1);
	for (int retry = 1; retry <= PSD_BACSEG_RETRIES; retry++) {
		t += tseg;
		for (int k = 1; k <= 3; k++)
			assert_int_equal(segment(&s, t, 475, 9500), k);
		assert_int_equal(segment(&s, t, 475, 9500), -1);
	}
	t += tseg;
	assert_int_equal(segment(&s, t, 475, 9500), -1);
	assert_false(psd_bacseg_busy(&s, peer, npdu, sizeof npdu, 7));
	assert_int_equal(s.timeouts, 1);
	psd_bacseg_free(&s);
	free(a);
}

/* a negative ack naming segment 2 of the window 1-4: 3 onwards again */
static void a_negative_ack_resends_after_it(void **state)
{
	struct psd_bacseg s = { 0 };
	size_t n = 3 + 9500;
	uint8_t *a = answer(n);
	(void)state;
	assert_int_equal(psd_bacseg_start(&s, peer, npdu, sizeof npdu, 0x03, a, n, 0), 0);
	assert_int_equal(segment(&s, 0, 475, 9500), 0);
	assert_int_equal(ack(&s, peer, 0x40, 0, 4, 0), 0);
	for (int k = 1; k <= 4; k++)
		assert_int_equal(segment(&s, 0, 475, 9500), k);
	assert_int_equal(ack(&s, peer, 0x42, 2, 4, 0.5), 0);
	for (int k = 3; k <= 6; k++)
		assert_int_equal(segment(&s, 0.5, 475, 9500), k);
	assert_int_equal(segment(&s, 0.5, 475, 9500), -1);
	/* an actual window size of 0: the transaction is aborted */
	assert_int_equal(ack(&s, peer, 0x40, 6, 0, 0.6), PSD_BACSEG_WINDOW_SIZE_OUT_OF_RANGE);
	assert_false(psd_bacseg_busy(&s, peer, npdu, sizeof npdu, 7));
	psd_bacseg_free(&s);
	free(a);
}

/* more segments than the asker takes: buffer-overflow; longer than psensd
 * sends: apdu-too-long; a ninth at once: out-of-resources */
static void refusals(void **state)
{
	struct psd_bacseg s = { 0 };
	size_t n = 3 + 9500;
	uint8_t *a = answer(n);
	(void)state;
	/* max segments 16 (code 4) of 475: 20 needed */
	assert_int_equal(psd_bacseg_start(&s, peer, npdu, sizeof npdu, 0x43, a, n, 0), PSD_BACSEG_BUFFER_OVERFLOW);
	/* max segments 32 (code 5): taken */
	assert_int_equal(psd_bacseg_start(&s, peer, npdu, sizeof npdu, 0x53, a, n, 0), 0);
	assert_int_equal(psd_bacseg_start(&s, peer, npdu, sizeof npdu, 0x05, a, PSD_BACSEG_MAX_LEN + 1, 0),
	                 PSD_BACSEG_APDU_TOO_LONG);
	/* the table filled by other hosts (10.0.1.i): full for everyone */
	for (int i = 1; i < PSD_BACSEG_MAX_TX; i++) {
		uint8_t host[6] = { 10, 0, 1, (uint8_t)i, 0xba, 0xc0 };
		a[1] = (uint8_t)(7 + i);
		assert_int_equal(psd_bacseg_start(&s, host, npdu, sizeof npdu, 0x05, a, n, 0), 0);
	}
	a[1] = 99;
	assert_int_equal(psd_bacseg_start(&s, peer, npdu, sizeof npdu, 0x05, a, n, 0), PSD_BACSEG_OUT_OF_RESOURCES);
	/* the asker's Abort frees one */
	{
		uint8_t host[6] = { 10, 0, 1, 1, 0xba, 0xc0 };
		psd_bacseg_cancel(&s, host, npdu, sizeof npdu, 8);
	}
	assert_int_equal(psd_bacseg_start(&s, peer, npdu, sizeof npdu, 0x05, a, n, 0), 0);
	psd_bacseg_free(&s);
	free(a);
}

/* One host's unacknowledged answers cannot take every transaction: past
 * its share (whatever its ports) it is refused out-of-resources, another
 * host is served. */
static void transactions_per_source(void **state)
{
	struct psd_bacseg s = { 0 };
	size_t n = 3 + 9500;
	uint8_t *a = answer(n);
	uint8_t port[6] = { 10, 0, 0, 7, 0xba, 0xc1 };
	(void)state;
	assert_true(PSD_BACSEG_PER_SOURCE < PSD_BACSEG_MAX_TX);
	for (int i = 0; i < PSD_BACSEG_PER_SOURCE; i++) {
		a[1] = (uint8_t)(20 + i);
		assert_int_equal(psd_bacseg_start(&s, peer, npdu, sizeof npdu, 0x05, a, n, 0), 0);
	}
	a[1] = 50;
	assert_int_equal(psd_bacseg_start(&s, peer, npdu, sizeof npdu, 0x05, a, n, 0), PSD_BACSEG_OUT_OF_RESOURCES);
	assert_int_equal(psd_bacseg_start(&s, port, npdu, sizeof npdu, 0x05, a, n, 0), PSD_BACSEG_OUT_OF_RESOURCES);
	assert_int_equal(psd_bacseg_start(&s, other, npdu, sizeof npdu, 0x05, a, n, 0), 0);
	psd_bacseg_free(&s);
	free(a);
}

/* ---- through the server: 100 zones' Object_List ------------------------ */

static struct psd_bacserve_zone zones[100];

static void model_of(struct psd_bacserve_model *m)
{
	memset(zones, 0, sizeof zones);
	for (size_t i = 0; i < 100; i++) {
		snprintf(zones[i].name, sizeof zones[i].name, "z%zu", i);
		for (int k = 0; k < PSD_BACSERVE_PRIORITIES; k++)
			zones[i].prio[k] = NAN;
		for (size_t k = 0; k < psd_points_count(); k++)
			zones[i].has[k] = 1;
	}
	*m = (struct psd_bacserve_model){ .device = 10, .name = "psensd", .vendor_id = 65535,
		                          .database_revision = 1, .nzone = 100, .zone = zones };
}

/* ReadProperty (device, 10) Object_List with the APDU's first two octets
 * h0, h1: the direct reply's APDU length (0: none) into *a */
static size_t read_list(struct psd_bacserve_model *m, uint8_t h0, uint8_t h1, uint8_t *out, const uint8_t **a)
{
	const uint8_t in[] = { 0x81, 0x0a, 0, 17, 1, 0x04, h0, h1, 0x07, 0x0c, 0x0c, 0x02, 0x00, 0x00, 0x0a, 0x19, 0x4c };
	struct psd_bacserve_reply r;
	psd_bacserve_handle(m, in, sizeof in, peer, 0, out, &r);
	*a = out + 6;
	return r.to == PSD_BACSERVE_NONE ? 0 : r.len - 6;
}

static void object_list_of_100_zones(void **state)
{
	struct psd_bacserve_model m;
	uint8_t out[PSD_BACSERVE_MAX_PACKET], to[6], *whole = malloc(PSD_BACSEG_MAX_LEN);
	const uint8_t *a;
	size_t got = 0, len, count, pos, segs = 0;
	int last = -1, more = 1;
	struct psd_bactag t;
	(void)state;
	assert_non_null(whole);
	model_of(&m);
	count = psd_bacobj_count(&m);
	assert_true(count > 1000);   /* 5 octets an identifier: far over one APDU */
	/* SA clear: Abort segmentation-not-supported */
	assert_int_equal(read_list(&m, 0x00, 0x05, out, &a), 3);
	assert_memory_equal(a, ((const uint8_t[]){ 0x71, 0x07, 0x04 }), 3);
	/* SA set, at most 2 segments (code 1) of 1476: Abort buffer-overflow */
	assert_int_equal(read_list(&m, 0x02, 0x15, out, &a), 3);
	assert_memory_equal(a, ((const uint8_t[]){ 0x71, 0x07, 0x01 }), 3);
	/* SA set, segments unlimited, 480 octets: nothing direct, then the
	 * segments, acked as the asker's window (4) fills */
	m.now = 5;
	assert_int_equal(read_list(&m, 0x02, 0x03, out, &a), 0);
	/* a repeat of the request while it is answered: dropped */
	assert_int_equal(read_list(&m, 0x02, 0x03, out, &a), 0);
	while (more) {
		size_t k = 0;
		uint8_t ackd[] = { 0x81, 0x0a, 0, 10, 1, 0, 0x40, 0x07, 0, 4 };
		struct psd_bacserve_reply r;
		while ((len = psd_bacseg_next(&m.seg, m.now, out, to))) {
			assert_true(len > 11 && len <= 6 + 480);
			assert_memory_equal(to, peer, 6);
			assert_int_equal(out[8], (last + 1) & 255);
			last++, segs++, k++;
			more = !!(out[6] & 0x04);
			if (last == 0) { /* the first keeps the header: 0x30, invoke, service */
				whole[0] = 0x30, whole[1] = out[7], whole[2] = out[10];
				got = 3;
			}
			memcpy(whole + got, out + 11, len - 11);
			got += len - 11;
		}
		/* the first segment alone, then windows of 4 (fewer at the end) */
		assert_true(last == 0 ? k == 1 : (k == 4 || (!more && k >= 1 && k <= 4)));
		ackd[8] = (uint8_t)last;
		m.now += 0.01;
		psd_bacserve_handle(&m, ackd, sizeof ackd, peer, 0, out, &r);
		assert_int_equal(r.len, 0);
	}
	assert_false(psd_bacseg_busy(&m.seg, peer, npdu, sizeof npdu, 7));
	assert_int_equal(segs, (got - 3 + 474) / 475);
	/* the whole: ComplexACK ReadProperty, [0] device 10, [1] 76, [3] the
	 * identifiers in psd_bacobj_at's order, [3] closed */
	assert_int_equal(whole[0], 0x30);
	assert_int_equal(whole[2], 12);
	pos = 3;
	assert_int_equal(psd_bactag_read(whole, got, &pos, &t), 0);
	assert_int_equal(psd_bactag_read(whole, got, &pos, &t), 0);
	assert_int_equal(psd_bactag_read(whole, got, &pos, &t), 0);
	assert_true(t.context && t.opening && t.number == 3);
	for (size_t i = 0; i < count; i++) {
		struct psd_bacobj o;
		uint32_t type, inst;
		psd_bacobj_at(&m, i, &o);
		assert_int_equal(psd_bactag_read(whole, got, &pos, &t), 0);
		assert_int_equal(psd_bactag_objectid(&t, &type, &inst), 0);
		assert_int_equal(type, o.type);
		assert_int_equal(inst, o.instance);
	}
	assert_int_equal(psd_bactag_read(whole, got, &pos, &t), 0);
	assert_true(t.context && t.closing && t.number == 3);
	assert_int_equal(pos, got);
	psd_bacseg_free(&m.seg);
	free(whole);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(windows_and_the_final_ack),
		cmocka_unit_test(a_lost_ack_resends_the_window),
		cmocka_unit_test(a_negative_ack_resends_after_it),
		cmocka_unit_test(refusals),
		cmocka_unit_test(transactions_per_source),
		cmocka_unit_test(object_list_of_100_zones),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
