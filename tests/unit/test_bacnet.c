/* SPDX-License-Identifier: ISC */
/* BACnet/IP framing and services (daemon/bacnet/bactag.c, bacserve.c)
 * against byte strings assembled by hand from ANSI/ASHRAE 135's encoding
 * rules: the tag octet of 20.2.1 (tag number, class, length/value/type;
 * extended numbers and lengths; opening 6, closing 7), the primitive
 * encodings of 20.2.2-20.2.14, the BVLL of Annex J (type 0x81, function,
 * length), the NPDU of 6.2 (version 1, control) and the APDU headers of
 * 20.1; the numbers of clause 21 (object types, properties, error classes
 * and codes, reject and abort reasons). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "bacobj.h"
#include "bacserve.h"
#include "bactag.h"
#include "bacconf.h"
#include "points.h"

static size_t enc(void (*f)(struct psd_bacbuf *), uint8_t *out, size_t cap)
{
	struct psd_bacbuf b = { out, cap, 0, 0 };
	f(&b);
	assert_false(b.overflow);
	return b.len;
}

#define EXPECT(f, ...)                                                     \
	do {                                                               \
		static const uint8_t want[] = { __VA_ARGS__ };             \
		uint8_t got[64];                                           \
		size_t n = enc(f, got, sizeof got);                        \
		assert_int_equal(n, sizeof want);                          \
		assert_memory_equal(got, want, sizeof want);               \
	} while (0)

static void u72(struct psd_bacbuf *b) { psd_bactag_put_unsigned(b, -1, 72); }
static void u256ctx1(struct psd_bacbuf *b) { psd_bactag_put_unsigned(b, 1, 256); }
static void real72(struct psd_bacbuf *b) { psd_bactag_put_real(b, -1, 72.0f); }
static void bools(struct psd_bacbuf *b) { psd_bactag_put_bool(b, -1, 1); psd_bactag_put_bool(b, -1, 0); psd_bactag_put_bool(b, 2, 1); }
static void null_and_enum(struct psd_bacbuf *b) { psd_bactag_put_null(b, -1); psd_bactag_put_enum(b, -1, 0); }
static void objid_bi15(struct psd_bacbuf *b) { psd_bactag_put_objectid(b, -1, 3, 15); }
static void bits10101(struct psd_bacbuf *b) { static const uint8_t v[] = { 0xa8 }; psd_bactag_put_bits(b, -1, v, 5); }
static void open_close3(struct psd_bacbuf *b) { psd_bactag_open(b, 3); psd_bactag_close(b, 3); }
static void ext_number(struct psd_bacbuf *b) { psd_bactag_put_unsigned(b, 18, 1); psd_bactag_open(b, 20); }
static void ext_len(struct psd_bacbuf *b) { psd_bactag_put_tag(b, 6, 0, 5); psd_bactag_put_tag(b, 6, 0, 300); }
static void string_bacnet(struct psd_bacbuf *b) { psd_bactag_put_string(b, -1, "This is a BACnet string!"); }

static void encodings_follow_clause_20_2(void **state)
{
	(void)state;
	/* unsigned 72: application tag 2, one octet */
	EXPECT(u72, 0x21, 0x48);
	/* context tag 1, unsigned 256: two octets */
	EXPECT(u256ctx1, 0x1a, 0x01, 0x00);
	/* REAL 72.0 = IEEE 754 0x42900000 */
	EXPECT(real72, 0x44, 0x42, 0x90, 0x00, 0x00);
	/* application booleans carry the value in the tag; a context one in an octet */
	EXPECT(bools, 0x11, 0x10, 0x29, 0x01);
	EXPECT(null_and_enum, 0x00, 0x91, 0x00);
	/* (binary-input, 15): type 3 in the top 10 bits */
	EXPECT(objid_bi15, 0xc4, 0x00, 0xc0, 0x00, 0x0f);
	/* B'10101': 3 unused bits */
	EXPECT(bits10101, 0x82, 0x03, 0xa8);
	EXPECT(open_close3, 0x3e, 0x3f);
	/* tag number 18 and 20: 15 in the tag octet, the number next */
	EXPECT(ext_number, 0xf9, 0x12, 0x01, 0xfe, 0x14);
	/* length 5: LVT 5 then the length; 300: 254 then two octets */
	EXPECT(ext_len, 0x65, 0x05, 0x65, 0xfe, 0x01, 0x2c);
	/* character set 0 (UTF-8) first: 24 characters + 1 */
	EXPECT(string_bacnet, 0x75, 0x19, 0x00, 'T', 'h', 'i', 's', ' ', 'i', 's', ' ', 'a', ' ', 'B', 'A', 'C', 'n', 'e',
	       't', ' ', 's', 't', 'r', 'i', 'n', 'g', '!');
}

static void decoding_reads_tags_and_stops_at_the_end(void **state)
{
	static const uint8_t s[] = { 0x31, 0xb8, 0x3a, 0xff, 0x38, 0xf9, 0x12, 0x07, 0x65, 0xfe, 0x00, 0x05, 1, 2, 3, 4, 5 };
	static const uint8_t bad[][4] = { { 0x65, 0x05, 1 }, { 0xf9 }, { 0x16 }, { 0x12 } };
	static const size_t badn[] = { 3, 1, 1, 1 };
	struct psd_bactag t;
	size_t pos = 0;
	int32_t v;
	uint32_t u;
	(void)state;
	/* signed -72 (0xB8), then context tag 3 with two octets 0xFF38 (-200) */
	assert_int_equal(psd_bactag_read(s, sizeof s, &pos, &t), 0);
	assert_int_equal(psd_bactag_signed(&t, &v), 0);
	assert_int_equal(v, -72);
	assert_int_equal(psd_bactag_read(s, sizeof s, &pos, &t), 0);
	assert_true(t.context);
	assert_int_equal(t.number, 3);
	assert_int_equal(psd_bactag_signed(&t, &v), 0);
	assert_int_equal(v, -200);
	assert_int_equal(psd_bactag_read(s, sizeof s, &pos, &t), 0);
	assert_int_equal(t.number, 18);
	assert_int_equal(psd_bactag_unsigned(&t, &u), 0);
	assert_int_equal(u, 7);
	/* octet string of 5 with the length in two octets after 254 */
	assert_int_equal(psd_bactag_read(s, sizeof s, &pos, &t), 0);
	assert_int_equal(t.len, 5);
	assert_int_equal(t.data[4], 5);
	assert_int_equal(pos, sizeof s);
	assert_int_equal(psd_bactag_read(s, sizeof s, &pos, &t), -1);
	/* a length past the end, an extended number missing, an application
	 * opening tag, an application boolean with LVT 2 */
	for (size_t i = 0; i < 4; i++) {
		pos = 0;
		assert_int_equal(psd_bactag_read(bad[i], badn[i], &pos, &t), -1);
	}
}

/* ---- the server over a two-zone model --------------------------------- */

static struct psd_bacserve_zone zones[6];
static const uint8_t peer[6] = { 10, 0, 0, 7, 0xba, 0xc0 };   /* 10.0.0.7:47808 */
static struct psd_bacserve_model model;
static int applied;

static int apply(void *user, size_t z)
{
	(void)user;
	applied = (int)z + 1;
	return 0;
}

