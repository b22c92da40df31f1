/* SPDX-License-Identifier: ISC */
#include "conf.h"

#include <errno.h>
#include <ini.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* inih does not give the handler a line number in Debian's build
 * (INI_HANDLER_LINENO is 0), so we feed it lines ourselves and count. */
struct reader {
	const char *text;      /* string input, or NULL */
	size_t pos;
	FILE *fp;              /* file input */
	int line;              /* line of the text handed out last */
	int oom;
	struct ps_conf *c;
};

enum { CONF_MAX_LINE = 4096 };

static char *xstrdup(const char *s)
{
	size_t n = strlen(s) + 1;
	char *p = malloc(n);
	if (p)
		memcpy(p, s, n);
	return p;
}

void ps_conf_error(struct ps_conf *c, int line, const char *fmt, ...)
{
	char msg[600], full[800];
	va_list ap;
	char **grown;
	va_start(ap, fmt);
	vsnprintf(msg, sizeof msg, fmt, ap);
	va_end(ap);
	if (line > 0)
		snprintf(full, sizeof full, "%s:%d: %s", c->path ? c->path : "(config)", line, msg);
	else
		snprintf(full, sizeof full, "%s: %s", c->path ? c->path : "(config)", msg);
	grown = realloc(c->errors, (c->nerrors + 1) * sizeof *grown);
	if (!grown)
		return;
	c->errors = grown;
	c->errors[c->nerrors] = xstrdup(full);
	if (c->errors[c->nerrors])
		c->nerrors++;
}

/* Our own check of each line's shape, so that every syntax error is reported
 * with its line (inih only returns the first). */
static struct ps_conf_section *add_section(struct ps_conf *c, const char *name, int line);

static void check_line_shape(struct reader *r, const char *line, size_t len)
{
	const char *p = line;
	const char *close;
	while (*p == ' ' || *p == '\t' || *p == '\r')
		p++;
	if (*p == '\0' || *p == '\n' || *p == ';' || *p == '#')
		return;
	if (*p == '[') {
		/* Sections are created here, not in the handler: inih calls the
		 * handler only for keys, so it would miss empty sections and give
		 * the line of the first key instead of the header's. */
		char name[CONF_MAX_LINE];
		size_t n;
		close = memchr(p, ']', len - (size_t)(p - line));
		if (!close) {
			ps_conf_error(r->c, r->line, "section header without ']'");
			return;
		}
		n = (size_t)(close - p - 1);
		memcpy(name, p + 1, n);
		name[n] = '\0';
		for (size_t i = 1; i < r->c->nsec; i++)
			if (strcmp(r->c->sec[i].name, name) == 0) {
				ps_conf_error(r->c, r->line, "section [%s] appears twice (first at line %d)",
				              name, r->c->sec[i].line);
				break;
			}
		if (!add_section(r->c, name, r->line))
			r->oom = 1;
		return;
	}
	if (!strchr(p, '=') && !strchr(p, ':'))
		ps_conf_error(r->c, r->line, "expected 'key = value', '[section]' or a comment");
}

static char *read_line(char *buf, int size, void *stream)
{
	struct reader *r = stream;
	size_t n = 0;
	int too_long = 0;
	if (r->text) {
		/* the line with its newline, copied whole (as much as fits) */
		const char *p = r->text + r->pos, *nl;
		size_t len;
		if (*p == '\0')
			return NULL;
		nl = strchr(p, '\n');
		len = nl ? (size_t)(nl - p) + 1 : strlen(p);
		r->pos += len;
		n = len < (size_t)size ? len : (size_t)size - 1;
		too_long = len > n;
		memcpy(buf, p, n);
		buf[n] = '\0';
	} else {
		int ch;
		if (feof(r->fp))
			return NULL;
		while ((ch = fgetc(r->fp)) != EOF) {
			if (n + 1 < (size_t)size)
				buf[n++] = (char)ch;
			else
				too_long = 1;
			if (ch == '\n')
				break;
		}
		if (n == 0 && ch == EOF)
			return NULL;
		buf[n] = '\0';
	}
	r->line++;
	if (memchr(buf, '\0', n) != NULL || strlen(buf) != n)
		ps_conf_error(r->c, r->line, "NUL byte in line");
	if (too_long) {
		ps_conf_error(r->c, r->line, "line longer than %d bytes", size - 1);
		buf[0] = '\0';   /* drop it rather than parse a fragment */
		return buf;
	}
	check_line_shape(r, buf, n);
	return buf;
}

