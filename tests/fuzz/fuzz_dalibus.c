/* SPDX-License-Identifier: ISC */
/* Fuzz psvirt's virtual DALI bus through its interfaces (daemon/psvirt/
 * daliserve.c over dalibus.c): the first byte chooses the protocol (Foxtron
 * or the AtxLED HAT), whether the gear start unaddressed and a fault; the
 * rest is what a host sends, written in pieces to one end of a socketpair
 * whose other end the server serves, the bus's time moving on between
 * pieces.  Invariants: nothing crashes or reads out of bounds; every gear's
 * arc level stays 0 to 254 and every zone's output 0 to 1; every reply is
 * framed (Foxtron: SOH ... ETB; HAT: lines ending in a newline); the 304's
 * value stays within its 10 bits. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <sys/socket.h>

#include "dalibus.h"
#include "daliserve.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check_reply(const uint8_t *r, size_t n, int protocol)
{
	if (!n)
		return;
	if (protocol == PSD_DALISERVE_FOXTRON) {
		if (r[0] != 0x01 || r[n - 1] != 0x17)
			abort();
	} else if (r[n - 1] != '\n') {
		abort();
	}
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	static struct psd_dalibus bus;
	struct psd_daliserve *s;
	int sv[2], protocol;
	double now = 1.0;
	uint8_t reply[4096];
	if (size < 1 || socketpair(AF_UNIX, SOCK_STREAM, 0, sv) != 0)
		return 0;
	protocol = data[0] & 1 ? PSD_DALISERVE_ATX : PSD_DALISERVE_FOXTRON;
	psd_dalibus_init(&bus, 4, 2, !(data[0] & 2), 7);
	bus.fault = (data[0] >> 2) % PSD_DALIBUS_NFAULT;
	bus.target = data[0] & 0x40 ? PSD_DALIBUS_EVERY : 1;
	psd_dalibus_sense(&bus, 0, 700, 1);
	psd_dalibus_sense(&bus, 1, 5000, 0);
	if (!(s = psd_daliserve_new(&bus, 0))) {
		close(sv[0]);
		close(sv[1]);
		return 0;
	}
	psd_daliserve_fd(s, sv[1], protocol);
	for (size_t i = 1; i < size;) {
		size_t piece = size - i < 48 ? size - i : 48;
		ssize_t got;
		if (write(sv[0], data + i, piece) != (ssize_t)piece)
			break;
		i += piece;
		now += 0.05 * (data[i - 1] & 7);
		psd_daliserve_step(s, now, 0);
		while ((got = recv(sv[0], reply, sizeof reply, MSG_DONTWAIT)) > 0)
			check_reply(reply, (size_t)got, protocol);
		for (int g = 0; g < bus.ngear; g++) {
			int lv = psd_dalibus_level(&bus.gear[g], now);
			if (lv < 0 || lv > 254)
				abort();
		}
		for (int z = 0; z < bus.ndev; z++) {
			double out = psd_dalibus_output(&bus, z, now);
			if (!(out >= 0 && out <= 1) || bus.dev[z].inst[1].value > 1023)
				abort();
		}
	}
	psd_daliserve_free(s);
	close(sv[0]);
	return 0;
}
