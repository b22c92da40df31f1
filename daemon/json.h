/* SPDX-License-Identifier: ISC */
/* The daemon's one JSON writer (json-c underneath): the control replies,
 * the MQTT payloads and the sample export.  A number that is not finite
 * (NaN, Inf) is written as null, never as a word JSON has not got; a
 * string is escaped as RFC 8259 asks (quote, backslash and the control
 * characters; "/" is left as it is). */
#ifndef PSD_JSON_H
#define PSD_JSON_H

#include <json-c/json.h>
#include <stddef.h>

/* o[key] = v, or null when v is NaN or infinite */
void psd_json_num(json_object *o, const char *key, double v);
/* o[key] = the string v, or null when v is NULL */
void psd_json_str(json_object *o, const char *key, const char *v);
/* o as one line of JSON, its numbers with at most digits significant
 * digits (10 for people, 17 for a double that reads back exactly).  The
 * text is o's: valid until o is changed or released. */
const char *psd_json_text(json_object *o, int digits);

#endif
