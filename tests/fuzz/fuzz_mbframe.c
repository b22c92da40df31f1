/* SPDX-License-Identifier: ISC */
/* Fuzz the Modbus server psvirt runs on: the bytes a client sends, framed
 * as Modbus TCP or RTU (daemon/psvirt/mbframe.c) and answered by the PDU handler
 * (daemon/psvirt/mbpdu.c) from psvirt's register map over three zones' rooms
 * (daemon/psvirt/virtmap.c, virtroom.c).  The first byte chooses the framing, the
 * line's silence and the rooms' time of day; the rest is the stream.
 * Invariants: every frame found lies inside the input and has the length
 * its header says; every reply is 2 to 253 bytes and answers the request's
 * function (or its exception); every run the map is asked for lies inside
 * its table; a refused TCP frame ends the stream, as the server closes the
 * connection; on RTU a byte that starts no frame is dropped. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "mbframe.h"
#include "mbpdu.h"
#include "results.h"
#include "scene.h"
#include "virtmap.h"
#include "virtroom.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static struct psd_virtroom *rooms[3];

static void make_rooms(void)
{
	static struct ps_result_cond cond[2];
	static struct ps_results res;
	static struct ps_opt o[] = { { "gain", "0.5", 1, 0 }, { "noise", "0.002", 2, 0 },
	                             { "faults", "open 11:00-12:00, drop 13:00-14:00, late 14:00-15:00", 3, 0 } };
	struct ps_opts opts = { o, 3, "fuzz" };
	struct psd_virtday day = { .res = &res, .date = "03-18", .sunrise = 6 * 3600.0, .sunset = 18.5 * 3600.0 };
	char err[256];
	cond[0] = (struct ps_result_cond){ "day", PS_COND_DAYLIGHT, "03-18", 43200, 1, 5.07, 6.69, 1197.6, 236.2, 0 };
	cond[1] = (struct ps_result_cond){ "elec", PS_COND_ELECTRIC, "", -1, 1, 1.094, 7.07, 1265.4, 1156.7, 0 };
	res.cond = cond;
	res.ncond = 2;
	ps_results_summarise(&res);
	for (int k = 0; k < 3; k++)
		if (!(rooms[k] = psd_virtroom_new(&day, &opts, 6 * 3600.0, err, sizeof err)))
			abort();
}

/* the map's callbacks, checked and passed on */
static const struct psd_mbmap *inner;

static int checked_read(void *user, int table, unsigned addr, unsigned count, uint16_t *v)
{
	if (table < 0 || table >= PSD_MB_TABLES || count < 1 || addr + count > inner->size[table])
		abort();
	return inner->read(user, table, addr, count, v);
}

static int checked_write(void *user, int table, unsigned addr, unsigned count, const uint16_t *v)
{
	if ((table != PSD_MB_COILS && table != PSD_MB_HOLDING) || count < 1 || addr + count > inner->size[table])
		abort();
	return inner->write(user, table, addr, count, v);
}

static void answer(const struct psd_mbmap *m, const struct psd_mbadu *adu, const uint8_t *lo, const uint8_t *hi)
{
	uint8_t out[PSD_MBPDU_MAX];
	struct psd_mbspan sp[2];
	size_t n;
	if (adu->pdu < lo || adu->pdu + adu->npdu > hi || adu->npdu < 1 || adu->npdu > PSD_MBPDU_MAX)
		abort();
	psd_mbpdu_spans(adu->pdu, adu->npdu, sp);
	n = psd_mbpdu_reply(m, adu->pdu, adu->npdu, out);
	if (n < 2 || n > PSD_MBPDU_MAX || (out[0] & 0x7f) != (adu->pdu[0] & 0x7f))
		abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	static struct psd_virtmap map;
	struct psd_mbmap mb, outer;
	struct psd_mbadu adu;
	const char *why;
	size_t at = 1;
	if (!rooms[0])
		make_rooms();
	if (size < 1)
		return 0;
	if ((data[0] & 1) && size > 1 + 2 * PSD_MBFRAME_RTU_MAX)
		size = 1 + 2 * PSD_MBFRAME_RTU_MAX;   /* the server's line buffer holds no more */
	psd_virtmap_init(&map, rooms, 3, &mb);
	map.now = 6 * 3600.0 + (data[0] >> 2) * 1800.0;   /* 06:00 to 13:30 and on */
	inner = &mb;
	outer = mb;
	outer.read = checked_read;
	outer.write = checked_write;
	while (at < size) {
		int rtu = data[0] & 1;
		int len = rtu ? psd_mbframe_rtu(data + at, size - at, (data[0] >> 1) & 1, &adu, &why)
		              : psd_mbframe_tcp(data + at, size - at, &adu, &why);
		if (len < 0 && rtu) {   /* no frame starts here: the next byte */
			at++;
			continue;
		}
		if (len <= 0)
			break;
		if ((size_t)len > size - at)
			abort();
		answer(&outer, &adu, data + at, data + at + len);
		at += (size_t)len;
	}
	return 0;
}
