/* SPDX-License-Identifier: ISC */
/* DALI-2 control devices: 24-bit command frames, event messages, input
 * values and timer codes (see dali_device.h; sources in doc/hardware.md). */
#include <math.h>
#include <stdio.h>

#include "dali_device.h"

long ps_dali_device_frame(int address_byte, int instance_byte, int opcode)
{
	if (address_byte < 0 || address_byte > 255 || instance_byte < 0 || instance_byte > 255 || opcode < 0 ||
	    opcode > 255)
		return -1;
	return (long)address_byte << 16 | (long)instance_byte << 8 | opcode;
}

long ps_dali_device_special(int command, int data)
{
	return ps_dali_device_frame(PS_DALI_DEVICE_SPECIAL, command, data);
}

static int addr_byte(int address)
{
	if (address == -1)
		return PS_DALI_DEVICE_BROADCAST;
	return address >= 0 && address <= 63 ? address << 1 | 1 : -1;
}

long ps_dali_device_cmd(int address, int opcode)
{
	int ab = addr_byte(address);
	return ab < 0 ? -1 : ps_dali_device_frame(ab, PS_DALI_DEVICE_SELF, opcode);
}

long ps_dali_device_inst_cmd(int address, int instance, int opcode)
{
	int ab = addr_byte(address);
	if (ab < 0 || instance < 0 || instance > 31)
		return -1;
	return ps_dali_device_frame(ab, instance, opcode);
}

/* Is the frame an instance or device command (not special, not an event)? */
static int addressed(uint32_t frame)
{
	unsigned ab = frame >> 16 & 0xFF;
	if (!(ab & 1) || frame > 0xFFFFFF)
		return 0;
	/* 0AAAAAA1, 10GGGGG1, 0xFD, 0xFF; 0xC1..0xFB odd are special */
	return ab < 0x80 || (ab >= 0x81 && ab <= 0xBF) || ab == 0xFD || ab == 0xFF;
}

int ps_dali_device_needs_twice(uint32_t frame)
{
	unsigned ab = frame >> 16 & 0xFF, ib = frame >> 8 & 0xFF, op = frame & 0xFF;
	if (frame > 0xFFFFFF)
		return 0;
	if (ab == PS_DALI_DEVICE_SPECIAL)
		return ib == PS_DALI_DEVICE_INITIALISE || ib == PS_DALI_DEVICE_RANDOMISE;
	if (!addressed(frame))
		return 0;
	if (ib == PS_DALI_DEVICE_SELF)
		return op <= 0x01 || (op >= 0x10 && op <= 0x21);
	/* instance commands: 0x61..0x68 (103), the parts' SET ... timers */
	if (op >= 0x61 && op <= 0x68)
		return 1;
	return op == PS_DALI_OCC_SET_HOLD_TIMER || op == PS_DALI_OCC_SET_REPORT_TIMER ||
	       op == PS_DALI_OCC_SET_DEADTIME_TIMER || (op >= PS_DALI_LIGHT_SET_REPORT_TIMER &&
	                                                 op <= PS_DALI_LIGHT_SET_HYSTERESIS_MIN);
}

int ps_dali_device_expects_answer(uint32_t frame)
{
	unsigned ab = frame >> 16 & 0xFF, ib = frame >> 8 & 0xFF, op = frame & 0xFF;
	if (frame > 0xFFFFFF)
		return 0;
	if (ab == PS_DALI_DEVICE_SPECIAL)
		return ib == PS_DALI_DEVICE_COMPARE || ib == PS_DALI_DEVICE_VERIFY_SHORT_ADDRESS ||
		       ib == PS_DALI_DEVICE_QUERY_SHORT_ADDRESS;
	if (!addressed(frame))
		return 0;
	if (ib == PS_DALI_DEVICE_SELF)
		return op >= 0x30 && op <= 0x48;
	/* instance queries 0x80..0x92 (103); 0x2C..0x2F (303) and 0x3C..0x3F (304) */
	return (op >= 0x80 && op <= 0x92) || (op >= 0x2C && op <= 0x2F) || (op >= 0x3C && op <= 0x3F);
}

