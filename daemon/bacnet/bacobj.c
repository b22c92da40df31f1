/* SPDX-License-Identifier: ISC */
/* The BACnet objects psensd serves and their properties (bacobj.h). */
#include "bacobj.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "bacconf.h"
#include "points.h"

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
	{ P_MAX_SEGMENTS_ACCEPTED, 1 },
	{ P_APDU_SEGMENT_TIMEOUT, 1 },
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
static const struct psd_bacobj_prop bi_props[] = {
	{ P_OBJECT_ID, 1 },      { P_OBJECT_NAME, 1 }, { P_OBJECT_TYPE, 1 },   { P_PRESENT_VALUE, 1 },
	{ P_STATUS_FLAGS, 1 },   { P_EVENT_STATE, 1 }, { P_OUT_OF_SERVICE, 1 }, { P_POLARITY, 1 },
	{ P_PROPERTY_LIST, 1 },  { P_DESCRIPTION, 0 },
};
static const struct psd_bacobj_prop msi_props[] = {
	{ P_OBJECT_ID, 1 },        { P_OBJECT_NAME, 1 },   { P_OBJECT_TYPE, 1 },    { P_PRESENT_VALUE, 1 },
	{ P_STATUS_FLAGS, 1 },     { P_EVENT_STATE, 1 },   { P_OUT_OF_SERVICE, 1 }, { P_NUMBER_OF_STATES, 1 },
	{ P_PROPERTY_LIST, 1 },    { P_STATE_TEXT, 0 },    { P_DESCRIPTION, 0 },
};
/* the Values: commandable (Priority_Array, Relinquish_Default, 19.2) */
static const struct psd_bacobj_prop av_props[] = {
	{ P_OBJECT_ID, 1 },        { P_OBJECT_NAME, 1 },        { P_OBJECT_TYPE, 1 },    { P_PRESENT_VALUE, 1 },
	{ P_STATUS_FLAGS, 1 },     { P_EVENT_STATE, 1 },        { P_OUT_OF_SERVICE, 1 }, { P_UNITS, 1 },
	{ P_PRIORITY_ARRAY, 1 },   { P_RELINQUISH_DEFAULT, 1 }, { P_PROPERTY_LIST, 1 },  { P_COV_INCREMENT, 0 },
	{ P_MIN_PRES_VALUE, 0 },   { P_MAX_PRES_VALUE, 0 },     { P_DESCRIPTION, 0 },
};
static const struct psd_bacobj_prop bv_props[] = {
	{ P_OBJECT_ID, 1 },      { P_OBJECT_NAME, 1 },        { P_OBJECT_TYPE, 1 },   { P_PRESENT_VALUE, 1 },
	{ P_STATUS_FLAGS, 1 },   { P_EVENT_STATE, 1 },        { P_OUT_OF_SERVICE, 1 }, { P_PRIORITY_ARRAY, 1 },
	{ P_RELINQUISH_DEFAULT, 1 }, { P_PROPERTY_LIST, 1 },  { P_DESCRIPTION, 0 },
};
static const struct psd_bacobj_prop msv_props[] = {
	{ P_OBJECT_ID, 1 },        { P_OBJECT_NAME, 1 },   { P_OBJECT_TYPE, 1 },    { P_PRESENT_VALUE, 1 },
	{ P_STATUS_FLAGS, 1 },     { P_EVENT_STATE, 1 },   { P_OUT_OF_SERVICE, 1 }, { P_NUMBER_OF_STATES, 1 },
	{ P_PRIORITY_ARRAY, 1 },   { P_RELINQUISH_DEFAULT, 1 }, { P_PROPERTY_LIST, 1 }, { P_STATE_TEXT, 0 },
	{ P_DESCRIPTION, 0 },
};
#define NPROPS(a) (sizeof(a) / sizeof(a)[0])

/* The point the Lighting Output shows: the commanded level. */
static int lo_point(void)
{
	static int p = -2;
	if (p == -2)
		p = psd_points_find("level");
	return p;
}

/* The BACnet type of point i: a writable one a Value, else an Input. */
static uint32_t type_of(size_t i)
{
	const struct psd_points_def *d = psd_points_def(i);
	if ((int)i == lo_point())
		return PSD_BAC_LO;
	if (d->writable)
		return d->kind == PSD_POINTS_BINARY       ? PSD_BAC_BV
		       : d->kind == PSD_POINTS_MULTISTATE ? PSD_BAC_MSV
		                                          : PSD_BAC_AV;
	return d->kind == PSD_POINTS_BINARY ? PSD_BAC_BI : d->kind == PSD_POINTS_MULTISTATE ? PSD_BAC_MSI : PSD_BAC_AI;
}

