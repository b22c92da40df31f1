/* SPDX-License-Identifier: ISC */
/* The BACnet/IP server's protocol (bacserve.h).  Numbers from ANSI/ASHRAE
 * 135: BVLL Annex J, NPDU clause 6, APDU clause 20, the enumerations of
 * clause 21. */
#include "bacserve.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "bactag.h"

/* property identifiers (BACnetPropertyIdentifier) */
enum {
	P_APDU_TIMEOUT = 11,
	P_COV_INCREMENT = 22,
	P_APP_SW_VERSION = 12,
	P_DESCRIPTION = 28,
	P_DEVICE_ADDRESS_BINDING = 30,
	P_EVENT_STATE = 36,
	P_FIRMWARE_REVISION = 44,
	P_ALL = 8,
	P_MAX_APDU = 62,
	P_MODEL_NAME = 70,
	P_APDU_RETRIES = 73,
	P_OBJECT_ID = 75,
	P_OBJECT_LIST = 76,
	P_OBJECT_NAME = 77,
	P_OBJECT_TYPE = 79,
	P_OPTIONAL = 80,
	P_OUT_OF_SERVICE = 81,
	P_PRESENT_VALUE = 85,
	P_PRIORITY_ARRAY = 87,
	P_OBJECT_TYPES_SUPPORTED = 96,
	P_SERVICES_SUPPORTED = 97,
	P_PROTOCOL_VERSION = 98,
	P_RELINQUISH_DEFAULT = 104,
	P_REQUIRED = 105,
	P_SEGMENTATION = 107,
	P_STATUS_FLAGS = 111,
	P_SYSTEM_STATUS = 112,
	P_UNITS = 117,
	P_VENDOR_ID = 120,
	P_VENDOR_NAME = 121,
	P_PROTOCOL_REVISION = 139,
	P_DATABASE_REVISION = 155,
	P_TRACKING_VALUE = 164,
	P_PROPERTY_LIST = 371,
	P_BLINK_WARN_ENABLE = 373,
	P_DEFAULT_FADE_TIME = 374,
	P_DEFAULT_RAMP_RATE = 375,
	P_DEFAULT_STEP_INCREMENT = 376,
	P_EGRESS_TIME = 377,
	P_IN_PROGRESS = 378,
	P_LIGHTING_COMMAND = 380,
	P_LIGHTING_COMMAND_DEFAULT_PRIORITY = 381,
	P_EGRESS_ACTIVE = 386,
};

/* error classes and codes (clause 18), reject and abort reasons (clause 18.8, 18.9) */
enum { EC_OBJECT = 1, EC_PROPERTY = 2, EC_RESOURCES = 3, EC_SERVICES = 5 };
enum {
	E_INVALID_DATA_TYPE = 9,
	E_NO_SPACE_TO_ADD = 19,
	E_UNKNOWN_OBJECT = 31,
	E_NOT_SUPPORTED = 45,
	E_UNKNOWN_PROPERTY = 32,
	E_VALUE_OUT_OF_RANGE = 37,
	E_WRITE_ACCESS_DENIED = 40,
	E_INVALID_ARRAY_INDEX = 42,
	E_NOT_AN_ARRAY = 50,
	E_PARAMETER_OUT_OF_RANGE = 80,
};
enum { R_INVALID_TAG = 4, R_MISSING_PARAMETER = 5, R_TOO_MANY_ARGUMENTS = 7, R_UNRECOGNIZED_SERVICE = 9 };
enum { A_SEGMENTATION_NOT_SUPPORTED = 4 };

/* services (BACnetConfirmedServiceChoice, BACnetUnconfirmedServiceChoice) */
enum {
	S_COV_NOTIFICATION = 1,
	S_SUBSCRIBE_COV = 5,
	S_READ_PROPERTY = 12,
	S_READ_PROPERTY_MULTIPLE = 14,
	S_WRITE_PROPERTY = 15
};
enum { U_I_AM = 0, U_I_HAVE = 1, U_COV_NOTIFICATION = 2, U_WHO_HAS = 7, U_WHO_IS = 8 };

enum { PROTOCOL_REVISION = 14, MAX_INSTANCE = 4194303 };

/* the properties of each object type; 1: required, 0: optional */
struct prop {
	uint32_t id;
	int required;
};
static const struct prop device_props[] = {
	{ P_OBJECT_ID, 1 },
	{ P_OBJECT_NAME, 1 },
	{ P_OBJECT_TYPE, 1 },
	{ P_SYSTEM_STATUS, 1 },
	{ P_VENDOR_NAME, 1 },
	{ P_VENDOR_ID, 1 },
	{ P_MODEL_NAME, 1 },
	{ P_FIRMWARE_REVISION, 1 },
	{ P_APP_SW_VERSION, 1 },
	{ P_PROTOCOL_VERSION, 1 },
	{ P_PROTOCOL_REVISION, 1 },
	{ P_SERVICES_SUPPORTED, 1 },
	{ P_OBJECT_TYPES_SUPPORTED, 1 },
	{ P_OBJECT_LIST, 1 },
	{ P_MAX_APDU, 1 },
	{ P_SEGMENTATION, 1 },
	{ P_APDU_TIMEOUT, 1 },
	{ P_APDU_RETRIES, 1 },
	{ P_DEVICE_ADDRESS_BINDING, 1 },
	{ P_DATABASE_REVISION, 1 },
	{ P_PROPERTY_LIST, 1 },
	{ P_DESCRIPTION, 0 },
};
static const struct prop lo_props[] = {
	{ P_OBJECT_ID, 1 },         { P_OBJECT_NAME, 1 },        { P_OBJECT_TYPE, 1 },
	{ P_PRESENT_VALUE, 1 },     { P_TRACKING_VALUE, 1 },     { P_LIGHTING_COMMAND, 1 },
	{ P_IN_PROGRESS, 1 },       { P_STATUS_FLAGS, 1 },       { P_OUT_OF_SERVICE, 1 },
	{ P_BLINK_WARN_ENABLE, 1 }, { P_EGRESS_TIME, 1 },        { P_EGRESS_ACTIVE, 1 },
	{ P_DEFAULT_FADE_TIME, 1 }, { P_DEFAULT_RAMP_RATE, 1 },  { P_DEFAULT_STEP_INCREMENT, 1 },
	{ P_PRIORITY_ARRAY, 1 },    { P_RELINQUISH_DEFAULT, 1 }, { P_LIGHTING_COMMAND_DEFAULT_PRIORITY, 1 },
	{ P_PROPERTY_LIST, 1 },     { P_EVENT_STATE, 0 },        { P_DESCRIPTION, 0 },
	{ P_COV_INCREMENT, 0 },
};
static const struct prop ai_props[] = {
	{ P_OBJECT_ID, 1 },     { P_OBJECT_NAME, 1 },   { P_OBJECT_TYPE, 1 },    { P_PRESENT_VALUE, 1 },
	{ P_STATUS_FLAGS, 1 },  { P_EVENT_STATE, 1 },   { P_OUT_OF_SERVICE, 1 }, { P_UNITS, 1 },
	{ P_PROPERTY_LIST, 1 }, { P_COV_INCREMENT, 1 }, { P_DESCRIPTION, 0 },
};
#define NPROPS(a) (sizeof(a) / sizeof(a)[0])

