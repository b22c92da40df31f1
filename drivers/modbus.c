/* Placeholder for the modbus driver: replaced by the real driver.  It keeps the
 * registry linkable while the driver is written. */
#include <errno.h>

#include "driver.h"

static int modbus_open(struct ps_dev *dev, const struct ps_opts *opts)
{
	(void)opts;
	return ps_dev_fail(dev, ENOSYS, "driver modbus: not yet implemented");
}

const struct ps_driver ps_driver_modbus = {
	.name = "modbus",
	.summary = "placeholder",
	.compiled_in = 1,
	.open = modbus_open,
};
