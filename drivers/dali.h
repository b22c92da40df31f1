/* SPDX-License-Identifier: ISC */
/* The DALI layer (IEC 62386-101/102): addresses, 16-bit forward frames, the
 * commands a dimming daemon needs, and the standard logarithmic dimming
 * curve.  Pure functions: no USB, no clock, no state.
 *
 * A forward frame is an address byte (bits 15..8) and a data byte (bits 7..0).
 * Bit 8 (the selector S) is 0 when the data byte is a direct arc power level
 * (DAPC) and 1 when it is a command opcode. */
#ifndef PS_DALI_H
#define PS_DALI_H

#include <stddef.h>
#include <stdint.h>

enum ps_dali_addr_kind { PS_DALI_SHORT = 0, PS_DALI_GROUP, PS_DALI_BROADCAST };

struct ps_dali_addr {
	int kind;   /* enum ps_dali_addr_kind */
	int n;      /* short address 0..63 or group 0..15; 0 for broadcast */
};

/* Arc power levels: 0 is off, 1..254 the curve, 255 MASK (no change). */
#define PS_DALI_MASK 255
#define PS_DALI_MAX_LEVEL 254

/* Command opcodes (S = 1). */
enum {
	PS_DALI_OFF = 0x00,
	PS_DALI_RECALL_MAX = 0x05,
	PS_DALI_RECALL_MIN = 0x06,
	PS_DALI_RESET = 0x20,
	PS_DALI_IDENTIFY_DEVICE = 0x25,
	PS_DALI_SET_MAX_LEVEL = 0x2A,
	PS_DALI_SET_MIN_LEVEL = 0x2B,
	PS_DALI_SET_SYSTEM_FAILURE_LEVEL = 0x2C,
	PS_DALI_SET_POWER_ON_LEVEL = 0x2D,
	PS_DALI_SET_FADE_TIME = 0x2E,
	PS_DALI_SET_FADE_RATE = 0x2F,
	PS_DALI_ADD_TO_GROUP = 0x60,        /* + group 0..15 */
	PS_DALI_REMOVE_FROM_GROUP = 0x70,   /* + group 0..15 */
	PS_DALI_SET_SHORT_ADDRESS = 0x80,
	PS_DALI_QUERY_STATUS = 0x90,
	PS_DALI_QUERY_GEAR_PRESENT = 0x91,
	PS_DALI_QUERY_LAMP_FAILURE = 0x92,
	PS_DALI_QUERY_MISSING_SHORT_ADDRESS = 0x96,
	PS_DALI_QUERY_VERSION = 0x97,
	PS_DALI_QUERY_DEVICE_TYPE = 0x99,
	PS_DALI_QUERY_PHYSICAL_MINIMUM = 0x9A,
	PS_DALI_QUERY_ACTUAL_LEVEL = 0xA0,
	PS_DALI_QUERY_MAX_LEVEL = 0xA1,
	PS_DALI_QUERY_MIN_LEVEL = 0xA2,
	PS_DALI_QUERY_POWER_ON_LEVEL = 0xA3,
	PS_DALI_QUERY_SYSTEM_FAILURE_LEVEL = 0xA4,
	PS_DALI_QUERY_FADE = 0xA5,
	PS_DALI_QUERY_GROUPS_0_7 = 0xC0,
	PS_DALI_QUERY_GROUPS_8_15 = 0xC1,
	PS_DALI_QUERY_RANDOM_H = 0xC2,
	PS_DALI_QUERY_RANDOM_M = 0xC3,
	PS_DALI_QUERY_RANDOM_L = 0xC4,
};

/* Special command address bytes (the data byte is the value); all gear
 * listen.  INITIALISE's data: 0x00 all gear, 0xFF gear without a short
 * address, 0AAAAAA1 the gear at short address A.  INITIALISE and RANDOMISE
 * are sent twice; the others act only inside INITIALISE's 15 minutes. */