/* An object of the model: its type, instance, zone (for LO, AI) and which AI. */
struct obj {
	uint32_t type, instance;
	size_t zone;
	int ai; /* 0 estimated task lux, 1 sensor signal, 2 target */
	const struct prop *props;
	size_t nprops;
};

static const char *const ai_what[PSD_BACSERVE_AI_PER_ZONE] = { "estimated task illuminance", "sensor signal",
	                                                       "target task illuminance" };
static const uint32_t ai_units[PSD_BACSERVE_AI_PER_ZONE] = { 37 /* luxes */, 5 /* volts */, 37 };

/* COV_Increment: a Lighting Output's 1 %, the Analog Inputs' 10 lx, 0.01 V, 1 lx */
static float cov_increment(const struct obj *o)
{
	static const float ai[PSD_BACSERVE_AI_PER_ZONE] = { 10.0f, 0.01f, 1.0f };
	return o->type == PSD_BAC_LO ? 1.0f : ai[o->ai];
}

static size_t nobjects(const struct psd_bacserve_model *m)
{
	return 1 + m->nzone * (1 + PSD_BACSERVE_AI_PER_ZONE);
}

/* The i-th object of Object_List (0: the Device). */
static void object_at(const struct psd_bacserve_model *m, size_t i, struct obj *o)
{
	memset(o, 0, sizeof *o);
	if (i == 0) {
		o->type = PSD_BAC_DEVICE, o->instance = m->device, o->props = device_props;
		o->nprops = NPROPS(device_props);
		return;
	}
	o->zone = (i - 1) / (1 + PSD_BACSERVE_AI_PER_ZONE);
	size_t k = (i - 1) % (1 + PSD_BACSERVE_AI_PER_ZONE);
	if (k == 0) {
		o->type = PSD_BAC_LO, o->instance = (uint32_t)o->zone + 1, o->props = lo_props;
		o->nprops = NPROPS(lo_props);
	} else {
		o->ai = (int)k - 1;
		o->type = PSD_BAC_AI, o->instance = (uint32_t)(o->zone * PSD_BACSERVE_AI_PER_ZONE + k);
		o->props = ai_props, o->nprops = NPROPS(ai_props);
	}
}

/* The object of a type and instance: 0 found. */
static int find(const struct psd_bacserve_model *m, uint32_t type, uint32_t instance, struct obj *o)
{
	if (type == PSD_BAC_DEVICE && (instance == m->device || instance == MAX_INSTANCE)) {
		object_at(m, 0, o);
		return 0;
	}
	if (type == PSD_BAC_LO && instance >= 1 && instance <= m->nzone) {
		object_at(m, 1 + (instance - 1) * (1 + PSD_BACSERVE_AI_PER_ZONE), o);
		return 0;
	}
	if (type == PSD_BAC_AI && instance >= 1 && instance <= m->nzone * PSD_BACSERVE_AI_PER_ZONE) {
		size_t z = (instance - 1) / PSD_BACSERVE_AI_PER_ZONE,
		       k = (instance - 1) % PSD_BACSERVE_AI_PER_ZONE;
		object_at(m, 1 + z * (1 + PSD_BACSERVE_AI_PER_ZONE) + 1 + k, o);
		return 0;
	}
	return -1;
}

static int has_prop(const struct obj *o, uint32_t id)
{
	for (size_t i = 0; i < o->nprops; i++)
		if (o->props[i].id == id)
			return 1;
	return 0;
}

static void put_bits(struct psd_bacbuf *b, const unsigned *set, size_t nset, unsigned nbits)
{
	uint8_t bits[8] = { 0 };
	for (size_t i = 0; i < nset; i++)
		bits[set[i] / 8] |= (uint8_t)(0x80u >> (set[i] % 8));
	psd_bactag_put_bits(b, -1, bits, nbits);
}

static void object_name(const struct psd_bacserve_model *m, const struct obj *o, char *s, size_t n)
{
	static const char *const ai_name[PSD_BACSERVE_AI_PER_ZONE] = { "task lux estimate", "sensor signal",
		                                                       "target lux" };
	if (o->type == PSD_BAC_DEVICE)
		snprintf(s, n, "%s", m->name);
	else if (o->type == PSD_BAC_LO)
		snprintf(s, n, "%s light level", m->zone[o->zone].name);
	else
		snprintf(s, n, "%s %s", m->zone[o->zone].name, ai_name[o->ai]);
}

static float ai_value(const struct psd_bacserve_zone *z, int ai)
{
	return (float)(ai == 0 ? z->est_lux : ai == 1 ? z->signal : z->target);
}

static float present_value(const struct psd_bacserve_model *m, const struct obj *o)
{
	const struct psd_bacserve_zone *z = &m->zone[o->zone];
	return o->type == PSD_BAC_LO ? (float)z->level : ai_value(z, o->ai);
}

/* Status_Flags' fault: the zone at its safe level, or a reading missing */
static int in_fault(const struct psd_bacserve_model *m, const struct obj *o)
{
	const struct psd_bacserve_zone *z = &m->zone[o->zone];
	return z->fault || (o->type == PSD_BAC_AI && o->ai < 2 && !isfinite(ai_value(z, o->ai)));
}

