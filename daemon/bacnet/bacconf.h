/* SPDX-License-Identifier: ISC */
/* The [bacnet] section of psensd.conf (psensd.conf(5) [bacnet]):
 * where the BACnet/IP server listens, who the device is, and what a BMS
 * may write.  Read and judged with the rest of the file (every error as
 * file:line).  A file with no [bacnet] section leaves `enabled` 0: psensd
 * then opens no socket. */
#ifndef PSD_BACCONF_H
#define PSD_BACCONF_H

#include "conf.h"

/* what a BMS may write (`writes`, any of them): bits */
enum {
	PSD_BACCONF_NONE = 0,
	PSD_BACCONF_LIGHTING_OUTPUT = 1, /* the Lighting Outputs' level */
	PSD_BACCONF_TARGET = 2,          /* the target lux (Analog Value) */
	PSD_BACCONF_DAYLIGHTING = 4,     /* daylight control on or off (Binary Value) */
	PSD_BACCONF_VACANCY_HOLD = 8,    /* the vacancy hold, s (Analog Value) */
};

struct psd_bacnet_conf {
	int enabled;    /* a [bacnet] section is there */
	int line;       /* its line */
	char bind[64];  /* the IPv4 address to listen on (0.0.0.0: every interface) */
	long port;      /* UDP, default 47808 (0xBAC0) */
	long instance;  /* the Device object's instance, 0 - 4194302 */
	char name[64];  /* its Object_Name */
	long vendor_id; /* Vendor_Identifier, default 65535 (none assigned) */
	int writes;     /* PSD_BACCONF_* bits */
	double hold;    /* s: a written level's override lasts this long, renewed while written */
	double target_min, target_max; /* lx: the target lux a BMS may write */
	double rate;    /* datagrams a second one source may send (and as many at once) */
	int bbmd;       /* register as a foreign device with a BBMD */
	char bbmd_host[64]; /* its IPv4 address */
	long bbmd_port; /* its UDP port, default 47808 */
	long bbmd_ttl;  /* s: the registration's Time-to-Live, renewed at half of it */
};

/* Read [bacnet] of c into b (errors go to c). */
void psd_bacconf_load(struct psd_bacnet_conf *b, struct ps_conf *c);

#endif
