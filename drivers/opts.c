/* Helpers every driver uses: options with their config lines, role names,
 * and the one way to fail (dev->err + errno). */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "driver.h"

static const char *const role_names[PS_ROLE_COUNT] = { "sensor", "task", "dim", "relay", "input" };

const char *ps_role_name(int role)
{
	return role >= 0 && role < PS_ROLE_COUNT ? role_names[role] : "?";
}

int ps_role_parse(const char *name)
{
	for (int i = 0; i < PS_ROLE_COUNT; i++)
		if (strcmp(name, role_names[i]) == 0)
			return i;
	return -1;
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

const char *ps_opt_get(const struct ps_opts *o, const char *key)
{
	struct ps_opt *p = find(o, key);
	return p ? p->value : NULL;
}

int ps_opt_line(const struct ps_opts *o, const char *key)
{
	for (size_t i = 0; o && i < o->n; i++)
		if (strcmp(o->v[i].key, key) == 0)
			return o->v[i].line;
	return 0;
}

static int bad(const struct ps_opts *o, const struct ps_opt *p, char *err, size_t len,
               const char *why)
{
	snprintf(err, len, "%s:%d: %s: '%s' %s", o->file ? o->file : "(config)", p->line, p->key,
	         p->value, why);
	errno = EINVAL;
	return -1;
}

int ps_opt_double(const struct ps_opts *o, const char *key, double def, double min, double max,
                  double *out, char *err, size_t errlen)
{
	struct ps_opt *p = find(o, key);
	char *end;
	double v;
	*out = def;
	if (!p)
		return 0;
	errno = 0;
	v = strtod(p->value, &end);
	if (end == p->value || *end || errno == ERANGE || !isfinite(v))
		return bad(o, p, err, errlen, "is not a number");
	if (v < min || v > max) {
		char why[96];
		snprintf(why, sizeof why, "is outside %g to %g", min, max);
		return bad(o, p, err, errlen, why);
	}
	*out = v;
	return 0;
}

int ps_opt_long(const struct ps_opts *o, const char *key, long def, long min, long max,
                long *out, char *err, size_t errlen)
{
	struct ps_opt *p = find(o, key);
	char *end;
	long v;
	*out = def;
	if (!p)
		return 0;
	errno = 0;
	v = strtol(p->value, &end, 0);
	if (end == p->value || *end || errno == ERANGE)
		return bad(o, p, err, errlen, "is not a whole number");
	if (v < min || v > max) {
		char why[96];
		snprintf(why, sizeof why, "is outside %ld to %ld", min, max);
		return bad(o, p, err, errlen, why);
	}
	*out = v;
	return 0;
}

int ps_opt_enum(const struct ps_opts *o, const char *key, const char *const *names, int def,
                int *out, char *err, size_t errlen)
{
	struct ps_opt *p = find(o, key);
	*out = def;
	if (!p)
		return 0;
	for (int i = 0; names[i]; i++)
		if (strcmp(p->value, names[i]) == 0)
			return *out = i, 0;
	return bad(o, p, err, errlen, "is not a known choice");
}

int ps_dev_fail(struct ps_dev *dev, int err, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(dev->err, sizeof dev->err, fmt, ap);
	va_end(ap);
	errno = err;
	return -1;
}