static struct ps_conf_section *add_section(struct ps_conf *c, const char *name, int line)
{
	struct ps_conf_section *grown = realloc(c->sec, (c->nsec + 1) * sizeof *grown);
	if (!grown)
		return NULL;
	c->sec = grown;
	memset(&c->sec[c->nsec], 0, sizeof c->sec[c->nsec]);
	c->sec[c->nsec].name = xstrdup(name);
	c->sec[c->nsec].line = line;
	if (!c->sec[c->nsec].name)
		return NULL;
	return &c->sec[c->nsec++];
}

struct handler_ctx {
	struct reader *r;
	struct ps_conf *c;
	int oom;
};

static int on_pair(void *user, const char *section, const char *key, const char *value)
{
	struct handler_ctx *h = user;
	struct ps_conf *c = h->c;
	struct ps_conf_section *s = &c->sec[c->nsec - 1];
	struct ps_conf_kv *grown;
	size_t first;
	if (key == NULL)
		return 1;
	if (strcmp(s->name, section) != 0) {
		/* The reader created the section; a mismatch means inih read the
		 * header differently from us: keep going under inih's name. */
		s = add_section(c, section, h->r->line);
		if (!s) {
			h->oom = 1;
			return 0;
		}
	}
	if (*key == '\0') {
		ps_conf_error(c, h->r->line, "empty key");
		return 1;
	}
	if (ps_keyidx_find(&s->keys, key, &first)) {
		ps_conf_error(c, h->r->line, "key '%s' set twice in [%s] (first at line %d)",
		              key, s->name, s->kv[first].line);
		return 1;
	}
	/* grown by doubling: a section of thousands of keys loads in linear time */
	if (s->nkv == s->kv_cap) {
		size_t cap = s->kv_cap ? s->kv_cap * 2 : 8;
		grown = cap < SIZE_MAX / sizeof *grown ? realloc(s->kv, cap * sizeof *grown) : NULL;
		if (!grown) {
			h->oom = 1;
			return 0;
		}
		s->kv = grown;
		s->kv_cap = cap;
	}
	s->kv[s->nkv].key = xstrdup(key);
	s->kv[s->nkv].value = xstrdup(value ? value : "");
	s->kv[s->nkv].line = h->r->line;
	s->kv[s->nkv].used = 0;
	if (!s->kv[s->nkv].key || !s->kv[s->nkv].value ||
	    ps_keyidx_add(&s->keys, s->kv[s->nkv].key, s->nkv) != 0) {
		free(s->kv[s->nkv].key);
		free(s->kv[s->nkv].value);
		h->oom = 1;
		return 0;
	}
	s->nkv++;
	return 1;
}

static int parse_common(struct ps_conf *c, struct reader *r, const char *path, struct ps_err *e)
{
	struct handler_ctx h = { r, c, 0 };
	const char *slash;
	int rc;
	memset(c, 0, sizeof *c);
	c->path = xstrdup(path ? path : "(config)");
	slash = c->path ? strrchr(c->path, '/') : NULL;
	if (!c->path)
		return ps_err_set(e, PS_ENOMEM, "out of memory reading %s", path);
	if (slash) {
		c->dir = malloc((size_t)(slash - c->path) + 2);
		if (c->dir) {
			memcpy(c->dir, c->path, (size_t)(slash - c->path) + 1);
			c->dir[slash - c->path + 1] = '\0';
		}
	} else {
		c->dir = xstrdup("./");
	}
	r->c = c;
	if (!c->dir || !add_section(c, "", 0)) {
		ps_conf_free(c);
		return ps_err_set(e, PS_ENOMEM, "out of memory reading %s", path);
	}
	rc = ini_parse_stream(read_line, r, on_pair, &h);
	if (h.oom || r->oom) {
		ps_conf_free(c);
		return ps_err_set(e, PS_ENOMEM, "out of memory reading %s", path);
	}
	/* Syntax errors inih found that our shape check did not (it reports the
	 * first one only): make sure at least that one is listed. */
	if (rc > 0 && c->nerrors == 0)
		ps_conf_error(c, rc, "syntax error");
	return 0;
}

