/* SPDX-License-Identifier: ISC */
/* The [bacnet] section of psensd.conf (bacconf.h). */
#include "bacconf.h"

#include <arpa/inet.h>
#include <stdio.h>
#include <string.h>

static int line_of(struct ps_conf_section *s, const char *key)
{
	struct ps_conf_kv *kv = ps_conf_kv(s, key);
	return kv ? kv->line : s->line;
}

void psd_bacconf_load(struct psd_bacnet_conf *b, struct ps_conf *c)
{
	static const char *const writes[] = { "none", "lighting-output", NULL };
	struct ps_conf_section *s = ps_conf_section(c, "bacnet");
	struct in_addr a;
	const char *v;
	memset(b, 0, sizeof *b);
	if (!s)
		return;
	s->used = 1;
	b->enabled = 1;
	b->line = s->line;
	/* no default: BACnet/IP has no authentication, so the interface a
	 * BMS may reach is the site's choice, said in the file */
	if (!(v = ps_conf_str(c, s, "bind", NULL)) || !*v)
		ps_conf_error(c, s->line,
		              "[bacnet] needs 'bind' (the IPv4 address of the interface the BMS "
		              "reaches, 0.0.0.0 for every one: BACnet/IP has no authentication)");
	else if (strlen(v) >= sizeof b->bind || inet_pton(AF_INET, v, &a) != 1)
		ps_conf_error(c, line_of(s, "bind"), "bind: '%s' is not an IPv4 address", v);
	else
		snprintf(b->bind, sizeof b->bind, "%s", v);
	ps_conf_int(c, s, "port", 47808, 1, 65535, &b->port);
	if (ps_conf_required(c, s, "instance") == 0)
		ps_conf_int(c, s, "instance", 0, 0, 4194302, &b->instance);
	v = ps_conf_str(c, s, "name", "psensd");
	if (!*v || strlen(v) >= sizeof b->name)
		ps_conf_error(c, line_of(s, "name"), "name: 1 to %zu characters", sizeof b->name - 1);
	else
		snprintf(b->name, sizeof b->name, "%s", v);
	ps_conf_int(c, s, "vendor_id", 65535, 0, 65535, &b->vendor_id);
	ps_conf_enum(c, s, "writes", writes, PSD_BACCONF_NONE, &b->writes);
	ps_conf_double(c, s, "hold", 3600, 60, 7 * 86400, &b->hold);
	ps_conf_double(c, s, "rate", 100, 1, 100000, &b->rate);
}
