#!/usr/bin/env python3
# SPDX-License-Identifier: ISC
"""A DALI interface emulator with a small bus behind it, for the serial
transports' tests.  The interface speaks one of two host protocols, written
from their public descriptions (doc/hardware.md sections 5 and 6), not from
psensd's codecs:

  atx      the AtxLED DALI HAT: lines 'h'+4 hex, 't'+4 (sent twice), 'j'+2,
           'l'+6; replies 'J'+2 hex, 'N', 'X' (answers collided), 'Z' (our
           frame collided)
  foxtron  the Foxtron DALI232/DALInet: SOH, hex bytes, checksum (one's
           complement of the byte sum), ETB; send 0x0B, replies 0x0D/0x0E,
           events 0x05, other masters' frames 0x04
  luba     the Lunatone LUBA: 'Y', command, length, payload, XOR checksum;
           queue 0x32 answered 0x33, then event 0x31 "sent" and, if one came,
           event 0x31 "seen" with the backward frame (no answer: nothing)

on a pty (--pty FILE: the slave's path is written to FILE) or on TCP
(--tcp FILE: 127.0.0.1, the port written to FILE).

The bus: control gear at short addresses (--gear 1:200,2:0) answering per
IEC 62386-102: DAPC (0AAAAAA0 level, 255 = MASK, clamped to MIN/MAX), OFF,
RECALL MAX/MIN, and the queries STATUS (0x90), CONTROL GEAR PRESENT (0x91,
"yes" = 0xFF), PHYSICAL MINIMUM (0x9A), ACTUAL LEVEL (0xA0), MAX/MIN LEVEL
(0xA1/0xA2); short, group and broadcast addresses.  No gear answering is
"no answer"; several gear answering different values garble the backward
frame (a collision of answers); identical answers superimpose into one.

Faults on demand, by the number of the frame they replace the reply of
(--faults 3:malformed,5:silent): malformed (a reply not in the protocol),
checksum (foxtron: the right reply with a wrong checksum; atx, which has no
checksum: the answer with a non-hex digit), short (half the reply, then
nothing), silent (no reply), collision (our frame collided: 'Z' / answer
length 0), power (foxtron: bus power lost instead of the reply, back before
the next one), observed (another master's frame before the reply).
SIGUSR1 mutes the interface (frames neither reach the bus nor get a reply),
SIGUSR2 brings it back.
The gear's levels are written to --state FILE after every frame.

Control devices (--devices SHORT:RANDOM,..., SHORT '-' for none, RANDOM a
24-bit number): DALI-2 multisensors per IEC 62386-103 with instance 0 an
occupancy sensor (part 303, type 3) and instance 1 a light sensor (part
304, type 4), written from the standard's facts (doc/hardware.md section
9): 24-bit frames, the device space's special commands under 0xC1
(INITIALISE, RANDOMISE, COMPARE, WITHDRAW, SEARCHADDRH/M/L, PROGRAM,
VERIFY and QUERY SHORT ADDRESS, DTR0-2), device and instance commands and
queries, send-twice commands acting only on the second of two identical
frames in a row, and event messages in the scheme each instance is set
to, sent as another master's frame would be seen by the interface: a
light sensor every T_report and when its value leaves the hysteresis band
(not within T_deadtime of its last), an occupancy sensor on occupied /
vacant and every T_report when repeats are on.  --control FILE (read
again when it changes) sets them: lines "light I VALUE", "occupied I 0|1",
"silent I 0|1" (the device neither answers nor reports), "garbage I 0|1"
(its answers come garbled), I the device's place in --devices.  Their
addresses and the QUERY INPUT VALUE frames each answered go to the --state
file as "device I short S random R polls N identified K" (K: IDENTIFY
DEVICE commands it obeyed).  --no-events: an interface
that does not pass bus traffic (the host must poll)."""
import argparse
import os
import random
import select
import signal
import socket
import sys
import time
import tty