int ps_dali_device_event_decode(uint32_t frame, struct ps_dali_device_event *ev)
{
	unsigned b23 = frame >> 23 & 1, b22 = frame >> 22 & 1, b15 = frame >> 15 & 1;
	unsigned hi5 = frame >> 17 & 0x1F, lo5 = frame >> 10 & 0x1F;
	*ev = (struct ps_dali_device_event){ -1, -1, -1, -1, -1, -1, frame & 0x3FF };
	if (frame > 0xFFFFFF || (frame >> 16 & 1))
		return -1;
	if (!b23) {
		ev->address = (int)(frame >> 17 & 0x3F);
		if (b15) {
			ev->scheme = PS_DALI_SCHEME_DEVICE_INSTANCE;
			ev->instance = (int)lo5;
		} else {
			ev->scheme = PS_DALI_SCHEME_DEVICE;
			ev->instance_type = (int)lo5;
		}
	} else if (!b22 && b15) {
		ev->scheme = PS_DALI_SCHEME_INSTANCE;
		ev->instance_type = (int)hi5;
		ev->instance = (int)lo5;
	} else if (!b22) {
		ev->scheme = PS_DALI_SCHEME_DEVICE_GROUP;
		ev->device_group = (int)hi5;
		ev->instance_type = (int)lo5;
	} else if (!b15) {
		ev->scheme = PS_DALI_SCHEME_INSTANCE_GROUP;
		ev->instance_group = (int)hi5;
		ev->instance_type = (int)lo5;
	} else {
		return -1;  /* 11xxxxx0 1...: not an event source form */
	}
	return 0;
}

static int in5(int v)
{
	return v >= 0 && v <= 31;
}

long ps_dali_device_event_encode(const struct ps_dali_device_event *ev)
{
	unsigned long f = ev->info & 0x3FF;
	switch (ev->scheme) {
	case PS_DALI_SCHEME_DEVICE:
	case PS_DALI_SCHEME_DEVICE_INSTANCE: {
		int lo = ev->scheme == PS_DALI_SCHEME_DEVICE ? ev->instance_type : ev->instance;
		if (ev->address < 0 || ev->address > 63 || !in5(lo))
			return -1;
		f |= (unsigned long)ev->address << 17 | (unsigned long)lo << 10;
		if (ev->scheme == PS_DALI_SCHEME_DEVICE_INSTANCE)
			f |= 1ul << 15;
		break;
	}
	case PS_DALI_SCHEME_INSTANCE:
		if (!in5(ev->instance_type) || !in5(ev->instance))
			return -1;
		f |= 1ul << 23 | 1ul << 15 | (unsigned long)ev->instance_type << 17 | (unsigned long)ev->instance << 10;
		break;
	case PS_DALI_SCHEME_DEVICE_GROUP:
		if (!in5(ev->device_group) || !in5(ev->instance_type))
			return -1;
		f |= 1ul << 23 | (unsigned long)ev->device_group << 17 | (unsigned long)ev->instance_type << 10;
		break;
	case PS_DALI_SCHEME_INSTANCE_GROUP:
		if (!in5(ev->instance_group) || !in5(ev->instance_type))
			return -1;
		f |= 1ul << 23 | 1ul << 22 | (unsigned long)ev->instance_group << 17 |
		     (unsigned long)ev->instance_type << 10;
		break;
	default:
		return -1;
	}
	return (long)f;
}

int ps_dali_device_input_bytes(int bits)
{
	return bits < 1 || bits > 32 ? 0 : (bits + 7) / 8;
}

long ps_dali_device_input_value(const uint8_t *bytes, int nbytes, int bits)
{
	uint64_t v = 0;
	if (nbytes < 1 || nbytes != ps_dali_device_input_bytes(bits))
		return -1;
	for (int i = 0; i < nbytes; i++)
		v = v << 8 | bytes[i];
	return (long)(v >> (8 * nbytes - bits));
}

