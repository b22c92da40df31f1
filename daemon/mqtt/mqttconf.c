/* SPDX-License-Identifier: ISC */
#include "mqttconf.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

int psd_mqttconf_level_ok(const char *s)
{
	size_t n = strlen(s);
	return n > 0 && n < PSD_MQTT_NAME &&
	       strspn(s, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-.") == n;
}

static const char *const commands_names[] = { "none", "override", "all", NULL };

static int line_of(struct ps_conf_section *s, const char *key)
{
	struct ps_conf_kv *kv = ps_conf_kv(s, key);
	return kv ? kv->line : s->line;
}

static char *dup_or_null(const char *v)
{
	return v ? strdup(v) : NULL;
}

/* The password: the file's first line, refused when others may read it or
 * its group or others may change it. */
static void read_password(struct psd_mqtt_conf *m, struct ps_conf *c, int line)
{
	struct stat st;
	char buf[512];
	FILE *fp = fopen(m->password_file, "re");
	size_t n;
	if (!fp) {
		ps_conf_error(c, line, "password_file: %s: %s", m->password_file, strerror(errno));
		return;
	}
	if (fstat(fileno(fp), &st) != 0 || !S_ISREG(st.st_mode)) {
		ps_conf_error(c, line, "password_file: %s is not a regular file", m->password_file);
	} else if (st.st_mode & (S_IWGRP | S_IWOTH)) {
		ps_conf_error(c, line, "password_file: %s is writable by %s (mode %04o): chmod go-w it",
		              m->password_file, (st.st_mode & S_IWOTH) ? "everyone" : "its group",
		              (unsigned)(st.st_mode & 07777));
	} else if (st.st_mode & S_IROTH) {
		/* as ssh does with a private key: a secret everyone can read is none */
		ps_conf_error(c, line, "password_file: %s is readable by everyone (mode %04o): chmod o-r it",
		              m->password_file, (unsigned)(st.st_mode & 07777));
	} else if (!fgets(buf, sizeof buf, fp)) {
		ps_conf_error(c, line, "password_file: %s is empty", m->password_file);
	} else {
		n = strcspn(buf, "\r\n");
		buf[n] = 0;
		if (n == 0)
			ps_conf_error(c, line, "password_file: %s: the first line is empty", m->password_file);
		else if (!(m->password = strdup(buf)))
			ps_conf_error(c, line, "out of memory");
	}
	memset(buf, 0, sizeof buf);
	fclose(fp);
}

static void tls_file(struct ps_conf *c, struct ps_conf_section *s, const char *key, char **out)
{
	*out = ps_conf_path(c, s, key);
	if (*out && access(*out, R_OK) != 0)
		ps_conf_error(c, line_of(s, key), "%s: %s: %s", key, *out, strerror(errno));
}

void psd_mqttconf_load(struct psd_mqtt_conf *m, struct ps_conf *c)
{
	struct ps_conf_section *s = ps_conf_section(c, "mqtt");
	const char *v;
	char host[256];
	memset(m, 0, sizeof *m);
	if (!s)
		return;
	s->used = 1;
	m->enabled = 1;
	m->line = s->line;
	if (!(v = ps_conf_str(c, s, "host", NULL)) || !*v)
		ps_conf_error(c, s->line, "[mqtt] needs 'host' (the broker's address)");
	m->host = dup_or_null(v);
	tls_file(c, s, "cafile", &m->cafile);
	tls_file(c, s, "certfile", &m->certfile);
	tls_file(c, s, "keyfile", &m->keyfile);
	if ((m->certfile != NULL) != (m->keyfile != NULL))
		ps_conf_error(c, s->line, "[mqtt]: certfile and keyfile go together");
	if (m->certfile && !m->cafile)
		ps_conf_error(c, line_of(s, "certfile"), "certfile: a client certificate needs TLS: set cafile");
	ps_conf_int(c, s, "port", m->cafile ? 8883 : 1883, 1, 65535, &m->port);
	if (gethostname(host, sizeof host) != 0)
		snprintf(host, sizeof host, "psensd");
	host[strcspn(host, ".")] = 0;   /* the short name */
	v = ps_conf_str(c, s, "site", host);
	if (!psd_mqttconf_level_ok(v))
		ps_conf_error(c, line_of(s, "site"), "site: '%s' is not 1 to %d letters, digits, '_', '-' or '.'", v,
		              PSD_MQTT_NAME - 1);
	else
		snprintf(m->site, sizeof m->site, "%s", v);
	m->user = dup_or_null(ps_conf_str(c, s, "user", NULL));
	if ((m->password_file = ps_conf_path(c, s, "password_file"))) {
		if (!m->user)
			ps_conf_error(c, line_of(s, "password_file"), "password_file: needs 'user'");
		read_password(m, c, line_of(s, "password_file"));
	}
	ps_conf_int(c, s, "keepalive", 30, 5, 3600, &m->keepalive);
	ps_conf_double(c, s, "rate", 200, 1, 100000, &m->rate);
	ps_conf_int(c, s, "inflight", 100, 1, 65535, &m->inflight);
	ps_conf_bool(c, s, "discovery", 1, &m->discovery);
	v = ps_conf_str(c, s, "discovery_prefix", "homeassistant");
	if (!psd_mqttconf_level_ok(v))
		ps_conf_error(c, line_of(s, "discovery_prefix"), "discovery_prefix: '%s' is not one topic level", v);
	else
		snprintf(m->discovery_prefix, sizeof m->discovery_prefix, "%s", v);
	ps_conf_enum(c, s, "commands", commands_names, PSD_MQTT_COMMANDS_NONE, &m->commands);
}

void psd_mqttconf_free(struct psd_mqtt_conf *m)
{
	free(m->host);
	free(m->user);
	free(m->password_file);
	if (m->password)
		memset(m->password, 0, strlen(m->password));
	free(m->password);
	free(m->cafile);
	free(m->certfile);
	free(m->keyfile);
	memset(m, 0, sizeof *m);
}
