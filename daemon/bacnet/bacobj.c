/* SPDX-License-Identifier: ISC */
/* The BACnet objects psensd serves and their properties (bacobj.h). */
#include "bacobj.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* the properties of each object type; 1: required, 0: optional */
static const struct psd_bacobj_prop device_props[] = {
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
static const struct psd_bacobj_prop lo_props[] = {
	{ P_OBJECT_ID, 1 },         { P_OBJECT_NAME, 1 },        { P_OBJECT_TYPE, 1 },
	{ P_PRESENT_VALUE, 1 },     { P_TRACKING_VALUE, 1 },     { P_LIGHTING_COMMAND, 1 },
	{ P_IN_PROGRESS, 1 },       { P_STATUS_FLAGS, 1 },       { P_OUT_OF_SERVICE, 1 },
	{ P_BLINK_WARN_ENABLE, 1 }, { P_EGRESS_TIME, 1 },        { P_EGRESS_ACTIVE, 1 },
	{ P_DEFAULT_FADE_TIME, 1 }, { P_DEFAULT_RAMP_RATE, 1 },  { P_DEFAULT_STEP_INCREMENT, 1 },
	{ P_PRIORITY_ARRAY, 1 },    { P_RELINQUISH_DEFAULT, 1 }, { P_LIGHTING_COMMAND_DEFAULT_PRIORITY, 1 },
	{ P_PROPERTY_LIST, 1 },     { P_EVENT_STATE, 0 },        { P_DESCRIPTION, 0 },
	{ P_COV_INCREMENT, 0 },
};
static const struct psd_bacobj_prop ai_props[] = {
	{ P_OBJECT_ID, 1 },     { P_OBJECT_NAME, 1 },   { P_OBJECT_TYPE, 1 },    { P_PRESENT_VALUE, 1 },
	{ P_STATUS_FLAGS, 1 },  { P_EVENT_STATE, 1 },   { P_OUT_OF_SERVICE, 1 }, { P_UNITS, 1 },
	{ P_PROPERTY_LIST, 1 }, { P_COV_INCREMENT, 1 }, { P_DESCRIPTION, 0 },
};
#define NPROPS(a) (sizeof(a) / sizeof(a)[0])

static const char *const ai_what[PSD_BACSERVE_AI_PER_ZONE] = { "estimated task illuminance", "sensor signal",
	                                                       "target task illuminance" };
static const uint32_t ai_units[PSD_BACSERVE_AI_PER_ZONE] = { 37 /* luxes */, 5 /* volts */, 37 };

/* COV_Increment: a Lighting Output's 1 %, the Analog Inputs' 10 lx, 0.01 V, 1 lx */
float psd_bacobj_cov_increment(const struct psd_bacobj *o)
{
	static const float ai[PSD_BACSERVE_AI_PER_ZONE] = { 10.0f, 0.01f, 1.0f };
	return o->type == PSD_BAC_LO ? 1.0f : ai[o->ai];
}

size_t psd_bacobj_count(const struct psd_bacserve_model *m)
{
	return 1 + m->nzone * (1 + PSD_BACSERVE_AI_PER_ZONE);
}

/* The i-th object of Object_List (0: the Device). */
void psd_bacobj_at(const struct psd_bacserve_model *m, size_t i, struct psd_bacobj *o)
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
int psd_bacobj_find(const struct psd_bacserve_model *m, uint32_t type, uint32_t instance,
                    struct psd_bacobj *o)
{
	if (type == PSD_BAC_DEVICE && (instance == m->device || instance == MAX_INSTANCE)) {
		psd_bacobj_at(m, 0, o);
		return 0;
	}
	if (type == PSD_BAC_LO && instance >= 1 && instance <= m->nzone) {
		psd_bacobj_at(m, 1 + (instance - 1) * (1 + PSD_BACSERVE_AI_PER_ZONE), o);
		return 0;
	}
	if (type == PSD_BAC_AI && instance >= 1 && instance <= m->nzone * PSD_BACSERVE_AI_PER_ZONE) {
		size_t z = (instance - 1) / PSD_BACSERVE_AI_PER_ZONE,
		       k = (instance - 1) % PSD_BACSERVE_AI_PER_ZONE;
		psd_bacobj_at(m, 1 + z * (1 + PSD_BACSERVE_AI_PER_ZONE) + 1 + k, o);
		return 0;
	}
	return -1;
}

int psd_bacobj_has(const struct psd_bacobj *o, uint32_t id)
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

void psd_bacobj_put_status_flags(struct psd_bacbuf *b, int fault)
{
	/* in-alarm, fault, overridden, out-of-service */
	static const unsigned f[] = { 1 };
	put_bits(b, f, fault ? 1 : 0, 4);
}

void psd_bacobj_name(const struct psd_bacserve_model *m, const struct psd_bacobj *o, char *s, size_t n)
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

float psd_bacobj_present_value(const struct psd_bacserve_model *m, const struct psd_bacobj *o)
{
	const struct psd_bacserve_zone *z = &m->zone[o->zone];
	return o->type == PSD_BAC_LO ? (float)z->level : ai_value(z, o->ai);
}

/* Status_Flags' fault: the zone at its safe level, or a reading missing */
int psd_bacobj_fault(const struct psd_bacserve_model *m, const struct psd_bacobj *o)
{
	const struct psd_bacserve_zone *z = &m->zone[o->zone];
	return z->fault || (o->type == PSD_BAC_AI && o->ai < 2 && !isfinite(ai_value(z, o->ai)));
}

/* Encode one array element (idx 1..) or, idx 0, the whole array; -1 when idx
 * is past its end. */
static int put_array(const struct psd_bacserve_model *m, const struct psd_bacobj *o, uint32_t prop,
                     int has_idx, uint32_t idx, struct psd_bacbuf *b)
{
	size_t count = prop == P_OBJECT_LIST      ? psd_bacobj_count(m)
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
			struct psd_bacobj e;
			psd_bacobj_at(m, i, &e);
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
int psd_bacobj_read(const struct psd_bacserve_model *m, const struct psd_bacobj *o, uint32_t prop,
                    int has_idx, uint32_t idx, struct psd_bacbuf *b, uint32_t *ec, uint32_t *code)
{
	const struct psd_bacserve_zone *z = o->type == PSD_BAC_DEVICE ? NULL : &m->zone[o->zone];
	char name[128];
	if (!psd_bacobj_has(o, prop)) {
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
		psd_bacobj_name(m, o, name, sizeof name);
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
	case P_TRACKING_VALUE: psd_bactag_put_real(b, -1, psd_bacobj_present_value(m, o)); break;
	case P_RELINQUISH_DEFAULT: psd_bactag_put_real(b, -1, (float)z->level); break;
	case P_LIGHTING_COMMAND:
		psd_bactag_put_enum(b, 0, 0); /* BACnetLightingCommand, operation none */
		break;
	case P_IN_PROGRESS:
		psd_bactag_put_enum(b, -1, 0); /* idle */
		break;
	case P_STATUS_FLAGS: psd_bacobj_put_status_flags(b, psd_bacobj_fault(m, o)); break;
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
	case P_COV_INCREMENT: psd_bactag_put_real(b, -1, psd_bacobj_cov_increment(o)); break;
	default: *ec = EC_PROPERTY, *code = E_UNKNOWN_PROPERTY; return -1;
	}
	return 0;
}