static int setup(void **state)
{
	(void)state;
	memset(zones, 0, sizeof zones);
	for (size_t i = 0; i < 6; i++) {
		snprintf(zones[i].name, sizeof zones[i].name, "z%zu", i);
		for (int k = 0; k < PSD_BACSERVE_PRIORITIES; k++) {
			zones[i].prio[k] = NAN;
			for (int v = 0; v < PSD_BACSERVE_VALUES; v++)
				zones[i].vprio[v][k] = NAN;
		}
		zones[i].level = 10;
	}
	/* every zone has every point of the point model (points.h) */
	for (size_t i = 0; i < 6; i++)
		for (size_t k = 0; k < psd_points_count(); k++)
			zones[i].has[k] = 1;
	zones[1].pv[psd_points_find("sensor_v")] = 72.0;
	model = (struct psd_bacserve_model){ .device = 10, .name = "psensd", .vendor_id = 65535, .writes = 1,
		                             .database_revision = 1, .nzone = 6, .zone = zones, .apply = apply };
	applied = 0;
	return 0;
}

/* send BVLL+NPDU+APDU; the reply's APDU (after 81 0A len 01 00) into *a */
static size_t ask(const uint8_t *apdu, size_t n, uint8_t fn, uint8_t *out, const uint8_t **a)
{
	uint8_t in[PSD_BACSERVE_MAX_PACKET];
	struct psd_bacserve_reply r;
	in[0] = 0x81, in[1] = fn, in[2] = (uint8_t)((n + 6) >> 8), in[3] = (uint8_t)(n + 6), in[4] = 1, in[5] = 0x04;
	memcpy(in + 6, apdu, n);
	psd_bacserve_handle(&model, in, n + 6, peer, 0, out, &r);
	if (r.to == PSD_BACSERVE_NONE)
		return 0;
	assert_int_equal(r.to, PSD_BACSERVE_TO_SENDER);
	assert_true(r.len >= 6);
	assert_int_equal(out[0], 0x81);
	assert_int_equal(out[1], 0x0a);
	assert_int_equal((size_t)out[2] << 8 | out[3], r.len);
	assert_int_equal(out[4], 1);
	assert_int_equal(out[5], 0);
	*a = out + 6;
	return r.len - 6;
}

#define ASK(fn, want_len, ...)                                                  \
	do {                                                                    \
		static const uint8_t want[] = { __VA_ARGS__ };                  \
		size_t n = ask(req, sizeof req, fn, out, &a);                   \
		assert_int_equal(n, want_len);                                  \
		if (want_len)                                                   \
			assert_memory_equal(a, want, sizeof want);              \
	} while (0)

static void who_is_with_a_range(void **state)
{
	uint8_t out[PSD_BACSERVE_MAX_PACKET];
	const uint8_t *a;
	(void)state;
	{
		/* Who-Is 10..10, broadcast: I-Am (device,10), 1476, segmented-transmit (1), vendor 65535 */
		static const uint8_t req[] = { 0x10, 0x08, 0x09, 0x0a, 0x19, 0x0a };
		ASK(0x0b, 15, 0x10, 0x00, 0xc4, 0x02, 0x00, 0x00, 0x0a, 0x22, 0x05, 0xc4, 0x91, 0x01, 0x22, 0xff, 0xff);
	}
	{
		static const uint8_t req[] = { 0x10, 0x08, 0x09, 0x0b, 0x1a, 0x01, 0x00 };   /* 11..256 */
		ASK(0x0b, 0, 0);
	}
	{
		static const uint8_t req[] = { 0x10, 0x08 };   /* no range */
		ASK(0x0b, 15, 0x10, 0x00);
	}
	{
		static const uint8_t req[] = { 0x10, 0x08, 0x09, 0x00 };   /* a low limit alone: malformed, silence */
		ASK(0x0b, 0, 0);
	}
}

static void who_has_by_identifier_and_by_name(void **state)
{
	uint8_t out[PSD_BACSERVE_MAX_PACKET];
	const uint8_t *a;
	(void)state;
	{
		/* Who-Has (7) [2] (analog-input, 102: zone 1's second analog
		 * point): I-Have (1), (device, 10), (analog-input, 102),
		 * "z1 sensor signal" (16 characters + set 0) */
		static const uint8_t req[] = { 0x10, 0x07, 0x2c, 0x00, 0x00, 0x00, 0x66 };
		ASK(0x0b, 31, 0x10, 0x01, 0xc4, 0x02, 0x00, 0x00, 0x0a, 0xc4, 0x00, 0x00, 0x00, 0x66, 0x75, 0x11, 0x00,
		    'z', '1', ' ', 's', 'e', 'n', 's', 'o', 'r', ' ', 's', 'i', 'g', 'n', 'a', 'l');
	}
	{
		/* by name, in a range 5..15: [0] 5 [1] 15 [3] "z2 light level" */
		static const uint8_t req[] = { 0x10, 0x07, 0x09, 0x05, 0x19, 0x0f, 0x3d, 0x0f, 0x00, 'z', '2', ' ',
			                       'l', 'i', 'g', 'h', 't', ' ', 'l', 'e', 'v', 'e', 'l' };
		/* (lighting-output, 3) */
		ASK(0x0b, 29, 0x10, 0x01, 0xc4, 0x02, 0x00, 0x00, 0x0a, 0xc4, 0x0d, 0x80, 0x00, 0x03);
	}
	{
		/* a range without this device, an object psensd lacks, a name
		 * psensd lacks: silence */
		static const uint8_t r1[] = { 0x10, 0x07, 0x09, 0x0b, 0x19, 0x0f, 0x2c, 0x00, 0x00, 0x00, 0x05 };
		static const uint8_t r2[] = { 0x10, 0x07, 0x2c, 0x00, 0x80, 0x00, 0x63 };
		static const uint8_t r3[] = { 0x10, 0x07, 0x3d, 0x03, 0x00, 'z', '9' };
		assert_int_equal(ask(r1, sizeof r1, 0x0b, out, &a), 0);
		assert_int_equal(ask(r2, sizeof r2, 0x0b, out, &a), 0);
		assert_int_equal(ask(r3, sizeof r3, 0x0b, out, &a), 0);
	}
}

