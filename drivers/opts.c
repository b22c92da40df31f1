/* SPDX-License-Identifier: ISC */
/* Driver options through their tables (opts.h). */
#include "opts.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "role.h"

const char *const ps_opts_type_names[] = { "double", "long", "enum", "bool", "string", "windows", NULL };
static const char *const bool_names[] = { "no", "yes", NULL };

const struct ps_opts_spec *ps_opts_spec_find(const struct ps_opts_spec *t, int scope, const char *key)
{
	for (; t && t->key; t++)
		if (t->scope == scope && strcmp(t->key, key) == 0)
			return t;
	return NULL;
}

static struct ps_opt *find(const struct ps_opts *o, const char *key)
{
	for (size_t i = 0; o && i < o->n; i++)
		if (strcmp(o->v[i].key, key) == 0) {
			o->v[i].used = 1;
			return &o->v[i];
		}
	return NULL;
}

const char *ps_opts_get(const struct ps_opts *o, const char *key)
{
	struct ps_opt *p = find(o, key);
	return p ? p->value : NULL;
}

int ps_opts_line(const struct ps_opts *o, const char *key)
{
	for (size_t i = 0; o && i < o->n; i++)
		if (strcmp(o->v[i].key, key) == 0)
			return o->v[i].line;
	return 0;
}

static const char *file_of(const struct ps_opts *o)
{
	return o && o->file ? o->file : "(config)";
}

/* The reader's error: at line, "file:line: msg" or msg alone (r->line). */
static int reader_fail(const struct ps_opts_reader *r, int line, const char *msg)
{
	if (r->line) {
		*r->line = line;
		snprintf(r->err, r->errlen, "%s", msg);
	} else {
		snprintf(r->err, r->errlen, "%s:%d: %s", file_of(r->opts), line, msg);
	}
	errno = EINVAL;
	return -1;
}

int ps_opts_fail(const struct ps_opts_reader *r, const char *key, const char *fmt, ...)
{
	char msg[300];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(msg, sizeof msg, fmt, ap);
	va_end(ap);
	return reader_fail(r, ps_opts_line(r->opts, key), msg);
}

/* ---- one value --------------------------------------------------------------- */

/* "a, b, c" of names, for messages. */
static void list_names(const char *const *names, char *out, size_t n)
{
	size_t len = 0;
	out[0] = 0;
	for (int i = 0; names[i] && len < n; i++)
		len += (size_t)snprintf(out + len, n - len, "%s%s", i == 0 ? "" : ", ", names[i]);
}