SOH, ETB = 0x01, 0x17


class Gear:
    def __init__(self, level):
        self.level, self.max, self.min, self.phys_min = level, 254, 1, 1
        self.groups = set()


class Bus:
    def __init__(self, spec, devices=""):
        self.devices = Devices(devices)
        self.gear = {}
        for item in filter(None, spec.split(",")):
            a, lv = item.split(":")
            self.gear[int(a)] = Gear(int(lv))

    def targets(self, a):
        if a & 0x80 == 0:
            s = (a >> 1) & 0x3F
            return [self.gear[s]] if s in self.gear else []
        if a & 0xE0 == 0x80:
            g = (a >> 1) & 0x0F
            return [x for x in self.gear.values() if g in x.groups]
        if a in (0xFE, 0xFF):
            return list(self.gear.values())
        return []   # special commands and unaddressed gear: none here

    def forward(self, bits, frame):
        """-> None (no answer), ('answer', v) or ('garbled',)"""
        if bits == 24:
            answers = self.devices.forward(frame)
            if not answers:
                return None
            if any(d.garbage for d, _ in answers) or len(set(a for _, a in answers)) > 1:
                return ("garbled",)
            return ("answer", answers[0][1])
        if bits != 16:
            return None
        a, d = frame >> 8, frame & 0xFF
        if 0xA0 <= a <= 0xCB and a & 1:
            return None   # special commands: no gear answers the ones used here
        answers = []
        for g in self.targets(a):
            if a & 1 == 0:
                if d != 255:
                    g.level = 0 if d == 0 else max(g.phys_min, min(g.max, max(g.min, d)))
                continue
            if d == 0x00:
                g.level = 0
            elif d == 0x05:
                g.level = g.max
            elif d == 0x06:
                g.level = g.min
            elif d == 0x90:
                answers.append(0x04 if g.level > 0 else 0x00)   # bit 2: lamp arc power on
            elif d == 0x91:
                answers.append(0xFF)
            elif d == 0x9A:
                answers.append(g.phys_min)
            elif d == 0xA0:
                answers.append(g.level)
            elif d == 0xA1:
                answers.append(g.max)
            elif d == 0xA2:
                answers.append(g.min)
        if not answers:
            return None
        if len(set(answers)) > 1:
            return ("garbled",)
        return ("answer", answers[0])

    def dump(self, path):
        with open(path + ".tmp", "w") as f:
            for s in sorted(self.gear):
                f.write("short %d level %d\n" % (s, self.gear[s].level))
            for n, d in enumerate(self.devices.devs):
                f.write("device %d short %s random 0x%06X polls %d identified %d\n" % (n, "-" if d.short is None else d.short, d.random, d.polls, d.identify))
        os.replace(path + ".tmp", path)


class Instance:
    def __init__(self, number, itype):
        self.number, self.type = number, itype
        self.enabled = True
        self.scheme = 0            # instance scheme until set
        self.filter = 0x01 if itype == 4 else 0x03
        self.priority = 4
        self.report = 30           # T_report, s
        self.deadtime = 30         # x 50 ms
        self.hysteresis, self.hysteresis_min = 10, 50
        self.hold = 90             # x 10 s
        self.value = 0             # light: 0..1023
        self.occupied = self.movement = False
        self.last_event = -1e9
        self.last_sent = None
        self.pending = None        # occupancy: a change to report

    bits = property(lambda self: 10 if self.type == 4 else 2)

    def input_bytes(self):
        v = self.value if self.type == 4 else (self.occupied << 1) | self.movement
        nb = (self.bits + 7) // 8
        total, out = 0, 0
        # left-aligned, the value's bits repeated below it to fill the bytes
        while total < 8 * nb:
            take = min(self.bits, 8 * nb - total)
            out = (out << take) | (v >> (self.bits - take))
            total += take
        return list(out.to_bytes(nb, "big"))