int ps_dali_device_timer_code(double t, double step, int lo)
{
	double c;
	if (!(step > 0) || !isfinite(t) || lo < 0 || lo > 255)
		return -1;
	c = t / step;
	if (c < lo - 0.5 || c >= 255.5)
		return -1;
	c = floor(c + 0.5);
	return c < lo ? lo : (int)c;
}

static const char *special_name(unsigned ib)
{
	static const char *const names[] = { "TERMINATE",   "INITIALISE",  "RANDOMISE",   "COMPARE",
	                                     "WITHDRAW",    "SEARCHADDRH", "SEARCHADDRM", "SEARCHADDRL",
	                                     "PROGRAM SHORT ADDRESS", "VERIFY SHORT ADDRESS",
	                                     "QUERY SHORT ADDRESS" };
	if (ib < sizeof names / sizeof names[0])
		return names[ib];
	return ib == PS_DALI_DEVICE_DTR0 ? "DTR0" : ib == PS_DALI_DEVICE_DTR1 ? "DTR1" : ib == PS_DALI_DEVICE_DTR2 ? "DTR2"
	                                                                                                     : NULL;
}

static const char *op_name(unsigned ib, unsigned op)
{
	if (ib == PS_DALI_DEVICE_SELF) {
		switch (op) {
		case PS_DALI_DEVICE_IDENTIFY: return "IDENTIFY DEVICE";
		case PS_DALI_DEVICE_RESET: return "RESET";
		case PS_DALI_DEVICE_SET_SHORT_ADDRESS: return "SET SHORT ADDRESS";
		case PS_DALI_DEVICE_QUERY_STATUS: return "QUERY DEVICE STATUS";
		case PS_DALI_DEVICE_QUERY_NUMBER_OF_INSTANCES: return "QUERY NUMBER OF INSTANCES";
		case PS_DALI_DEVICE_QUERY_VERSION: return "QUERY VERSION NUMBER";
		case PS_DALI_DEVICE_QUERY_RANDOM_H: return "QUERY RANDOM ADDRESS (H)";
		case PS_DALI_DEVICE_QUERY_RANDOM_M: return "QUERY RANDOM ADDRESS (M)";
		case PS_DALI_DEVICE_QUERY_RANDOM_L: return "QUERY RANDOM ADDRESS (L)";
		}
		return NULL;
	}
	switch (op) {
	case PS_DALI_DEVICE_ENABLE_INSTANCE: return "ENABLE INSTANCE";
	case PS_DALI_DEVICE_DISABLE_INSTANCE: return "DISABLE INSTANCE";
	case PS_DALI_DEVICE_SET_EVENT_PRIORITY: return "SET EVENT PRIORITY";
	case PS_DALI_DEVICE_SET_EVENT_SCHEME: return "SET EVENT SCHEME";
	case PS_DALI_DEVICE_SET_EVENT_FILTER: return "SET EVENT FILTER";
	case PS_DALI_DEVICE_QUERY_INSTANCE_TYPE: return "QUERY INSTANCE TYPE";
	case PS_DALI_DEVICE_QUERY_RESOLUTION: return "QUERY RESOLUTION";
	case PS_DALI_DEVICE_QUERY_INSTANCE_ENABLED: return "QUERY INSTANCE ENABLED";
	case PS_DALI_DEVICE_QUERY_EVENT_SCHEME: return "QUERY EVENT SCHEME";
	case PS_DALI_DEVICE_QUERY_INPUT_VALUE: return "QUERY INPUT VALUE";
	case PS_DALI_DEVICE_QUERY_INPUT_VALUE_LATCH: return "QUERY INPUT VALUE LATCH";
	case PS_DALI_DEVICE_QUERY_EVENT_FILTER_0_7: return "QUERY EVENT FILTER 0-7";
	case PS_DALI_LIGHT_SET_REPORT_TIMER: return "SET REPORT TIMER (304)";
	case PS_DALI_LIGHT_SET_HYSTERESIS: return "SET HYSTERESIS (304)";
	case PS_DALI_LIGHT_SET_DEADTIME_TIMER: return "SET DEADTIME TIMER (304)";
	case PS_DALI_LIGHT_SET_HYSTERESIS_MIN: return "SET HYSTERESIS MIN (304)";
	case PS_DALI_LIGHT_QUERY_REPORT_TIMER: return "QUERY REPORT TIMER (304)";
	case PS_DALI_OCC_SET_HOLD_TIMER: return "SET HOLD TIMER (303)";
	case PS_DALI_OCC_SET_REPORT_TIMER: return "SET REPORT TIMER (303)";
	case PS_DALI_OCC_SET_DEADTIME_TIMER: return "SET DEADTIME TIMER (303)";
	}
	return NULL;
}

