/* SPDX-License-Identifier: ISC */
/* psvirt's register map over the zones' rooms (see virtmap.h). */
#include "virtmap.h"

#include <math.h>
#include <string.h>

static void put_f32(uint16_t *r, double x, int cdab)
{
	float f = (float)x;
	uint32_t u;
	memcpy(&u, &f, sizeof u);
	r[cdab] = (uint16_t)(u >> 16);
	r[!cdab] = (uint16_t)u;
}

static void put_u32(uint16_t *r, double x)
{
	uint32_t u = (uint32_t)lround(fmin(fmax(x, 0), 4294967295.0));
	r[0] = (uint16_t)(u >> 16);
	r[1] = (uint16_t)u;
}

/* The zone a holding or input register belongs to, -1 for none. */
static int zone_of(const struct psd_virtmap *m, unsigned addr)
{
	int z = -1;
	if (addr < PSD_VIRT_AI_STATUS + PSD_VIRT_MAX_ZONES)
		z = (int)(addr % 10);
	else if (addr >= PSD_VIRT_METER && addr < PSD_VIRT_METER + 10 * PSD_VIRT_MAX_ZONES)
		z = (int)(addr - PSD_VIRT_METER) / 10;
	else if ((addr >= PSD_VIRT_OUTPUT0 && addr <= PSD_VIRT_TRUTH0 + 1) ||
	         (addr >= PSD_VIRT_ROOFTOP && addr < PSD_VIRT_ROOFTOP + 4))
		z = 0;
	else if (addr >= PSD_VIRT_ZONE && addr < PSD_VIRT_ZONE + 10 * PSD_VIRT_MAX_ZONES)
		z = (int)(addr - PSD_VIRT_ZONE) / 10;
	return z < m->nzone ? z : -1;
}

/* One zone's registers from its room now.  A sensor with no reading (the
 * room drops or delays its reply) keeps its last value, as a module's
 * register holds its last conversion. */
static void refresh_zone(struct psd_virtmap *m, int k, double now)
{
	struct psd_virtroom *r = m->room[k];
	uint16_t *hr = m->hr, *meter = hr + PSD_VIRT_METER + 10 * k, *zone = hr + PSD_VIRT_ZONE + 10 * k;
	double volts, lux;
	int state;
	if (psd_virtroom_sensor(r, now, &volts, &state) == 0) {
		hr[PSD_VIRT_AI + k] = (uint16_t)lround(fmin(fmax(volts, 0), 10) / 10 * 65535);
		hr[PSD_VIRT_AI_STATUS + k] = (uint16_t)((volts >= 10 || (state & PSD_VIRTROOM_SATURATED) ? 0x0002 : 0) |
		                                        (state & PSD_VIRTROOM_OPEN ? 0x0008 : 0));
	}
	lux = psd_virtroom_task(r, now);
	put_u32(meter, lux);
	meter[2] = 0;
	put_f32(meter + 4, lux, 0);
	put_f32(meter + 6, lux, 1);
	zone[0] = (uint16_t)lround(psd_virtroom_output(r, now) * 10000);
	put_f32(zone + 1, psd_virtroom_truth(r, now), 0);
	if (k == 0) {
		/* one sky over the site: zone 0's room plays it */
		double g = psd_virtroom_rooftop(r, now);
		put_u32(hr + PSD_VIRT_ROOFTOP, g);
		put_f32(hr + PSD_VIRT_ROOFTOP + 2, g, 0);
		hr[PSD_VIRT_OUTPUT0] = zone[0];
		hr[PSD_VIRT_TRUTH0] = zone[1];
		hr[PSD_VIRT_TRUTH0 + 1] = zone[2];
	}
}

static unsigned run_zones(const struct psd_virtmap *m, unsigned addr, unsigned count)
{
	unsigned zones = 0;
	for (unsigned a = addr; a < addr + count && a < PSD_VIRT_HOLDING; a++) {
		int z = zone_of(m, a);
		if (z >= 0)
			zones |= 1u << z;
	}
	return zones;
}