static int is_value(uint32_t type)
{
	return type == PSD_BAC_AV || type == PSD_BAC_BV || type == PSD_BAC_MSV;
}

int psd_bacobj_value_slot(size_t point)
{
	int k = 0;
	if (point >= psd_points_count() || !is_value(type_of(point)))
		return -1;
	for (size_t j = 0; j < point; j++)
		k += is_value(type_of(j));
	return k < PSD_BACSERVE_VALUES ? k : -1;
}

/* The [bacnet] writes bit that opens point i's Value to writes (0: none). */
static int write_bit(size_t i)
{
	static const struct {
		const char *key;
		int bit;
	} bits[] = { { "target_lux", PSD_BACCONF_TARGET },
		     { "daylighting", PSD_BACCONF_DAYLIGHTING },
		     { "vacancy_hold", PSD_BACCONF_VACANCY_HOLD } };
	for (size_t k = 0; k < sizeof bits / sizeof bits[0]; k++)
		if (!strcmp(psd_points_def(i)->key, bits[k].key))
			return bits[k].bit;
	return 0;
}

/* Point i's place among the points of its type (0-based). */
static uint32_t place_of(size_t i)
{
	uint32_t k = 0;
	for (size_t j = 0; j < i; j++)
		k += type_of(j) == type_of(i);
	return k;
}

static size_t npoints(void)
{
	size_t n = psd_points_count();
	return n < PSD_BACSERVE_POINTS ? n : PSD_BACSERVE_POINTS;
}

/* COV_Increment by unit: 1 %, 10 lx, 0.01 V, 0.1 h or kWh; 0 for a
 * binary or multi-state point (every change) */
float psd_bacobj_cov_increment(const struct psd_bacobj *o)
{
	const struct psd_points_def *d = psd_points_def((size_t)o->point);
	if (o->type == PSD_BAC_LO)
		return 1.0f;
	if (!d || !d->unit)
		return 0.0f;
	return !strcmp(d->unit, "lx") ? 10.0f : !strcmp(d->unit, "V") ? 0.01f : !strcmp(d->unit, "%") ? 1.0f : 0.1f;
}

/* Objects a zone has: its Lighting Output and one per other point. */
static size_t zone_objects(const struct psd_bacserve_zone *z)
{
	size_t n = 1;
	for (size_t i = 0; i < npoints(); i++)
		n += z->has[i] && (int)i != lo_point();
	return n;
}

size_t psd_bacobj_count(const struct psd_bacserve_model *m)
{
	size_t n = 1;
	for (size_t z = 0; z < m->nzone; z++)
		n += zone_objects(&m->zone[z]);
	return n;
}

static void set(struct psd_bacobj *o, size_t zone, size_t point)
{
	memset(o, 0, sizeof *o);
	o->zone = zone, o->point = (int)point, o->type = type_of(point);
	switch (o->type) {
	case PSD_BAC_LO:
		o->instance = (uint32_t)zone + 1, o->props = lo_props, o->nprops = NPROPS(lo_props);
		return;
	case PSD_BAC_BI: o->props = bi_props, o->nprops = NPROPS(bi_props); break;
	case PSD_BAC_MSI: o->props = msi_props, o->nprops = NPROPS(msi_props); break;
	case PSD_BAC_AV: o->props = av_props, o->nprops = NPROPS(av_props); break;
	case PSD_BAC_BV: o->props = bv_props, o->nprops = NPROPS(bv_props); break;
	case PSD_BAC_MSV: o->props = msv_props, o->nprops = NPROPS(msv_props); break;
	default: o->props = ai_props, o->nprops = NPROPS(ai_props); break;
	}
	o->instance = (uint32_t)(zone * PSD_BACSERVE_STRIDE + place_of(point) + 1);
}

/* The i-th object of Object_List (0: the Device; per zone its Lighting
 * Output, then its points in the table's order). */