static void read_property_and_its_errors(void **state)
{
	uint8_t out[PSD_BACSERVE_MAX_PACKET];
	const uint8_t *a;
	(void)state;
	{
		/* confirmed, max APDU 1476 (5), invoke 1, readProperty (12):
		 * [0] (analog-input, 102) [1] present-value (85) */
		static const uint8_t req[] = { 0x00, 0x05, 0x01, 0x0c, 0x0c, 0x00, 0x00, 0x00, 0x66, 0x19, 0x55 };
		/* ComplexACK, the same object and property, [3] REAL 72.0 [3] */
		ASK(0x0a, 17, 0x30, 0x01, 0x0c, 0x0c, 0x00, 0x00, 0x00, 0x66, 0x19, 0x55, 0x3e, 0x44, 0x42, 0x90, 0x00,
		    0x00, 0x3f);
	}
	{
		/* Device 10 Object_Name: "psensd" */
		static const uint8_t req[] = { 0x00, 0x05, 0x02, 0x0c, 0x0c, 0x02, 0x00, 0x00, 0x0a, 0x19, 0x4d };
		ASK(0x0a, 21, 0x30, 0x02, 0x0c, 0x0c, 0x02, 0x00, 0x00, 0x0a, 0x19, 0x4d, 0x3e, 0x75, 0x07, 0x00, 'p',
		    's', 'e', 'n', 's', 'd', 0x3f);
	}
	{
		/* (analog-input, 99): Error, class object (1), unknown-object (31) */
		static const uint8_t req[] = { 0x00, 0x05, 0x03, 0x0c, 0x0c, 0x00, 0x00, 0x00, 0x63, 0x19, 0x55 };
		ASK(0x0a, 7, 0x50, 0x03, 0x0c, 0x91, 0x01, 0x91, 0x1f);
	}
	{
		/* Device 10 property 9999: class property (2), unknown-property (32) */
		static const uint8_t req[] = { 0x00, 0x05, 0x04, 0x0c, 0x0c, 0x02, 0x00, 0x00, 0x0a, 0x1a, 0x27, 0x0f };
		ASK(0x0a, 7, 0x50, 0x04, 0x0c, 0x91, 0x02, 0x91, 0x20);
	}
	{
		/* Object_Name [2] 1: property-is-not-an-array (50) */
		static const uint8_t req[] = { 0x00, 0x05, 0x05, 0x0c, 0x0c, 0x02, 0x00, 0x00, 0x0a, 0x19, 0x4d, 0x29, 0x01 };
		ASK(0x0a, 7, 0x50, 0x05, 0x0c, 0x91, 0x02, 0x91, 0x32);
	}
	{
		/* Object_List [2] 0: the count, the Device and per zone one object
		 * per point (the level's is the Lighting Output): 1 + 6 n */
		static const uint8_t req[] = { 0x00, 0x05, 0x06, 0x0c, 0x0c, 0x02, 0x00, 0x00, 0x0a, 0x19, 0x4c, 0x29, 0x00 };
		static const uint8_t want[] = { 0x30, 0x06, 0x0c, 0x0c, 0x02, 0x00, 0x00, 0x0a, 0x19, 0x4c, 0x29, 0x00, 0x3e, 0x21 };
		size_t n = ask(req, sizeof req, 0x0a, out, &a);
		assert_true(1 + 6 * psd_points_count() < 256);
		assert_int_equal(n, 16);
		assert_memory_equal(a, want, sizeof want);
		assert_int_equal(a[14], 1 + 6 * psd_points_count());
		assert_int_equal(a[15], 0x3f);
	}
	{
		/* Object_List [2] 1 + 6 n + 1: invalid-array-index (42) */
		uint8_t req[] = { 0x00, 0x05, 0x07, 0x0c, 0x0c, 0x02, 0x00, 0x00, 0x0a, 0x19, 0x4c, 0x29, 0x00 };
		req[12] = (uint8_t)(2 + 6 * psd_points_count());
		ASK(0x0a, 7, 0x50, 0x07, 0x0c, 0x91, 0x02, 0x91, 0x2a);
	}
	{
		/* the property identifier missing: Reject missing-required-parameter (5) */
		static const uint8_t req[] = { 0x00, 0x05, 0x08, 0x0c, 0x0c, 0x02, 0x00, 0x00, 0x0a };
		ASK(0x0a, 3, 0x60, 0x08, 0x05);
	}
	{
		/* an application tag where [0] belongs: Reject invalid-tag (4) */
		static const uint8_t req[] = { 0x00, 0x05, 0x09, 0x0c, 0xc4, 0x02, 0x00, 0x00, 0x0a, 0x19, 0x4d };
		ASK(0x0a, 3, 0x60, 0x09, 0x04);
	}
	{
		/* a trailing tag: Reject too-many-arguments (7) */
		static const uint8_t req[] = { 0x00, 0x05, 0x0a, 0x0c, 0x0c, 0x02, 0x00, 0x00, 0x0a, 0x19, 0x4d, 0x39, 0x01 };
		ASK(0x0a, 3, 0x60, 0x0a, 0x07);
	}
	{
		/* atomicReadFile (6), not supported: Reject unrecognized-service (9) */
		static const uint8_t req[] = { 0x00, 0x05, 0x0b, 0x06, 0x09, 0x01 };
		ASK(0x0a, 3, 0x60, 0x0b, 0x09);
	}
	{
		/* a segmented request (SEG bit 0x08, sequence 0, window 1): Abort
		 * from the server (0x71), segmentation-not-supported (4) */
		static const uint8_t req[] = { 0x0c, 0x05, 0x0c, 0x00, 0x01, 0x0c, 0x0c, 0x02, 0x00, 0x00, 0x0a };
		ASK(0x0a, 3, 0x71, 0x0c, 0x04);
	}
	{
		/* a confirmed request sent to everyone: no answer */
		static const uint8_t req[] = { 0x00, 0x05, 0x0d, 0x0c, 0x0c, 0x02, 0x00, 0x00, 0x0a, 0x19, 0x4d };
		ASK(0x0b, 0, 0);
	}
}

static void read_property_multiple(void **state)
{
	uint8_t out[PSD_BACSERVE_MAX_PACKET];
	const uint8_t *a;
	(void)state;
	{
		/* (analog-input, 501: zone 5's first analog point): [1](
		 * present-value, reliability ): the value and
		 * [5] property unknown-property (reliability 103 is not served) */
		static const uint8_t req[] = { 0x00, 0x05, 0x01, 0x0e, 0x0c, 0x00, 0x00, 0x01, 0xf5,
			                       0x1e, 0x09, 0x55, 0x09, 0x67, 0x1f };
		zones[5].pv[psd_points_find("est_task_lux")] = 72.0;
		ASK(0x0a, 27, 0x30, 0x01, 0x0e, 0x0c, 0x00, 0x00, 0x01, 0xf5, 0x1e, 0x29, 0x55, 0x4e, 0x44, 0x42, 0x90,
		    0x00, 0x00, 0x4f, 0x29, 0x67, 0x5e, 0x91, 0x02, 0x91, 0x20, 0x5f, 0x1f);
	}
	{
		/* (analog-value, 99: past zone 0's Values) present-value: [5] object unknown-object */
		static const uint8_t req[] = { 0x00, 0x05, 0x02, 0x0e, 0x0c, 0x00, 0x80, 0x00, 0x63, 0x1e, 0x09, 0x55, 0x1f };
		ASK(0x0a, 18, 0x30, 0x02, 0x0e, 0x0c, 0x00, 0x80, 0x00, 0x63, 0x1e, 0x29, 0x55, 0x5e, 0x91, 0x01, 0x91,
		    0x1f, 0x5f, 0x1f);
	}
	{
		/* ALL on the Device with max APDU 50 (code 0) and no segmented
		 * answer accepted (SA clear): the answer would be longer: Abort
		 * segmentation-not-supported */
		static const uint8_t req[] = { 0x00, 0x00, 0x03, 0x0e, 0x0c, 0x02, 0x00, 0x00, 0x0a, 0x1e, 0x09, 0x08, 0x1f };
		ASK(0x0a, 3, 0x71, 0x03, 0x04);
	}
	{
		/* an empty list of properties: Reject missing-required-parameter */
		static const uint8_t req[] = { 0x00, 0x05, 0x04, 0x0e, 0x0c, 0x02, 0x00, 0x00, 0x0a, 0x1e, 0x1f };
		ASK(0x0a, 3, 0x60, 0x04, 0x05);
	}
}

/* REQUIRED returns the required ones only: (analog-input, 1) has 10 */
static void rpm_required_and_optional(void **state)
{
	uint8_t out[PSD_BACSERVE_MAX_PACKET];
	const uint8_t *a;
	struct psd_bactag t;
	(void)state;
	for (int which = 0; which < 2; which++) {
		uint8_t req[] = { 0x00, 0x05, 0x01, 0x0e, 0x0c, 0x00, 0x00, 0x00, 0x01, 0x1e, 0x09, which ? 0x50 : 0x69, 0x1f };
		size_t n = ask(req, sizeof req, 0x0a, out, &a), pos = 3, props = 0;
		int depth = 0;
		assert_true(n > 3);
		while (pos < n) {
			assert_int_equal(psd_bactag_read(a, n, &pos, &t), 0);
			if (t.opening)
				depth++;
			else if (t.closing)
				depth--;
			else if (depth == 1 && t.context && t.number == 2)
				props++;
		}
		/* required: object-identifier, -name, -type, present-value, status-flags,
		 * event-state, out-of-service, units, property-list, and cov-increment
		 * (an object that reports COV); optional: description */
		assert_int_equal(props, which ? 1 : 10);
	}
}

