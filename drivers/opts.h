/* SPDX-License-Identifier: ISC */
/* Driver options.  A configuration section hands a driver its keys as a
 * struct ps_opts (key, value, file and line); each driver declares the keys
 * it takes in one table of struct ps_opts_spec (key, type, default, range,
 * device or point, one line of documentation), and everything that judges
 * or reads a key goes through that table:
 *
 *   ps_opts_check    the daemon's configuration check (psensd -n, SIGHUP):
 *                   every key of a section judged, every error with its line
 *   ps_opts_double and the other readers   the driver's open and add_point:
 *                   typed values, the table's default when a key is absent
 *   psensd -L       the tables printed; the man pages list the same keys
 *                   (tests/system/510 compares them)
 *
 * so a default or a range is written once and nothing parses a key twice. */
#ifndef PS_OPTS_H
#define PS_OPTS_H

#include <stddef.h>

/* One configuration option handed to a driver: key, value and where it was
 * written, so a driver's message can name file and line. */
struct ps_opt {
	const char *key;
	const char *value;
	int line;
	int used;             /* set when read; a caller may report keys never read */
};

struct ps_opts {
	struct ps_opt *v;
	size_t n;
	const char *file;     /* config file name for messages */
};

enum ps_opts_type {
	PS_OPT_DOUBLE = 0,    /* a number in [min, max] */
	PS_OPT_LONG,          /* a whole number (0x.. hex) in [min, max]; names: the only values allowed */
	PS_OPT_ENUM,          /* one of names */
	PS_OPT_BOOL,          /* yes or no */
	PS_OPT_STRING,        /* any text, or what valid accepts */
	PS_OPT_WINDOWS,       /* "HH:MM-HH:MM, ..." (at most max), each after one of names if names */
	PS_OPT_TYPE_COUNT
};
extern const char *const ps_opts_type_names[];   /* "double", "long", ... */

enum ps_opts_scope { PS_OPT_DEVICE = 1, PS_OPT_POINT = 2 };

/* A point key applies to the roles in its mask (0: every role). */
#define PS_ROLE_BIT(role) (1u << (role))

struct ps_opts_spec {
	const char *key;
	int type;                  /* enum ps_opts_type */
	int scope;                 /* enum ps_opts_scope */
	unsigned roles;            /* point keys: PS_ROLE_BIT()s of the roles it applies to; 0: all */
	const char *def;           /* the default as written in a file; NULL: none (doc says what absent means) */
	double min, max;           /* DOUBLE, LONG: the range; WINDOWS: max is the most windows */
	const char *const *names;  /* ENUM: the choices; LONG: the only values; WINDOWS: each window's kinds */
	int (*valid)(const char *value, char *why, size_t n);   /* STRING: its syntax, 0 good (NULL: any) */
	const char *doc;           /* one line for psensd -L and the man pages */
};
/* A table ends with an entry whose key is NULL. */

/* A time window of a WINDOWS option, seconds since midnight (start > end
 * crosses midnight); kind indexes the spec's names (0 when it has none). */
struct ps_opts_window {
	int kind;
	double start, end;
};
enum { PS_OPT_MAX_WINDOWS = 16 };

/* The entry for key in a scope; NULL when the table has none. */
const struct ps_opts_spec *ps_opts_spec_find(const struct ps_opts_spec *table, int scope, const char *key);

/* Judge every key of a device section (role < 0) or a point section with a
 * role against a table: keys it does not know, keys of another role, values
 * of the wrong type or outside the range.  Each error goes to report with
 * its line (0 for a key that is missing: the caller knows the section's)
 * and the text without a location ("baud: '96000' is not one of
 * 1200, ..."); returns the number of errors.  driver names the driver in
 * messages. */
typedef void (*ps_opts_report_fn)(void *user, int line, const char *why);
int ps_opts_check(const struct ps_opts_spec *table, const char *driver, const struct ps_opts *o, int role,
                  ps_opts_report_fn report, void *user);

/* Reading a section's values through a table, in a driver's open or
 * add_point.  A key absent from the section gives the table's default, or
 * leaves *out as it was when the table has none; a bad value gives -1, errno
 * EINVAL and "file:line: key: 'value' why" in err. */
struct ps_opts_reader {
	const struct ps_opts *opts;       /* NULL: every key absent */
	const struct ps_opts_spec *table;
	int scope;                        /* PS_OPT_DEVICE or PS_OPT_POINT */
	char *err;
	size_t errlen;
	int *line;                        /* NULL; else the key's line goes here and err has no
	                                     "file:line: " (a check method's form) */
};
int ps_opts_double(const struct ps_opts_reader *r, const char *key, double *out);
int ps_opts_long(const struct ps_opts_reader *r, const char *key, long *out);
/* ENUM: the index into names; BOOL: 1 yes, 0 no. */
int ps_opts_choice(const struct ps_opts_reader *r, const char *key, int *out);
int ps_opts_string(const struct ps_opts_reader *r, const char *key, const char **out);
/* w has room for the spec's max windows; *n gets the count. */
int ps_opts_windows(const struct ps_opts_reader *r, const char *key, struct ps_opts_window *w, size_t *n);

/* Raw access, no table: the value (marked used), NULL if absent; the line
 * of a key for messages (0 if absent). */
const char *ps_opts_get(const struct ps_opts *o, const char *key);
int ps_opts_line(const struct ps_opts *o, const char *key);
/* A bad option found outside the readers (a rule across keys): the key's
 * location and the message into the reader's err (or line), errno EINVAL;
 * returns -1. */
int ps_opts_fail(const struct ps_opts_reader *r, const char *key, const char *fmt, ...)
	__attribute__((format(printf, 3, 4)));

#endif