static int why_not(char *why, size_t n, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static int why_not(char *why, size_t n, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(why, n, fmt, ap);
	va_end(ap);
	return -1;
}

static int name_index(const char *const *names, const char *s, size_t len)
{
	for (int i = 0; names[i]; i++)
		if (strlen(names[i]) == len && strncmp(names[i], s, len) == 0)
			return i;
	return -1;
}

/* "HH:MM" at s: seconds since midnight, -1 if malformed (24:00 is the end
 * of the day). */
static double hhmm(const char *s, const char **end)
{
	int h, m, n = 0;
	if (sscanf(s, "%2d:%2d%n", &h, &m, &n) != 2 || h < 0 || h > 24 || m < 0 || m > 59 || (h == 24 && m))
		return -1;
	*end = s + n;
	return h * 3600.0 + m * 60.0;
}

static int parse_windows(const struct ps_opts_spec *s, const char *text, struct ps_opts_window *w, size_t *nw,
                         char *why, size_t n)
{
	char names[160] = "";
	const char *p = text;
	size_t max = s->max >= 1 && s->max <= PS_OPT_MAX_WINDOWS ? (size_t)s->max : PS_OPT_MAX_WINDOWS;
	if (s->names)
		list_names(s->names, names, sizeof names);
	*nw = 0;
	for (;;) {
		struct ps_opts_window win = { 0, 0, 0 };
		const char *item, *end;
		while (*p == ' ' || *p == '\t')
			p++;
		item = p;
		if (s->names) {
			size_t len = strcspn(p, " \t,");
			if ((win.kind = name_index(s->names, p, len)) < 0)
				return why_not(why, n, "'%.*s' is not one of %s", (int)len, p, names);
			p += len;
			while (*p == ' ' || *p == '\t')
				p++;
		}
		if ((win.start = hhmm(p, &end)) < 0 || *end != '-' || (win.end = hhmm(end + 1, &p)) < 0)
			return why_not(why, n, "'%.*s' is not %sHH:MM-HH:MM", (int)strcspn(item, ","), item,
			               s->names ? "KIND " : "");
		while (*p == ' ' || *p == '\t')
			p++;
		if (*p && *p != ',')
			return why_not(why, n, "'%.*s' is not %sHH:MM-HH:MM", (int)strcspn(item, ","), item,
			               s->names ? "KIND " : "");
		if (*nw >= max)
			return why_not(why, n, "more than %zu windows", max);
		w[(*nw)++] = win;
		if (!*p)
			return 0;
		p++;
	}
}

union value {
	double d;
	long l;
	int choice;
	const char *s;
};

/* Judge text as the spec's type: 0 with the value, or -1 with why (the
 * text after "key: 'value' "). */
static int parse(const struct ps_opts_spec *s, const char *text, union value *v, char *why, size_t n)
{
	char names[200];
	char *end;
	switch (s->type) {
	case PS_OPT_DOUBLE:
		errno = 0;
		v->d = strtod(text, &end);
		if (end == text || *end || errno == ERANGE || !isfinite(v->d))
			return why_not(why, n, "is not a number");
		if (v->d < s->min || v->d > s->max)
			return why_not(why, n, "is outside %g to %g", s->min, s->max);
		return 0;
	case PS_OPT_LONG:
		errno = 0;
		v->l = strtol(text, &end, 0);
		if (end == text || *end || errno == ERANGE)
			return why_not(why, n, "is not a whole number");
		if (s->names) {
			for (int i = 0; s->names[i]; i++)
				if (strtol(s->names[i], NULL, 0) == v->l)
					return 0;
			list_names(s->names, names, sizeof names);
			return why_not(why, n, "is not one of %s", names);
		}
		if ((double)v->l < s->min || (double)v->l > s->max)
			return why_not(why, n, "is outside %.0f to %.0f", s->min, s->max);
		return 0;
	case PS_OPT_ENUM:
	case PS_OPT_BOOL: {
		const char *const *choices = s->type == PS_OPT_BOOL ? bool_names : s->names;
		if ((v->choice = name_index(choices, text, strlen(text))) >= 0)
			return 0;
		list_names(choices, names, sizeof names);
		return why_not(why, n, "is not one of %s", names);
	}
	case PS_OPT_STRING:
		v->s = text;
		return s->valid ? s->valid(text, why, n) : 0;
	default: {
		struct ps_opts_window w[PS_OPT_MAX_WINDOWS];
		size_t nw;
		return parse_windows(s, text, w, &nw, why, n);
	}
	}
}

/* ---- a section against a table -------------------------------------------- */

int ps_opts_check(const struct ps_opts_spec *table, const char *driver, const struct ps_opts *o, int role,
                  ps_opts_report_fn report, void *user)
{
	int errors = 0;
	int scope = role < 0 ? PS_OPT_DEVICE : PS_OPT_POINT;
	for (size_t i = 0; o && i < o->n; i++) {
		const struct ps_opt *p = &o->v[i];
		const struct ps_opts_spec *s = ps_opts_spec_find(table, scope, p->key);
		char why[300], msg[400];
		union value v;
		if (!s) {
			const struct ps_opts_spec *other = ps_opts_spec_find(table, scope == PS_OPT_DEVICE ? PS_OPT_POINT
			                                                                                 : PS_OPT_DEVICE, p->key);
			snprintf(msg, sizeof msg, "unknown key '%s' for driver %s%s", p->key, driver,
			         !other ? "" : scope == PS_OPT_DEVICE ? " (a point key, not a device key)"
			                                               : " (a device key, not a point key)");
		} else if (s->roles && role >= 0 && !(s->roles & PS_ROLE_BIT(role))) {
			char roles[100] = "";
			size_t len = 0;
			for (int r = 0; r < PS_ROLE_COUNT; r++)
				if (s->roles & PS_ROLE_BIT(r))
					len += (size_t)snprintf(roles + len, sizeof roles - len, "%s%s", len ? ", " : "",
					                        ps_role_name(r));
			snprintf(msg, sizeof msg, "%s: driver %s takes it on %s points, not %s", p->key, driver, roles,
			         ps_role_name(role));
		} else if (parse(s, p->value, &v, why, sizeof why) != 0) {
			if (s->type == PS_OPT_WINDOWS)   /* why quotes the item at fault */
				snprintf(msg, sizeof msg, "%s: %s", p->key, why);
			else
				snprintf(msg, sizeof msg, "%s: '%s' %s", p->key, p->value, why);
		} else {
			continue;
		}
		report(user, p->line, msg);
		errors++;
	}
	return errors;
}

/* ---- reading values --------------------------------------------------------- */

/* The key's spec and its text (the section's, else the default; NULL: absent
 * with no default).  -1 when the table does not have the key of that type. */
static int lookup(const struct ps_opts_reader *r, const char *key, int type, const struct ps_opts_spec **s,
                  const struct ps_opt **given, const char **text)
{
	*s = ps_opts_spec_find(r->table, r->scope, key);
	if (!*s || ((*s)->type != type && !(type == PS_OPT_ENUM && (*s)->type == PS_OPT_BOOL)))
		return ps_opts_fail(r, key, "%s: not in the driver's option table as a %s", key,
		                    ps_opts_type_names[type]);
	*given = find(r->opts, key);
	*text = *given ? (*given)->value : (*s)->def;
	return 0;
}

static int read_value(const struct ps_opts_reader *r, const char *key, int type, union value *v)
{
	const struct ps_opts_spec *s;
	const struct ps_opt *given;
	const char *text;
	char why[300], msg[400];
	if (lookup(r, key, type, &s, &given, &text) != 0)
		return -1;
	if (!text)
		return 1;   /* absent, no default */
	if (parse(s, text, v, why, sizeof why) == 0)
		return 0;
	snprintf(msg, sizeof msg, "%s: '%s' %s", key, text, why);
	return reader_fail(r, given ? given->line : 0, msg);
}

int ps_opts_double(const struct ps_opts_reader *r, const char *key, double *out)
{
	union value v;
	int rc = read_value(r, key, PS_OPT_DOUBLE, &v);
	if (rc == 0)
		*out = v.d;
	return rc < 0 ? -1 : 0;
}

int ps_opts_long(const struct ps_opts_reader *r, const char *key, long *out)
{
	union value v;
	int rc = read_value(r, key, PS_OPT_LONG, &v);
	if (rc == 0)
		*out = v.l;
	return rc < 0 ? -1 : 0;
}

int ps_opts_choice(const struct ps_opts_reader *r, const char *key, int *out)
{
	union value v;
	int rc = read_value(r, key, PS_OPT_ENUM, &v);
	if (rc == 0)
		*out = v.choice;
	return rc < 0 ? -1 : 0;
}

int ps_opts_string(const struct ps_opts_reader *r, const char *key, const char **out)
{
	union value v;
	int rc = read_value(r, key, PS_OPT_STRING, &v);
	if (rc == 0)
		*out = v.s;
	return rc < 0 ? -1 : 0;
}

int ps_opts_windows(const struct ps_opts_reader *r, const char *key, struct ps_opts_window *w, size_t *nw)
{
	const struct ps_opts_spec *s;
	const struct ps_opt *given;
	const char *text;
	char why[300], msg[400];
	*nw = 0;
	if (lookup(r, key, PS_OPT_WINDOWS, &s, &given, &text) != 0)
		return -1;
	if (!text || parse_windows(s, text, w, nw, why, sizeof why) == 0)
		return 0;
	snprintf(msg, sizeof msg, "%s: %s", key, why);
	return reader_fail(r, given ? given->line : 0, msg);
}
