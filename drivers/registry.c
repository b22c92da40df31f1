/* SPDX-License-Identifier: ISC */
/* Every driver this build knows.  A driver whose library was not found at
 * build time stays in the table and fails with "not compiled in" (its keys
 * are then not judged: a stub has no option table).  drivers/module.mk
 * decides which are compiled; drivers/README.md says how to add one. */
#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "driver.h"
#include "file.h"
#include "loopback.h"
#include "registry.h"
#ifdef PS_WITH_MODBUS
#include "modbus.h"
#endif
#ifdef PS_WITH_USB
#include "dali_usb.h"
#endif
#ifdef PS_WITH_GPIOD
#include "gpio.h"
#endif

__attribute__((unused)) static int not_compiled(struct ps_dev *dev, const struct ps_opts *opts)
{
	(void)opts;
	return ps_dev_fail(dev, ENOTSUP, "driver %s not compiled in (its library was missing at build time)",
	                   dev->drv ? dev->drv->name : "?");
}

#define STUB(n, what) { .name = n, .summary = what, .compiled_in = 0, .open = not_compiled }

#ifndef PS_WITH_MODBUS
static const struct ps_driver ps_driver_modbus = STUB("modbus", "Modbus TCP and RTU (libmodbus)");
#endif
#ifndef PS_WITH_USB
static const struct ps_driver ps_driver_dali_usb = STUB("dali_usb", "DALI over USB (libusb)");
#endif
#ifndef PS_WITH_GPIOD
static const struct ps_driver ps_driver_gpio = STUB("gpio", "GPIO relays, buttons, light-to-frequency (libgpiod)");
#endif

const struct ps_driver *const ps_registry_drivers[] = {
	&ps_driver_loopback,
	&ps_driver_modbus,
	&ps_driver_dali_usb,
	&ps_driver_gpio,
	&ps_driver_file,
	NULL,
};

void ps_registry_names(char *out, size_t n)
{
	size_t len = 0;
	out[0] = 0;
	for (int i = 0; ps_registry_drivers[i] && len < n; i++)
		len += (size_t)snprintf(out + len, n - len, "%s%s", i ? ", " : "", ps_registry_drivers[i]->name);
}

const struct ps_driver *ps_registry_find(const char *name)
{
	for (int i = 0; ps_registry_drivers[i]; i++)
		if (strcmp(ps_registry_drivers[i]->name, name) == 0)
			return ps_registry_drivers[i];
	return NULL;
}
