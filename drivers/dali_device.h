/* SPDX-License-Identifier: ISC */
/* DALI-2 control devices (IEC 62386-103) and the two input-device parts a
 * daylight controller reads: 303 occupancy sensors and 304 light sensors.
 * Pure functions: 24-bit forward frames in, event messages out; no I/O.
 *
 * A 24-bit frame is an address byte (bits 23..16), an instance byte
 * (bits 15..8) and an opcode byte (bits 7..0).  Control devices have their
 * own short addresses 0..63, apart from the gear's.  Commands have bit 16
 * set (the address byte is odd); event messages a device sends have it
 * clear.  Which table and source each value comes from: doc/hardware.md,
 * "DALI-2 control devices". */
#ifndef PS_DALI_DEVICE_H
#define PS_DALI_DEVICE_H

#include <stddef.h>
#include <stdint.h>

/* Address bytes: short 0AAAAAA1, device group 10GGGGG1 (0..31),
 * broadcast to devices without a short address 0xFD, broadcast 0xFF. */
#define PS_DALI_DEVICE_UNADDRESSED 0xFD
#define PS_DALI_DEVICE_BROADCAST 0xFF
/* Instance bytes: instance number 000NNNNN (0..31), instance group
 * 100GGGGG, instance type 110TTTTT, the device itself 0xFE, every instance
 * 0xFF. */
#define PS_DALI_DEVICE_INSTANCE_GROUP 0x80
#define PS_DALI_DEVICE_INSTANCE_TYPE 0xC0
#define PS_DALI_DEVICE_SELF 0xFE
#define PS_DALI_DEVICE_ALL_INSTANCES 0xFF

/* Special commands: address byte 0xC1, the command in the instance byte,
 * its value in the opcode byte. */
#define PS_DALI_DEVICE_SPECIAL 0xC1
enum {
	PS_DALI_DEVICE_TERMINATE = 0x00,
	PS_DALI_DEVICE_INITIALISE = 0x01,    /* twice; data 0..63 one device, 0x7F unaddressed, 0xFF all */
	PS_DALI_DEVICE_RANDOMISE = 0x02,     /* twice */
	PS_DALI_DEVICE_COMPARE = 0x03,       /* "yes" from devices whose random address <= the search address */
	PS_DALI_DEVICE_WITHDRAW = 0x04,
	PS_DALI_DEVICE_SEARCHADDRH = 0x05,
	PS_DALI_DEVICE_SEARCHADDRM = 0x06,
	PS_DALI_DEVICE_SEARCHADDRL = 0x07,
	PS_DALI_DEVICE_PROGRAM_SHORT_ADDRESS = 0x08,  /* data 0..63, or 0xFF to delete */
	PS_DALI_DEVICE_VERIFY_SHORT_ADDRESS = 0x09,   /* data 0..63; "yes" */
	PS_DALI_DEVICE_QUERY_SHORT_ADDRESS = 0x0A,    /* answer 0..63, or 0xFF: none */
	PS_DALI_DEVICE_DTR0 = 0x30,
	PS_DALI_DEVICE_DTR1 = 0x31,
	PS_DALI_DEVICE_DTR2 = 0x32,
};
/* INITIALISE's data for devices without a short address. */
#define PS_DALI_DEVICE_INIT_UNADDRESSED 0x7F
#define PS_DALI_DEVICE_INIT_ALL 0xFF

