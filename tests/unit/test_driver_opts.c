/* SPDX-License-Identifier: ISC */
/* The drivers' option tables and the skeleton driver through them: every
 * table's defaults pass its own checks, a section's errors come with their
 * lines, the readers give the defaults, and the file driver (drivers/file.c)
 * opens, reads, writes and fails as driver.h says. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

#include "driver.h"
#include "registry.h"

#define assert_near(a, b, tol) assert_true(fabs((double)(a) - (double)(b)) <= (tol))

struct errors {
	int n;
	int line[16];
	char text[16][200];
};

static void collect(void *user, int line, const char *why)
{
	struct errors *e = user;
	if (e->n < 16) {
		e->line[e->n] = line;
		snprintf(e->text[e->n], sizeof e->text[0], "%s", why);
	}
	e->n++;
}

/* A role a point key applies to. */
static int role_of(const struct ps_opts_spec *s)
{
	for (int r = 0; r < PS_ROLE_COUNT; r++)
		if (!s->roles || (s->roles & PS_ROLE_BIT(r)))
			return r;
	return -1;
}

/* Every compiled driver's table: keys unique in their scope, a line of
 * documentation each, choices where a type needs them, and every default
 * accepted by the table's own judgement and read back by the readers. */
static void tables_are_consistent(void **state)
{
	(void)state;
	for (int d = 0; ps_registry_drivers[d]; d++) {
		const struct ps_driver *drv = ps_registry_drivers[d];
		if (!drv->compiled_in) {
			assert_null(drv->options);   /* a stub judges nothing */
			continue;
		}
		assert_non_null(drv->options);
		for (const struct ps_opts_spec *s = drv->options; s->key; s++) {
			struct ps_opt kv = { s->key, s->def, 7, 0 };
			struct ps_opts o = { &kv, 1, "t.conf" };
			struct errors e = { 0 };
			char err[256];
			struct ps_opts_reader r = { NULL, drv->options, s->scope, err, sizeof err, NULL };
			assert_true(s->scope == PS_OPT_DEVICE || s->scope == PS_OPT_POINT);
			assert_ptr_equal(ps_opts_spec_find(drv->options, s->scope, s->key), s);
			assert_true(s->doc && strlen(s->doc) > 10);
			if (s->type == PS_OPT_ENUM)
				assert_non_null(s->names);
			if (!s->def)
				continue;
			ps_opts_check(drv->options, drv->name, &o, s->scope == PS_OPT_DEVICE ? -1 : role_of(s), collect, &e);
			if (e.n)
				fail_msg("%s %s default '%s': %s", drv->name, s->key, s->def, e.text[0]);
			/* absent from the section: the reader gives the default */
			if (s->type == PS_OPT_DOUBLE) {
				double v = NAN;
				assert_int_equal(ps_opts_double(&r, s->key, &v), 0);
				assert_near(v, strtod(s->def, NULL), 0);
			} else if (s->type == PS_OPT_LONG) {
				long v = -1;
				assert_int_equal(ps_opts_long(&r, s->key, &v), 0);
				assert_int_equal(v, strtol(s->def, NULL, 0));
			}
		}
	}
}

/* One pass over a section: each bad key with its own line; a key of
 * another role or scope said so. */
static void section_errors_with_lines(void **state)
{
	const struct ps_driver *lb = ps_registry_find("loopback");
	struct ps_opt kv[] = {
		{ "gain", "0.5.5", 11, 0 }, { "seed", "-3", 12, 0 }, { "off_below_min", "maybe", 13, 0 },
		{ "faults", "open 12:00-12:20, stuck 25:00-26:00", 14, 0 }, { "fade_rte", "0.2", 15, 0 },
		{ "occupied", "07:00-08:00", 16, 0 }, { "noise", "0.002", 17, 0 },
	};
	struct ps_opts o = { kv, 7, "t.conf" };
	struct errors e = { 0 };
	(void)state;
	assert_int_equal(ps_driver_check(lb, &o, -1, collect, &e), 6);
	assert_int_equal(e.line[0], 11);
	assert_string_equal(e.text[0], "gain: '0.5.5' is not a number");
	assert_string_equal(e.text[1], "seed: '-3' is outside 0 to 2147483647");
	assert_string_equal(e.text[2], "off_below_min: 'maybe' is not one of no, yes");
	assert_string_equal(e.text[3], "faults: 'stuck 25:00-26:00' is not KIND HH:MM-HH:MM");
	assert_string_equal(e.text[4], "unknown key 'fade_rte' for driver loopback");
	assert_int_equal(e.line[5], 16);
	assert_string_equal(e.text[5], "unknown key 'occupied' for driver loopback (a point key, not a device key)");
}

/* The readers: values and windows, and a bad value's location. */
static void readers(void **state)
{
	const struct ps_driver *lb = ps_registry_find("loopback");
	struct ps_opt kv[] = { { "faults", "open 12:00-12:20, obstruct 23:30-00:30", 5, 0 }, { "gain", "x", 6, 0 } };
	struct ps_opts o = { kv, 2, "t.conf" };
	char err[256];
	int line = -1;
	struct ps_opts_reader r = { &o, lb->options, PS_OPT_DEVICE, err, sizeof err, NULL };
	struct ps_opts_window w[16];
	size_t n;
	double v = 7;
	(void)state;
	assert_int_equal(ps_opts_windows(&r, "faults", w, &n), 0);
	assert_int_equal(n, 2);
	assert_int_equal(w[0].kind, 1);   /* "open", the second name */
	assert_near(w[0].start, 12 * 3600, 0);
	assert_near(w[1].start, 23.5 * 3600, 0);
	assert_near(w[1].end, 0.5 * 3600, 0);   /* across midnight */
	assert_int_equal(ps_opts_double(&r, "gain", &v), -1);
	assert_int_equal(errno, EINVAL);
	assert_string_equal(err, "t.conf:6: gain: 'x' is not a number");
	assert_near(v, 7, 0);
	r.line = &line;   /* the check methods' form: the line apart */
	assert_int_equal(ps_opts_double(&r, "gain", &v), -1);
	assert_int_equal(line, 6);
	assert_string_equal(err, "gain: 'x' is not a number");
	/* a key the table lacks is the driver's mistake, said as such */
	r.line = NULL;
	assert_int_equal(ps_opts_double(&r, "nosuch", &v), -1);
	assert_non_null(strstr(err, "nosuch: not in the driver's option table"));
}

