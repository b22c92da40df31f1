/* Placeholder for the gpio driver: replaced by the real driver.  It keeps the
 * registry linkable while the driver is written. */
#include <errno.h>

#include "driver.h"

static int gpio_open(struct ps_dev *dev, const struct ps_opts *opts)
{
	(void)opts;
	return ps_dev_fail(dev, ENOSYS, "driver gpio: not yet implemented");
}

const struct ps_driver ps_driver_gpio = {
	.name = "gpio",
	.summary = "placeholder",
	.compiled_in = 1,
	.open = gpio_open,
};
