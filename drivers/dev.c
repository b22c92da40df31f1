/* SPDX-License-Identifier: ISC */
/* A device's failure (dev.h). */
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>

#include "driver.h"

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
