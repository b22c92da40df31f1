/* SPDX-License-Identifier: ISC */
/* Fuzz what comes back from a DALI USB interface: the transport's report
 * decoder on reports of any length and content, and the DALI layer's frame
 * describer and address parser on the same bytes.  Checks the decoder's
 * promises: final events carry a sequence number, answers fit in a byte. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "dali.h"
#ifdef PS_WITH_USB
#include "usb_tridonic.h"
#endif

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	char buf[64], *text;
	struct ps_dali_addr a;
#ifdef PS_WITH_USB
	struct ps_dali_reply r;
	/* the whole input as one report, then as a stream of 64-byte reports */
	ps_usb_tridonic.decode(data, size, &r);
	for (size_t off = 0; off + 9 <= size; off += 64) {
		size_t n = size - off < 64 ? size - off : 64;
		ps_usb_tridonic.decode(data + off, n, &r);
		if (r.seq < -1 || r.seq > 255)
			abort();
		if ((r.event == PS_DALI_EV_ANSWER || r.event == PS_DALI_EV_NO_ANSWER || r.event == PS_DALI_EV_ECHO ||
		     r.event == PS_DALI_EV_BUS_ERROR) && r.seq < 0)
			abort();
		if (r.event == PS_DALI_EV_ANSWER && r.value > 255)
			abort();
	}
#endif
	for (size_t i = 0; i + 1 < size && i < 64; i += 2)
		ps_dali_describe((unsigned)data[i] << 8 | data[i + 1], buf, sizeof buf);
	text = malloc(size + 1);
	if (!text)
		return 0;
	memcpy(text, data, size);
	text[size] = 0;
	if (ps_dali_addr_parse(text, &a, buf, sizeof buf) == 0 && ps_dali_dapc(&a, 1) < 0)
		abort();
	free(text);
	return 0;
}
