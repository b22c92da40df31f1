/* SPDX-License-Identifier: ISC */
/* Fuzz the hasseb DALI Master's report decoder (drivers/usb_hasseb.c) on
 * reports of any length and content, whole and as a stream of 10-byte
 * reports, and its encoders on any frame.  Checks its promises: final events
 * carry a sequence number 1 to 255, answers fit in a byte, version reports
 * carry none, encoded reports are 10 bytes. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#ifdef PS_WITH_USB
#include "usb_hasseb.h"
#endif

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
#ifdef PS_WITH_USB
	struct ps_dali_reply r;
	uint8_t out[64];
	ps_usb_hasseb.decode(data, size, &r);
	for (size_t off = 0; off < size; off += 10) {
		ps_usb_hasseb.decode(data + off, size - off < 10 ? size - off : 10, &r);
		if ((r.event == PS_DALI_EV_ANSWER || r.event == PS_DALI_EV_NO_ANSWER || r.event == PS_DALI_EV_BUS_ERROR) &&
		    (r.seq < 1 || r.seq > 255))
			abort();
		if (r.event == PS_DALI_EV_ANSWER && r.value > 255)
			abort();
		/* a version report answers no sequence number */
		if (r.event == PS_DALI_EV_INFO && (r.seq != -1 || r.value > 0xFFFF))
			abort();
	}
	if (size >= 5) {
		int n = ps_usb_hasseb.encode_send(out, sizeof out, data[0], (unsigned)data[1] << 8 | data[2], data[3] & 1,
		                                  data[4] < 128 ? -1 : data[4] - 128);
		if (n != -1 && n != 10)
			abort();
		/* the version request: 10 bytes for sequence numbers 1..255 only */
		n = ps_usb_hasseb.encode_version(out, sizeof out, data[0]);
		if ((data[0] == 0) != (n == -1) || (n != -1 && n != 10))
			abort();
	}
#else
	(void)data;
	(void)size;
#endif
	return 0;
}