/* Encode one array element (idx 1..) or, idx 0, the whole array; -1 when idx
 * is past its end. */
static int put_array(const struct psd_bacserve_model *m, const struct obj *o, uint32_t prop, int has_idx,
                     uint32_t idx, struct psd_bacbuf *b)
{
	size_t count = prop == P_OBJECT_LIST      ? nobjects(m)
	               : prop == P_PRIORITY_ARRAY ? PSD_BACSERVE_PRIORITIES
	                                          : 0;
	size_t from = 0, to;
	if (prop == P_PROPERTY_LIST)
		for (size_t i = 0; i < o->nprops; i++)
			count += o->props[i].id != P_OBJECT_ID && o->props[i].id != P_OBJECT_NAME &&
			         o->props[i].id != P_OBJECT_TYPE && o->props[i].id != P_PROPERTY_LIST;
	if (has_idx && idx == 0) {
		psd_bactag_put_unsigned(b, -1, (uint32_t)count);
		return 0;
	}
	if (has_idx && idx > count)
		return -1;
	to = count;
	if (has_idx)
		from = idx - 1, to = idx;
	for (size_t i = from; i < to; i++) {
		if (prop == P_OBJECT_LIST) {
			struct obj e;
			object_at(m, i, &e);
			psd_bactag_put_objectid(b, -1, e.type, e.instance);
		} else if (prop == P_PRIORITY_ARRAY) {
			double v = m->zone[o->zone].prio[i];
			if (isnan(v))
				psd_bactag_put_null(b, -1);
			else
				psd_bactag_put_real(b, -1, (float)v);
		} else {
			size_t k = 0;
			for (size_t j = 0; j < o->nprops; j++) {
				uint32_t id = o->props[j].id;
				if (id == P_OBJECT_ID || id == P_OBJECT_NAME || id == P_OBJECT_TYPE ||
				    id == P_PROPERTY_LIST)
					continue;
				if (k++ == i)
					psd_bactag_put_enum(b, -1, id);
			}
		}
	}
	return 0;
}

/* Encode the value of o's property: 0, or -1 with an error class and code
 * (and nothing written). */
static int read_prop(const struct psd_bacserve_model *m, const struct obj *o, uint32_t prop, int has_idx,
                     uint32_t idx, struct psd_bacbuf *b, uint32_t *ec, uint32_t *code)
{
	const struct psd_bacserve_zone *z = o->type == PSD_BAC_DEVICE ? NULL : &m->zone[o->zone];
	char name[128];
	if (!has_prop(o, prop)) {
		*ec = EC_PROPERTY, *code = E_UNKNOWN_PROPERTY;
		return -1;
	}
	if (prop == P_OBJECT_LIST || prop == P_PRIORITY_ARRAY || prop == P_PROPERTY_LIST) {
		if (put_array(m, o, prop, has_idx, idx, b) == 0)
			return 0;
		*ec = EC_PROPERTY, *code = E_INVALID_ARRAY_INDEX;
		return -1;
	}
	if (has_idx) {
		*ec = EC_PROPERTY, *code = E_NOT_AN_ARRAY;
		return -1;
	}
	switch (prop) {
	case P_OBJECT_ID: psd_bactag_put_objectid(b, -1, o->type, o->instance); break;
	case P_OBJECT_NAME:
		object_name(m, o, name, sizeof name);
		psd_bactag_put_string(b, -1, name);
		break;
	case P_OBJECT_TYPE: psd_bactag_put_enum(b, -1, o->type); break;
	case P_DESCRIPTION:
		if (o->type == PSD_BAC_DEVICE)
			snprintf(name, sizeof name, "psensd: daylight-linked lighting control, %zu zone(s)",
			         m->nzone);
		else if (o->type == PSD_BAC_LO)
			snprintf(name, sizeof name, "zone %s: the light output in force, %%", z->name);
		else
			snprintf(name, sizeof name, "zone %s: %s", z->name, ai_what[o->ai]);
		psd_bactag_put_string(b, -1, name);
		break;
	case P_SYSTEM_STATUS:
		psd_bactag_put_enum(b, -1, 0); /* operational */
		break;
	case P_VENDOR_NAME: psd_bactag_put_string(b, -1, "psensd"); break;
	case P_VENDOR_ID: psd_bactag_put_unsigned(b, -1, m->vendor_id); break;
	case P_MODEL_NAME: psd_bactag_put_string(b, -1, "psensd daylight controller"); break;
	case P_FIRMWARE_REVISION:
	case P_APP_SW_VERSION: psd_bactag_put_string(b, -1, "psensd"); break;
	case P_PROTOCOL_VERSION: psd_bactag_put_unsigned(b, -1, 1); break;
	case P_PROTOCOL_REVISION: psd_bactag_put_unsigned(b, -1, PROTOCOL_REVISION); break;
	case P_SERVICES_SUPPORTED: {
		/* subscribeCOV 5, readProperty 12, readPropertyMultiple 14,
		 * writeProperty 15, i-Am 26, i-Have 27, who-Has 33, who-Is 34
		 * (BACnetServicesSupported); 41 bits at revision 14 */
		static const unsigned s[] = { 5, 12, 14, 15, 26, 27, 33, 34 };
		put_bits(b, s, NPROPS(s), 41);
		break;
	}
	case P_OBJECT_TYPES_SUPPORTED: {
		/* analog-input 0, device 8, lighting-output 54; 55 bits at revision 14 */
		static const unsigned t[] = { PSD_BAC_AI, PSD_BAC_DEVICE, PSD_BAC_LO };
		put_bits(b, t, NPROPS(t), 55);
		break;
	}
	case P_MAX_APDU: psd_bactag_put_unsigned(b, -1, PSD_BACSERVE_MAX_APDU); break;
	case P_SEGMENTATION:
		psd_bactag_put_enum(b, -1, 3); /* no-segmentation */
		break;
	case P_APDU_TIMEOUT: psd_bactag_put_unsigned(b, -1, 3000); break;
	case P_APDU_RETRIES: psd_bactag_put_unsigned(b, -1, 3); break;
	case P_DEVICE_ADDRESS_BINDING: break; /* an empty list: psensd binds to no other device */
	case P_DATABASE_REVISION: psd_bactag_put_unsigned(b, -1, m->database_revision); break;
	case P_PRESENT_VALUE:
	case P_TRACKING_VALUE: psd_bactag_put_real(b, -1, present_value(m, o)); break;
	case P_RELINQUISH_DEFAULT: psd_bactag_put_real(b, -1, (float)z->level); break;
	case P_LIGHTING_COMMAND:
		psd_bactag_put_enum(b, 0, 0); /* BACnetLightingCommand, operation none */
		break;
	case P_IN_PROGRESS:
		psd_bactag_put_enum(b, -1, 0); /* idle */
		break;
	case P_STATUS_FLAGS: {
		/* in-alarm, fault, overridden, out-of-service */
		static const unsigned f[] = { 1 };
		put_bits(b, f, in_fault(m, o) ? 1 : 0, 4);
		break;
	}
	case P_EVENT_STATE:
		psd_bactag_put_enum(b, -1, 0); /* normal */
		break;
	case P_OUT_OF_SERVICE:
	case P_BLINK_WARN_ENABLE:
	case P_EGRESS_ACTIVE: psd_bactag_put_bool(b, -1, 0); break;
	case P_EGRESS_TIME: psd_bactag_put_unsigned(b, -1, 0); break;
	case P_DEFAULT_FADE_TIME:
		psd_bactag_put_unsigned(b, -1, 100); /* ms, the least the standard allows */
		break;
	case P_DEFAULT_RAMP_RATE:
		psd_bactag_put_real(b, -1, 100.0f); /* %/s */
		break;
	case P_DEFAULT_STEP_INCREMENT:
		psd_bactag_put_real(b, -1, 1.0f); /* % */
		break;
	case P_LIGHTING_COMMAND_DEFAULT_PRIORITY: psd_bactag_put_unsigned(b, -1, 16); break;
	case P_UNITS: psd_bactag_put_enum(b, -1, ai_units[o->ai]); break;
	case P_COV_INCREMENT: psd_bactag_put_real(b, -1, cov_increment(o)); break;
	default: *ec = EC_PROPERTY, *code = E_UNKNOWN_PROPERTY; return -1;
	}
	return 0;
}

