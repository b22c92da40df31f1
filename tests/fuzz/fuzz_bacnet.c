/* SPDX-License-Identifier: ISC */
/* Fuzz psensd's BACnet/IP server (daemon/bacnet/bacserve.c, bacobj.c, bactag.c): the
 * datagram a client sends (BVLL, NPDU, APDU) answered over a three-zone
 * model with every write on (the Lighting Outputs and the Values).  The first byte chooses whether it came to a
 * broadcast address; the rest is the datagram.
 * Invariants: a reply is at most PSD_BACSERVE_MAX_PACKET octets, starts
 * with a BVLL header whose length is the reply's, and is never larger than
 * 1476 octets of APDU; a datagram to a broadcast address gets at most an
 * I-Am or an I-Have (unconfirmed, 0x10 0x00 or 0x01), never an error,
 * reject or abort; the
 * priority arrays hold only NULL or 0-100 %, a Value's only NULL or its
 * point's range; every reply's tags read back
 * to its end (each tag lies inside the reply); so do the COV
 * notifications a subscription in the datagram makes due.
 * With bit 2 of the first byte, a segmented answer is in progress before
 * the datagram (a ReadProperty of the Object_List with SA set and max-APDU
 * 50, its first segment sent): the datagram may ack it, abort it or
 * repeat it.  Then every segment due is read, the clock moved past every
 * timeout: each is a ComplexACK segment within 1476 octets of APDU (50 for
 * the answer started here) with
 * the BVLL length its own, their number bounded (a window per ack, the
 * retries), and no transaction outlives its retries. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bacobj.h"
#include "bacserve.h"
#include "points.h"
#include "bactag.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int apply(void *user, size_t z)
{
	(void)user;
	return z == 2 ? -1 : 0;   /* the third zone refuses, as the engine may */
}

static int apply_value(void *user, size_t z, size_t point)
{
	(void)user, (void)point;
	return z == 2 ? -1 : 0;
}

/* Every COV notification due: a BVLL Original-Unicast-NPDU of its own
 * length to a subscriber's address, an unconfirmed or confirmed COV
 * notification whose tags read back; at most one per subscription a call. */
static void notifications(struct psd_bacserve_model *m)
{
	static uint8_t out[PSD_BACSERVE_MAX_PACKET];
	struct psd_bacserve_reply r;
	int k = 0;
	while (psd_bacserve_cov(m, out, &r)) {
		size_t pos = 6;
		struct psd_bactag t;
		if (++k > PSD_BACSERVE_SUBS || r.to != PSD_BACSERVE_TO_ADDRESS || r.len < 8 ||
		    ((size_t)out[2] << 8 | out[3]) != r.len || out[1] != 0x0a || out[4] != 1)
			abort();
		if (out[5] & 0x20)
			pos += 3 + out[8] + 1;
		if (out[pos] == 0x10 && out[pos + 1] == 0x02)
			pos += 2;
		else if (out[pos] == 0x00 && out[pos + 3] == 0x01)
			pos += 4;
		else
			abort();
		while (pos < r.len)
			if (psd_bactag_read(out, r.len, &pos, &t) != 0)
				abort();
	}
}

/* Every segment due at the model's time: a BVLL Original-Unicast-NPDU of
 * its own length holding a ComplexACK segment within max_apdu octets. */