/* The point model's other kinds: (binary-input, 1), zone z0's first
 * binary point (fault), Present_Value an enumerated active (1);
 * (multi-state-input, 1), its first multi-state point (the control state),
 * an Unsigned 1..n, Number_Of_States (74) and State_Text (110) from the
 * table. */
static void binary_and_multistate_inputs(void **state)
{
	uint8_t out[PSD_BACSERVE_MAX_PACKET];
	const uint8_t *a;
	(void)state;
	zones[0].pv[psd_points_find("fault")] = 1;
	zones[0].pv[psd_points_find("state")] = 3;
	{
		static const uint8_t req[] = { 0x00, 0x05, 0x40, 0x0c, 0x0c, 0x00, 0xc0, 0x00, 0x01, 0x19, 0x55 };
		ASK(0x0a, 14, 0x30, 0x40, 0x0c, 0x0c, 0x00, 0xc0, 0x00, 0x01, 0x19, 0x55, 0x3e, 0x91, 0x01, 0x3f);
	}
	{
		static const uint8_t req[] = { 0x00, 0x05, 0x41, 0x0c, 0x0c, 0x03, 0x40, 0x00, 0x01, 0x19, 0x55 };
		ASK(0x0a, 14, 0x30, 0x41, 0x0c, 0x0c, 0x03, 0x40, 0x00, 0x01, 0x19, 0x55, 0x3e, 0x21, 0x03, 0x3f);
	}
	{
		static const uint8_t req[] = { 0x00, 0x05, 0x42, 0x0c, 0x0c, 0x03, 0x40, 0x00, 0x01, 0x19, 0x4a };
		/* auto, override, calibrating, fault, safe */
		ASK(0x0a, 14, 0x30, 0x42, 0x0c, 0x0c, 0x03, 0x40, 0x00, 0x01, 0x19, 0x4a, 0x3e, 0x21, 0x05, 0x3f);
	}
	{
		/* State_Text[3]: "calibrating" (11 characters + set 0) */
		static const uint8_t req[] = { 0x00, 0x05, 0x43, 0x0c, 0x0c, 0x03, 0x40, 0x00, 0x01, 0x19, 0x6e, 0x29, 0x03 };
		ASK(0x0a, 28, 0x30, 0x43, 0x0c, 0x0c, 0x03, 0x40, 0x00, 0x01, 0x19, 0x6e, 0x29, 0x03, 0x3e, 0x75, 0x0c,
		    0x00, 'c', 'a', 'l', 'i', 'b', 'r', 'a', 't', 'i', 'n', 'g', 0x3f);
	}
	{
		/* a Binary Input's Present_Value is not writable: write-access-denied (40) */
		static const uint8_t req[] = { 0x00, 0x05, 0x44, 0x0f, 0x0c, 0x00, 0xc0, 0x00, 0x01, 0x19, 0x55,
			                       0x3e, 0x91, 0x00, 0x3f };
		ASK(0x0a, 7, 0x50, 0x44, 0x0f, 0x91, 0x02, 0x91, 0x28);
	}
}

/* Lighting_Command (380 = 0x017c, BACnetLightingCommand 12.54.8) on
 * (lighting-output, 1): [0] operation, [1] target level, [3] step
 * increment, [5] priority; In_Progress (378 = 0x017a) while the lamps
 * (the point model's actual level) have not reached a fade's level. */
static void lighting_command(void **state)
{
	uint8_t out[PSD_BACSERVE_MAX_PACKET];
	const uint8_t *a;
	size_t actual = (size_t)psd_points_find("level_actual");
	(void)state;
	zones[0].pv[actual] = 10.0;
	{
		/* fade-to (1) 42.0 (0x42280000) at priority 8: SimpleACK, priority 8 holds 42 */
		static const uint8_t req[] = { 0x00, 0x05, 0x20, 0x0f, 0x0c, 0x0d, 0x80, 0x00, 0x01, 0x1a, 0x01, 0x7c,
			                       0x3e, 0x09, 0x01, 0x1c, 0x42, 0x28, 0x00, 0x00, 0x59, 0x08, 0x3f };
		applied = 0;
		ASK(0x0a, 3, 0x20, 0x20, 0x0f);
		assert_true(zones[0].prio[7] == 42.0);
		assert_int_equal(applied, 1);
	}
	{
		/* read back: the same command */
		static const uint8_t req[] = { 0x00, 0x05, 0x21, 0x0c, 0x0c, 0x0d, 0x80, 0x00, 0x01, 0x1a, 0x01, 0x7c };
		ASK(0x0a, 22, 0x30, 0x21, 0x0c, 0x0c, 0x0d, 0x80, 0x00, 0x01, 0x1a, 0x01, 0x7c, 0x3e, 0x09, 0x01, 0x1c,
		    0x42, 0x28, 0x00, 0x00, 0x59, 0x08, 0x3f);
	}
	{
		/* In_Progress: fade-active (1) with the lamps at 10 %, idle (0) at 42 % */
		static const uint8_t req[] = { 0x00, 0x05, 0x22, 0x0c, 0x0c, 0x0d, 0x80, 0x00, 0x01, 0x1a, 0x01, 0x7a };
		ASK(0x0a, 15, 0x30, 0x22, 0x0c, 0x0c, 0x0d, 0x80, 0x00, 0x01, 0x1a, 0x01, 0x7a, 0x3e, 0x91, 0x01, 0x3f);
		zones[0].pv[actual] = 42.0;
		ASK(0x0a, 15, 0x30, 0x22, 0x0c, 0x0c, 0x0d, 0x80, 0x00, 0x01, 0x1a, 0x01, 0x7a, 0x3e, 0x91, 0x00, 0x3f);
	}
	{
		/* step-up (3) by 5.0 (0x40a00000) from the level in force, 10 %:
		 * 15 % at the default priority, 16 */
		static const uint8_t req[] = { 0x00, 0x05, 0x23, 0x0f, 0x0c, 0x0d, 0x80, 0x00, 0x01, 0x1a, 0x01, 0x7c,
			                       0x3e, 0x09, 0x03, 0x3c, 0x40, 0xa0, 0x00, 0x00, 0x3f };
		ASK(0x0a, 3, 0x20, 0x23, 0x0f);
		assert_true(zones[0].prio[15] == 15.0);
	}
	{
		/* step-off (6), default step 1 %, from 0.5 %: off */
		static const uint8_t req[] = { 0x00, 0x05, 0x24, 0x0f, 0x0c, 0x0d, 0x80, 0x00, 0x02, 0x1a, 0x01, 0x7c,
			                       0x3e, 0x09, 0x06, 0x3f };
		zones[1].level = 0.5;
		ASK(0x0a, 3, 0x20, 0x24, 0x0f);
		assert_true(zones[1].prio[15] == 0.0);
		zones[1].level = 10;
	}
	{
		/* stop (10): the level the lamps have reached, 42 %, at priority 16 */
		static const uint8_t req[] = { 0x00, 0x05, 0x25, 0x0f, 0x0c, 0x0d, 0x80, 0x00, 0x01, 0x1a, 0x01, 0x7c,
			                       0x3e, 0x09, 0x0a, 0x3f };
		ASK(0x0a, 3, 0x20, 0x25, 0x0f);
		assert_true(zones[0].prio[15] == 42.0);
	}
	{
		/* warn (7): optional-functionality-not-supported (45); fade-to
		 * 120.0 (0x42f00000): value-out-of-range (37); no operation:
		 * invalid-data-type (9) */
		static const uint8_t warn[] = { 0x00, 0x05, 0x26, 0x0f, 0x0c, 0x0d, 0x80, 0x00, 0x01, 0x1a, 0x01, 0x7c,
			                        0x3e, 0x09, 0x07, 0x3f };
		static const uint8_t far[] = { 0x00, 0x05, 0x26, 0x0f, 0x0c, 0x0d, 0x80, 0x00, 0x01, 0x1a, 0x01, 0x7c,
			                       0x3e, 0x09, 0x01, 0x1c, 0x42, 0xf0, 0x00, 0x00, 0x3f };
		static const uint8_t noop[] = { 0x00, 0x05, 0x26, 0x0f, 0x0c, 0x0d, 0x80, 0x00, 0x01, 0x1a, 0x01, 0x7c,
			                        0x3e, 0x1c, 0x42, 0x28, 0x00, 0x00, 0x3f };
		static const uint8_t e45[] = { 0x50, 0x26, 0x0f, 0x91, 0x02, 0x91, 0x2d };
		static const uint8_t e37[] = { 0x50, 0x26, 0x0f, 0x91, 0x02, 0x91, 0x25 };
		static const uint8_t e9[] = { 0x50, 0x26, 0x0f, 0x91, 0x02, 0x91, 0x09 };
		assert_int_equal(ask(warn, sizeof warn, 0x0a, out, &a), 7);
		assert_memory_equal(a, e45, 7);
		assert_int_equal(ask(far, sizeof far, 0x0a, out, &a), 7);
		assert_memory_equal(a, e37, 7);
		assert_int_equal(ask(noop, sizeof noop, 0x0a, out, &a), 7);
		assert_memory_equal(a, e9, 7);
	}
	for (int k = 0; k < PSD_BACSERVE_PRIORITIES; k++)
		zones[0].prio[k] = zones[1].prio[k] = NAN;
	zones[0].lc_op = zones[1].lc_op = 0;
}

