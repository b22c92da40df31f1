/* SPDX-License-Identifier: ISC */
/* Drive a serial or TCP DALI interface through drivers/dali_serial.c, one
 * frame after another, and print each transaction's result, for the system
 * tests (tests/system/417).
 *
 *   dali-serial CODEC WHERE [-t TIMEOUT] [-k KEEPALIVE] STEP...
 *     CODEC  atx | foxtron | luba;  WHERE  a tty path or HOST:PORT
 *     STEP   q:HHHH  a 16-bit query        s:HHHH  a 16-bit command
 *            t:HHHH  sent twice            l:HHHHHH a 24-bit frame
 *            w:SECONDS  wait, serving the link (keep-alives, other masters' frames)
 *
 * Prints "N FRAME: answer 0xHH", "N FRAME: no answer" or "N FRAME: error
 * NAME: why" per step, then one line of the link's counters. */
#include <errno.h>
#include <math.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "dali_atx.h"
#include "dali_foxtron.h"
#include "dali_luba.h"
#include "dali_serial.h"

static double mono(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + ts.tv_nsec / 1e9;
}

static const char *errname(int e)
{
	return e == ETIMEDOUT ? "ETIMEDOUT" : e == EPROTO ? "EPROTO" : e == EIO ? "EIO" : "other";
}

int main(int argc, char **argv)
{
	const struct ps_dali_codec *c;
	struct ps_dali_serial *s;
	struct ps_dali_serial_stats st;
	double timeout = 0.3, keepalive = -1;
	char err[200];
	int i = 3, n = 0;
	if (argc < 3) {
		fprintf(stderr, "usage: dali-serial atx|foxtron|luba WHERE [-t TIMEOUT] STEP...\n");
		return 2;
	}
	c = strcmp(argv[1], "atx") == 0       ? &ps_dali_atx
	    : strcmp(argv[1], "foxtron") == 0 ? &ps_dali_foxtron
	    : strcmp(argv[1], "luba") == 0    ? &ps_dali_luba
	                                      : NULL;
	if (!c) {
		fprintf(stderr, "no codec '%s'\n", argv[1]);
		return 2;
	}
	while (i + 1 < argc && (strcmp(argv[i], "-t") == 0 || strcmp(argv[i], "-k") == 0)) {
		if (argv[i][1] == 't')
			timeout = atof(argv[i + 1]);
		else
			keepalive = atof(argv[i + 1]);
		i += 2;
	}
	if (!(s = ps_dali_serial_open(c, argv[2], 0, err, sizeof err))) {
		printf("open: %s\n", err);
		return 1;
	}
	if (keepalive >= 0)
		ps_dali_serial_keepalive(s, keepalive);
	for (; i < argc; i++) {
		struct ps_dali_frame f = { 0 };
		struct ps_dali_serial_result res;
		
		char *end;
		int r = 0;
		if (strlen(argv[i]) < 3 || argv[i][1] != ':') {
			fprintf(stderr, "bad step '%s'\n", argv[i]);
			return 2;
		}
		if (argv[i][0] == 'w') {
			double until = mono() + atof(argv[i] + 2);
			while (mono() < until) {
				struct pollfd p = { .fd = ps_dali_serial_fd(s), .events = POLLIN };
				double next = fmin(until, ps_dali_serial_deadline(s)) - mono();
				poll(&p, 1, next > 0 ? (int)(next * 1000) + 1 : 0);
				if (ps_dali_serial_service(s, mono(), &res) < 0) {
					printf("wait: link gone: %s\n", res.why);
					ps_dali_serial_close(s);
					return 1;
				}
			}
			continue;
		}
		f.data = (uint32_t)strtoul(argv[i] + 2, &end, 16);
		f.bits = argv[i][0] == 'l' ? 24 : 16;
		f.twice = argv[i][0] == 't';
		f.expect_answer = argv[i][0] == 'q';
		n++;
		if (ps_dali_serial_send(s, &f, mono(), timeout) != 0) {
			printf("%d %s: send failed: %s\n", n, argv[i] + 2, strerror(errno));
			continue;
		}
		while (r == 0) {
			struct pollfd p = { .fd = ps_dali_serial_fd(s), .events = POLLIN };
			double left = ps_dali_serial_deadline(s) - mono();
			poll(&p, 1, isfinite(left) ? (left > 0 ? (int)(left * 1000) + 1 : 0) : 1000);
			r = ps_dali_serial_service(s, mono(), &res);
		}
		if (r < 0) {
			printf("%d %s: link gone: %s\n", n, argv[i] + 2, res.why);
			ps_dali_serial_close(s);
			return 1;
		}
		if (res.err)
			printf("%d %s: error %s: %s\n", n, argv[i] + 2, errname(res.err), res.why);
		else if (res.event == PS_DALI_EV_ANSWER)
			printf("%d %s: answer 0x%02X\n", n, argv[i] + 2, res.value);
		else
			printf("%d %s: %s\n", n, argv[i] + 2, ps_dali_frame_event_name(res.event));
	}
	ps_dali_serial_stats(s, &st);
	printf("stats frames %lu answers %lu no_answers %lu bus_errors %lu malformed %lu timeouts %lu observed %lu "
	       "last_observed %04X stray %lu power_lost %d keepalives %lu\n",
	       st.frames, st.answers, st.no_answers, st.bus_errors, st.malformed, st.timeouts, st.observed,
	       st.last_observed, st.stray, st.power_lost, st.keepalives);
	ps_dali_serial_close(s);
	return 0;
}