/* ---- the APDU ------------------------------------------------------------ */

struct req {
	const uint8_t *p; /* the service's parameters */
	size_t n;
	uint8_t invoke;
	uint8_t service;
};

static void put_error(struct psd_bacbuf *b, const struct req *q, uint32_t ec, uint32_t code)
{
	uint8_t h[3] = { 0x50, q->invoke, q->service };
	b->len = 0, b->overflow = 0;
	psd_bactag_put_raw(b, h, 3);
	psd_bactag_put_enum(b, -1, ec);
	psd_bactag_put_enum(b, -1, code);
}

static void put_reject(struct psd_bacbuf *b, uint8_t invoke, uint8_t reason)
{
	uint8_t h[3] = { 0x60, invoke, reason };
	b->len = 0, b->overflow = 0;
	psd_bactag_put_raw(b, h, 3);
}

static void put_abort(struct psd_bacbuf *b, uint8_t invoke, uint8_t reason)
{
	uint8_t h[3] = { 0x71 /* abort, sent by the server */, invoke, reason };
	b->len = 0, b->overflow = 0;
	psd_bactag_put_raw(b, h, 3);
}

/* Read a context tag `num` at *pos: 0 found, 1 absent (another tag or the
 * end), -1 malformed. */
static int ctx_tag(const struct req *q, size_t *pos, uint32_t num, struct psd_bactag *t)
{
	if (*pos >= q->n)
		return 1;
	if (psd_bactag_peek(q->p, q->n, *pos, t) != 0)
		return -1;
	if (!t->context || t->number != num || t->opening || t->closing)
		return 1;
	return psd_bactag_read(q->p, q->n, pos, t);
}

/* A required [num] unsigned or object identifier: 0, or a reject reason. */
static int need_unsigned(const struct req *q, size_t *pos, uint32_t num, uint32_t *v)
{
	struct psd_bactag t;
	int rc = ctx_tag(q, pos, num, &t);
	if (rc < 0)
		return R_INVALID_TAG;
	if (rc > 0)
		return *pos >= q->n ? R_MISSING_PARAMETER : R_INVALID_TAG;
	return psd_bactag_unsigned(&t, v) == 0 ? 0 : R_INVALID_TAG;
}

static int need_objectid(const struct req *q, size_t *pos, uint32_t num, uint32_t *type, uint32_t *inst)
{
	struct psd_bactag t;
	int rc = ctx_tag(q, pos, num, &t);
	if (rc < 0)
		return R_INVALID_TAG;
	if (rc > 0)
		return *pos >= q->n ? R_MISSING_PARAMETER : R_INVALID_TAG;
	return psd_bactag_objectid(&t, type, inst) == 0 ? 0 : R_INVALID_TAG;
}

/* An optional [num] unsigned: 0 absent, 1 present, -1 malformed. */
static int opt_unsigned(const struct req *q, size_t *pos, uint32_t num, uint32_t *v)
{
	struct psd_bactag t;
	int rc = ctx_tag(q, pos, num, &t);
	if (rc != 0)
		return rc < 0 ? -1 : 0;
	return psd_bactag_unsigned(&t, v) == 0 ? 1 : -1;
}

