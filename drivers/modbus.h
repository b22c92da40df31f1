/* SPDX-License-Identifier: ISC */
/* The modbus driver: Modbus TCP and RTU through libmodbus (psensd-modbus(5)). */
#ifndef PS_MODBUS_H
#define PS_MODBUS_H

#include "driver.h"

extern const struct ps_driver ps_driver_modbus;

#endif
