/* SPDX-License-Identifier: ISC */
/* Fuzz the view-option parser. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "view.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct ps_view v;
	struct ps_err e;
	char buf[512], *text = malloc(size + 1);
	if (!text)
		return 0;
	memcpy(text, data, size);
	text[size] = '\0';
	ps_view_default(&v);
	if (ps_view_parse(&v, text, "fuzz", &e) == 0) {
		(void)ps_view_check_fisheye(&v, "fuzz", &e);
		ps_view_format(&v, buf, sizeof buf);
	}
	free(text);
	return 0;
}
