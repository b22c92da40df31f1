/* SPDX-License-Identifier: ISC */
/* The DALI layer: frames, commands and the logarithmic dimming curve
 * (see dali.h; the facts are IEC 62386-102's as doc/hardware.md section 2
 * restates them). */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dali.h"

/* steps per decade of the curve: 253 levels span three decades */
#define STEPS_PER_DECADE (253.0 / 3.0)

int ps_dali_addr_byte(const struct ps_dali_addr *a, int command)
{
	int s = command ? 1 : 0;
	switch (a->kind) {
	case PS_DALI_SHORT:
		return a->n >= 0 && a->n <= 63 ? (a->n << 1) | s : -1;
	case PS_DALI_GROUP:
		return a->n >= 0 && a->n <= 15 ? 0x80 | (a->n << 1) | s : -1;
	case PS_DALI_BROADCAST:
		return 0xFE | s;
	}
	return -1;
}

int ps_dali_dapc(const struct ps_dali_addr *a, int level)
{
	int b = ps_dali_addr_byte(a, 0);
	return b < 0 || level < 0 || level > 255 ? -1 : (b << 8) | level;
}

int ps_dali_cmd(const struct ps_dali_addr *a, int opcode)
{
	int b = ps_dali_addr_byte(a, 1);
	return b < 0 || opcode < 0 || opcode > 255 ? -1 : (b << 8) | opcode;
}

int ps_dali_dtr0(int value)
{
	return value < 0 || value > 255 ? -1 : (PS_DALI_DTR0 << 8) | value;
}

int ps_dali_special(int address_byte, int data)
{
	if (address_byte < 0xA1 || address_byte > 0xCB || !(address_byte & 1) || data < 0 || data > 255)
		return -1;
	return address_byte << 8 | data;
}

int ps_dali_frame_addr(unsigned frame, struct ps_dali_addr *a)
{
	unsigned ab = (frame >> 8) & 0xFF;
	if (ab >= 0xFE) {
		*a = (struct ps_dali_addr){ PS_DALI_BROADCAST, 0 };
	} else if ((ab & 0x80) == 0) {
		*a = (struct ps_dali_addr){ PS_DALI_SHORT, (int)(ab >> 1) };
	} else if ((ab & 0xE0) == 0x80) {
		*a = (struct ps_dali_addr){ PS_DALI_GROUP, (int)((ab >> 1) & 0x0F) };
	} else {
		return -1;   /* special command (0xA1..0xCB) or broadcast-unaddressed */
	}
	return 0;
}

static int is_device_command(unsigned frame)
{
	struct ps_dali_addr a;
	return ps_dali_frame_addr(frame, &a) == 0 && (frame & 0x100);
}

int ps_dali_needs_twice(unsigned frame)
{
	unsigned op = frame & 0xFF;
	return is_device_command(frame) && op >= 0x20 && op <= 0x81;
}

int ps_dali_expects_answer(unsigned frame)
{
	unsigned op = frame & 0xFF;
	return is_device_command(frame) && op >= 0x90 && op <= 0xC5;
}

