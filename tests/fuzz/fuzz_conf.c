/* SPDX-License-Identifier: ISC */
/* Fuzz the INI reader behind psensd.conf and scene files. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "conf.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct ps_conf c;
	struct ps_err e;
	char *text = malloc(size + 1);
	if (!text)
		return 0;
	memcpy(text, data, size);
	text[size] = '\0';
	if (ps_conf_load_string(&c, text, "fuzz.conf", &e) == 0) {
		for (size_t i = 0; i < c.nsec; i++) {
			double d;
			long n;
			int b;
			ps_conf_double(&c, &c.sec[i], "x", 0, -1e9, 1e9, &d);
			ps_conf_int(&c, &c.sec[i], "n", 0, -100, 100, &n);
			ps_conf_bool(&c, &c.sec[i], "b", 0, &b);
			free(ps_conf_path(&c, &c.sec[i], "p"));
		}
		ps_conf_check_unused(&c);
		ps_conf_free(&c);
	}
	free(text);
	return 0;
}