static void write_property_with_priorities(void **state)
{
	uint8_t out[PSD_BACSERVE_MAX_PACKET];
	const uint8_t *a;
	(void)state;
	{
		/* writeProperty (15) (lighting-output, 1) present-value [3] REAL 50.0 [3] [4] 8: SimpleACK */
		static const uint8_t req[] = { 0x00, 0x05, 0x07, 0x0f, 0x0c, 0x0d, 0x80, 0x00, 0x01, 0x19, 0x55,
			                       0x3e, 0x44, 0x42, 0x48, 0x00, 0x00, 0x3f, 0x49, 0x08 };
		ASK(0x0a, 3, 0x20, 0x07, 0x0f);
		assert_true(zones[0].prio[7] == 50.0);
		assert_int_equal(applied, 1);
	}
	{
		/* the same 50 % at the same priority again: a SimpleACK, and
		 * nothing applied (the array did not change) */
		static const uint8_t req[] = { 0x00, 0x05, 0x17, 0x0f, 0x0c, 0x0d, 0x80, 0x00, 0x01, 0x19, 0x55,
			                       0x3e, 0x44, 0x42, 0x48, 0x00, 0x00, 0x3f, 0x49, 0x08 };
		applied = 0;
		ASK(0x0a, 3, 0x20, 0x17, 0x0f);
		assert_int_equal(applied, 0);
		assert_true(zones[0].prio[7] == 50.0);
	}
	{
		/* NULL at 8: relinquished */
		static const uint8_t req[] = { 0x00, 0x05, 0x08, 0x0f, 0x0c, 0x0d, 0x80, 0x00, 0x01, 0x19, 0x55,
			                       0x3e, 0x00, 0x3f, 0x49, 0x08 };
		ASK(0x0a, 3, 0x20, 0x08, 0x0f);
		assert_true(isnan(zones[0].prio[7]));
	}
	{
		/* 101 %: value-out-of-range (37) */
		static const uint8_t req[] = { 0x00, 0x05, 0x09, 0x0f, 0x0c, 0x0d, 0x80, 0x00, 0x01, 0x19, 0x55,
			                       0x3e, 0x44, 0x42, 0xca, 0x00, 0x00, 0x3f };
		ASK(0x0a, 7, 0x50, 0x09, 0x0f, 0x91, 0x02, 0x91, 0x25);
	}
	{
		/* an unsigned where a REAL belongs: invalid-data-type (9) */
		static const uint8_t req[] = { 0x00, 0x05, 0x0a, 0x0f, 0x0c, 0x0d, 0x80, 0x00, 0x01, 0x19, 0x55,
			                       0x3e, 0x21, 0x32, 0x3f };
		ASK(0x0a, 7, 0x50, 0x0a, 0x0f, 0x91, 0x02, 0x91, 0x09);
	}
	{
		/* priority 6 (minimum on/off's): write-access-denied (40) */
		static const uint8_t req[] = { 0x00, 0x05, 0x0b, 0x0f, 0x0c, 0x0d, 0x80, 0x00, 0x01, 0x19, 0x55,
			                       0x3e, 0x44, 0x42, 0x48, 0x00, 0x00, 0x3f, 0x49, 0x06 };
		ASK(0x0a, 7, 0x50, 0x0b, 0x0f, 0x91, 0x02, 0x91, 0x28);
	}
	{
		/* priority 17: class services (5), parameter-out-of-range (80) */
		static const uint8_t req[] = { 0x00, 0x05, 0x0c, 0x0f, 0x0c, 0x0d, 0x80, 0x00, 0x01, 0x19, 0x55,
			                       0x3e, 0x44, 0x42, 0x48, 0x00, 0x00, 0x3f, 0x49, 0x11 };
		ASK(0x0a, 7, 0x50, 0x0c, 0x0f, 0x91, 0x05, 0x91, 0x50);
	}
	{
		/* Object_Name is not writable: write-access-denied */
		static const uint8_t req[] = { 0x00, 0x05, 0x0d, 0x0f, 0x0c, 0x0d, 0x80, 0x00, 0x01, 0x19, 0x4d,
			                       0x3e, 0x75, 0x02, 0x00, 'x', 0x3f };
		ASK(0x0a, 7, 0x50, 0x0d, 0x0f, 0x91, 0x02, 0x91, 0x28);
	}
	model.writes = 0;
	{
		/* writes off: write-access-denied, nothing applied */
		static const uint8_t req[] = { 0x00, 0x05, 0x0e, 0x0f, 0x0c, 0x0d, 0x80, 0x00, 0x01, 0x19, 0x55,
			                       0x3e, 0x44, 0x42, 0x48, 0x00, 0x00, 0x3f, 0x49, 0x08 };
		applied = 0;
		ASK(0x0a, 7, 0x50, 0x0e, 0x0f, 0x91, 0x02, 0x91, 0x28);
		assert_int_equal(applied, 0);
		assert_true(isnan(zones[0].prio[7]));
	}
}