int ps_conf_load(struct ps_conf *c, const char *path, struct ps_err *e)
{
	struct reader r = { 0 };
	int rc;
	r.fp = fopen(path, "r");
	if (!r.fp) {
		memset(c, 0, sizeof *c);
		return ps_err_sys(e, "%s", path);
	}
	ini_max_line = CONF_MAX_LINE;
	rc = parse_common(c, &r, path, e);
	if (rc == 0 && ferror(r.fp)) {
		fclose(r.fp);
		ps_conf_free(c);
		return ps_err_sys(e, "%s: read error", path);
	}
	fclose(r.fp);
	return rc;
}

int ps_conf_load_string(struct ps_conf *c, const char *text, const char *path, struct ps_err *e)
{
	struct reader r = { 0 };
	r.text = text;
	ini_max_line = CONF_MAX_LINE;
	return parse_common(c, &r, path, e);
}

void ps_conf_free(struct ps_conf *c)
{
	for (size_t i = 0; i < c->nsec; i++) {
		for (size_t j = 0; j < c->sec[i].nkv; j++) {
			free(c->sec[i].kv[j].key);
			free(c->sec[i].kv[j].value);
		}
		free(c->sec[i].kv);
		ps_keyidx_free(&c->sec[i].keys);
		free(c->sec[i].name);
	}
	for (size_t i = 0; i < c->nerrors; i++)
		free(c->errors[i]);
	free(c->errors);
	free(c->sec);
	free(c->path);
	free(c->dir);
	memset(c, 0, sizeof *c);
}

struct ps_conf_section *ps_conf_section(struct ps_conf *c, const char *name)
{
	for (size_t i = 0; i < c->nsec; i++)
		if (strcmp(c->sec[i].name, name) == 0) {
			c->sec[i].used = 1;
			return &c->sec[i];
		}
	return NULL;
}

const char *ps_conf_section_is(const struct ps_conf_section *s, const char *kind)
{
	size_t n = strlen(kind);
	if (strncmp(s->name, kind, n) != 0)
		return NULL;
	if (s->name[n] == '\0')
		return s->name + n;
	if (s->name[n] != ' ' && s->name[n] != '\t')
		return NULL;
	const char *p = s->name + n;
	while (*p == ' ' || *p == '\t')
		p++;
	return p;
}

struct ps_conf_kv *ps_conf_kv(struct ps_conf_section *s, const char *key)
{
	if (!s)
		return NULL;
	size_t i;
	s->used = 1;
	if (!ps_keyidx_find(&s->keys, key, &i))
		return NULL;
	s->kv[i].used = 1;
	return &s->kv[i];
}

const char *ps_conf_str(struct ps_conf *c, struct ps_conf_section *s, const char *key,
                        const char *def)
{
	struct ps_conf_kv *kv = ps_conf_kv(s, key);
	(void)c;
	return kv ? kv->value : def;
}

int ps_conf_required(struct ps_conf *c, struct ps_conf_section *s, const char *key)
{
	if (ps_conf_kv(s, key))
		return 0;
	ps_conf_error(c, s ? s->line : 0, "[%s] needs '%s'", s ? s->name : "", key);
	return -1;
}

int ps_conf_parse_double(const char *text, double *out)
{
	char *end;
	double v;
	errno = 0;
	v = strtod(text, &end);
	if (end == text)
		return -1;
	while (*end == ' ' || *end == '\t')
		end++;
	if (*end != '\0' || errno == ERANGE || !isfinite(v))
		return -1;
	*out = v;
	return 0;
}

static int ps_conf_parse_long(const char *text, long *out)
{
	char *end;
	long v;
	errno = 0;
	v = strtol(text, &end, 0);
	if (end == text)
		return -1;
	while (*end == ' ' || *end == '\t')
		end++;
	if (*end != '\0' || errno == ERANGE)
		return -1;
	*out = v;
	return 0;
}