static const char *opcode_name(unsigned op)
{
	switch (op) {
	case PS_DALI_OFF: return "OFF";
	case PS_DALI_RECALL_MAX: return "RECALL MAX LEVEL";
	case PS_DALI_RECALL_MIN: return "RECALL MIN LEVEL";
	case PS_DALI_RESET: return "RESET";
	case PS_DALI_IDENTIFY_DEVICE: return "IDENTIFY DEVICE";
	case PS_DALI_SET_MAX_LEVEL: return "SET MAX LEVEL";
	case PS_DALI_SET_MIN_LEVEL: return "SET MIN LEVEL";
	case PS_DALI_SET_SYSTEM_FAILURE_LEVEL: return "SET SYSTEM FAILURE LEVEL";
	case PS_DALI_SET_POWER_ON_LEVEL: return "SET POWER ON LEVEL";
	case PS_DALI_SET_FADE_TIME: return "SET FADE TIME";
	case PS_DALI_SET_FADE_RATE: return "SET FADE RATE";
	case PS_DALI_QUERY_STATUS: return "QUERY STATUS";
	case PS_DALI_QUERY_GEAR_PRESENT: return "QUERY CONTROL GEAR PRESENT";
	case PS_DALI_QUERY_LAMP_FAILURE: return "QUERY LAMP FAILURE";
	case PS_DALI_QUERY_MISSING_SHORT_ADDRESS: return "QUERY MISSING SHORT ADDRESS";
	case PS_DALI_QUERY_VERSION: return "QUERY VERSION NUMBER";
	case PS_DALI_QUERY_DEVICE_TYPE: return "QUERY DEVICE TYPE";
	case PS_DALI_QUERY_PHYSICAL_MINIMUM: return "QUERY PHYSICAL MINIMUM";
	case PS_DALI_QUERY_ACTUAL_LEVEL: return "QUERY ACTUAL LEVEL";
	case PS_DALI_QUERY_MAX_LEVEL: return "QUERY MAX LEVEL";
	case PS_DALI_QUERY_MIN_LEVEL: return "QUERY MIN LEVEL";
	case PS_DALI_QUERY_POWER_ON_LEVEL: return "QUERY POWER ON LEVEL";
	case PS_DALI_QUERY_SYSTEM_FAILURE_LEVEL: return "QUERY SYSTEM FAILURE LEVEL";
	case PS_DALI_QUERY_FADE: return "QUERY FADE TIME/RATE";
	case PS_DALI_QUERY_GROUPS_0_7: return "QUERY GROUPS 0-7";
	case PS_DALI_QUERY_GROUPS_8_15: return "QUERY GROUPS 8-15";
	case PS_DALI_QUERY_RANDOM_H: return "QUERY RANDOM ADDRESS (H)";
	case PS_DALI_QUERY_RANDOM_M: return "QUERY RANDOM ADDRESS (M)";
	case PS_DALI_QUERY_RANDOM_L: return "QUERY RANDOM ADDRESS (L)";
	}
	return NULL;
}

static const char *special_name(unsigned ab)
{
	switch (ab) {
	case PS_DALI_TERMINATE: return "TERMINATE";
	case PS_DALI_DTR0: return "DTR0";
	case PS_DALI_INITIALISE: return "INITIALISE";
	case PS_DALI_RANDOMISE: return "RANDOMISE";
	case PS_DALI_COMPARE: return "COMPARE";
	case PS_DALI_WITHDRAW: return "WITHDRAW";
	case PS_DALI_SEARCHADDRH: return "SEARCHADDRH";
	case PS_DALI_SEARCHADDRM: return "SEARCHADDRM";
	case PS_DALI_SEARCHADDRL: return "SEARCHADDRL";
	case PS_DALI_PROGRAM_SHORT_ADDRESS: return "PROGRAM SHORT ADDRESS";
	case PS_DALI_VERIFY_SHORT_ADDRESS: return "VERIFY SHORT ADDRESS";
	case PS_DALI_QUERY_SHORT_ADDRESS: return "QUERY SHORT ADDRESS";
	}
	return NULL;
}