static void fault_classes(void **state)
{
	(void)state;
	assert_true(ps_dev_fault_at_once(ENODEV) && ps_dev_fault_at_once(ENOTSUP) && ps_dev_fault_at_once(EINVAL) &&
	            ps_dev_fault_at_once(ERANGE) && ps_dev_fault_at_once(EOVERFLOW));
	assert_false(ps_dev_fault_at_once(ETIMEDOUT) || ps_dev_fault_at_once(EPROTO) || ps_dev_fault_at_once(EAGAIN));
}

static void put(const char *path, const char *text)
{
	FILE *fp = fopen(path, "w");
	assert_non_null(fp);
	fputs(text, fp);
	fclose(fp);
}

/* The skeleton driver end to end through the registry and its table. */
static void file_driver(void **state)
{
	char dir[] = "/tmp/test_driver_opts.XXXXXX", path[128], text[64];
	const struct ps_driver *drv = ps_registry_find("file");
	struct ps_opt dkv[] = { { "dir", dir, 2, 0 } };
	struct ps_opts dopts = { dkv, 1, "t.conf" };
	struct ps_opt skv[] = { { "path", "light", 5, 0 }, { "scale", "2", 6, 0 } };
	struct ps_opts sopts = { skv, 2, "t.conf" };
	struct ps_opt okv[] = { { "path", "lamps", 8, 0 }, { "scale", "2", 9, 0 } };
	struct ps_opts oopts = { okv, 2, "t.conf" };
	struct ps_opt bkv[] = { { "scale", "0", 12, 0 } };
	struct ps_opts bopts = { bkv, 1, "t.conf" };
	struct ps_dev dev = { 0 };
	struct ps_point s = { "light", PS_ROLE_SENSOR, NULL }, d = { "lamps", PS_ROLE_DIM, NULL };
	struct ps_point in = { "button", PS_ROLE_INPUT, NULL };
	struct errors e = { 0 };
	double v = 0;
	FILE *fp;
	(void)state;
	assert_non_null(drv);
	assert_non_null(mkdtemp(dir));
	/* the configuration's check: no path, a zero scale, an input */
	assert_int_equal(ps_driver_check(drv, &bopts, PS_ROLE_SENSOR, collect, &e), 1);
	assert_int_equal(e.line[0], 0);   /* a missing key: the caller gives the section's line */
	assert_string_equal(e.text[0], "file: 'path' (the point's file) is required");
	assert_int_equal(ps_driver_check(drv, &sopts, PS_ROLE_INPUT, collect, &e), 1);
	assert_non_null(strstr(e.text[1], "no input points"));
	dev.drv = drv;
	assert_int_equal(drv->open(&dev, &dopts), 0);
	assert_int_equal(drv->add_point(&dev, &s, &sopts), 0);
	assert_int_equal(drv->add_point(&dev, &d, &oopts), 0);
	assert_int_equal(drv->add_point(&dev, &in, &sopts), -1);
	assert_int_equal(errno, EINVAL);
	assert_string_equal(dev.err, "t.conf:5: file: no input points (sensor, task, dim and relay)");
	/* no file yet: the device is gone, a fault at once */
	assert_int_equal(drv->read(&dev, &s, 0, 0, &v), -1);
	assert_int_equal(errno, ENODEV);
	assert_true(ps_dev_fault_at_once(errno));
	snprintf(path, sizeof path, "%s/light", dir);
	put(path, "1.25\n");
	assert_int_equal(drv->read(&dev, &s, 0, 0, &v), 0);
	assert_near(v, 2.5, 0);   /* times scale */
	/* half a number is a garbled reply: a fault only once stale */
	put(path, "1.2x");
	assert_int_equal(drv->read(&dev, &s, 0, 0, &v), -1);
	assert_int_equal(errno, EPROTO);
	assert_false(ps_dev_fault_at_once(errno));
	/* an output writes its level over scale, and reads it back */
	assert_int_equal(drv->write(&dev, &d, 0, 0, 0.5), 0);
	snprintf(path, sizeof path, "%s/lamps", dir);
	fp = fopen(path, "r");
	assert_non_null(fp);
	assert_non_null(fgets(text, sizeof text, fp));
	fclose(fp);
	assert_string_equal(text, "0.25\n");
	assert_int_equal(drv->read(&dev, &d, 0, 0, &v), 0);
	assert_near(v, 0.5, 0);
	assert_int_equal(drv->write(&dev, &s, 0, 0, 0.5), -1);   /* a sensor is not an output */
	drv->close(&dev);
	unlink(path);
	snprintf(path, sizeof path, "%s/light", dir);
	unlink(path);
	rmdir(dir);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(tables_are_consistent),
		cmocka_unit_test(section_errors_with_lines),
		cmocka_unit_test(readers),
		cmocka_unit_test(fault_classes),
		cmocka_unit_test(file_driver),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