void psd_bacobj_at(const struct psd_bacserve_model *m, size_t i, struct psd_bacobj *o)
{
	memset(o, 0, sizeof *o);
	o->point = -1;
	if (i == 0) {
		o->type = PSD_BAC_DEVICE, o->instance = m->device, o->props = device_props;
		o->nprops = NPROPS(device_props);
		return;
	}
	i--;
	for (size_t z = 0; z < m->nzone; z++) {
		size_t n = zone_objects(&m->zone[z]);
		if (i >= n) {
			i -= n;
			continue;
		}
		if (i == 0) {
			set(o, z, (size_t)lo_point());
			return;
		}
		for (size_t p = 0; p < npoints(); p++)
			if (m->zone[z].has[p] && (int)p != lo_point() && --i == 0) {
				set(o, z, p);
				return;
			}
	}
}

/* The object of a type and instance: 0 found. */
int psd_bacobj_find(const struct psd_bacserve_model *m, uint32_t type, uint32_t instance,
                    struct psd_bacobj *o)
{
	size_t z, k;
	if (type == PSD_BAC_DEVICE && (instance == m->device || instance == MAX_INSTANCE)) {
		psd_bacobj_at(m, 0, o);
		return 0;
	}
	if (type == PSD_BAC_LO && instance >= 1 && instance <= m->nzone) {
		set(o, instance - 1, (size_t)lo_point());
		return 0;
	}
	if ((type != PSD_BAC_AI && type != PSD_BAC_BI && type != PSD_BAC_MSI && !is_value(type)) || instance < 1)
		return -1;
	z = (instance - 1) / PSD_BACSERVE_STRIDE, k = (instance - 1) % PSD_BACSERVE_STRIDE;
	if (z >= m->nzone)
		return -1;
	for (size_t p = 0; p < npoints(); p++)
		if (type_of(p) == type && place_of(p) == k) {
			if (!m->zone[z].has[p])
				return -1;
			set(o, z, p);
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
	if (o->type == PSD_BAC_DEVICE)
		snprintf(s, n, "%s", m->name);
	else
		snprintf(s, n, "%s %s", m->zone[o->zone].name, psd_points_def((size_t)o->point)->name);
}

float psd_bacobj_present_value(const struct psd_bacserve_model *m, const struct psd_bacobj *o)
{
	const struct psd_bacserve_zone *z = &m->zone[o->zone];
	return o->type == PSD_BAC_LO ? (float)z->level : (float)z->pv[o->point];
}

/* A value of type's Present_Value (and of its Priority_Array, Relinquish_Default). */
static void put_typed(struct psd_bacbuf *b, uint32_t type, double v)
{
	if (type == PSD_BAC_BI || type == PSD_BAC_BV)
		psd_bactag_put_enum(b, -1, v == 1.0); /* BACnetBinaryPV: inactive 0, active 1 */
	else if (type == PSD_BAC_MSI || type == PSD_BAC_MSV)
		psd_bactag_put_unsigned(b, -1, v >= 1.0 && v < 4294967295.0 ? (uint32_t)v : 1);
	else
		psd_bactag_put_real(b, -1, (float)v);
}

void psd_bacobj_put_present_value(const struct psd_bacserve_model *m, const struct psd_bacobj *o,
                                  struct psd_bacbuf *b)
{
	float v = psd_bacobj_present_value(m, o);
	put_typed(b, o->type, v);
}

double psd_bacobj_actual_level(const struct psd_bacserve_model *m, const struct psd_bacobj *o)
{
	static int actual = -2;
	const struct psd_bacserve_zone *z = &m->zone[o->zone];
	if (actual == -2)
		actual = psd_points_find("level_actual");
	return actual >= 0 && actual < PSD_BACSERVE_POINTS && z->has[actual] && isfinite(z->pv[actual])
	               ? z->pv[actual]
	               : z->level;
}

/* In_Progress: a fade-to or ramp-to whose level the lamps have not reached
 * (within 0.5 %) */
static uint32_t in_progress(const struct psd_bacserve_model *m, const struct psd_bacobj *o)
{
	const struct psd_bacserve_zone *z = &m->zone[o->zone];
	if ((z->lc_op != LC_FADE_TO && z->lc_op != LC_RAMP_TO) || !(fabs(z->prio[z->lc_prio - 1] - z->lc_target) < 1e-9) ||
	    fabs(psd_bacobj_actual_level(m, o) - z->lc_target) < 0.5)
		return IP_IDLE;
	return z->lc_op == LC_FADE_TO ? IP_FADE_ACTIVE : IP_RAMP_ACTIVE;
}

/* Status_Flags' fault: the zone at its safe level, or a reading missing */
int psd_bacobj_fault(const struct psd_bacserve_model *m, const struct psd_bacobj *o)
{
	const struct psd_bacserve_zone *z = &m->zone[o->zone];
	return z->fault || (o->type != PSD_BAC_LO && isnan(z->pv[o->point]));
}

/* The range a write to point i's Value must keep to: the point's, the
 * target's narrowed by the configuration. */
static void range_of(const struct psd_bacserve_model *m, size_t i, double *lo, double *hi)
{
	const struct psd_points_def *d = psd_points_def(i);
	*lo = d->min, *hi = d->max;
	if (write_bit(i) == PSD_BACCONF_TARGET && m->target_max > m->target_min) {
		*lo = fmax(*lo, m->target_min);
		*hi = fmin(*hi, m->target_max);
	}
}

/* Encode one array element (idx 1..) or, idx 0, the whole array; -1 when idx
 * is past its end. */
static int put_array(const struct psd_bacserve_model *m, const struct psd_bacobj *o, uint32_t prop,
                     int has_idx, uint32_t idx, struct psd_bacbuf *b)
{
	size_t count = prop == P_OBJECT_LIST      ? psd_bacobj_count(m)
	               : prop == P_PRIORITY_ARRAY ? PSD_BACSERVE_PRIORITIES
	               : prop == P_STATE_TEXT     ? psd_points_nstates((size_t)o->point)
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
			int slot = psd_bacobj_value_slot((size_t)o->point);
			double v = o->type == PSD_BAC_LO ? m->zone[o->zone].prio[i]
			           : slot >= 0          ? m->zone[o->zone].vprio[slot][i]
			                                : NAN;
			if (isnan(v))
				psd_bactag_put_null(b, -1);
			else
				put_typed(b, o->type, v);
		} else if (prop == P_STATE_TEXT) {
			psd_bactag_put_string(b, -1, psd_points_def((size_t)o->point)->states[i]);
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
	if (prop == P_OBJECT_LIST || prop == P_PRIORITY_ARRAY || prop == P_PROPERTY_LIST || prop == P_STATE_TEXT) {
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
		else
			snprintf(name, sizeof name, "zone %s: %s", z->name,
			         psd_points_def((size_t)o->point)->description);
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
		/* analog-input 0, analog-value 2, binary-input 3, binary-value 5,
		 * device 8, multi-state-input 13, multi-state-value 19,
		 * lighting-output 54; 55 bits at revision 14 */
		static const unsigned t[] = { PSD_BAC_AI,  PSD_BAC_AV,  PSD_BAC_BI, PSD_BAC_BV,
			                      PSD_BAC_DEVICE, PSD_BAC_MSI, PSD_BAC_MSV, PSD_BAC_LO };
		put_bits(b, t, NPROPS(t), 55);
		break;
	}
	case P_MAX_APDU: psd_bactag_put_unsigned(b, -1, PSD_BACSERVE_MAX_APDU); break;
	case P_SEGMENTATION:
		psd_bactag_put_enum(b, -1, 1); /* segmented-transmit (bacseg.h) */
		break;
	/* segmented requests are refused: one segment, the whole APDU */
	case P_MAX_SEGMENTS_ACCEPTED: psd_bactag_put_unsigned(b, -1, 1); break;
	case P_APDU_SEGMENT_TIMEOUT: psd_bactag_put_unsigned(b, -1, PSD_BACSEG_TIMEOUT_MS); break;
	case P_APDU_TIMEOUT: psd_bactag_put_unsigned(b, -1, 3000); break;
	case P_APDU_RETRIES: psd_bactag_put_unsigned(b, -1, PSD_BACSEG_RETRIES); break;
	case P_DEVICE_ADDRESS_BINDING: break; /* an empty list: psensd binds to no other device */
	case P_DATABASE_REVISION: psd_bactag_put_unsigned(b, -1, m->database_revision); break;
	case P_PRESENT_VALUE:
	case P_TRACKING_VALUE: psd_bacobj_put_present_value(m, o, b); break;
	case P_POLARITY: psd_bactag_put_enum(b, -1, 0); break; /* normal */
	case P_NUMBER_OF_STATES:
		psd_bactag_put_unsigned(b, -1, (uint32_t)psd_points_nstates((size_t)o->point));
		break;
	case P_RELINQUISH_DEFAULT:
		if (is_value(o->type)) {
			int slot = psd_bacobj_value_slot((size_t)o->point);
			put_typed(b, o->type, slot >= 0 ? z->vdef[slot] : z->pv[o->point]);
		} else
			psd_bactag_put_real(b, -1, (float)z->level);
		break;
	case P_MIN_PRES_VALUE:
	case P_MAX_PRES_VALUE: {
		double lo, hi;
		range_of(m, (size_t)o->point, &lo, &hi);
		psd_bactag_put_real(b, -1, (float)(prop == P_MIN_PRES_VALUE ? lo : hi));
		break;
	}
	case P_LIGHTING_COMMAND: /* the last one taken (none at first) */
		psd_bactag_put_enum(b, 0, z->lc_op);
		if (z->lc_op == LC_FADE_TO || z->lc_op == LC_RAMP_TO)
			psd_bactag_put_real(b, 1, (float)z->lc_target);
		if (z->lc_op != LC_NONE)
			psd_bactag_put_unsigned(b, 5, z->lc_prio);
		break;
	case P_IN_PROGRESS: psd_bactag_put_enum(b, -1, in_progress(m, o)); break;
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
	case P_UNITS: psd_bactag_put_enum(b, -1, psd_points_def((size_t)o->point)->bacnet_units); break;
	case P_COV_INCREMENT: psd_bactag_put_real(b, -1, psd_bacobj_cov_increment(o)); break;
	default: *ec = EC_PROPERTY, *code = E_UNKNOWN_PROPERTY; return -1;
	}
	return 0;
}

