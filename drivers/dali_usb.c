/* Placeholder for the dali_usb driver: replaced by the real driver.  It keeps the
 * registry linkable while the driver is written. */
#include <errno.h>

#include "driver.h"

static int dali_usb_open(struct ps_dev *dev, const struct ps_opts *opts)
{
	(void)opts;
	return ps_dev_fail(dev, ENOSYS, "driver dali_usb: not yet implemented");
}

const struct ps_driver ps_driver_dali_usb = {
	.name = "dali_usb",
	.summary = "placeholder",
	.compiled_in = 1,
	.open = dali_usb_open,
};
