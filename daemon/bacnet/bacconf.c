/* SPDX-License-Identifier: ISC */
/* The [bacnet] section of psensd.conf (bacconf.h). */
#include "bacconf.h"

#include <arpa/inet.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int line_of(struct ps_conf_section *s, const char *key)
{
	struct ps_conf_kv *kv = ps_conf_kv(s, key);
	return kv ? kv->line : s->line;
}

void psd_bacconf_load(struct psd_bacnet_conf *b, struct ps_conf *c)
{
	/* the words of `writes`, bit i - 1 for word i */
	static const char *const writes[] = { "none", "lighting-output", "target", "daylighting", "vacancy-hold",
		                              NULL };
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
	if ((v = ps_conf_str(c, s, "writes", "none"))) {
		char word[32];
		const char *p = v;
		size_t len;
		while (*(p += strspn(p, " ,\t"))) {
			int k;
			len = strcspn(p, " ,\t");
			snprintf(word, sizeof word, "%.*s", (int)(len < sizeof word ? len : sizeof word - 1), p);
			for (k = 0; writes[k] && (len >= sizeof word || strcmp(writes[k], word) != 0); k++)
				;
			if (!writes[k]) {
				ps_conf_error(c, line_of(s, "writes"),
				              "writes: '%s' is not one of none, lighting-output, target, daylighting, "
				              "vacancy-hold",
				              word);
				break;
			}
			if (k > 0)
				b->writes |= 1 << (k - 1);
			p += len;
		}
	}
	ps_conf_double(c, s, "hold", 3600, 60, 7 * 86400, &b->hold);
	ps_conf_double(c, s, "target_min", 0, 0, 5000, &b->target_min);
	ps_conf_double(c, s, "target_max", 5000, 0, 5000, &b->target_max);
	if (b->target_max <= b->target_min)
		ps_conf_error(c, line_of(s, ps_conf_kv(s, "target_max") ? "target_max" : "target_min"),
		              "target_max (%g lx) must be above target_min (%g lx)", b->target_max, b->target_min);
	ps_conf_double(c, s, "rate", 100, 1, 100000, &b->rate);
	ps_conf_int(c, s, "bbmd_ttl", 600, 10, 65535, &b->bbmd_ttl);
	if ((v = ps_conf_str(c, s, "bbmd", NULL))) {
		const char *colon = strchr(v, ':');
		size_t hl = colon ? (size_t)(colon - v) : strlen(v);
		char *end = NULL;
		long port = colon ? strtol(colon + 1, &end, 10) : 47808;
		if (hl == 0 || hl >= sizeof b->bbmd_host || (colon && (!colon[1] || *end || port < 1 || port > 65535))) {
			ps_conf_error(c, line_of(s, "bbmd"), "bbmd: '%s' is not IPV4-ADDRESS[:PORT]", v);
			return;
		}
		memcpy(b->bbmd_host, v, hl);
		b->bbmd_host[hl] = 0;
		if (inet_pton(AF_INET, b->bbmd_host, &a) != 1) {
			ps_conf_error(c, line_of(s, "bbmd"), "bbmd: '%s' is not an IPv4 address", b->bbmd_host);
			return;
		}
		b->bbmd = 1, b->bbmd_port = port;
	}
}