static void refresh_run(struct psd_virtmap *m, unsigned addr, unsigned count)
{
	unsigned zones = run_zones(m, addr, count);
	for (int k = 0; k < m->nzone; k++)
		if (zones & (1u << k))
			refresh_zone(m, k, m->now);
	if (addr < PSD_VIRT_TOD + 2 && addr + count > PSD_VIRT_TOD)
		put_u32(m->hr + PSD_VIRT_TOD, psd_virtroom_tod(m->now));
}

static int map_read(void *user, int table, unsigned addr, unsigned count, uint16_t *v)
{
	struct psd_virtmap *m = user;
	switch (table) {
	case PSD_MB_COILS: memcpy(v, m->coil + addr, count * sizeof *v); return 0;
	case PSD_MB_DISCRETE: memcpy(v, m->di + addr, count * sizeof *v); return 0;
	default:   /* input registers are the first holding registers */
		refresh_run(m, addr, count);
		memcpy(v, m->hr + addr, count * sizeof *v);
		return 0;
	}
}

static int map_write(void *user, int table, unsigned addr, unsigned count, const uint16_t *v)
{
	struct psd_virtmap *m = user;
	if (table == PSD_MB_COILS) {
		memcpy(m->coil + addr, v, count * sizeof *v);
		return 0;
	}
	memcpy(m->hr + addr, v, count * sizeof *v);
	for (unsigned a = addr; a < addr + count; a++) {
		int k = (int)a - PSD_VIRT_AO;
		if (k < 0 || k >= m->nzone)
			continue;
		if (m->hr[a] > PSD_VIRT_AO_MAX)
			m->hr[a] = PSD_VIRT_AO_MAX;
		psd_virtroom_command(m->room[k], m->now, m->hr[a] / (double)PSD_VIRT_AO_MAX);
	}
	return 0;
}

void psd_virtmap_init(struct psd_virtmap *m, struct psd_virtroom *const *room, int nzone,
                      struct psd_mbmap *mb)
{
	memset(m, 0, sizeof *m);
	m->nzone = nzone > PSD_VIRT_MAX_ZONES ? PSD_VIRT_MAX_ZONES : nzone;
	for (int k = 0; k < m->nzone; k++) {
		m->room[k] = room[k];
		m->hr[PSD_VIRT_AO + k] = PSD_VIRT_AO_MAX;   /* the rooms start at full output */
	}
	memset(mb, 0, sizeof *mb);
	mb->size[PSD_MB_COILS] = PSD_VIRT_COILS;
	mb->size[PSD_MB_DISCRETE] = PSD_VIRT_DISCRETE;
	mb->size[PSD_MB_HOLDING] = PSD_VIRT_HOLDING;
	mb->size[PSD_MB_INPUT] = PSD_VIRT_INPUT;
	mb->user = m;
	mb->read = map_read;
	mb->write = map_write;
}

unsigned psd_virtmap_zones(const struct psd_virtmap *m, const struct psd_mbspan *sp, int nsp)
{
	unsigned zones = 0;
	for (int i = 0; i < nsp; i++)
		if (sp[i].table == PSD_MB_HOLDING || sp[i].table == PSD_MB_INPUT)
			zones |= run_zones(m, sp[i].addr, sp[i].count);
	return zones;
}

int psd_virtmap_comms(const struct psd_virtmap *m, unsigned zones, double now)
{
	int worst = PSD_VIRTROOM_ANSWER;
	for (int k = 0; k < m->nzone; k++)
		if (zones & (1u << k)) {
			int c = psd_virtroom_comms(m->room[k], now);
			if (c == PSD_VIRTROOM_DROP)
				return c;
			if (c == PSD_VIRTROOM_LATE)
				worst = c;
		}
	return worst;
}

void psd_virtmap_refresh(struct psd_virtmap *m, double now)
{
	m->now = now;
	refresh_run(m, 0, PSD_VIRT_HOLDING);
}