static void bvll_and_npdu(void **state)
{
	uint8_t out[PSD_BACSERVE_MAX_PACKET];
	struct psd_bacserve_reply r;
	(void)state;
	{
		/* Register-Foreign-Device (0x05), TTL 60: BVLC-Result NAK 0x0030 */
		static const uint8_t in[] = { 0x81, 0x05, 0x00, 0x06, 0x00, 0x3c };
		static const uint8_t want[] = { 0x81, 0x00, 0x00, 0x06, 0x00, 0x30 };
		psd_bacserve_handle(&model, in, sizeof in, peer, 0, out, &r);
		assert_int_equal(r.len, 6);
		assert_memory_equal(out, want, 6);
	}
	{
		/* Read-Broadcast-Distribution-Table (0x02): NAK 0x0020 */
		static const uint8_t in[] = { 0x81, 0x02, 0x00, 0x04 };
		psd_bacserve_handle(&model, in, sizeof in, peer, 0, out, &r);
		assert_int_equal(r.len, 6);
		assert_int_equal(out[5], 0x20);
	}
	{
		/* a BVLC-Result to psensd, a wrong length, a wrong type: silence */
		static const uint8_t res[] = { 0x81, 0x00, 0x00, 0x06, 0x00, 0x00 };
		static const uint8_t len[] = { 0x81, 0x0a, 0x00, 0x09, 0x01, 0x00, 0x10, 0x08 };
		static const uint8_t typ[] = { 0x82, 0x0a, 0x00, 0x08, 0x01, 0x00, 0x10, 0x08 };
		psd_bacserve_handle(&model, res, sizeof res, peer, 0, out, &r);
		assert_int_equal(r.len, 0);
		psd_bacserve_handle(&model, len, sizeof len, peer, 0, out, &r);
		assert_int_equal(r.len, 0);
		psd_bacserve_handle(&model, typ, sizeof typ, peer, 0, out, &r);
		assert_int_equal(r.len, 0);
	}
	{
		/* a network-layer message (control 0x80, Who-Is-Router-To-Network): ignored */
		static const uint8_t in[] = { 0x81, 0x0b, 0x00, 0x07, 0x01, 0x80, 0x00 };
		psd_bacserve_handle(&model, in, sizeof in, peer, 0, out, &r);
		assert_int_equal(r.len, 0);
	}
	{
		/* for network 5 (DNET 5, DLEN 0, hop 255): psensd routes nothing */
		static const uint8_t in[] = { 0x81, 0x0a, 0x00, 0x0c, 0x01, 0x20, 0x00, 0x05, 0x00, 0xff, 0x10, 0x08 };
		psd_bacserve_handle(&model, in, sizeof in, peer, 0, out, &r);
		assert_int_equal(r.len, 0);
	}
	{
		/* a global broadcast Who-Is (DNET 0xFFFF) from network 7, MAC 0x21
		 * (SNET 7, SLEN 1): the I-Am goes back to DNET 7, DADR 0x21, hop 255 */
		static const uint8_t in[] = { 0x81, 0x0b, 0x00, 0x10, 0x01, 0x28, 0xff, 0xff, 0x00,
			                      0x00, 0x07, 0x01, 0x21, 0xff, 0x10, 0x08 };
		static const uint8_t want[] = { 0x81, 0x0a, 0x00, 0x1a, 0x01, 0x20, 0x00, 0x07, 0x01, 0x21, 0xff, 0x10, 0x00 };
		psd_bacserve_handle(&model, in, sizeof in, peer, 0, out, &r);
		assert_int_equal(r.len, 0x1a);
		assert_memory_equal(out, want, sizeof want);
	}
	{
		/* Forwarded-NPDU from 192.168.1.9:47808: the I-Am to that address */
		static const uint8_t in[] = { 0x81, 0x04, 0x00, 0x0e, 192, 168, 1, 9, 0xba, 0xc0, 0x01, 0x00, 0x10, 0x08 };
		static const uint8_t addr[] = { 192, 168, 1, 9, 0xba, 0xc0 };
		psd_bacserve_handle(&model, in, sizeof in, peer, 0, out, &r);
		assert_int_equal(r.to, PSD_BACSERVE_TO_ADDRESS);
		assert_memory_equal(r.addr, addr, 6);
		assert_int_equal(r.len, 21);
	}
}

static void subscribe_cov_and_notifications(void **state)
{
	uint8_t out[PSD_BACSERVE_MAX_PACKET];
	const uint8_t *a;
	struct psd_bacserve_reply r;
	(void)state;
	model.now = 1000.4;   /* 1000.4 + 60 - 1000.4 is 60.000000000000114: still 60 s left */
	{
		/* subscribeCOV (5): [0] process 18, [1] (lighting-output, 1),
		 * [2] FALSE (unconfirmed), [3] lifetime 60 s: SimpleACK */
		static const uint8_t req[] = { 0x00, 0x05, 0x0f, 0x05, 0x09, 0x12, 0x1c, 0x0d, 0x80, 0x00, 0x01,
			                       0x29, 0x00, 0x39, 0x3c };
		ASK(0x0a, 3, 0x20, 0x0f, 0x05);
	}
	{
		/* the first notification at once: unconfirmedCOVNotification (2),
		 * [0] 18, [1] (device, 10), [2] (lighting-output, 1), [3] 60 s left,
		 * [4]( [0] present-value [2]( REAL 10.0 ) [0] status-flags [2]( B'0000' ) ) */
		static const uint8_t want[] = { 0x81, 0x0a, 0x00, 0x28, 0x01, 0x00, 0x10, 0x02, 0x09, 0x12,
			                        0x1c, 0x02, 0x00, 0x00, 0x0a, 0x2c, 0x0d, 0x80, 0x00, 0x01,
			                        0x39, 0x3c, 0x4e, 0x09, 0x55, 0x2e, 0x44, 0x41, 0x20, 0x00,
			                        0x00, 0x2f, 0x09, 0x6f, 0x2e, 0x82, 0x04, 0x00, 0x2f, 0x4f };
		assert_int_equal(psd_bacserve_cov(&model, out, &r), 1);
		assert_int_equal(r.to, PSD_BACSERVE_TO_ADDRESS);
		assert_memory_equal(r.addr, peer, 6);
		assert_int_equal(r.len, sizeof want);
		assert_memory_equal(out, want, sizeof want);
	}
	/* nothing moved: nothing; 0.5 % (under the 1 % increment): nothing */
	assert_int_equal(psd_bacserve_cov(&model, out, &r), 0);
	zones[0].level = 10.5;
	assert_int_equal(psd_bacserve_cov(&model, out, &r), 0);
	/* 1.5 % from the last sent: a notification with 11.5 (0x41380000) */
	zones[0].level = 11.5;
	model.now = 1030.9;
	assert_int_equal(psd_bacserve_cov(&model, out, &r), 1);
	assert_int_equal(out[20], 0x39);
	assert_int_equal(out[21], 30);   /* 29.5 s left, rounded up */
	assert_int_equal(out[27], 0x41);
	assert_int_equal(out[28], 0x38);
	/* the fault flag changes: a notification even without a level change */
	zones[0].fault = 1;
	assert_int_equal(psd_bacserve_cov(&model, out, &r), 1);
	assert_int_equal(out[r.len - 3], 0x40);
	/* the lifetime ends: the subscription goes */
	zones[0].level = 50;
	model.now = 1060.4;
	assert_int_equal(psd_bacserve_cov(&model, out, &r), 0);
	{
		/* again without a lifetime, then cancelled ([2] and [3] left out) */
		static const uint8_t req[] = { 0x00, 0x05, 0x10, 0x05, 0x09, 0x12, 0x1c, 0x0d, 0x80, 0x00, 0x01, 0x29, 0x01 };
		ASK(0x0a, 3, 0x20, 0x10, 0x05);
	}
	assert_int_equal(psd_bacserve_cov(&model, out, &r), 1);
	assert_int_equal(out[6], 0x00);   /* confirmed: a ConfirmedRequest, confirmedCOVNotification (1) */
	assert_int_equal(out[9], 0x01);
	{
		static const uint8_t req[] = { 0x00, 0x05, 0x11, 0x05, 0x09, 0x12, 0x1c, 0x0d, 0x80, 0x00, 0x01 };
		ASK(0x0a, 3, 0x20, 0x11, 0x05);
	}
	zones[0].level = 90;
	assert_int_equal(psd_bacserve_cov(&model, out, &r), 0);
	{
		/* the Device: object/optional-functionality-not-supported (45) */
		static const uint8_t req[] = { 0x00, 0x05, 0x12, 0x05, 0x09, 0x12, 0x1c, 0x02, 0x00, 0x00, 0x0a, 0x29, 0x00 };
		ASK(0x0a, 7, 0x50, 0x12, 0x05, 0x91, 0x01, 0x91, 0x2d);
	}
	{
		/* (analog-value, 99): object/unknown-object */
		static const uint8_t req[] = { 0x00, 0x05, 0x13, 0x05, 0x09, 0x12, 0x1c, 0x00, 0x80, 0x00, 0x63, 0x29, 0x00 };
		ASK(0x0a, 7, 0x50, 0x13, 0x05, 0x91, 0x01, 0x91, 0x1f);
	}
}