enum {
	PS_DALI_TERMINATE = 0xA1,
	PS_DALI_DTR0 = 0xA3,
	PS_DALI_INITIALISE = 0xA5,
	PS_DALI_RANDOMISE = 0xA7,
	PS_DALI_COMPARE = 0xA9,            /* "yes" from gear whose random address <= the search address */
	PS_DALI_WITHDRAW = 0xAB,
	PS_DALI_SEARCHADDRH = 0xB1,
	PS_DALI_SEARCHADDRM = 0xB3,
	PS_DALI_SEARCHADDRL = 0xB5,
	PS_DALI_PROGRAM_SHORT_ADDRESS = 0xB7,   /* data 0AAAAAA1, or 0xFF to delete */
	PS_DALI_VERIFY_SHORT_ADDRESS = 0xB9,
	PS_DALI_QUERY_SHORT_ADDRESS = 0xBB,     /* answer 0AAAAAA1, or 0xFF: none */
};
/* Address byte of a command to all gear without a short address (1111110S). */
#define PS_DALI_UNADDRESSED 0xFD

/* Frame of a special command. */
int ps_dali_special(int address_byte, int data);

/* Address byte with the selector bit: DAPC when command == 0, command else. */
int ps_dali_addr_byte(const struct ps_dali_addr *a, int command);
/* Forward frames.  Return the frame, or -1 for an invalid address. */
int ps_dali_dapc(const struct ps_dali_addr *a, int level);
int ps_dali_cmd(const struct ps_dali_addr *a, int opcode);
/* Frame for "DTR0 = value" (special command, all gear listen). */
int ps_dali_dtr0(int value);
/* Configuration commands (0x20..0x81) must be sent twice within 100 ms. */
int ps_dali_needs_twice(unsigned frame);
/* Queries (0x90..0xFF with S = 1, on a device address) expect a backward frame. */
int ps_dali_expects_answer(unsigned frame);
/* Decode a frame back into its address (-1 for a special command). */
int ps_dali_frame_addr(unsigned frame, struct ps_dali_addr *a);
/* Human-readable frame for messages, e.g. "short 5 DAPC 200", "group 3 OFF". */
void ps_dali_describe(unsigned frame, char *buf, size_t len);

/* Parse an address as written in the configuration: "5" or "short 5",
 * "group 3" or "g3", "broadcast".  0 ok, -1 on a bad address (why in err). */
int ps_dali_addr_parse(const char *s, struct ps_dali_addr *a, char *err, size_t errlen);

/* The standard logarithmic curve: X(n) = 10^((n - 1) / (253/3) - 1) percent
 * for n = 1..254 (0.1 % at 1, 100 % at 254).  Returned as a fraction of full
 * output: level 0 gives 0, level 255 (MASK) gives NAN. */
double ps_dali_level_to_fraction(int level);
/* The nearest level on the log scale.  Rounding: n* = 1 + (253/3)(log10(100 f) + 1)
 * is exact and linear in log f, so rounding n* to the nearest integer picks the
 * level whose output is nearest in ratio (ties, which need an exact midpoint,
 * round up).  f <= 0 (and NAN) gives 0 (off); 0 < f < 0.1 % gives 1, the lowest
 * arc power: only an explicit 0 switches a lamp off; f >= 1 gives 254. */
int ps_dali_fraction_to_level(double f);
/* Clamp a level to a ballast's physical minimum (1..254): nonzero levels below
 * it are raised to it; 0 stays off. */
int ps_dali_clamp_physical_min(int level, int phys_min);

/* FADE TIME code 1..15: T = 0.5 sqrt(2^n) s; 0 = no fade. */
double ps_dali_fade_time_seconds(int code);
/* The code whose fade time is nearest to t on the log scale (0 for t < 0.5 s,
 * 15 beyond 90.5 s). */
int ps_dali_fade_time_code(double t);

#endif
