/* SPDX-License-Identifier: ISC */
/* Fuzz the DALI commissioning jobs (drivers/dali_commission.c) with any
 * bus: the first bytes choose a job and its parameters, the rest are the
 * outcomes of its transactions (no answer, an answer and its value, a
 * garbled frame, an interface failure) and the time that passes.  Checks
 * the jobs' promises: frames are 16 bits, waits are finite, a job that has
 * ended asks for nothing, no two ballasts are given one short address, and
 * the report is JSON. */
#include <json-c/json.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "dali_commission.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static struct ps_dali_commission c;

static int start(const uint8_t *p, double now)
{
	struct ps_dali_addr t[3] = { { PS_DALI_GROUP, p[1] & 15 }, { PS_DALI_SHORT, p[2] & 63 }, { PS_DALI_BROADCAST, 0 } };
	static const char *const names[3] = { "a", "b", "c" };
	switch (p[0] % 5) {
	case 0: return ps_dali_commission_scan(&c, now);
	case 1: return ps_dali_commission_address(&c, p[1] & 1, now);
	case 2: return ps_dali_commission_group(&c, &t[p[2] % 3], p[1] & 15, p[3] & 1, now);
	case 3: return ps_dali_commission_identify(&c, p[1] & 63, 1 + p[2] % 4, now);
	default: return ps_dali_commission_verify(&c, t, names, 1 + p[3] % 3, 254, p[1] % 254, now);
	}
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	double now = 100, until;
	struct ps_dali_tx tx;
	size_t i = 4;
	json_object *o;
	if (size < 4 || start(data, now) != 0)
		return 0;
	while (i + 1 < size) {
		int r = ps_dali_commission_next(&c, &tx, &until);
		if (r == PS_DALI_NEXT_NONE)
			break;
		if (r == PS_DALI_NEXT_WAIT) {
			if (isnan(until) || until > now + 1000)
				abort();
			now = fmax(now, until);
			ps_dali_commission_poll(&c, now);
			continue;
		}
		if (tx.frame > 0xFFFF || (tx.twice != 0 && tx.twice != 1))
			abort();
		/* byte i: outcome (low 2 bits) and time passing (high bits, up to 8 min) */
		now += (data[i] >> 2) * 8.0;
		if (data[i] == 0xFF)
			ps_dali_commission_abort(&c, now);
		ps_dali_commission_result(&c, now, data[i] & 3, data[i + 1], "fuzz");
		i += 2;
	}
	if (c.state == PS_DALI_COMMISSION_RUNNING && size > 4 && data[3] == 0x55)
		ps_dali_commission_fail(&c, now, "fuzz");
	if (c.state != PS_DALI_COMMISSION_RUNNING && ps_dali_commission_next(&c, &tx, &until) != PS_DALI_NEXT_NONE)
		abort();
	for (int a = 0; a < c.nfound && a < 64; a++)
		for (int b = a + 1; b < c.nfound && b < 64; b++)
			if (c.found[a].address >= 0 && c.found[a].address == c.found[b].address)
				abort();
	o = json_object_new_object();
	ps_dali_commission_json(&c, now, o);
	if (!json_object_to_json_string(o))
		abort();
	json_object_put(o);
	return 0;
}
