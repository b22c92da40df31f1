/* SPDX-License-Identifier: ISC */
#include "freq.h"

#include <string.h>

const int ps_freq_dividers[4] = { 1, 2, 10, 100 };

void ps_freq_gate_reset(struct ps_freq_gate *g)
{
	memset(g, 0, sizeof *g);
	g->min_dt = UINT64_MAX;
}

void ps_freq_gate_edge(struct ps_freq_gate *g, uint64_t ts)
{
	if (g->n == 0) {
		g->first_ns = ts;
	} else {
		uint64_t dt = ts >= g->prev_ns ? ts - g->prev_ns : 0;
		if (dt < g->min_dt)
			g->min_dt = dt;
		if (dt > g->max_dt)
			g->max_dt = dt;
	}
	g->prev_ns = g->last_ns = ts;
	g->n++;
}

void ps_freq_gate_read(struct ps_freq_gate *g, int nevents)
{
	if (nevents >= PS_FREQ_KERNEL_FIFO)
		g->full_reads++;
}

int ps_freq_gate_overran(const struct ps_freq_gate *g, double gap)
{
	if (g->n >= 3 && g->min_dt > 0 && (double)g->max_dt > gap * (double)g->min_dt)
		return 1;
	/* a full buffer is only harmless when the gaps prove nothing was lost,
	 * which needs intervals to compare */
	return g->full_reads > 0 && g->n < 3;
}

double ps_freq_gate_hz(const struct ps_freq_gate *g, double gate_s)
{
	if (g->n < 2 || g->last_ns <= g->first_ns)
		return gate_s > 0 ? (double)g->n / gate_s : 0;
	return (double)(g->n - 1) / ((double)(g->last_ns - g->first_ns) * 1e-9);
}

int ps_freq_next_divider(int idx, double pin_hz, double max_rate, int overran)
{
	if ((overran || pin_hz > max_rate) && idx < 3)
		return idx + 1;
	if (!overran && idx > 0 && pin_hz * ps_freq_dividers[idx] / ps_freq_dividers[idx - 1] < max_rate / 4 &&
	    pin_hz < max_rate / 40)
		return idx - 1;
	return idx;
}

void ps_freq_divider_pins(int idx, int *s2, int *s3)
{
	*s2 = (idx >> 1) & 1;
	*s3 = idx & 1;
}
