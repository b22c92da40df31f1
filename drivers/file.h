/* SPDX-License-Identifier: ISC */
/* The file driver: points in text files (psensd-file(7)). */
#ifndef PS_FILE_H
#define PS_FILE_H

#include "driver.h"

extern const struct ps_driver ps_driver_file;

#endif