void ps_dali_describe(unsigned frame, char *buf, size_t len)
{
	struct ps_dali_addr a;
	char who[24];
	const char *name;
	frame &= 0xFFFF;
	if (ps_dali_frame_addr(frame, &a) != 0) {
		const char *sp = special_name(frame >> 8);
		unsigned data = frame & 0xFF;
		if ((frame >> 8) == PS_DALI_UNADDRESSED && (name = opcode_name(data)))
			snprintf(buf, len, "unaddressed %s", name);
		else if (sp && (frame >> 8 == PS_DALI_SEARCHADDRH || frame >> 8 == PS_DALI_SEARCHADDRM ||
		                frame >> 8 == PS_DALI_SEARCHADDRL || frame >> 8 == PS_DALI_DTR0))
			snprintf(buf, len, "%s %u", sp, data);
		else if (sp && (frame >> 8 == PS_DALI_PROGRAM_SHORT_ADDRESS || frame >> 8 == PS_DALI_VERIFY_SHORT_ADDRESS ||
		                frame >> 8 == PS_DALI_INITIALISE) && (data & 0x81) == 0x01)
			snprintf(buf, len, "%s short %u", sp, data >> 1);
		else if (sp && frame >> 8 == PS_DALI_INITIALISE)
			snprintf(buf, len, "%s %s", sp, data == 0 ? "all" : data == 0xFF ? "unaddressed" : "?");
		else if (sp)
			snprintf(buf, len, "%s%s", sp, data == 0xFF && frame >> 8 == PS_DALI_PROGRAM_SHORT_ADDRESS ? " none" : "");
		else
			snprintf(buf, len, "special %02X %02X", frame >> 8, data);
		return;
	}
	if (a.kind == PS_DALI_SHORT)
		snprintf(who, sizeof who, "short %d", a.n);
	else if (a.kind == PS_DALI_GROUP)
		snprintf(who, sizeof who, "group %d", a.n);
	else
		snprintf(who, sizeof who, "broadcast");
	if (!(frame & 0x100)) {
		snprintf(buf, len, "%s DAPC %u", who, frame & 0xFF);
		return;
	}
	name = opcode_name(frame & 0xFF);
	if (name)
		snprintf(buf, len, "%s %s", who, name);
	else
		snprintf(buf, len, "%s command 0x%02X", who, frame & 0xFF);
}

static int parse_num(const char *s, long max, int *out)
{
	char *end;
	long v;
	if (!isdigit((unsigned char)*s))
		return -1;
	v = strtol(s, &end, 10);
	while (isspace((unsigned char)*end))
		end++;
	if (*end || v < 0 || v > max)
		return -1;
	*out = (int)v;
	return 0;
}

int ps_dali_addr_parse(const char *s, struct ps_dali_addr *a, char *err, size_t errlen)
{
	while (isspace((unsigned char)*s))
		s++;
	if (strcmp(s, "broadcast") == 0) {
		*a = (struct ps_dali_addr){ PS_DALI_BROADCAST, 0 };
		return 0;
	}
	if (strncmp(s, "group", 5) == 0 || (s[0] == 'g' && isdigit((unsigned char)s[1]))) {
		s += s[1] == 'r' ? 5 : 1;
		while (isspace((unsigned char)*s))
			s++;
		a->kind = PS_DALI_GROUP;
		if (parse_num(s, 15, &a->n) == 0)
			return 0;
		snprintf(err, errlen, "a group is 0 to 15");
		return -1;
	}
	if (strncmp(s, "short", 5) == 0) {
		s += 5;
		while (isspace((unsigned char)*s))
			s++;
	}
	a->kind = PS_DALI_SHORT;
	if (parse_num(s, 63, &a->n) == 0)
		return 0;
	snprintf(err, errlen, "not a DALI address (a short address 0 to 63, 'group N' or 'broadcast')");
	return -1;
}

double ps_dali_level_to_fraction(int level)
{
	if (level <= 0)
		return 0;
	if (level > PS_DALI_MAX_LEVEL)
		return NAN;
	/* percent -> fraction: one more decade down */
	return pow(10.0, (level - 1) / STEPS_PER_DECADE - 3.0);
}

int ps_dali_fraction_to_level(double f)
{
	double n;
	if (!(f > 0))
		return 0;
	if (f >= 1)
		return PS_DALI_MAX_LEVEL;
	n = 1 + STEPS_PER_DECADE * (log10(f) + 3.0);
	if (n < 1)
		return 1;
	/* floor(n + 0.5): exact midpoints round up */
	return (int)floor(n + 0.5);
}

int ps_dali_clamp_physical_min(int level, int phys_min)
{
	if (level <= 0 || level == PS_DALI_MASK)
		return level;
	if (phys_min < 1)
		phys_min = 1;
	return level < phys_min ? phys_min : level;
}

double ps_dali_fade_time_seconds(int code)
{
	if (code <= 0 || code > 15)
		return 0;
	return 0.5 * pow(2.0, code / 2.0);
}

int ps_dali_fade_time_code(double t)
{
	double n;
	if (!(t > 0))
		return 0;
	n = floor(2 * log2(2 * t) + 0.5);
	return n < 0 ? 0 : n > 15 ? 15 : (int)n;
}
