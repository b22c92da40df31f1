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
The gear's levels are written to --state FILE after every frame."""
import argparse
import os
import select
import signal
import socket
import sys
import tty

SOH, ETB = 0x01, 0x17


class Gear:
    def __init__(self, level):
        self.level, self.max, self.min, self.phys_min = level, 254, 1, 1
        self.groups = set()


class Bus:
    def __init__(self, spec):
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
        if bits != 16:
            return None   # no control devices on this bus
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
        os.replace(path + ".tmp", path)


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


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--codec", choices=("atx", "foxtron", "luba"), required=True)
    ap.add_argument("--pty")
    ap.add_argument("--tcp")
    ap.add_argument("--gear", default="")
    ap.add_argument("--faults", default="")
    ap.add_argument("--state")
    ap.add_argument("--idle-close", type=float, default=0,
                    help="TCP: close a connection silent for this many seconds, as DALInet does")
    args = ap.parse_args()
    bus = Bus(args.gear)
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
        r, _, _ = select.select([conn_r], [], [], args.idle_close if lsock is not None and args.idle_close > 0 else None)
        if not r:
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