static void read_property(const struct psd_bacserve_model *m, const struct req *q, struct psd_bacbuf *b)
{
	size_t pos = 0, mark;
	uint32_t type, inst, prop, idx = 0, ec, code;
	int rc, has_idx;
	struct obj o;
	if ((rc = need_objectid(q, &pos, 0, &type, &inst)) || (rc = need_unsigned(q, &pos, 1, &prop))) {
		put_reject(b, q->invoke, (uint8_t)rc);
		return;
	}
	if ((has_idx = opt_unsigned(q, &pos, 2, &idx)) < 0) {
		put_reject(b, q->invoke, R_INVALID_TAG);
		return;
	}
	if (pos != q->n) {
		put_reject(b, q->invoke, R_TOO_MANY_ARGUMENTS);
		return;
	}
	if (find(m, type, inst, &o) != 0) {
		put_error(b, q, EC_OBJECT, E_UNKNOWN_OBJECT);
		return;
	}
	{
		uint8_t h[3] = { 0x30, q->invoke, q->service };
		psd_bactag_put_raw(b, h, 3);
	}
	psd_bactag_put_objectid(b, 0, o.type, o.instance);
	psd_bactag_put_enum(b, 1, prop);
	if (has_idx)
		psd_bactag_put_unsigned(b, 2, idx);
	psd_bactag_open(b, 3);
	mark = b->len;
	if (prop == P_ALL || prop == P_REQUIRED || prop == P_OPTIONAL ||
	    read_prop(m, &o, prop, has_idx, idx, b, &ec, &code) != 0) {
		if (prop == P_ALL || prop == P_REQUIRED || prop == P_OPTIONAL) /* RPM only (15.5.1.1.2) */
			ec = EC_PROPERTY, code = E_UNKNOWN_PROPERTY;
		b->len = mark;
		put_error(b, q, ec, code);
		return;
	}
	psd_bactag_close(b, 3);
}

/* One ReadAccessResult's element: [2] property, [3] index, [4] value or [5] error. */
static void rpm_one(const struct psd_bacserve_model *m, const struct obj *o, uint32_t prop, int has_idx,
                    uint32_t idx, struct psd_bacbuf *b)
{
	uint32_t ec = EC_OBJECT, code = E_UNKNOWN_OBJECT;
	size_t mark;
	psd_bactag_put_enum(b, 2, prop);
	if (has_idx)
		psd_bactag_put_unsigned(b, 3, idx);
	psd_bactag_open(b, 4);
	mark = b->len;
	if (o && read_prop(m, o, prop, has_idx, idx, b, &ec, &code) == 0) {
		psd_bactag_close(b, 4);
		return;
	}
	b->len = mark - 1; /* the opening [4] is one octet */
	psd_bactag_open(b, 5);
	psd_bactag_put_enum(b, -1, ec);
	psd_bactag_put_enum(b, -1, code);
	psd_bactag_close(b, 5);
}

static void read_property_multiple(const struct psd_bacserve_model *m, const struct req *q,
                                   struct psd_bacbuf *b)
{
	size_t pos = 0;
	uint8_t h[3] = { 0x30, q->invoke, q->service };
	psd_bactag_put_raw(b, h, 3);
	if (q->n == 0) {
		put_reject(b, q->invoke, R_MISSING_PARAMETER);
		return;
	}
	while (pos < q->n) {
		uint32_t type, inst;
		struct psd_bactag t;
		struct obj o;
		int known, rc, nprop = 0;
		if ((rc = need_objectid(q, &pos, 0, &type, &inst))) {
			put_reject(b, q->invoke, (uint8_t)rc);
			return;
		}
		if (psd_bactag_read(q->p, q->n, &pos, &t) != 0 || !t.context || !t.opening || t.number != 1) {
			put_reject(b, q->invoke, R_INVALID_TAG);
			return;
		}
		known = find(m, type, inst, &o) == 0;
		psd_bactag_put_objectid(b, 0, known ? o.type : type, known ? o.instance : inst);
		psd_bactag_open(b, 1);
		for (;;) {
			uint32_t prop, idx = 0;
			int has_idx;
			if (psd_bactag_peek(q->p, q->n, pos, &t) != 0) {
				put_reject(b, q->invoke, pos >= q->n ? R_MISSING_PARAMETER : R_INVALID_TAG);
				return;
			}
			if (t.context && t.closing && t.number == 1) {
				psd_bactag_read(q->p, q->n, &pos, &t);
				break;
			}
			if ((rc = need_unsigned(q, &pos, 0, &prop))) {
				put_reject(b, q->invoke, (uint8_t)rc);
				return;
			}
			if ((has_idx = opt_unsigned(q, &pos, 1, &idx)) < 0) {
				put_reject(b, q->invoke, R_INVALID_TAG);
				return;
			}
			nprop++;
			if ((prop == P_ALL || prop == P_REQUIRED || prop == P_OPTIONAL) && known) {
				for (size_t i = 0; i < o.nprops; i++)
					if (prop == P_ALL ||
					    (prop == P_REQUIRED) == (o.props[i].required == 1))
						rpm_one(m, &o, o.props[i].id, 0, 0, b);
			} else {
				rpm_one(m, known ? &o : NULL, prop, has_idx, idx, b);
			}
		}
		if (nprop == 0) { /* the list of property references may not be empty */
			put_reject(b, q->invoke, R_MISSING_PARAMETER);
			return;
		}
		psd_bactag_close(b, 1);
	}
}