class CtlDevice:
    def __init__(self, short, rnd):
        self.short, self.random = short, rnd
        self.instances = [Instance(0, 3), Instance(1, 4)]
        self.initialised = self.withdrawn = False
        self.silent = self.garbage = False
        self.latch = []
        self.identify = 0
        self.polls = 0             # QUERY INPUT VALUE frames it answered


class Devices:
    """The control devices' part of the bus (IEC 62386-103/303/304)."""
    TWICE_DEV = {0x00, 0x01} | set(range(0x10, 0x22))
    TWICE_INST = set(range(0x61, 0x69)) | {0x21, 0x22, 0x23, 0x30, 0x31, 0x32, 0x33}

    def __init__(self, spec):
        self.devs = []
        for item in filter(None, spec.split(",")):
            sh, rnd = item.split(":")
            self.devs.append(CtlDevice(None if sh == "-" else int(sh), int(rnd, 0)))
        self.search = 0xFFFFFF
        self.dtr = [0, 0, 0]
        self.last = None           # the previous frame, for send-twice

    def twice_ok(self, frame, needs):
        """a send-twice command acts on the second of two in a row"""
        if not needs:
            self.last = None
            return True
        if self.last == frame:
            self.last = None
            return True
        self.last = frame
        return False

    def live(self):
        return [d for d in self.devs if not d.silent]

    def special(self, cmd, data):
        dv = self.live()
        sel = [d for d in dv if d.initialised and not d.withdrawn and d.random == self.search]
        if cmd == 0x00:
            for d in self.devs:
                d.initialised = False
        elif cmd == 0x01:
            if not self.twice_ok((0xC1, cmd, data), True):
                return []
            for d in dv:
                if data == 0xFF or (data == 0x7F and d.short is None) or d.short == data:
                    d.initialised, d.withdrawn = True, False
        elif cmd == 0x02:
            if not self.twice_ok((0xC1, cmd, data), True):
                return []
            for d in dv:
                if d.initialised:
                    d.random = random.randrange(0x1000000)
        elif cmd == 0x03:
            return [(d, 0xFF) for d in dv if d.initialised and not d.withdrawn and d.random <= self.search]
        elif cmd == 0x04:
            for d in sel:
                d.withdrawn = True
        elif cmd in (0x05, 0x06, 0x07):
            shift = {0x05: 16, 0x06: 8, 0x07: 0}[cmd]
            self.search = (self.search & ~(0xFF << shift)) | (data << shift)
        elif cmd == 0x08:
            for d in sel:
                d.short = None if data == 0xFF else data & 0x3F
        elif cmd == 0x09:
            return [(d, 0xFF) for d in dv if d.initialised and d.short == data]
        elif cmd == 0x0A:
            return [(d, 0xFF if d.short is None else d.short) for d in sel]
        elif cmd in (0x30, 0x31, 0x32):
            self.dtr[cmd - 0x30] = data
        return []

    def targets(self, ab):
        if ab == 0xFF:
            return self.live()
        if ab == 0xFD:
            return [d for d in self.live() if d.short is None]
        if ab & 0x80 == 0:
            return [d for d in self.live() if d.short == ab >> 1]
        return []

    def forward(self, frame):
        """-> a list of (device, answer byte)"""
        ab, ib, op = frame >> 16, (frame >> 8) & 0xFF, frame & 0xFF
        if not ab & 1:
            return []      # an event message: not for devices
        if ab == 0xC1:
            if ib in (0x01, 0x02):
                return self.special(ib, op)
            self.last = None
            return self.special(ib, op)
        devs = self.targets(ab)
        if ib == 0xFE:
            if not self.twice_ok(frame, op in self.TWICE_DEV):
                return []
            out = []
            for d in devs:
                if op == 0x00:
                    d.identify += 1
                elif op == 0x14:
                    d.short = None if self.dtr[0] == 0xFF else self.dtr[0] & 0x3F
                elif op == 0x30:
                    out.append((d, 0x04 if d.short is None else 0x00))   # bit 2: short address is MASK
                elif op == 0x34:
                    out.append((d, 0x08))   # version 2.0
                elif op == 0x35:
                    out.append((d, len(d.instances)))
                elif op in (0x39, 0x3A, 0x3B):
                    out.append((d, (d.random >> (8 * (0x3B - op))) & 0xFF))
                elif op == 0x46:
                    out.append((d, 0x02))   # instances, no application controller
            return out
        if not self.twice_ok(frame, op in self.TWICE_INST):
            return []
        out = []
        for d in devs:
            for i in d.instances:
                if not (ib == 0xFF or ib == i.number or ib == 0xC0 | i.type):
                    continue
                a = self.instance_cmd(d, i, op)
                if a is not None:
                    out.append((d, a))
        return out

    def instance_cmd(self, d, i, op):
        v = self.dtr[0]
        if op == 0x62:
            i.enabled = True
        elif op == 0x63:
            i.enabled = False
        elif op == 0x61:
            i.priority = v
        elif op == 0x67:
            i.scheme = v if v <= 4 else 0
        elif op == 0x68:
            i.filter = v | self.dtr[1] << 8 | self.dtr[2] << 16
        elif op == 0x80:
            return i.type
        elif op == 0x81:
            return i.bits
        elif op == 0x83:
            return 0x02 if i.enabled else 0x00
        elif op == 0x86:
            return 0xFF if i.enabled else None
        elif op == 0x8B:
            return i.scheme
        elif op == 0x90:
            return i.filter & 0xFF
        elif op == 0x8C:
            d.polls += 1
            d.latch = i.input_bytes()
            return d.latch.pop(0)
        elif op == 0x8D:
            return d.latch.pop(0) if d.latch else None
        elif i.type == 4 and op in (0x30, 0x31, 0x32, 0x33):
            if op == 0x30:
                i.report = max(1, v)
            elif op == 0x31:
                i.hysteresis = min(v, 25)
            elif op == 0x32:
                i.deadtime = v
            else:
                i.hysteresis_min = v
        elif i.type == 4 and op in (0x3C, 0x3D, 0x3E, 0x3F):
            return {0x3C: i.hysteresis_min, 0x3D: i.deadtime, 0x3E: i.report, 0x3F: i.hysteresis}[op]
        elif i.type == 3 and op in (0x21, 0x22, 0x23):
            if op == 0x21:
                i.hold = max(1, v)
            elif op == 0x22:
                i.report = max(1, v)
            else:
                i.deadtime = v
        elif i.type == 3 and op in (0x2C, 0x2D, 0x2E):
            return {0x2C: i.deadtime, 0x2D: i.hold, 0x2E: i.report}[op]
        return None

    def event_frame(self, d, i, info):
        if i.scheme == 1 and d.short is not None:
            return d.short << 17 | i.type << 10 | info
        if i.scheme == 2 and d.short is not None:
            return d.short << 17 | 1 << 15 | i.number << 10 | info
        if i.scheme in (1, 2):
            return None        # no short address: it cannot name itself
        return 1 << 23 | i.type << 17 | 1 << 15 | i.number << 10 | info

    def events(self, now):
        """-> the event frames due at now, and when the next one may be"""
        out, nxt = [], now + 3600
        for d in self.live():
            for i in d.instances:
                if not i.enabled:
                    continue
                dead = i.last_event + i.deadtime * 0.05
                info = None
                if i.type == 4 and i.filter & 1:
                    band = max(i.hysteresis * (i.last_sent or 0) / 100.0, i.hysteresis_min)
                    moved = i.last_sent is None or abs(i.value - i.last_sent) > band
                    if i.last_sent is None or now >= i.last_event + i.report or (moved and now >= dead):
                        info = i.value
                    nxt = min(nxt, i.last_event + i.report, dead if moved else nxt)
                elif i.type == 3:
                    state = (i.occupied << 1) | i.movement
                    if i.pending is not None:
                        if not i.filter & (1 if i.occupied else 2):
                            i.pending = None
                        elif now >= dead:
                            info = state | 0x08
                        else:
                            nxt = min(nxt, dead)
                    if info is None and i.filter & 4:
                        if now >= i.last_event + i.report:
                            info = state | 0x04 | 0x08
                        nxt = min(nxt, i.last_event + i.report)
                if info is None:
                    continue
                i.last_event = now
                i.last_sent = info if i.type == 4 else i.last_sent
                i.pending = None
                f = self.event_frame(d, i, info)
                if f is not None:
                    out.append(f)
                nxt = min(nxt, now + i.report)
        return out, max(nxt, now + 0.01)

    def control(self, line):
        w = line.split()
        if len(w) != 3 or not w[1].isdigit() or int(w[1]) >= len(self.devs):
            return
        d, v = self.devs[int(w[1])], int(w[2])
        if w[0] == "light":
            d.instances[1].value = max(0, min(1023, v))
        elif w[0] == "occupied":
            occ = d.instances[0]
            if bool(v) != occ.occupied:
                occ.occupied = occ.movement = bool(v)
                occ.pending = (occ.occupied << 1) | occ.movement
        elif w[0] == "silent":
            d.silent = bool(v)
        elif w[0] == "garbage":
            d.garbage = bool(v)


