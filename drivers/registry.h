/* SPDX-License-Identifier: ISC */
/* The registry: every driver this build knows, compiled in or not
 * (registry.c). */
#ifndef PS_REGISTRY_H
#define PS_REGISTRY_H

#include <stddef.h>

struct ps_driver;

/* Every driver, NULL-terminated. */
extern const struct ps_driver *const ps_registry_drivers[];
/* Find by name; NULL if no such driver exists at all. */
const struct ps_driver *ps_registry_find(const char *name);
/* "loopback, modbus, ..." of the registry, for messages. */
void ps_registry_names(char *out, size_t n);

#endif
