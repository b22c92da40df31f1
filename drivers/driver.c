/* SPDX-License-Identifier: ISC */
/* A driver's options judged: its table, then its check method. */
#include <stdio.h>

#include "driver.h"

int ps_driver_check(const struct ps_driver *drv, const struct ps_opts *o, int role, ps_opts_report_fn report,
                    void *user)
{
	char why[200];
	int line = 0, errors;
	if (!drv->options)
		return 0;
	errors = ps_opts_check(drv->options, drv->name, o, role, report, user);
	if (errors == 0 && drv->check && drv->check(o, role, &line, why, sizeof why) != 0) {
		report(user, line, why);
		errors++;
	}
	return errors;
}