def hexs(bs):
    return "".join("%02X" % b for b in bs)


def fox_msg(payload, good=True):
    ck = (~sum(payload)) & 0xFF
    if not good:
        ck ^= 0x5A
    return bytes([SOH]) + (hexs(payload) + "%02X" % ck).encode() + bytes([ETB])


class Atx:
    def __init__(self):
        self.buf = b""

    def requests(self, data):
        """-> list of (bits, frame, twice) or ('bad', text)"""
        self.buf += data
        out = []
        while b"\n" in self.buf:
            line, self.buf = self.buf.split(b"\n", 1)
            line = line.strip(b"\r").decode("ascii", "replace")
            sizes = {"j": 8, "h": 16, "t": 16, "l": 24}
            if line and line[0] in sizes and len(line) == 1 + sizes[line[0]] // 4:
                out.append((sizes[line[0]], int(line[1:], 16), line[0] == "t"))
        return out

    def reply(self, result, fault, twice):
        if fault == "malformed":
            return b"?bogus\n"
        if fault == "checksum":
            return b"J4G\n"
        if fault == "collision":
            return b"Z\n"
        if result is None:
            one = b"N\n"
        elif result[0] == "garbled":
            one = b"X\n"
        else:
            one = b"J%02X\n" % result[1]
        return one * (2 if twice else 1)

    def observed(self):
        return b"h7F91\n"

    def seen(self, frame):
        return b"l%06X\n" % frame