static void write_property(struct psd_bacserve_model *m, const struct req *q, struct psd_bacbuf *b)
{
	size_t pos = 0;
	uint32_t type, inst, prop, idx = 0, prio = 16;
	int rc, has_idx, is_null = 0;
	float v = 0;
	struct psd_bactag t, val;
	struct obj o;
	if ((rc = need_objectid(q, &pos, 0, &type, &inst)) || (rc = need_unsigned(q, &pos, 1, &prop))) {
		put_reject(b, q->invoke, (uint8_t)rc);
		return;
	}
	if ((has_idx = opt_unsigned(q, &pos, 2, &idx)) < 0 || psd_bactag_read(q->p, q->n, &pos, &t) != 0 ||
	    !t.context || !t.opening || t.number != 3) {
		put_reject(b, q->invoke, pos >= q->n ? R_MISSING_PARAMETER : R_INVALID_TAG);
		return;
	}
	/* the value: one application-tagged datum, then [3] closing */
	if (psd_bactag_read(q->p, q->n, &pos, &val) != 0 || psd_bactag_read(q->p, q->n, &pos, &t) != 0) {
		put_reject(b, q->invoke, R_INVALID_TAG);
		return;
	}
	if (!(t.context && t.closing && t.number == 3)) {
		/* a constructed value: no property here takes one */
		int depth = 1;
		while (depth > 0 && !(t.context && t.closing && t.number == 3 && depth == 1)) {
			if (t.opening)
				depth++;
			else if (t.closing)
				depth--;
			if (psd_bactag_read(q->p, q->n, &pos, &t) != 0) {
				put_reject(b, q->invoke, R_INVALID_TAG);
				return;
			}
		}
		val.context = 1; /* judged below as the wrong type */
	}
	if ((rc = opt_unsigned(q, &pos, 4, &prio)) < 0) {
		put_reject(b, q->invoke, R_INVALID_TAG);
		return;
	}
	if (pos != q->n) {
		put_reject(b, q->invoke, R_TOO_MANY_ARGUMENTS);
		return;
	}
	if (find(m, type, inst, &o) != 0) {
		put_error(b, q, EC_OBJECT, E_UNKNOWN_OBJECT);
		return;
	}
	if (!has_prop(&o, prop)) {
		put_error(b, q, EC_PROPERTY, E_UNKNOWN_PROPERTY);
		return;
	}
	if (!(o.type == PSD_BAC_LO && prop == P_PRESENT_VALUE) || !m->writes) {
		put_error(b, q, EC_PROPERTY, E_WRITE_ACCESS_DENIED);
		return;
	}
	if (has_idx) {
		put_error(b, q, EC_PROPERTY, E_NOT_AN_ARRAY);
		return;
	}
	if (prio < 1 || prio > PSD_BACSERVE_PRIORITIES) {
		put_error(b, q, EC_SERVICES, E_PARAMETER_OUT_OF_RANGE);
		return;
	}
	if (prio == 6) { /* reserved for minimum on/off (19.2.1.1) */
		put_error(b, q, EC_PROPERTY, E_WRITE_ACCESS_DENIED);
		return;
	}
	if (!val.context && val.number == PSD_BACTAG_NULL && val.len == 0)
		is_null = 1;
	else if (val.context || val.number != PSD_BACTAG_REAL || psd_bactag_real(&val, &v) != 0) {
		put_error(b, q, EC_PROPERTY, E_INVALID_DATA_TYPE);
		return;
	}
	if (!is_null && !(v >= 0.0f && v <= 100.0f)) {
		put_error(b, q, EC_PROPERTY, E_VALUE_OUT_OF_RANGE);
		return;
	}
	{
		struct psd_bacserve_zone *z = &m->zone[o.zone];
		double was = z->prio[prio - 1];
		z->prio[prio - 1] = is_null ? NAN : (double)v;
		if (m->apply && m->apply(m->user, o.zone) != 0) {
			z->prio[prio - 1] = was;
			put_error(b, q, EC_PROPERTY, E_WRITE_ACCESS_DENIED);
			return;
		}
	}
	{
		uint8_t h[3] = { 0x20, q->invoke, q->service };
		psd_bactag_put_raw(b, h, 3);
	}
}

/* SubscribeCOV (13.14): a subscription made, renewed or cancelled. */
static void subscribe_cov(struct psd_bacserve_model *m, const struct req *q, const uint8_t *src,
                          const uint8_t *npdu, size_t npdu_len, struct psd_bacbuf *b)
{
	size_t pos = 0;
	uint32_t pid, type, inst, life = 0;
	int rc, has_conf, has_life, confirmed = 0;
	struct psd_bactag t;
	struct psd_bacserve_sub *free_slot = NULL, *s = NULL;
	struct obj o;
	if ((rc = need_unsigned(q, &pos, 0, &pid)) || (rc = need_objectid(q, &pos, 1, &type, &inst))) {
		put_reject(b, q->invoke, (uint8_t)rc);
		return;
	}
	if ((has_conf = ctx_tag(q, &pos, 2, &t)) < 0 || (has_conf == 0 && (t.len != 1 || t.data[0] > 1))) {
		put_reject(b, q->invoke, R_INVALID_TAG);
		return;
	}
	has_conf = has_conf == 0;
	if (has_conf)
		confirmed = t.data[0];
	if ((has_life = opt_unsigned(q, &pos, 3, &life)) < 0) {
		put_reject(b, q->invoke, R_INVALID_TAG);
		return;
	}
	if (pos != q->n) {
		put_reject(b, q->invoke, R_TOO_MANY_ARGUMENTS);
		return;
	}
	if (has_life && !has_conf) {
		put_reject(b, q->invoke, R_MISSING_PARAMETER);
		return;
	}
	if (npdu_len > sizeof s->npdu)
		return;
	for (size_t i = 0; i < PSD_BACSERVE_SUBS; i++) {
		struct psd_bacserve_sub *x = &m->sub[i];
		if (!x->used) {
			if (!free_slot)
				free_slot = x;
		} else if (x->pid == pid && x->type == type && x->instance == inst &&
		           memcmp(x->addr, src, 6) == 0) {
			s = x;
		}
	}
	if (!has_conf) { /* a cancellation: done whether or not it was there */
		if (s)
			s->used = 0;
	} else {
		if (find(m, type, inst, &o) != 0) {
			put_error(b, q, EC_OBJECT, E_UNKNOWN_OBJECT);
			return;
		}
		if (o.type == PSD_BAC_DEVICE) {
			put_error(b, q, EC_OBJECT, E_NOT_SUPPORTED);
			return;
		}
		if (!s && !(s = free_slot)) {
			put_error(b, q, EC_RESOURCES, E_NO_SPACE_TO_ADD);
			return;
		}
		*s = (struct psd_bacserve_sub){ .used = 1,
			                        .pid = pid,
			                        .type = o.type,
			                        .instance = o.instance,
			                        .confirmed = confirmed,
			                        .npdu_len = npdu_len,
			                        .expires = life ? m->now + life : 0 };
		memcpy(s->addr, src, 6);
		memcpy(s->npdu, npdu, npdu_len);
	}
	{
		uint8_t h[3] = { 0x20, q->invoke, q->service };
		psd_bactag_put_raw(b, h, 3);
	}
}

/* Whole seconds left, rounded up; a sum's last bit (300.000000001) is not
 * a second more. */
static uint32_t remaining(double left)
{
	return left > 1e-6 ? (uint32_t)ceil(left - 1e-6) : 0;
}