/* A SubscribeCOV of (lighting-output, 1), process pid, no lifetime, from
 * src: the reply's APDU type octet (0x20 SimpleACK, 0x50 Error). */
static uint8_t subscribe_from(const uint8_t src[6], uint8_t pid)
{
	uint8_t in[] = { 0x81, 0x0a, 0x00, 0x13, 0x01, 0x04, 0x00, 0x05, 0x01, 0x05, 0x09, pid,
		         0x1c, 0x0d, 0x80, 0x00, 0x01, 0x29, 0x00 };
	uint8_t out[PSD_BACSERVE_MAX_PACKET];
	struct psd_bacserve_reply r;
	psd_bacserve_handle(&model, in, sizeof in, src, 0, out, &r);
	assert_true(r.len > 6);
	return out[6];
}

/* One address cannot take every subscription: past its share its next
 * is refused resources/no-space-to-add, another address is served. */
static void subscriptions_per_source(void **state)
{
	static const uint8_t other[6] = { 10, 0, 0, 8, 0xba, 0xc0 };
	(void)state;
	memset(model.sub, 0, sizeof model.sub);
	for (int i = 0; i < PSD_BACSERVE_SUBS_PER_SOURCE; i++)
		assert_int_equal(subscribe_from(peer, (uint8_t)i), 0x20);
	/* its own again (a renewal) is taken; a new one is not */
	assert_int_equal(subscribe_from(peer, 0), 0x20);
	assert_int_equal(subscribe_from(peer, PSD_BACSERVE_SUBS_PER_SOURCE), 0x50);
	/* another port of the same host is the same source */
	{
		uint8_t port[6] = { 10, 0, 0, 7, 0xba, 0xc1 };
		assert_int_equal(subscribe_from(port, 99), 0x50);
	}
	assert_int_equal(subscribe_from(other, 1), 0x20);
	assert_true(PSD_BACSERVE_SUBS_PER_SOURCE < PSD_BACSERVE_SUBS);
}

static size_t value_applied[2]; /* the zone + 1 and point of the last Value applied */

static int apply_value(void *user, size_t z, size_t point)
{
	(void)user;
	value_applied[0] = z + 1, value_applied[1] = point;
	return 0;
}

/* The Values (commandable, 19.2): zone 0's target lux is (analog-value,
 * 1) = 0x00800001, its daylight control (binary-value, 1) = 0x01400001,
 * its vacancy hold (analog-value, 2); writes opened per class. */