void ps_dali_device_describe(uint32_t frame, char *buf, size_t len)
{
	unsigned ab = frame >> 16 & 0xFF, ib = frame >> 8 & 0xFF, op = frame & 0xFF;
	struct ps_dali_device_event ev;
	const char *name;
	char who[48], inst[48];
	if (!len)
		return;
	if (frame > 0xFFFFFF) {
		snprintf(buf, len, "frame 0x%lX (not 24 bits)", (unsigned long)frame);
		return;
	}
	if (ps_dali_device_event_decode(frame, &ev) == 0) {
		if (ev.address >= 0)
			snprintf(who, sizeof who, "device %d", ev.address);
		else if (ev.device_group >= 0)
			snprintf(who, sizeof who, "device group %d", ev.device_group);
		else if (ev.instance_group >= 0)
			snprintf(who, sizeof who, "instance group %d", ev.instance_group);
		else
			snprintf(who, sizeof who, "instance");
		if (ev.instance_type >= 0 && ev.instance >= 0)
			snprintf(inst, sizeof inst, "type %d number %d", ev.instance_type, ev.instance);
		else if (ev.instance >= 0)
			snprintf(inst, sizeof inst, "number %d", ev.instance);
		else
			snprintf(inst, sizeof inst, "type %d", ev.instance_type);
		snprintf(buf, len, "event %s %s info %u", who, inst, ev.info);
		return;
	}
	if (ab == PS_DALI_DEVICE_SPECIAL && (name = special_name(ib))) {
		snprintf(buf, len, "%s 0x%02X", name, op);
		return;
	}
	if (!addressed(frame)) {
		snprintf(buf, len, "frame %06lX", (unsigned long)frame);
		return;
	}
	if (ab < 0x80)
		snprintf(who, sizeof who, "device %u", ab >> 1);
	else if (ab <= 0xBF)
		snprintf(who, sizeof who, "device group %u", (ab >> 1) & 0x1F);
	else
		snprintf(who, sizeof who, ab == 0xFF ? "devices" : "unaddressed devices");
	if (ib == PS_DALI_DEVICE_SELF)
		inst[0] = 0;
	else if (ib < 32)
		snprintf(inst, sizeof inst, " instance %u", ib);
	else if ((ib & 0xE0) == PS_DALI_DEVICE_INSTANCE_GROUP)
		snprintf(inst, sizeof inst, " instance group %u", ib & 0x1F);
	else if ((ib & 0xE0) == PS_DALI_DEVICE_INSTANCE_TYPE)
		snprintf(inst, sizeof inst, " instance type %u", ib & 0x1F);
	else if (ib == PS_DALI_DEVICE_ALL_INSTANCES)
		snprintf(inst, sizeof inst, " all instances");
	else
		snprintf(inst, sizeof inst, " instance byte 0x%02X", ib);
	name = op_name(ib, op);
	if (name)
		snprintf(buf, len, "%s%s %s", who, inst, name);
	else
		snprintf(buf, len, "%s%s opcode 0x%02X", who, inst, op);
}