int psd_bacserve_cov(struct psd_bacserve_model *m, uint8_t *out, struct psd_bacserve_reply *r)
{
	memset(r, 0, sizeof *r);
	for (size_t i = 0; i < PSD_BACSERVE_SUBS; i++) {
		struct psd_bacserve_sub *s = &m->sub[i];
		struct psd_bacbuf b;
		struct obj o;
		float pv;
		int fault;
		static const unsigned f[] = { 1 };
		if (!s->used)
			continue;
		if ((s->expires > 0 && m->now >= s->expires) || find(m, s->type, s->instance, &o) != 0) {
			s->used = 0; /* its lifetime ended, or its zone left at a reload */
			continue;
		}
		pv = present_value(m, &o);
		fault = in_fault(m, &o);
		if (s->sent && fault == s->last_fault &&
		    (pv == s->last_pv || (isnan(pv) && isnan(s->last_pv)) ||
		     fabsf(pv - s->last_pv) < cov_increment(&o)))
			continue;
		s->sent = 1, s->last_pv = pv, s->last_fault = fault;
		out[0] = 0x81, out[1] = 0x0a;
		memcpy(out + 4, s->npdu, s->npdu_len);
		b = (struct psd_bacbuf){ out + 4 + s->npdu_len, PSD_BACSERVE_MAX_APDU, 0, 0 };
		if (s->confirmed) {
			uint8_t h[4] = { 0x00, 0x05, m->invoke++, S_COV_NOTIFICATION };
			psd_bactag_put_raw(&b, h, 4);
		} else {
			uint8_t h[2] = { 0x10, U_COV_NOTIFICATION };
			psd_bactag_put_raw(&b, h, 2);
		}
		psd_bactag_put_unsigned(&b, 0, s->pid);
		psd_bactag_put_objectid(&b, 1, PSD_BAC_DEVICE, m->device);
		psd_bactag_put_objectid(&b, 2, s->type, s->instance);
		psd_bactag_put_unsigned(&b, 3, s->expires > 0 ? remaining(s->expires - m->now) : 0);
		psd_bactag_open(&b, 4);
		psd_bactag_put_enum(&b, 0, P_PRESENT_VALUE);
		psd_bactag_open(&b, 2);
		psd_bactag_put_real(&b, -1, pv);
		psd_bactag_close(&b, 2);
		psd_bactag_put_enum(&b, 0, P_STATUS_FLAGS);
		psd_bactag_open(&b, 2);
		put_bits(&b, f, fault ? 1 : 0, 4);
		psd_bactag_close(&b, 2);
		psd_bactag_close(&b, 4);
		r->len = 4 + s->npdu_len + b.len;
		out[2] = (uint8_t)(r->len >> 8), out[3] = (uint8_t)r->len;
		r->to = PSD_BACSERVE_TO_ADDRESS;
		memcpy(r->addr, s->addr, 6);
		return 1;
	}
	return 0;
}

/* Who-Is: 1 when this device is in its range (or it has none), 0 not,
 * -1 malformed. */
static int who_is_me(const struct psd_bacserve_model *m, const uint8_t *p, size_t n)
{
	struct req q = { p, n, 0, 0 };
	size_t pos = 0;
	uint32_t lo, hi;
	if (n == 0)
		return 1;
	if (need_unsigned(&q, &pos, 0, &lo) || need_unsigned(&q, &pos, 1, &hi) || pos != n ||
	    lo > MAX_INSTANCE || hi > MAX_INSTANCE)
		return -1;
	return m->device >= lo && m->device <= hi;
}

/* Who-Has (16.9): the I-Have for the object named by identifier or by
 * name, when this device is in the range (or there is none); nothing
 * when psensd has no such object or the request is malformed. */
static void who_has(const struct psd_bacserve_model *m, const uint8_t *p, size_t n, struct psd_bacbuf *b)
{
	struct req q = { p, n, 0, 0 };
	size_t pos = 0;
	uint32_t lo, hi, type, inst;
	int has_lo, has_hi;
	struct psd_bactag t;
	struct obj o;
	char name[128];
	if ((has_lo = opt_unsigned(&q, &pos, 0, &lo)) < 0 || (has_hi = opt_unsigned(&q, &pos, 1, &hi)) < 0 ||
	    has_lo != has_hi || (has_lo && (lo > MAX_INSTANCE || hi > MAX_INSTANCE)))
		return;
	if (has_lo && !(m->device >= lo && m->device <= hi))
		return;
	if (psd_bactag_read(p, n, &pos, &t) != 0 || pos != n || !t.context || t.opening || t.closing)
		return;
	if (t.number == 2) {
		if (psd_bactag_objectid(&t, &type, &inst) != 0 || find(m, type, inst, &o) != 0 ||
		    (o.type == PSD_BAC_DEVICE && inst != m->device))
			return;
	} else if (t.number == 3) { /* a character string in UTF-8 (set 0) */
		size_t i, count = nobjects(m);
		if (t.len < 1 || t.data[0] != 0)
			return;
		for (i = 0; i < count; i++) {
			object_at(m, i, &o);
			object_name(m, &o, name, sizeof name);
			if (strlen(name) == t.len - 1 && memcmp(name, t.data + 1, t.len - 1) == 0)
				break;
		}
		if (i == count)
			return;
	} else {
		return;
	}
	{
		uint8_t h[2] = { 0x10, U_I_HAVE };
		psd_bactag_put_raw(b, h, 2);
	}
	object_name(m, &o, name, sizeof name);
	psd_bactag_put_objectid(b, -1, PSD_BAC_DEVICE, m->device);
	psd_bactag_put_objectid(b, -1, o.type, o.instance);
	psd_bactag_put_string(b, -1, name);
}

/* The largest APDU the asker accepts (20.1.2.5); reserved codes: the least. */
static size_t max_apdu(uint8_t code)
{
	static const size_t len[6] = { 50, 128, 206, 480, 1024, 1476 };
	return code < 6 ? len[code] : 50;
}