int psd_bacobj_write_value(struct psd_bacserve_model *m, const struct psd_bacobj *o, uint32_t prop, int has_idx,
                           uint32_t prio, const struct psd_bactag *val, uint32_t *ec, uint32_t *code)
{
	struct psd_bacserve_zone *z;
	int slot = o->point >= 0 ? psd_bacobj_value_slot((size_t)o->point) : -1;
	double v = NAN, was, lo, hi;
	int is_null;
	uint32_t u;
	float f;
	*ec = EC_PROPERTY;
	if (slot < 0 || prop != P_PRESENT_VALUE || !(m->writes & write_bit((size_t)o->point))) {
		*code = E_WRITE_ACCESS_DENIED;
		return -1;
	}
	if (has_idx) {
		*code = E_NOT_AN_ARRAY;
		return -1;
	}
	if (prio < 1 || prio > PSD_BACSERVE_PRIORITIES) {
		*ec = EC_SERVICES, *code = E_PARAMETER_OUT_OF_RANGE;
		return -1;
	}
	if (prio == 6 && o->type == PSD_BAC_BV) { /* minimum on/off's (19.2.1.1): psensd has none */
		*code = E_WRITE_ACCESS_DENIED;
		return -1;
	}
	*code = E_INVALID_DATA_TYPE;
	is_null = !val->context && val->number == PSD_BACTAG_NULL && val->len == 0;
	if (is_null)
		v = NAN; /* relinquish: NAN is the priority array's empty slot */
	else if (val->context)
		return -1;
	else if (o->type == PSD_BAC_AV) {
		if (val->number != PSD_BACTAG_REAL || psd_bactag_real(val, &f) != 0)
			return -1;
		v = f;
	} else if (o->type == PSD_BAC_BV) {
		if (val->number != PSD_BACTAG_ENUM || psd_bactag_unsigned(val, &u) != 0)
			return -1;
		v = u;
	} else {
		if (val->number != PSD_BACTAG_UNSIGNED || psd_bactag_unsigned(val, &u) != 0)
			return -1;
		v = u;
	}
	range_of(m, (size_t)o->point, &lo, &hi);
	/* a REAL NaN or infinity is no value (a BMS forwarding a failed
	 * reading); NaN would otherwise pass for the empty slot, a relinquish */
	if (!is_null && !(isfinite(v) && v >= lo && v <= hi)) {
		*code = E_VALUE_OUT_OF_RANGE;
		return -1;
	}
	z = &m->zone[o->zone];
	was = z->vprio[slot][prio - 1];
	/* the same value at the same priority (a BMS re-commanding its
	 * points): acknowledged, nothing applied, logged or sent */
	if (was == v || (isnan(was) && isnan(v)))
		return 0;
	z->vprio[slot][prio - 1] = v;
	if (m->apply_value && m->apply_value(m->user, o->zone, (size_t)o->point) != 0) {
		z->vprio[slot][prio - 1] = was;
		*code = E_WRITE_ACCESS_DENIED;
		return -1;
	}
	return 0;
}
