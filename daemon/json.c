/* SPDX-License-Identifier: ISC */
/* The daemon's one JSON writer: see json.h. */
#include "json.h"

#include <math.h>
#include <stdio.h>

void psd_json_num(json_object *o, const char *key, double v)
{
	/* JSON has no NaN: an unknown value is null */
	json_object_object_add(o, key, isfinite(v) ? json_object_new_double(v) : NULL);
}

void psd_json_str(json_object *o, const char *key, const char *v)
{
	json_object_object_add(o, key, v ? json_object_new_string(v) : NULL);
}

const char *psd_json_text(json_object *o, int digits)
{
	char fmt[8];
	snprintf(fmt, sizeof fmt, "%%.%dg", digits >= 1 && digits <= 17 ? digits : 17);
	json_c_set_serialization_double_format(fmt, JSON_C_OPTION_THREAD);
	return json_object_to_json_string_ext(o, JSON_C_TO_STRING_PLAIN | JSON_C_TO_STRING_NOSLASHESCAPE);
}
