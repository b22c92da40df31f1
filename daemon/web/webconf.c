/* SPDX-License-Identifier: ISC */
/* The [web] section of psensd.conf (webconf.h). */
#include "webconf.h"

#include <arpa/inet.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static int line_of(struct ps_conf_section *s, const char *key)
{
	struct ps_conf_kv *kv = ps_conf_kv(s, key);
	return kv ? kv->line : s->line;
}

static void bind_addr(struct psd_web_conf *w, struct ps_conf *c, struct ps_conf_section *s)
{
	const char *v = ps_conf_str(c, s, "bind", NULL), *colon;
	struct in_addr a;
	char *end;
	long port;
	if (!v || !*v) {
		ps_conf_error(c, s->line, "[web] needs 'bind' (ADDR:PORT, e.g. 127.0.0.1:8080 behind a reverse proxy)");
		return;
	}
	colon = strrchr(v, ':');
	if (!colon || (size_t)(colon - v) >= sizeof w->addr) {
		ps_conf_error(c, line_of(s, "bind"), "bind: '%s' is not ADDR:PORT", v);
		return;
	}
	snprintf(w->addr, sizeof w->addr, "%.*s", (int)(colon - v), v);
	errno = 0;
	port = strtol(colon + 1, &end, 10);
	if (inet_pton(AF_INET, w->addr, &a) != 1)
		ps_conf_error(c, line_of(s, "bind"), "bind: '%s' is not an IPv4 address", w->addr);
	else if (end == colon + 1 || *end || errno || port < 1 || port > 65535)
		ps_conf_error(c, line_of(s, "bind"), "bind: port '%s' is not 1 to 65535", colon + 1);
	else
		w->port = port;
}

/* The hash: the file's first line, refused when others may read it or its
 * group or others may change it. */
static void read_hash(struct psd_web_conf *w, struct ps_conf *c, struct ps_conf_section *s)
{
	char *path = ps_conf_path(c, s, "password_file"), buf[PSD_WEBPASS_LINE + 2], why[160];
	int line = line_of(s, "password_file");
	struct stat st;
	FILE *fp;
	if (!path) {
		ps_conf_error(c, s->line, "[web] needs 'password_file' (make one with psensctl web-passwd FILE)");
		return;
	}
	if (!(fp = fopen(path, "re"))) {
		ps_conf_error(c, line, "password_file: %s: %s", path, strerror(errno));
	} else {
		if (fstat(fileno(fp), &st) != 0 || !S_ISREG(st.st_mode))
			ps_conf_error(c, line, "password_file: %s is not a regular file", path);
		else if (st.st_mode & (S_IWGRP | S_IWOTH | S_IROTH))
			ps_conf_error(c, line, "password_file: %s is %s by others (mode %04o): chmod o-rw,g-w it", path,
			              (st.st_mode & S_IROTH) ? "readable" : "writable", (unsigned)(st.st_mode & 07777));
		else if (!fgets(buf, sizeof buf, fp))
			ps_conf_error(c, line, "password_file: %s is empty", path);
		else if (buf[strcspn(buf, "\r\n")] = 0, !psd_webpass_valid(buf, why, sizeof why))
			ps_conf_error(c, line, "password_file: %s: %s", path, why);
		else if (strlen(buf) >= sizeof w->hash)
			ps_conf_error(c, line, "password_file: %s: the hash line is too long", path);
		else
			memcpy(w->hash, buf, strlen(buf) + 1);
		fclose(fp);
	}
	free(path);
}

void psd_webconf_load(struct psd_web_conf *w, struct ps_conf *c)
{
	struct ps_conf_section *s = ps_conf_section(c, "web");
	const char *v;
	memset(w, 0, sizeof *w);
	if (!s)
		return;
	s->used = 1;
	w->enabled = 1;
	w->line = s->line;
	bind_addr(w, c, s);
	read_hash(w, c, s);
	ps_conf_double(c, s, "session", 12 * 3600, 10, 30 * 86400, &w->session);
	ps_conf_double(c, s, "update", 1, 0.1, 60, &w->update);
	v = ps_conf_str(c, s, "url", "");
	if (*v && strncmp(v, "http://", 7) != 0 && strncmp(v, "https://", 8) != 0)
		ps_conf_error(c, line_of(s, "url"), "url: '%s' is not an http:// or https:// address", v);
	else if (strlen(v) >= sizeof w->url - 64)
		ps_conf_error(c, line_of(s, "url"), "url: at most %zu characters", sizeof w->url - 65);
	else
		snprintf(w->url, sizeof w->url, "%s", v);
}