int ps_conf_double(struct ps_conf *c, struct ps_conf_section *s, const char *key,
                   double def, double min, double max, double *out)
{
	struct ps_conf_kv *kv = ps_conf_kv(s, key);
	double v;
	*out = def;
	if (!kv)
		return 0;
	if (ps_conf_parse_double(kv->value, &v) != 0) {
		ps_conf_error(c, kv->line, "%s: '%s' is not a number", key, kv->value);
		return -1;
	}
	if (v < min || v > max) {
		ps_conf_error(c, kv->line, "%s: %g is outside %g to %g", key, v, min, max);
		return -1;
	}
	*out = v;
	return 0;
}

int ps_conf_int(struct ps_conf *c, struct ps_conf_section *s, const char *key,
                long def, long min, long max, long *out)
{
	struct ps_conf_kv *kv = ps_conf_kv(s, key);
	long v;
	*out = def;
	if (!kv)
		return 0;
	if (ps_conf_parse_long(kv->value, &v) != 0) {
		ps_conf_error(c, kv->line, "%s: '%s' is not a whole number", key, kv->value);
		return -1;
	}
	if (v < min || v > max) {
		ps_conf_error(c, kv->line, "%s: %ld is outside %ld to %ld", key, v, min, max);
		return -1;
	}
	*out = v;
	return 0;
}

int ps_conf_bool(struct ps_conf *c, struct ps_conf_section *s, const char *key,
                 int def, int *out)
{
	static const char *const yes[] = { "yes", "true", "on", "1", NULL };
	static const char *const no[] = { "no", "false", "off", "0", NULL };
	struct ps_conf_kv *kv = ps_conf_kv(s, key);
	*out = def;
	if (!kv)
		return 0;
	for (int i = 0; yes[i]; i++)
		if (strcmp(kv->value, yes[i]) == 0)
			return *out = 1, 0;
	for (int i = 0; no[i]; i++)
		if (strcmp(kv->value, no[i]) == 0)
			return *out = 0, 0;
	ps_conf_error(c, kv->line, "%s: '%s' is not yes or no", key, kv->value);
	return -1;
}

int ps_conf_enum(struct ps_conf *c, struct ps_conf_section *s, const char *key,
                 const char *const *names, int def, int *out)
{
	struct ps_conf_kv *kv = ps_conf_kv(s, key);
	char choices[400] = "";
	size_t used = 0;
	*out = def;
	if (!kv)
		return 0;
	for (int i = 0; names[i]; i++) {
		if (strcmp(kv->value, names[i]) == 0)
			return *out = i, 0;
		used += (size_t)snprintf(choices + used, used < sizeof choices ? sizeof choices - used : 0,
		                         "%s%s", i ? ", " : "", names[i]);
		if (used >= sizeof choices)
			used = sizeof choices - 1;
	}
	ps_conf_error(c, kv->line, "%s: '%s' is not one of %s", key, kv->value, choices);
	return -1;
}

char *ps_conf_path_join(const char *dir, const char *name)
{
	size_t nd, nn;
	char *p;
	if (name[0] == '/' || !dir || !*dir)
		return xstrdup(name);
	nd = strlen(dir);
	nn = strlen(name);
	p = malloc(nd + nn + 2);
	if (!p)
		return NULL;
	memcpy(p, dir, nd);
	if (dir[nd - 1] != '/')
		p[nd++] = '/';
	memcpy(p + nd, name, nn + 1);
	return p;
}

char *ps_conf_path(struct ps_conf *c, struct ps_conf_section *s, const char *key)
{
	const char *v = ps_conf_str(c, s, key, NULL);
	if (!v)
		return NULL;
	return ps_conf_path_join(c->dir, v);
}

void ps_conf_check_unused(struct ps_conf *c)
{
	for (size_t i = 0; i < c->nsec; i++) {
		struct ps_conf_section *s = &c->sec[i];
		if (!s->used && i > 0) {
			ps_conf_error(c, s->line, "unknown section [%s]", s->name);
			continue;
		}
		for (size_t j = 0; j < s->nkv; j++)
			if (!s->kv[j].used)
				ps_conf_error(c, s->kv[j].line, "unknown key '%s'%s%s%s", s->kv[j].key,
				              i ? " in [" : "", i ? s->name : "", i ? "]" : "");
	}
}
