/* SPDX-License-Identifier: ISC */
/* The DALI frame layer's shared helpers (dali_frame.h). */
#include "dali_frame.h"

int ps_dali_frame_valid(const struct ps_dali_frame *f)
{
	if (!f || (f->bits != 8 && f->bits != 16 && f->bits != 24))
		return -1;
	return f->data >> f->bits ? -1 : 0;
}

const char *ps_dali_frame_event_name(int event)
{
	static const char *const names[PS_DALI_EV_COUNT] = {
		"ignored", "echo", "no answer", "answer", "bus error", "observed", "info", "malformed", "bus power",
	};
	return event >= 0 && event < PS_DALI_EV_COUNT ? names[event] : "unknown";
}

size_t ps_dali_frame_hex(char *out, uint32_t v, int n)
{
	static const char digits[] = "0123456789ABCDEF";
	for (int i = 0; i < 2 * n; i++)
		out[i] = digits[(v >> (4 * (2 * n - 1 - i))) & 0xF];
	return (size_t)(2 * n);
}

long ps_dali_frame_unhex(const uint8_t *s, size_t n)
{
	long v = 0;
	for (size_t i = 0; i < n; i++) {
		int c = s[i], d;
		if (c >= '0' && c <= '9')
			d = c - '0';
		else if (c >= 'A' && c <= 'F')
			d = c - 'A' + 10;
		else if (c >= 'a' && c <= 'f')
			d = c - 'a' + 10;
		else
			return -1;
		v = v << 4 | d;
	}
	return v;
}
