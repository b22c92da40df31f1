/* SPDX-License-Identifier: ISC */
/* What every driver shares besides its options: role names, the one way to
 * fail (dev->err and errno), and what a failure means to the daemon. */
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "driver.h"

static const char *const role_names[PS_ROLE_COUNT] = { "sensor", "task", "dim", "relay", "input", "rooftop" };

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

int ps_dev_fail(struct ps_dev *dev, int err, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(dev->err, sizeof dev->err, fmt, ap);
	va_end(ap);
	errno = err;
	return -1;
}

int ps_dev_fault_at_once(int err)
{
	switch (err) {
	case ENODEV:      /* gone: unplugged, the connection lost */
	case ENOTSUP:     /* not compiled in */
	case EINVAL:      /* a bad option, a point the driver cannot serve */
	case ERANGE:      /* a reading outside its valid range: open circuit, saturation */
	case EOVERFLOW:   /* a counting sensor lost events: its value would read low */
		return 1;
	default:          /* ETIMEDOUT, EPROTO, EAGAIN: a missed or garbled reply */
		return 0;
	}
}

int ps_dev_check(struct ps_dev *dev, const struct ps_opts *o, int role)
{
	char why[200];
	int line = 0;
	if (!dev->drv || !dev->drv->check || dev->drv->check(o, role, &line, why, sizeof why) == 0)
		return 0;
	return ps_dev_fail(dev, EINVAL, "%s:%d: %s", o && o->file ? o->file : "(config)", line, why);
}

int ps_driver_check(const struct ps_driver *drv, const struct ps_opts *o, int role, ps_opt_report_fn report,
                    void *user)
{
	char why[200];
	int line = 0, errors;
	if (!drv->options)
		return 0;
	errors = ps_opt_check(drv->options, drv->name, o, role, report, user);
	if (errors == 0 && drv->check && drv->check(o, role, &line, why, sizeof why) != 0) {
		report(user, line, why);
		errors++;
	}
	return errors;
}
