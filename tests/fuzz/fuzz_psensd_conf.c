/* SPDX-License-Identifier: ISC */
/* Fuzz psensd.conf as the daemon reads it: devices, points, zones and the
 * driver keys they hand on.  Invariant: a file either loads with no error,
 * or fails with at least one "file:line" or "file:" message. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "config.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	static struct psd_config cf;
	char *text = malloc(size + 1);
	int rc;
	if (!text)
		return 0;
	memcpy(text, data, size);
	text[size] = '\0';
	rc = psd_config_load_string(&cf, text, "fuzz.conf");
	if ((rc == 0) != (cf.conf.nerrors == 0))
		abort();
	for (size_t i = 0; i < cf.conf.nerrors; i++)
		if (strncmp(cf.conf.errors[i], "fuzz.conf:", 10) != 0)
			abort();
	for (size_t i = 0; rc == 0 && i < cf.nzone; i++)
		if (cf.zone[i].sensor < 0 || (size_t)cf.zone[i].sensor >= cf.npt)
			abort();
	psd_config_free(&cf);
	free(text);
	return 0;
}
