/* SPDX-License-Identifier: ISC */
/* Fuzz the control socket's requests through the real handler, against a
 * running engine on a loopback room (results written at start-up).
 * Invariants: every reply is one line of JSON with "ok" (json-c parses it
 * back), and nothing a request does breaks the next control step. */
#include <json-c/json.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "loop.h"
#include "cmdtab.h"
#include "log.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerInitialize(int *argc, char ***argv);

static struct psd_daemon d;

static const char results[] =
	"[psresults]\nversion = 1\nscene = s\nscene_hash = 00\nsensitivity = c\nrotation = 0\n"
	"reading = linear\nrgb = 0.265 0.670 0.0648\n"
	"[condition day]\nkind = daylight\ndate = 03-18\ntod_s = 54000\ncomputed = yes\n"
	"sensor_response = 5.07\ntask_irradiance = 6.69\ntask_lux = 1197.6\nratio = 236.2\nbrightest_share = 0.0002\n"
	"[condition elec]\nkind = electric\ntod_s = -1\ncomputed = yes\nsensor_response = 1.094\n"
	"task_irradiance = 7.07\ntask_lux = 1265.4\nratio = 1156.7\nbrightest_share = 0.01\n";

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
	static struct psd_config cf;
	char dir[] = "/tmp/fuzz_ctl.XXXXXX", path[128], text[512], err[512];
	FILE *fp;
	(void)argc;
	(void)argv;
	psd_log_init(1, -1, "fuzz_ctl");   /* quiet */
	if (!mkdtemp(dir))
		abort();
	snprintf(path, sizeof path, "%s/r", dir);
	if (!(fp = fopen(path, "w")) || fputs(results, fp) < 0 || fclose(fp) != 0)
		abort();
	snprintf(text, sizeof text,
	         "[psensd]\nresults = %s\n[device room]\ndriver = loopback\ngain = 0.5\nnoise = 0.01\n"
	         "[zone office]\ndevice = room\nsensor_gain = 0.5\n", path);
	if (psd_config_load_string(&cf, text, "fuzz.conf") != 0)
		abort();
	psd_clock_simulated(&d.clock, 12 * 3600.0);
	if (psd_engine_open(&d.engine, &cf, 12 * 3600.0, 1, NULL, err, sizeof err) != 0) {
		fprintf(stderr, "fuzz_ctl: %s\n", err);
		abort();
	}
	d.config_path = "fuzz.conf";
	unlink(path);
	rmdir(dir);
	return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct psd_ctl_reply r = { 0 };
	const char *reply;
	char line[PSD_CTL_MAX_LINE];
	struct psd_ctl_client c = { .fd = -1 };
	json_object *o, *ok;
	size_t n = size < sizeof line - 1 ? size : sizeof line - 1;
	memcpy(line, data, n);
	line[n] = '\0';
	if (strlen(line) != n || memchr(line, '\n', n))
		return 0;   /* the socket splits lines and refuses NUL before the handler */
	psd_cmdtab_handle(&d, &c, line, &r);
	reply = r.text;
	if (!reply || strchr(reply, '\n') || !(o = json_tokener_parse(reply)) || !json_object_object_get_ex(o, "ok", &ok))
		abort();
	json_object_put(o);
	psd_ctlsock_reply_free(&r);
	psd_clock_advance(&d.clock, psd_clock_now(&d.clock) + 1);
	psd_engine_step(&d.engine, psd_clock_now(&d.clock));
	d.reload = 0;
	return 0;
}
