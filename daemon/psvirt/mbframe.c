/* SPDX-License-Identifier: ISC */
/* Modbus TCP and RTU framing for a server (see mbframe.h). */
#include "mbframe.h"

#include <string.h>

#include "mbpdu.h"

int psd_mbframe_tcp(const uint8_t *buf, size_t len, struct psd_mbadu *adu, const char **why)
{
	unsigned proto, n;
	int want;
	if (len < 7)
		return 0;
	proto = (unsigned)buf[2] << 8 | buf[3];
	n = (unsigned)buf[4] << 8 | buf[5];
	if (proto != 0) {
		*why = "protocol id is not 0 (not Modbus)";
		return -1;
	}
	if (n < 2 || n > 1 + PSD_MBPDU_MAX) {
		*why = "MBAP length outside 2 to 254";
		return -1;
	}
	/* the function's own length, as soon as the PDU's first bytes tell it
	 * (a PDU too short to hold its own fields does not match either) */
	want = psd_mbpdu_length(buf + 7, len - 7 < n - 1 ? len - 7 : n - 1);
	if ((want > 0 && (unsigned)want != n - 1) || (want == 0 && len - 7 >= n - 1)) {
		*why = "MBAP length does not match the PDU";
		return -1;
	}
	if (len < 6 + (size_t)n)
		return 0;
	adu->tid = (unsigned)buf[0] << 8 | buf[1];
	adu->unit = buf[6];
	adu->pdu = buf + 7;
	adu->npdu = n - 1;
	return (int)(6 + n);
}

size_t psd_mbframe_tcp_put(const struct psd_mbadu *req, const uint8_t *pdu, size_t n, uint8_t *out)
{
	out[0] = (uint8_t)(req->tid >> 8);
	out[1] = (uint8_t)req->tid;
	out[2] = out[3] = 0;
	out[4] = (uint8_t)((n + 1) >> 8);
	out[5] = (uint8_t)(n + 1);
	out[6] = (uint8_t)req->unit;
	memcpy(out + 7, pdu, n);
	return 7 + n;
}

uint16_t psd_mbframe_crc(const uint8_t *p, size_t n)
{
	uint16_t crc = 0xffff;
	for (size_t i = 0; i < n; i++) {
		crc ^= p[i];
		for (int b = 0; b < 8; b++)   /* without a branch: XOR the polynomial when bit 0 is set */
			crc = (uint16_t)((crc >> 1) ^ (0xa001 & -(crc & 1)));
	}
	return crc;
}

static int crc_ok(const uint8_t *buf, size_t len)
{
	uint16_t crc = psd_mbframe_crc(buf, len - 2);
	return buf[len - 2] == (crc & 0xff) && buf[len - 1] == crc >> 8;
}

int psd_mbframe_rtu(const uint8_t *buf, size_t len, int silent, struct psd_mbadu *adu, const char **why)
{
	int want = len >= 2 ? psd_mbpdu_length(buf + 1, len - 1) : 0;
	size_t total;
	if (want > 0) {
		/* a served function: its own length ends it, silence or not (a
		 * pseudo-terminal or a loaded host may split a frame) */
		total = 1 + (size_t)want + 2;
		if (total > PSD_MBFRAME_RTU_MAX) {
			*why = "longer than an RTU frame";
			return -1;
		}
		if (len < total)
			return 0;
		if (!crc_ok(buf, total)) {
			*why = "bad CRC";
			return -1;
		}
	} else if (want == 0 || !silent) {
		return 0;
	} else if (len >= 4 && len <= PSD_MBFRAME_RTU_MAX && crc_ok(buf, len)) {
		total = len;   /* a function this server does not know: the silence ends it */
	} else {
		*why = len < 4 ? "frame cut short" : "bad CRC";
		return -1;
	}
	adu->tid = 0;
	adu->unit = buf[0];
	adu->pdu = buf + 1;
	adu->npdu = total - 3;
	return (int)total;
}

size_t psd_mbframe_rtu_put(unsigned unit, const uint8_t *pdu, size_t n, uint8_t *out)
{
	uint16_t crc;
	out[0] = (uint8_t)unit;
	memcpy(out + 1, pdu, n);
	crc = psd_mbframe_crc(out, n + 1);
	out[n + 1] = (uint8_t)(crc & 0xff);
	out[n + 2] = (uint8_t)(crc >> 8);
	return n + 3;
}

double psd_mbframe_rtu_silence(long baud)
{
	return baud > 19200 || baud <= 0 ? 1.75e-3 : 3.5 * 11.0 / (double)baud;
}