class Foxtron:
    def __init__(self):
        self.buf = b""
        self.power_lost = False

    def requests(self, data):
        self.buf += data
        out = []
        while True:
            s = self.buf.find(bytes([SOH]))
            if s < 0:
                self.buf = b""
                return out
            e = self.buf.find(bytes([ETB]), s)
            if e < 0:
                self.buf = self.buf[s:]
                return out
            body, self.buf = self.buf[s + 1:e], self.buf[e + 1:]
            try:
                raw = bytes.fromhex(body.decode())
            except ValueError:
                out.append(("event", 6))
                continue
            if len(raw) < 2 or (~sum(raw[:-1])) & 0xFF != raw[-1]:
                out.append(("event", 5))
                continue
            p = raw[:-1]
            if p[0] == 0x06 and len(p) == 2:
                out.append(("conf", p[1]))
            elif p[0] == 0x0B and len(p) >= 5:
                nb = p[2] // 8
                frame = int.from_bytes(p[3:3 + nb], "big")
                out.append((p[2], frame, bool(p[3 + nb] & 1)))
            else:
                out.append(("event", 6))

    def reply(self, bits, frame, result, fault):
        fb = frame.to_bytes(bits // 8, "big")
        pre = b""
        if self.power_lost:
            pre = fox_msg([0x05, 0x00])
            self.power_lost = False
        if fault == "power":
            self.power_lost = True
            return pre + fox_msg([0x05, 0x01])
        if fault == "malformed":
            return pre + fox_msg([0x42, 0x00])
        if fault == "collision":
            return pre + fox_msg([0x0D, bits, 0x00] + list(fb))
        if result is None:
            msg = [0x0E, bits] + list(fb)
        elif result[0] == "garbled":
            msg = [0x0D, bits, 0x00] + list(fb)
        else:
            msg = [0x0D, bits, 0x08] + list(fb) + [result[1]]
        return pre + fox_msg(msg, good=fault != "checksum")

    def observed(self):
        return fox_msg([0x04, 0x10, 0x7F, 0x91])

    def seen(self, frame):
        return fox_msg([0x04, 0x18] + list(frame.to_bytes(3, "big")))


def luba_msg(cmd, payload, good=True):
    body = [cmd, len(payload)] + list(payload)
    ck = 0
    for b in body:
        ck ^= b
    if not good:
        ck ^= 0x5A
    return bytes([0x59] + body + [ck])


class Luba:
    def __init__(self):
        self.buf = b""
        self.tick = 0

    def requests(self, data):
        self.buf += data
        out = []
        while True:
            s = self.buf.find(b"Y")
            if s < 0 or len(self.buf) < s + 3:
                self.buf = self.buf[s:] if s >= 0 else b""
                return out
            n = self.buf[s + 2]
            if len(self.buf) < s + 4 + n:
                self.buf = self.buf[s:]
                return out
            m, self.buf = self.buf[s:s + 4 + n], self.buf[s + 4 + n:]
            p = m[3:-1]
            if m[1] == 0x32 and n == 7 and p[1] in (16, 24):
                nb = p[1] // 8
                out.append((p[1], int.from_bytes(p[3:3 + nb], "big"), bool(p[2] & 0x80)))

    def event(self, status, data, good=True):
        self.tick = (self.tick + 7) & 0xFFFF
        return luba_msg(0x31, [self.tick >> 8, self.tick & 0xFF, 0, status] + list(data), good)

    def reply(self, bits, frame, result, fault, twice):
        fb = list(frame.to_bytes(bits // 8, "big"))
        if fault == "malformed":
            return luba_msg(0x42, [0])
        out = luba_msg(0x33, [5, 0])
        for _ in range(2 if twice else 1):
            out += self.event(0x00, [5] + fb)
        if fault == "collision":
            return out + self.event(0x80 | 63, [])
        if result is None:
            return out
        if result[0] == "garbled":
            return out + self.event(0x80 | 63, [])
        return out + self.event(0x80 | 8, [result[1]], good=fault != "checksum")

    def observed(self):
        return self.event(0x80 | 16, [0x7F, 0x91])

    def seen(self, frame):
        return self.event(0x80 | 24, list(frame.to_bytes(3, "big")))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--codec", choices=("atx", "foxtron", "luba"), required=True)
    ap.add_argument("--pty")
    ap.add_argument("--tcp")
    ap.add_argument("--gear", default="")
    ap.add_argument("--faults", default="")
    ap.add_argument("--state")
    ap.add_argument("--devices", default="")
    ap.add_argument("--control")
    ap.add_argument("--no-events", action="store_true",
                    help="the interface does not pass bus traffic: devices' events never reach the host")
    ap.add_argument("--idle-close", type=float, default=0,
                    help="TCP: close a connection silent for this many seconds, as DALInet does")
    args = ap.parse_args()
    bus = Bus(args.gear, args.devices)
    control_mtime = [None]

    def read_control():
        if not args.control:
            return
        try:
            st = os.stat(args.control)
        except OSError:
            return
        if st.st_mtime_ns == control_mtime[0]:
            return
        control_mtime[0] = st.st_mtime_ns
        with open(args.control) as f:
            for line in f:
                bus.devices.control(line)
    muted = [False]
    signal.signal(signal.SIGUSR1, lambda *_: muted.__setitem__(0, True))
    signal.signal(signal.SIGUSR2, lambda *_: muted.__setitem__(0, False))
    faults = {}
    for item in filter(None, args.faults.split(",")):
        n, what = item.split(":")
        faults[int(n)] = what
    proto = {"atx": Atx, "foxtron": Foxtron, "luba": Luba}[args.codec]()
    nframe = 0
    lsock = None
    if args.pty:
        master, slave = os.openpty()
        tty.setraw(slave)
        with open(args.pty + ".tmp", "w") as f:
            f.write(os.ttyname(slave) + "\n")
        os.replace(args.pty + ".tmp", args.pty)
        conn_r = conn_w = master
    else:
        lsock = socket.socket()
        lsock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        lsock.bind(("127.0.0.1", 0))
        lsock.listen(1)
        with open(args.tcp + ".tmp", "w") as f:
            f.write("%d\n" % lsock.getsockname()[1])
        os.replace(args.tcp + ".tmp", args.tcp)
        conn = None
    if args.state:
        bus.dump(args.state)
    while True:
        if lsock is not None and conn is None:
            conn, _ = lsock.accept()
            conn_r = conn_w = conn.fileno()
            proto.buf = b""
        read_control()
        now = time.monotonic()
        evs, nxt = bus.devices.events(now)
        if evs and not muted[0] and not args.no_events:
            os.write(conn_w, b"".join(proto.seen(f) for f in evs))
        wait = None
        if bus.devices.devs:
            wait = max(0.0, min(nxt - time.monotonic(), 0.2))
        idle = args.idle_close if lsock is not None and args.idle_close > 0 else None
        r, _, _ = select.select([conn_r], [], [], wait if idle is None else min(idle, wait if wait is not None else idle))
        if not r:
            if idle is not None and wait is None:
                conn.close()
                conn = None
            continue
        try:
            data = os.read(conn_r, 4096)
        except OSError:
            data = b""
        if not data:
            if lsock is None:
                # the pty's other side closed: wait for it to be opened again
                select.select([], [], [], 0.05)
                continue
            conn.close()
            conn = None
            continue
        out = b""
        for req in proto.requests(data):
            if req[0] == "event":
                out += fox_msg([0x05, req[1]])
                continue
            if req[0] == "conf":
                out += fox_msg([0x07, req[1], 0x04, 0x06])   # firmware 4.6
                continue
            bits, frame, twice = req
            nframe += 1
            if muted[0]:
                continue
            fault = faults.get(nframe)
            # a frame that collided with another master's never reached the gear
            result = None if fault == "collision" else bus.forward(bits, frame)
            if twice and args.codec != "atx" and fault != "collision":
                result = bus.forward(bits, frame)
            if fault == "observed":
                out += proto.observed()
                fault = None
            if fault == "silent":
                continue
            if args.codec == "atx":
                r = proto.reply(result, fault, twice)
            elif args.codec == "luba":
                r = proto.reply(bits, frame, result, fault, twice)
            else:
                r = proto.reply(bits, frame, result, fault)
            if fault == "short":
                r = r[:max(1, len(r) // 2)]
            out += r
            if args.state:
                bus.dump(args.state)
        if out:
            os.write(conn_w, out)


if __name__ == "__main__":
    try:
        main()
    except KeyboardInterrupt:
        sys.exit(0)
