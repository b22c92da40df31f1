/* SPDX-License-Identifier: ISC */
/* Frequency from edge timestamps over a gate, for light-to-frequency
 * sensors (TSL230R kind) read through GPIO edge events.  Pure: no I/O, so
 * the arithmetic and the overrun rule are unit-tested alone.
 *
 * Frequency over a gate: f = (n - 1) / (t_last - t_first) for the n rising
 * edges timed in it, times the sensor's divider.  Lost edges are never
 * silently counted as a lower frequency: the kernel's GPIO event buffer
 * holds 16 events and the v1 interface has no sequence numbers, so an
 * overrun is recognised when a read drained a full buffer, or when an
 * interval between edges is longer than `gap` times the shortest one in the
 * gate (with a steady light the intervals are equal). */
#ifndef PS_FREQ_H
#define PS_FREQ_H

#include <stdint.h>

enum { PS_FREQ_KERNEL_FIFO = 16 };

struct ps_freq_gate {
	uint64_t first_ns, last_ns, prev_ns;
	uint64_t min_dt, max_dt;  /* shortest and longest interval, ns */
	long n;                   /* edges */
	int full_reads;           /* reads that returned a full kernel buffer */
};

void ps_freq_gate_reset(struct ps_freq_gate *g);
/* One edge's timestamp (ns, nondecreasing). */
void ps_freq_gate_edge(struct ps_freq_gate *g, uint64_t ts_ns);
/* A read returned this many events (PS_FREQ_KERNEL_FIFO: it may have overrun). */
void ps_freq_gate_read(struct ps_freq_gate *g, int nevents);
/* 1 if edges were lost in this gate. */
int ps_freq_gate_overran(const struct ps_freq_gate *g, double gap);
/* Edges per second at the pin: (n-1)/(last-first); with fewer than 2 edges,
 * n / gate_s (a bound: dark). */
double ps_freq_gate_hz(const struct ps_freq_gate *g, double gate_s);

/* TSL230R frequency scaling: divide by 1, 2, 10 or 100 (S2/S3 pins). */
extern const int ps_freq_dividers[4];
/* The divider index for the next gate: up one step when the pin's rate was
 * above max_rate or the gate overran, down one when it was below max_rate/40
 * (so a step down cannot land above max_rate), else unchanged. */
int ps_freq_next_divider(int idx, double pin_hz, double max_rate, int overran);
/* S2/S3 levels for a divider index: 00 /1, 01 /2, 10 /10, 11 /100. */
void ps_freq_divider_pins(int idx, int *s2, int *s3);

#endif