static void writable_values(void **state)
{
	uint8_t out[PSD_BACSERVE_MAX_PACKET];
	const uint8_t *a;
	size_t target = (size_t)psd_points_find("target_lux"), day = (size_t)psd_points_find("daylighting");
	(void)state;
	/* every writable point but the level has a priority array of its own */
	for (size_t i = 0, k = 0; i < psd_points_count(); i++)
		if (psd_points_def(i)->writable && strcmp(psd_points_def(i)->key, "level") != 0)
			assert_int_equal(psd_bacobj_value_slot(i), (int)k++);
	model.writes = PSD_BACCONF_TARGET | PSD_BACCONF_DAYLIGHTING;
	model.apply_value = apply_value;
	zones[0].vdef[psd_bacobj_value_slot(target)] = 500;
	zones[0].pv[day] = 1;
	{
		/* 350 lx (REAL 0x43af0000) at priority 8: a SimpleACK, applied */
		static const uint8_t req[] = { 0x00, 0x05, 0x50, 0x0f, 0x0c, 0x00, 0x80, 0x00, 0x01, 0x19, 0x55,
			                       0x3e, 0x44, 0x43, 0xaf, 0x00, 0x00, 0x3f, 0x49, 0x08 };
		ASK(0x0a, 3, 0x20, 0x50, 0x0f);
		assert_int_equal(value_applied[0], 1);
		assert_int_equal(value_applied[1], target);
		assert_true(zones[0].vprio[psd_bacobj_value_slot(target)][7] == 350.0);
	}
	{
		/* the same 350 lx at priority 8 again: acknowledged, not applied */
		static const uint8_t req[] = { 0x00, 0x05, 0x61, 0x0f, 0x0c, 0x00, 0x80, 0x00, 0x01, 0x19, 0x55,
			                       0x3e, 0x44, 0x43, 0xaf, 0x00, 0x00, 0x3f, 0x49, 0x08 };
		value_applied[0] = 0;
		ASK(0x0a, 3, 0x20, 0x61, 0x0f);
		assert_int_equal(value_applied[0], 0);
	}
	{
		/* Priority_Array[8] (87 = 0x57) reads it back */
		static const uint8_t req[] = { 0x00, 0x05, 0x51, 0x0c, 0x0c, 0x00, 0x80, 0x00, 0x01, 0x19, 0x57, 0x29, 0x08 };
		ASK(0x0a, 19, 0x30, 0x51, 0x0c, 0x0c, 0x00, 0x80, 0x00, 0x01, 0x19, 0x57, 0x29, 0x08, 0x3e, 0x44, 0x43,
		    0xaf, 0x00, 0x00, 0x3f);
	}
	{
		/* Relinquish_Default (104 = 0x68): the configured 500 lx */
		static const uint8_t req[] = { 0x00, 0x05, 0x52, 0x0c, 0x0c, 0x00, 0x80, 0x00, 0x01, 0x19, 0x68 };
		ASK(0x0a, 17, 0x30, 0x52, 0x0c, 0x0c, 0x00, 0x80, 0x00, 0x01, 0x19, 0x68, 0x3e, 0x44, 0x43, 0xfa, 0x00,
		    0x00, 0x3f);
	}
	{
		/* 6000 lx (0x45bb8000), past the point's 5000: property/value-out-of-range (37) */
		static const uint8_t req[] = { 0x00, 0x05, 0x53, 0x0f, 0x0c, 0x00, 0x80, 0x00, 0x01, 0x19, 0x55,
			                       0x3e, 0x44, 0x45, 0xbb, 0x80, 0x00, 0x3f, 0x49, 0x08 };
		ASK(0x0a, 7, 0x50, 0x53, 0x0f, 0x91, 0x02, 0x91, 0x25);
		assert_true(zones[0].vprio[psd_bacobj_value_slot(target)][7] == 350.0);
	}
	{
		/* a REAL NaN (0x7fc00000), +infinity (0x7f800000), -infinity
		 * (0xff800000) at priority 8: property/value-out-of-range (37),
		 * never a relinquish; the 350 lx stays, nothing applied */
		static const uint8_t bits[3][4] = { { 0x7f, 0xc0, 0x00, 0x00 },
			                            { 0x7f, 0x80, 0x00, 0x00 },
			                            { 0xff, 0x80, 0x00, 0x00 } };
		static const uint8_t want[] = { 0x50, 0x60, 0x0f, 0x91, 0x02, 0x91, 0x25 };
		for (size_t i = 0; i < 3; i++) {
			uint8_t req[] = { 0x00, 0x05, 0x60, 0x0f, 0x0c, 0x00, 0x80, 0x00, 0x01, 0x19, 0x55,
				          0x3e, 0x44, 0, 0, 0, 0, 0x3f, 0x49, 0x08 };
			memcpy(req + 13, bits[i], 4);
			value_applied[0] = 0;
			assert_int_equal(ask(req, sizeof req, 0x0a, out, &a), sizeof want);
			assert_memory_equal(a, want, sizeof want);
			assert_int_equal(value_applied[0], 0);
			assert_true(zones[0].vprio[psd_bacobj_value_slot(target)][7] == 350.0);
		}
	}
	{
		/* an unsigned for the REAL: property/invalid-data-type (9) */
		static const uint8_t req[] = { 0x00, 0x05, 0x54, 0x0f, 0x0c, 0x00, 0x80, 0x00, 0x01, 0x19, 0x55,
			                       0x3e, 0x21, 0x05, 0x3f };
		ASK(0x0a, 7, 0x50, 0x54, 0x0f, 0x91, 0x02, 0x91, 0x09);
	}
	{
		/* the vacancy hold (analog-value, 2), not opened: write-access-denied (40) */
		static const uint8_t req[] = { 0x00, 0x05, 0x55, 0x0f, 0x0c, 0x00, 0x80, 0x00, 0x02, 0x19, 0x55,
			                       0x3e, 0x44, 0x42, 0x48, 0x00, 0x00, 0x3f };
		ASK(0x0a, 7, 0x50, 0x55, 0x0f, 0x91, 0x02, 0x91, 0x28);
	}
	{
		/* daylight control off (enumerated 0) at priority 6: minimum on/off's, denied */
		static const uint8_t req[] = { 0x00, 0x05, 0x56, 0x0f, 0x0c, 0x01, 0x40, 0x00, 0x01, 0x19, 0x55,
			                       0x3e, 0x91, 0x00, 0x3f, 0x49, 0x06 };
		ASK(0x0a, 7, 0x50, 0x56, 0x0f, 0x91, 0x02, 0x91, 0x28);
	}
	{
		/* at priority 9: taken */
		static const uint8_t req[] = { 0x00, 0x05, 0x57, 0x0f, 0x0c, 0x01, 0x40, 0x00, 0x01, 0x19, 0x55,
			                       0x3e, 0x91, 0x00, 0x3f, 0x49, 0x09 };
		ASK(0x0a, 3, 0x20, 0x57, 0x0f);
		assert_int_equal(value_applied[1], day);
		assert_true(zones[0].vprio[psd_bacobj_value_slot(day)][8] == 0.0);
	}
	{
		/* active is 1 of BACnetBinaryPV; 2 is out of range */
		static const uint8_t req[] = { 0x00, 0x05, 0x58, 0x0f, 0x0c, 0x01, 0x40, 0x00, 0x01, 0x19, 0x55,
			                       0x3e, 0x91, 0x02, 0x3f, 0x49, 0x09 };
		ASK(0x0a, 7, 0x50, 0x58, 0x0f, 0x91, 0x02, 0x91, 0x25);
	}
	{
		/* its Present_Value, the point model's (1: active) */
		static const uint8_t req[] = { 0x00, 0x05, 0x59, 0x0c, 0x0c, 0x01, 0x40, 0x00, 0x01, 0x19, 0x55 };
		ASK(0x0a, 14, 0x30, 0x59, 0x0c, 0x0c, 0x01, 0x40, 0x00, 0x01, 0x19, 0x55, 0x3e, 0x91, 0x01, 0x3f);
	}
	{
		/* NULL at priority 8: relinquished, applied again */
		static const uint8_t req[] = { 0x00, 0x05, 0x5a, 0x0f, 0x0c, 0x00, 0x80, 0x00, 0x01, 0x19, 0x55,
			                       0x3e, 0x00, 0x3f, 0x49, 0x08 };
		value_applied[0] = 0;
		ASK(0x0a, 3, 0x20, 0x5a, 0x0f);
		assert_int_equal(value_applied[0], 1);
		assert_true(isnan(zones[0].vprio[psd_bacobj_value_slot(target)][7]));
	}
	model.target_min = 100, model.target_max = 300;
	{
		/* [bacnet] target_max 300: 350 lx is out of range now */
		static const uint8_t req[] = { 0x00, 0x05, 0x5c, 0x0f, 0x0c, 0x00, 0x80, 0x00, 0x01, 0x19, 0x55,
			                       0x3e, 0x44, 0x43, 0xaf, 0x00, 0x00, 0x3f, 0x49, 0x08 };
		ASK(0x0a, 7, 0x50, 0x5c, 0x0f, 0x91, 0x02, 0x91, 0x25);
	}
	{
		/* Max_Pres_Value (65 = 0x41): 300.0 (0x43960000) */
		static const uint8_t req[] = { 0x00, 0x05, 0x5d, 0x0c, 0x0c, 0x00, 0x80, 0x00, 0x01, 0x19, 0x41 };
		ASK(0x0a, 17, 0x30, 0x5d, 0x0c, 0x0c, 0x00, 0x80, 0x00, 0x01, 0x19, 0x41, 0x3e, 0x44, 0x43, 0x96, 0x00,
		    0x00, 0x3f);
	}
	model.writes = PSD_BACCONF_LIGHTING_OUTPUT;
	{
		/* the Lighting Output alone opened: the target is refused */
		static const uint8_t req[] = { 0x00, 0x05, 0x5b, 0x0f, 0x0c, 0x00, 0x80, 0x00, 0x01, 0x19, 0x55,
			                       0x3e, 0x44, 0x43, 0xaf, 0x00, 0x00, 0x3f, 0x49, 0x08 };
		ASK(0x0a, 7, 0x50, 0x5b, 0x0f, 0x91, 0x02, 0x91, 0x28);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(encodings_follow_clause_20_2),
		cmocka_unit_test(decoding_reads_tags_and_stops_at_the_end),
		cmocka_unit_test_setup(who_is_with_a_range, setup),
		cmocka_unit_test_setup(who_has_by_identifier_and_by_name, setup),
		cmocka_unit_test_setup(read_property_and_its_errors, setup),
		cmocka_unit_test_setup(read_property_multiple, setup),
		cmocka_unit_test_setup(rpm_required_and_optional, setup),
		cmocka_unit_test_setup(binary_and_multistate_inputs, setup),
		cmocka_unit_test_setup(lighting_command, setup),
		cmocka_unit_test_setup(write_property_with_priorities, setup),
		cmocka_unit_test_setup(bvll_and_npdu, setup),
		cmocka_unit_test_setup(subscribe_cov_and_notifications, setup),
		cmocka_unit_test_setup(writable_values, setup),
		cmocka_unit_test_setup(subscriptions_per_source, setup),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
