/* SPDX-License-Identifier: ISC */
/* INI configuration files (the scene file and psensd.conf) read with inih,
 * with every error located as file:line and all of them reported in one pass.
 *
 * Sections may carry a name after their kind: "[condition day_0318]" has
 * kind "condition" and name "day_0318".  Keys are case-sensitive.  Every
 * lookup marks the key as used; ps_conf_check_unused() then reports keys
 * nobody asked for (typos) as errors. */
#ifndef PS_CONF_H
#define PS_CONF_H

#include <stddef.h>

#include "err.h"
#include "keyidx.h"

struct ps_conf_kv {
	char *key;
	char *value;
	int line;
	int used;
};

struct ps_conf_section {
	char *name;          /* the whole text between [ ] */
	int line;
	struct ps_conf_kv *kv;
	size_t nkv;
	size_t kv_cap;         /* kv's allocated length */
	struct ps_keyidx keys; /* key -> its index in kv */
	int used;
};

struct ps_conf {
	char *path;          /* as given to ps_conf_load */
	char *dir;           /* directory of path, for relative names */
	struct ps_conf_section *sec;   /* sec[0] is the unnamed section before any [ ] */
	size_t nsec;
	char **errors;       /* "path:line: message", in order found */
	size_t nerrors;
};

/* Read path.  Returns 0 and fills c even when the file has syntax errors
 * (they are in c->errors); -1 with *e set when the file cannot be read. */
int ps_conf_load(struct ps_conf *c, const char *path, struct ps_err *e);
/* Same from a string (path is only used in messages). */
int ps_conf_load_string(struct ps_conf *c, const char *text, const char *path, struct ps_err *e);
void ps_conf_free(struct ps_conf *c);

/* Add an error "path:line: ..." (line 0: no line). */
void ps_conf_error(struct ps_conf *c, int line, const char *fmt, ...)
	__attribute__((format(printf, 3, 4)));

/* The section with this exact name, or NULL. */
struct ps_conf_section *ps_conf_section(struct ps_conf *c, const char *name);
/* If s is "[kind name]" with the given kind, return name (may be ""), else NULL. */
const char *ps_conf_section_is(const struct ps_conf_section *s, const char *kind);

/* Lookups.  A missing key gives the default (or, with required, an error).
 * A present but malformed or out-of-range value adds an error naming the
 * file and line and returns -1, leaving *out at the default. */
struct ps_conf_kv *ps_conf_kv(struct ps_conf_section *s, const char *key);
const char *ps_conf_str(struct ps_conf *c, struct ps_conf_section *s, const char *key,
                        const char *def);
int ps_conf_required(struct ps_conf *c, struct ps_conf_section *s, const char *key);
int ps_conf_double(struct ps_conf *c, struct ps_conf_section *s, const char *key,
                   double def, double min, double max, double *out);
int ps_conf_int(struct ps_conf *c, struct ps_conf_section *s, const char *key,
                long def, long min, long max, long *out);
int ps_conf_bool(struct ps_conf *c, struct ps_conf_section *s, const char *key,
                 int def, int *out);
/* names is NULL-terminated; *out is the index of the match. */
int ps_conf_enum(struct ps_conf *c, struct ps_conf_section *s, const char *key,
                 const char *const *names, int def, int *out);
/* A path value resolved against the config file's directory (malloc'd), or
 * NULL when the key is absent. */
char *ps_conf_path(struct ps_conf *c, struct ps_conf_section *s, const char *key);

/* Report every key never looked up, and every section never looked at. */
void ps_conf_check_unused(struct ps_conf *c);

/* Parse a whole string as a finite double; 0 on success. */
int ps_conf_parse_double(const char *text, double *out);

/* Join dir and a relative name (an absolute name is returned as is); malloc'd. */
char *ps_conf_path_join(const char *dir, const char *name);

#endif