/* The APDU apdu[0..n): the reply's APDU into b (nothing: b->len 0). */
static void apdu(struct psd_bacserve_model *m, const uint8_t *a, size_t n, int broadcast, const uint8_t *src,
                 const uint8_t *npdu, size_t npdu_len, struct psd_bacbuf *b)
{
	unsigned type;
	struct req q;
	size_t cap = b->cap;
	if (n < 2)
		return;
	type = a[0] >> 4;
	if (type == 1) { /* unconfirmed request */
		if (a[1] == U_WHO_IS && who_is_me(m, a + 2, n - 2) == 1) {
			uint8_t h[2] = { 0x10, U_I_AM };
			psd_bactag_put_raw(b, h, 2);
			psd_bactag_put_objectid(b, -1, PSD_BAC_DEVICE, m->device);
			psd_bactag_put_unsigned(b, -1, PSD_BACSERVE_MAX_APDU);
			psd_bactag_put_enum(b, -1, 3); /* no-segmentation */
			psd_bactag_put_unsigned(b, -1, m->vendor_id);
		} else if (a[1] == U_WHO_HAS) {
			who_has(m, a + 2, n - 2, b);
		}
		return;
	}
	/* only a confirmed request is answered; one sent to everyone is not
	 * (no amplified replies to a forged broadcast) */
	if (type != 0 || broadcast || n < 3)
		return;
	if (a[0] & 0x08) { /* segmented: refused (20.1.2.1), whatever follows */
		put_abort(b, a[2], A_SEGMENTATION_NOT_SUPPORTED);
		return;
	}
	if (n < 4)
		return;
	q = (struct req){ a + 4, n - 4, a[2], a[3] };
	if (max_apdu(a[1] & 15) < cap)
		b->cap = max_apdu(a[1] & 15);
	switch (q.service) {
	case S_READ_PROPERTY: read_property(m, &q, b); break;
	case S_READ_PROPERTY_MULTIPLE: read_property_multiple(m, &q, b); break;
	case S_WRITE_PROPERTY: write_property(m, &q, b); break;
	case S_SUBSCRIBE_COV: subscribe_cov(m, &q, src, npdu, npdu_len, b); break;
	default: put_reject(b, q.invoke, R_UNRECOGNIZED_SERVICE); break;
	}
	if (b->overflow) { /* longer than the asker takes: no segmentation */
		b->cap = cap;
		put_abort(b, q.invoke, A_SEGMENTATION_NOT_SUPPORTED);
	}
	b->cap = cap;
}

/* ---- BVLL and NPDU ----------------------------------------------------- */

void psd_bacserve_handle(struct psd_bacserve_model *m, const uint8_t *in, size_t n, const uint8_t src[6],
                         int broadcast, uint8_t *out, struct psd_bacserve_reply *r)
{
	size_t pos, snet_at = 0, h;
	unsigned fn, ctrl;
	struct psd_bacbuf b;
	memset(r, 0, sizeof *r);
	if (n < 4 || n > PSD_BACSERVE_MAX_PACKET || in[0] != 0x81 || ((size_t)in[2] << 8 | in[3]) != n)
		return;
	fn = in[1];
	pos = 4;
	switch (fn) {
	case 0x0a: /* Original-Unicast-NPDU */ r->to = PSD_BACSERVE_TO_SENDER; break;
	case 0x0b: /* Original-Broadcast-NPDU */
		r->to = PSD_BACSERVE_TO_SENDER;
		broadcast = 1;
		break;
	case 0x04: /* Forwarded-NPDU: a BBMD passes on a broadcast from addr */
		if (n < 10)
			goto none;
		memcpy(r->addr, in + 4, 6);
		src = r->addr;
		r->to = PSD_BACSERVE_TO_ADDRESS;
		broadcast = 1;
		pos = 10;
		break;
	case 0x01:
	case 0x02:
	case 0x05:
	case 0x06:
	case 0x08:
	case 0x09: {
		/* a BBMD's or foreign device's function psensd does not do: the
		 * BVLC-Result NAK for it (J.2.1), 0x0010 to 0x0060 */
		static const uint8_t nak[10] = {
			[1] = 0x10, [2] = 0x20, [5] = 0x30, [6] = 0x40, [8] = 0x50, [9] = 0x60
		};
		if (broadcast)
			return;
		out[0] = 0x81, out[1] = 0x00, out[2] = 0, out[3] = 6, out[4] = 0, out[5] = nak[fn];
		r->to = PSD_BACSERVE_TO_SENDER;
		r->len = 6;
		return;
	}
	default: /* results, acknowledgements, secure BVLL: nothing to say */ return;
	}
	/* the NPDU (clause 6.2) */
	if (n - pos < 2 || in[pos] != 1)
		goto none;
	ctrl = in[pos + 1];
	pos += 2;
	if (ctrl & 0x80 || ctrl & 0x50) /* a network-layer message, or reserved bits */
		goto none;
	if (ctrl & 0x20) { /* DNET: for another network unless a global broadcast */
		if (n - pos < 3 || ((unsigned)in[pos] << 8 | in[pos + 1]) != 0xffff)
			goto none;
		if (n - pos - 3 < in[pos + 2])
			goto none;
		pos += 3 + in[pos + 2];
		broadcast = 1;
	}
	if (ctrl & 0x08) { /* SNET: from another network, through a router */
		if (n - pos < 3 || in[pos + 2] == 0 || n - pos - 3 < in[pos + 2] || in[pos + 2] > 8 ||
		    ((unsigned)in[pos] << 8 | in[pos + 1]) == 0xffff)
			goto none;
		snet_at = pos;
		pos += 3 + in[pos + 2];
	}
	if (ctrl & 0x20) { /* the hop count */
		if (pos >= n)
			goto none;
		pos++;
	}
	/* the reply's NPDU: to the source network's address when it came
	 * through a router */
	out[0] = 0x81, out[1] = 0x0a;
	out[4] = 1;
	h = 6;
	if (snet_at) {
		size_t slen = in[snet_at + 2];
		out[5] = 0x20;
		memcpy(out + 6, in + snet_at, 3 + slen);
		h += 3 + slen;
		out[h++] = 255; /* hop count */
	} else {
		out[5] = 0;
	}
	b = (struct psd_bacbuf){ out + h, PSD_BACSERVE_MAX_APDU, 0, 0 };
	apdu(m, in + pos, n - pos, broadcast, src, out + 4, h - 4, &b);
	if (b.len == 0 || b.overflow)
		goto none;
	r->len = h + b.len;
	out[2] = (uint8_t)(r->len >> 8), out[3] = (uint8_t)r->len;
	return;
none:
	r->to = PSD_BACSERVE_NONE;
	r->len = 0;
}
