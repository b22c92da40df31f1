/* SPDX-License-Identifier: ISC */
/* The BACnet objects psensd serves (doc/bacnet-pics.md): the Device, per
 * zone a Lighting Output (the point model's "level") and one object per
 * other point the zone has (daemon/points.h): an Analog Input for an
 * analog point, a Binary Input for a binary one, a Multi-state Input for a
 * multi-state one, and for a writable point the Value of its kind
 * (commandable: a priority array), instance 100 x zone index + the point's
 * place among the points of its BACnet type + 1; their properties (which are required, which
 * optional) and the encoding of each property's value from the model
 * (bacserve.h).  The numbers are ANSI/ASHRAE 135's: object
 * types, property identifiers, error classes and codes (clauses 18, 21). */
#ifndef PSD_BACOBJ_H
#define PSD_BACOBJ_H

#include <stddef.h>
#include <stdint.h>

#include "bacserve.h"
#include "bactag.h"

/* property identifiers (BACnetPropertyIdentifier) */
enum {
	P_APDU_SEGMENT_TIMEOUT = 10,
	P_APDU_TIMEOUT = 11,
	P_COV_INCREMENT = 22,
	P_APP_SW_VERSION = 12,
	P_DESCRIPTION = 28,
	P_DEVICE_ADDRESS_BINDING = 30,
	P_EVENT_STATE = 36,
	P_FIRMWARE_REVISION = 44,
	P_ALL = 8,
	P_MAX_APDU = 62,
	P_MAX_PRES_VALUE = 65,
	P_MIN_PRES_VALUE = 69,
	P_MODEL_NAME = 70,
	P_NUMBER_OF_STATES = 74,
	P_APDU_RETRIES = 73,
	P_OBJECT_ID = 75,
	P_OBJECT_LIST = 76,
	P_OBJECT_NAME = 77,
	P_OBJECT_TYPE = 79,
	P_OPTIONAL = 80,
	P_OUT_OF_SERVICE = 81,
	P_POLARITY = 84,
	P_PRESENT_VALUE = 85,
	P_PRIORITY_ARRAY = 87,
	P_OBJECT_TYPES_SUPPORTED = 96,
	P_SERVICES_SUPPORTED = 97,
	P_PROTOCOL_VERSION = 98,
	P_RELINQUISH_DEFAULT = 104,
	P_REQUIRED = 105,
	P_SEGMENTATION = 107,
	P_STATE_TEXT = 110,
	P_STATUS_FLAGS = 111,
	P_SYSTEM_STATUS = 112,
	P_UNITS = 117,
	P_VENDOR_ID = 120,
	P_VENDOR_NAME = 121,
	P_PROTOCOL_REVISION = 139,
	P_DATABASE_REVISION = 155,
	P_TRACKING_VALUE = 164,
	P_MAX_SEGMENTS_ACCEPTED = 167,
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

/* error classes and codes (clause 18) */
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
enum { PROTOCOL_REVISION = 14, MAX_INSTANCE = 4194303 };
/* BACnetLightingOperation (12.54.8) and BACnetLightingInProgress */
enum {
	LC_NONE = 0,
	LC_FADE_TO = 1,
	LC_RAMP_TO = 2,
	LC_STEP_UP = 3,
	LC_STEP_DOWN = 4,
	LC_STEP_ON = 5,
	LC_STEP_OFF = 6,
	LC_STOP = 10
};
enum { IP_IDLE = 0, IP_FADE_ACTIVE = 1, IP_RAMP_ACTIVE = 2 };

struct psd_bacobj_prop {
	uint32_t id;
	int required;
};

/* An object of the model: its type, instance, zone and point. */
struct psd_bacobj {
	uint32_t type, instance;
	size_t zone;
	int point; /* the point model's index (psd_points_def); -1: the Device */
	const struct psd_bacobj_prop *props;
	size_t nprops;
};

/* Objects in Object_List (the Device first). */
size_t psd_bacobj_count(const struct psd_bacserve_model *m);
/* The i-th object of Object_List. */
void psd_bacobj_at(const struct psd_bacserve_model *m, size_t i, struct psd_bacobj *o);
/* The object of a type and instance (the Device also as 4194303): 0 found, -1 none. */
int psd_bacobj_find(const struct psd_bacserve_model *m, uint32_t type, uint32_t instance,
                    struct psd_bacobj *o);
/* 1 when o has the property. */
int psd_bacobj_has(const struct psd_bacobj *o, uint32_t id);
/* Its Object_Name into s. */
void psd_bacobj_name(const struct psd_bacserve_model *m, const struct psd_bacobj *o, char *s, size_t n);
/* A zone object's Present_Value (a Binary Input's 0 or 1, a Multi-state
 * Input's state 1..n), COV_Increment (0: any change), and Status_Flags'
 * fault. */
float psd_bacobj_present_value(const struct psd_bacserve_model *m, const struct psd_bacobj *o);
/* Its Present_Value encoded as the type has it (REAL, enumerated, unsigned). */
void psd_bacobj_put_present_value(const struct psd_bacserve_model *m, const struct psd_bacobj *o,
                                  struct psd_bacbuf *b);
float psd_bacobj_cov_increment(const struct psd_bacobj *o);
int psd_bacobj_fault(const struct psd_bacserve_model *m, const struct psd_bacobj *o);
/* A Lighting Output's zone's light level as the lamps have it (the point
 * model's actual level; the commanded one when the zone has none), %. */
double psd_bacobj_actual_level(const struct psd_bacserve_model *m, const struct psd_bacobj *o);
/* Point i's place among the Values (their priority arrays in the model's
 * zones, bacserve.h), -1 when it is not a Value. */
int psd_bacobj_value_slot(size_t point);
/* A WriteProperty of prop of o (a Value), array index or not (has_idx), at
 * priority prio (1-16) of the one application-tagged datum val (NULL:
 * relinquish): the priority array set and applied (m->apply_value): 0, or
 * -1 with the error class and code (write-access-denied: not a Value's
 * Present_Value, not opened by [bacnet] writes, priority 6 of a Binary
 * Value, or the engine refused; value-out-of-range: outside the point's
 * range; invalid-data-type) and nothing changed. */
int psd_bacobj_write_value(struct psd_bacserve_model *m, const struct psd_bacobj *o, uint32_t prop, int has_idx,
                           uint32_t prio, const struct psd_bactag *val, uint32_t *ec, uint32_t *code);
/* Status_Flags: in-alarm, fault, overridden, out-of-service (fault alone set or not). */
void psd_bacobj_put_status_flags(struct psd_bacbuf *b, int fault);
/* Encode the value of o's property (the whole array, or with has_idx
 * element idx, 0 the count): 0, or -1 with an error class and code and
 * nothing written. */
int psd_bacobj_read(const struct psd_bacserve_model *m, const struct psd_bacobj *o, uint32_t prop,
                    int has_idx, uint32_t idx, struct psd_bacbuf *b, uint32_t *ec, uint32_t *code);

#endif
