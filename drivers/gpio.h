/* SPDX-License-Identifier: ISC */
/* The gpio driver: GPIO relays, inputs and light-to-frequency sensors
 * through libgpiod (psensd-gpio(7)). */
#ifndef PS_GPIO_H
#define PS_GPIO_H

#include "driver.h"

extern const struct ps_driver ps_driver_gpio;

#endif
