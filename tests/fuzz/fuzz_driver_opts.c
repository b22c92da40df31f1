/* SPDX-License-Identifier: ISC */
/* Fuzz the drivers' option tables as psensd -n and the drivers' open use
 * them: the first byte picks a driver and a role (or the device section),
 * the rest is "key=value" lines.  Invariants: every error names a line of
 * the input or the section's, and the readers agree with the check: a
 * section the check passes reads every key of its table without error. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "driver.h"
#include "registry.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

enum { MAXKV = 32 };

struct seen {
	int n, bad_line;
	size_t nkv;
};

static void report(void *user, int line, const char *why)
{
	struct seen *s = user;
	s->n++;
	if (!why[0] || line < 0 || (size_t)line > s->nkv)   /* 0: a key that is missing */
		s->bad_line = 1;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	static struct ps_opt kv[MAXKV];
	size_t ndrv = 0, n = 0;
	const struct ps_driver *drv;
	struct ps_opts o;
	struct seen seen = { 0, 0, 0 };
	char *text, *save = NULL, err[300];
	int role;
	if (size < 1)
		return 0;
	while (ps_registry_drivers[ndrv])
		ndrv++;
	drv = ps_registry_drivers[data[0] % ndrv];
	role = (int)(data[0] / ndrv) % (PS_ROLE_COUNT + 1) - 1;   /* -1: the device */
	if (!(text = malloc(size)))
		return 0;
	memcpy(text, data + 1, size - 1);
	text[size - 1] = 0;
	for (char *l = strtok_r(text, "\n", &save); l && n < MAXKV; l = strtok_r(NULL, "\n", &save)) {
		char *eq = strchr(l, '=');
		if (!eq)
			continue;
		*eq = 0;
		kv[n] = (struct ps_opt){ l, eq + 1, (int)n + 1, 0 };
		n++;
	}
	o = (struct ps_opts){ kv, n, "fuzz.conf" };
	seen.nkv = n;
	ps_driver_check(drv, &o, role, report, &seen);
	if (seen.bad_line)
		abort();
	if (seen.n == 0 && drv->options) {
		struct ps_opts_reader r = { &o, drv->options, role < 0 ? PS_OPT_DEVICE : PS_OPT_POINT, err, sizeof err, NULL };
		for (const struct ps_opts_spec *s = drv->options; s->key; s++) {
			union { double d; long l; int i; const char *s; } v;
			struct ps_opts_window w[PS_OPT_MAX_WINDOWS];
			size_t nw;
			int rc;
			if (s->scope != r.scope)
				continue;
			switch (s->type) {
			case PS_OPT_DOUBLE: rc = ps_opts_double(&r, s->key, &v.d); break;
			case PS_OPT_LONG: rc = ps_opts_long(&r, s->key, &v.l); break;
			case PS_OPT_ENUM:
			case PS_OPT_BOOL: rc = ps_opts_choice(&r, s->key, &v.i); break;
			case PS_OPT_STRING: rc = ps_opts_string(&r, s->key, &v.s); break;
			default: rc = ps_opts_windows(&r, s->key, w, &nw); break;
			}
			if (rc != 0)
				abort();   /* the check passed what a reader refuses */
		}
	}
	free(text);
	return 0;
}