/* Device commands (instance byte 0xFE). */
enum {
	PS_DALI_DEVICE_IDENTIFY = 0x00,               /* twice */
	PS_DALI_DEVICE_RESET = 0x10,                  /* twice */
	PS_DALI_DEVICE_SET_SHORT_ADDRESS = 0x14,      /* twice, DTR0 */
	PS_DALI_DEVICE_ADD_TO_GROUPS_0_15 = 0x19,     /* twice, DTR2:DTR1 */
	PS_DALI_DEVICE_REMOVE_FROM_GROUPS_0_15 = 0x1B,
	PS_DALI_DEVICE_START_QUIESCENT = 0x1D,
	PS_DALI_DEVICE_STOP_QUIESCENT = 0x1E,
	PS_DALI_DEVICE_QUERY_STATUS = 0x30,
	PS_DALI_DEVICE_QUERY_MISSING_SHORT_ADDRESS = 0x33,
	PS_DALI_DEVICE_QUERY_VERSION = 0x34,
	PS_DALI_DEVICE_QUERY_NUMBER_OF_INSTANCES = 0x35,
	PS_DALI_DEVICE_QUERY_RANDOM_H = 0x39,
	PS_DALI_DEVICE_QUERY_RANDOM_M = 0x3A,
	PS_DALI_DEVICE_QUERY_RANDOM_L = 0x3B,
	PS_DALI_DEVICE_QUERY_GROUPS_0_7 = 0x41,       /* then 8-15, 16-23, 24-31 at 0x42..0x44 */
	PS_DALI_DEVICE_QUERY_CAPABILITIES = 0x46,
};

/* Instance commands (instance byte a number, group or type). */
enum {
	PS_DALI_DEVICE_SET_EVENT_PRIORITY = 0x61,     /* twice, DTR0 2..5 */
	PS_DALI_DEVICE_ENABLE_INSTANCE = 0x62,        /* twice */
	PS_DALI_DEVICE_DISABLE_INSTANCE = 0x63,       /* twice */
	PS_DALI_DEVICE_SET_EVENT_SCHEME = 0x67,       /* twice, DTR0 */
	PS_DALI_DEVICE_SET_EVENT_FILTER = 0x68,       /* twice, DTR0 (bits 0..7), DTR1, DTR2 */
	PS_DALI_DEVICE_QUERY_INSTANCE_TYPE = 0x80,
	PS_DALI_DEVICE_QUERY_RESOLUTION = 0x81,
	PS_DALI_DEVICE_QUERY_INSTANCE_ERROR = 0x82,
	PS_DALI_DEVICE_QUERY_INSTANCE_STATUS = 0x83,
	PS_DALI_DEVICE_QUERY_EVENT_PRIORITY = 0x84,
	PS_DALI_DEVICE_QUERY_INSTANCE_ENABLED = 0x86,
	PS_DALI_DEVICE_QUERY_EVENT_SCHEME = 0x8B,
	PS_DALI_DEVICE_QUERY_INPUT_VALUE = 0x8C,      /* the most significant byte; latches the rest */
	PS_DALI_DEVICE_QUERY_INPUT_VALUE_LATCH = 0x8D, /* the next byte of the latched value */
	PS_DALI_DEVICE_QUERY_EVENT_FILTER_0_7 = 0x90,
};

/* Part 303, occupancy (instance type 3). */
enum {
	PS_DALI_OCC_SET_HOLD_TIMER = 0x21,      /* twice, DTR0: 10 s steps */
	PS_DALI_OCC_SET_REPORT_TIMER = 0x22,    /* twice, DTR0: 1 s steps */
	PS_DALI_OCC_SET_DEADTIME_TIMER = 0x23,  /* twice, DTR0: 50 ms steps */
	PS_DALI_OCC_QUERY_DEADTIME_TIMER = 0x2C,
	PS_DALI_OCC_QUERY_HOLD_TIMER = 0x2D,
	PS_DALI_OCC_QUERY_REPORT_TIMER = 0x2E,
};
/* Part 304, light sensor (instance type 4). */
enum {
	PS_DALI_LIGHT_SET_REPORT_TIMER = 0x30,    /* twice, DTR0: 1 s steps */
	PS_DALI_LIGHT_SET_HYSTERESIS = 0x31,      /* twice, DTR0: percent */
	PS_DALI_LIGHT_SET_DEADTIME_TIMER = 0x32,  /* twice, DTR0: 50 ms steps */
	PS_DALI_LIGHT_SET_HYSTERESIS_MIN = 0x33,  /* twice, DTR0: absolute, in input-value units */
	PS_DALI_LIGHT_QUERY_HYSTERESIS_MIN = 0x3C,
	PS_DALI_LIGHT_QUERY_DEADTIME_TIMER = 0x3D,
	PS_DALI_LIGHT_QUERY_REPORT_TIMER = 0x3E,
	PS_DALI_LIGHT_QUERY_HYSTERESIS = 0x3F,
};