static size_t segments(struct psd_bacserve_model *m, size_t max_apdu)
{
	static uint8_t out[4 + PSD_BACSEG_NPDU + 1476];
	uint8_t to[6];
	size_t len, k = 0;
	while ((len = psd_bacseg_next(&m->seg, m->now, out, to))) {
		size_t pos = 6;
		if (++k > PSD_BACSEG_MAX_TX * PSD_BACSEG_WINDOW || len < 11 || ((size_t)out[2] << 8 | out[3]) != len ||
		    out[0] != 0x81 || out[1] != 0x0a || out[4] != 1)
			abort();
		if (out[5] & 0x20)
			pos += 3 + out[8] + 1;
		if (pos + 5 > len || (out[pos] & 0xfb) != 0x38 || len - pos > max_apdu)
			abort();
	}
	return k;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	static struct psd_bacserve_zone zone[3];
	static uint8_t out[PSD_BACSERVE_MAX_PACKET];
	static struct psd_bacserve_model m;
	psd_bacseg_free(&m.seg);
	m = (struct psd_bacserve_model){ .device = 260001, .name = "fuzz", .vendor_id = 65535, .writes = 15,
		                             .database_revision = 1, .nzone = 3, .zone = zone, .apply = apply,
		                             .apply_value = apply_value };
	struct psd_bacserve_reply r;
	int broadcast;
	if (size < 1)
		return 0;
	broadcast = data[0] & 1;
	for (int i = 0; i < 3; i++) {
		snprintf(zone[i].name, sizeof zone[i].name, "zone%d", i);
		zone[i].level = 25.0 * i;
		/* every point but zone 2's last ones, values on each side of an
		 * increment, a missing one in zone 1 */
		for (size_t k = 0; k < PSD_BACSERVE_POINTS; k++) {
			zone[i].has[k] = k < psd_points_count() && !(i == 2 && k + 3 >= psd_points_count());
			zone[i].pv[k] = i == 1 && k == 0 ? NAN : 1.0 + (double)k;
		}
		zone[i].fault = i == 1;
		if (data[0] & 2)
			for (int k = 0; k < PSD_BACSERVE_PRIORITIES; k++) {
				zone[i].prio[k] = NAN;
				for (int v = 0; v < PSD_BACSERVE_VALUES; v++)
					zone[i].vprio[v][k] = NAN;
			}
	}
	static const uint8_t src[6] = { 127, 0, 0, 1, 0xba, 0xc1 };
	m.now = 100;
	if (data[0] & 4) { /* (device, 260001) Object_List, SA, max-APDU 50, invoke 0x21 */
		static const uint8_t rp[] = { 0x81, 0x0a, 0x00, 0x11, 0x01, 0x04, 0x02, 0x00,
			                      0x21, 0x0c, 0x0c, 0x02, 0x03, 0xf7, 0xa1, 0x19, 0x4c };
		struct psd_bacserve_reply r0;
		psd_bacserve_handle(&m, rp, sizeof rp, src, 0, out, &r0);
		if (r0.len != 0 || segments(&m, 50) != 1)
			abort();
	}
	psd_bacserve_handle(&m, data + 1, size - 1, src, broadcast, out, &r);
	{ /* the segments due now, then at each timeout until none is left */
		size_t total = segments(&m, PSD_BACSERVE_MAX_APDU);
		for (int k = 0; k <= PSD_BACSEG_RETRIES + 1; k++) {
			m.now += PSD_BACSEG_TIMEOUT_MS / 1000.0;
			total += segments(&m, PSD_BACSERVE_MAX_APDU);
		}
		if (total > (size_t)PSD_BACSEG_MAX_TX * PSD_BACSEG_WINDOW * (PSD_BACSEG_RETRIES + 1) ||
		    psd_bacseg_due(&m.seg, m.now) >= 0)
			abort();
		m.now = 100;
	}
	/* a subscription's first notification; then the levels move and a
	 * lifetime of up to 50 s ends */
	notifications(&m);
	for (int i = 0; i < 3; i++)
		zone[i].level = 100 - zone[i].level;
	m.now = 150;
	notifications(&m);
	if (r.to == PSD_BACSERVE_NONE) {
		if (r.len != 0)
			abort();
		return 0;
	}
	if (r.len < 6 || r.len > PSD_BACSERVE_MAX_PACKET || out[0] != 0x81 || ((size_t)out[2] << 8 | out[3]) != r.len)
		abort();
	for (int i = 0; i < 3; i++)
		for (size_t p = 0; p < psd_points_count(); p++) {
			int slot = psd_bacobj_value_slot(p);
			for (int k = 0; slot >= 0 && k < PSD_BACSERVE_PRIORITIES; k++) {
				double v = zone[i].vprio[slot][k];
				if (!isnan(v) && !(v >= psd_points_def(p)->min && v <= psd_points_def(p)->max))
					abort();
			}
		}
	for (int i = 0; i < 3; i++)
		for (int k = 0; k < PSD_BACSERVE_PRIORITIES; k++)
			if (!isnan(zone[i].prio[k]) && !(zone[i].prio[k] >= 0 && zone[i].prio[k] <= 100))
				abort();
	if (out[1] == 0x0a) {   /* an NPDU reply: version 1, then the APDU */
		size_t pos = 6;
		if (out[4] != 1)
			abort();
		if (out[5] & 0x20)
			pos += 3 + out[8] + 1;
		if (pos > r.len || r.len - pos > PSD_BACSERVE_MAX_APDU || pos + 2 > r.len)
			abort();
		if (broadcast && !(out[pos] == 0x10 && (out[pos + 1] == 0x00 || out[pos + 1] == 0x01)))
			abort();
		/* the tags after the header of a complex ACK or an I-Am read back */
		if (out[pos] == 0x30 || out[pos] == 0x10) {
			size_t p = out[pos] == 0x30 ? 3 : 2;
			struct psd_bactag t;
			while (pos + p < r.len)
				if (psd_bactag_read(out + pos, r.len - pos, &p, &t) != 0)
					abort();
		}
	}
	psd_bacseg_free(&m.seg);
	return 0;
}
