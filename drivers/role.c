/* SPDX-License-Identifier: ISC */
/* The roles' names (role.h). */
#include <string.h>

#include "role.h"

static const char *const role_names[PS_ROLE_COUNT] = { "sensor", "task", "dim", "relay", "input", "rooftop" };

const char *ps_role_name(int role)
{
	return role >= 0 && role < PS_ROLE_COUNT ? role_names[role] : "?";
}

int ps_role_parse(const char *name)
{
	for (int i = 0; i < PS_ROLE_COUNT; i++)
		if (strcmp(name, role_names[i]) == 0)
			return i;
	return -1;
}