/* Instance types (103's table of parts). */
enum {
	PS_DALI_TYPE_PUSH_BUTTON = 1,
	PS_DALI_TYPE_OCCUPANCY = 3,
	PS_DALI_TYPE_LIGHT = 4,
};

/* Event schemes (SET EVENT SCHEME's DTR0): how an event names its source. */
enum ps_dali_device_scheme {
	PS_DALI_SCHEME_INSTANCE = 0,        /* instance type + instance number */
	PS_DALI_SCHEME_DEVICE = 1,          /* short address + instance type */
	PS_DALI_SCHEME_DEVICE_INSTANCE = 2, /* short address + instance number */
	PS_DALI_SCHEME_DEVICE_GROUP = 3,    /* device group + instance type */
	PS_DALI_SCHEME_INSTANCE_GROUP = 4,  /* instance group + instance type */
};

/* Event filter bits. */
#define PS_DALI_LIGHT_FILTER_ILLUMINANCE 0x01
#define PS_DALI_OCC_FILTER_OCCUPIED 0x01
#define PS_DALI_OCC_FILTER_VACANT 0x02
#define PS_DALI_OCC_FILTER_REPEAT 0x04
/* 303 event information bits. */
#define PS_DALI_OCC_EV_MOVEMENT 0x01
#define PS_DALI_OCC_EV_OCCUPIED 0x02
#define PS_DALI_OCC_EV_REPEAT 0x04
#define PS_DALI_OCC_EV_MOVEMENT_SENSOR 0x08

/* An event message, decoded.  Fields the scheme does not carry are -1. */
struct ps_dali_device_event {
	int scheme;          /* enum ps_dali_device_scheme */
	int address;         /* device short address 0..63 */
	int device_group;    /* 0..31 */
	int instance_group;  /* 0..31 */
	int instance_type;   /* 0..31 */
	int instance;        /* instance number 0..31 */
	unsigned info;       /* event information, 10 bits */
};

/* Frames.  Each returns the 24-bit frame, or -1 for a value out of range. */
long ps_dali_device_frame(int address_byte, int instance_byte, int opcode);
long ps_dali_device_special(int command, int data);
/* A device (short address 0..63, or -1 for broadcast) command. */
long ps_dali_device_cmd(int address, int opcode);
/* An instance command to instance number 0..31 of a device (address -1: broadcast). */
long ps_dali_device_inst_cmd(int address, int instance, int opcode);
/* 1 when a command frame must be sent twice within 100 ms. */
int ps_dali_device_needs_twice(uint32_t frame);
/* 1 when a command frame may be answered with a backward frame. */
int ps_dali_device_expects_answer(uint32_t frame);

/* Decode an event message.  0 ok; -1 when frame is a command (bit 16 set),
 * not 24 bits, or uses an undefined source form. */
int ps_dali_device_event_decode(uint32_t frame, struct ps_dali_device_event *ev);
/* Encode an event (the inverse, for tests and emulators): -1 when a field
 * the scheme needs is out of range. */
long ps_dali_device_event_encode(const struct ps_dali_device_event *ev);

/* The input value of an instance of resolution bits (1..32) from the bytes
 * QUERY INPUT VALUE and then QUERY INPUT VALUE LATCH answered, most
 * significant first (ceil(bits / 8) of them).  The device left-aligns the
 * value and repeats its top bits below it; this drops them.  -1 when
 * nbytes does not match bits. */
long ps_dali_device_input_value(const uint8_t *bytes, int nbytes, int bits);
/* Bytes a value of resolution bits takes: ceil(bits / 8), 0 if out of 1..32. */
int ps_dali_device_input_bytes(int bits);

/* Timer codes.  The code nearest t for a timer of step seconds that holds
 * codes lo..255, or -1 when t is outside [lo step, 255 step]. */
int ps_dali_device_timer_code(double t, double step, int lo);

/* A command frame in words for messages, e.g. "device 5 instance 1 QUERY
 * INPUT VALUE", "INITIALISE 0x7F", "event device 5 type 4 info 512". */
void ps_dali_device_describe(uint32_t frame, char *buf, size_t len);

#endif
