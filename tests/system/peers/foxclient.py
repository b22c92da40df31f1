#!/usr/bin/env python3
# SPDX-License-Identifier: ISC
"""A Foxtron DALI232/DALInet host, written from the protocol's public
description (doc/hardware.md section 6), to talk to psvirt's virtual DALI
bus in tests without psensd's codec.

  foxclient.py (tcp:HOST:PORT | pty:PATH) COMMAND...

COMMAND is one of
  send BITS HEX [twice]   one frame: prints "answer XX", "none", "garbled",
                          "power lost" (or "event N")
  ask BITS HEX [twice]    the same, an answer printed as a decimal number
  events SECONDS          collects the frames the converter reports as other
                          masters' traffic for that long; prints "frame XXXXXX"
  raw HEXBYTES            sends SOH HEX + checksum ETB with the checksum worked
                          here, prints the reply's bytes as hex
  badsum HEXBYTES         the same with a wrong checksum
  search103 FIRST         commissions the unaddressed control devices (IEC
                          62386-103): INITIALISE, RANDOMISE, then for each a
                          binary search with COMPARE, PROGRAM SHORT ADDRESS
                          FIRST, FIRST + 1, ..., WITHDRAW; prints "device
                          RANDOM short N" for each
Several commands may follow one another, separated by ';'."""
import os
import select
import socket
import sys
import time

SOH, ETB = 0x01, 0x17


def checksum(b):
    return ~sum(b) & 0xFF


def message(b, bad=False):
    c = checksum(b) ^ (0x5A if bad else 0)
    return bytes([SOH]) + (bytes(b).hex().upper() + "%02X" % c).encode() + bytes([ETB])


class Link:
    def __init__(self, where):
        if where.startswith("tcp:"):
            host, port = where[4:].rsplit(":", 1)
            self.sock = socket.create_connection((host, int(port)), timeout=5)
            self.fd = self.sock.fileno()
        else:
            self.sock = None
            self.fd = os.open(where[4:], os.O_RDWR | os.O_NOCTTY)
            import tty
            tty.setraw(self.fd)
        self.buf = b""

    def write(self, b):
        os.write(self.fd, b)

    def message(self, timeout=2.0):
        """The next complete message's bytes (checksum checked), or None."""
        end = time.monotonic() + timeout
        while True:
            s = self.buf.find(bytes([SOH]))
            e = self.buf.find(bytes([ETB]), s + 1) if s >= 0 else -1
            if s >= 0 and e > s:
                body = self.buf[s + 1:e]
                self.buf = self.buf[e + 1:]
                b = bytes.fromhex(body.decode())
                if checksum(b[:-1]) != b[-1]:
                    raise SystemExit("reply with a wrong checksum: %s" % body)
                return b[:-1]
            left = end - time.monotonic()
            if left <= 0:
                return None
            r, _, _ = select.select([self.fd], [], [], left)
            if r:
                got = os.read(self.fd, 256)
                if not got:
                    return None
                self.buf += got

    def send(self, bits, frame, twice):
        n = bits // 8
        fb = frame.to_bytes(n, "big")
        self.write(message([0x0B, 0, bits] + list(fb) + [1 if twice else 0]))
        while True:
            m = self.message()
            if m is None:
                return "silent"
            if m[0] == 0x0D and m[2] == 0:
                return "garbled"
            if m[0] == 0x0D:
                return "answer %02X" % m[-1]
            if m[0] == 0x0E:
                return "none"
            if m[0] == 0x05:
                return "power lost" if m[1] == 1 else "event %d" % m[1]
            # 0x03/0x04: another master's traffic (an input device's event): skip


def search103(link, first):
    def ask(f, twice=False):
        return link.send(24, f, twice)

    def search_addr(a):
        ask(0xC10500 | a >> 16)
        ask(0xC10600 | (a >> 8 & 0xFF))
        ask(0xC10700 | (a & 0xFF))

    ask(0xC1017F, True)    # INITIALISE the devices without a short address
    ask(0xC10200, True)    # RANDOMISE
    short = first
    while True:
        lo, hi = 0, 0xFFFFFF
        search_addr(hi)
        if ask(0xC10300) == "none":
            break
        while lo < hi:
            mid = (lo + hi) // 2
            search_addr(mid)
            if ask(0xC10300) != "none":   # a yes, or several (garbled)
                hi = mid
            else:
                lo = mid + 1
        search_addr(lo)
        ask(0xC10800 | short)          # PROGRAM SHORT ADDRESS
        ok = ask(0xC10900 | short)     # VERIFY SHORT ADDRESS
        print("device %06X short %d %s" % (lo, short, "verified" if ok == "answer FF" else ok))
        ask(0xC10400)                  # WITHDRAW
        short += 1
    ask(0xC10000)                      # TERMINATE


def main():
    link = Link(sys.argv[1])
    words = " ".join(sys.argv[2:]).split(";")
    for cmd in words:
        w = cmd.split()
        if not w:
            continue
        if w[0] in ("send", "ask"):
            r = link.send(int(w[1]), int(w[2], 16), len(w) > 3 and w[3] == "twice")
            if w[0] == "ask" and r.startswith("answer "):
                r = str(int(r[7:], 16))
            print(r)
        elif w[0] == "events":
            end = time.monotonic() + float(w[1])
            while time.monotonic() < end:
                m = link.message(end - time.monotonic())
                if m and m[0] == 0x04 and m[1] == 24:
                    print("frame %s" % m[2:5].hex().upper())
        elif w[0] == "search103":
            search103(link, int(w[1]))
        elif w[0] in ("raw", "badsum"):
            link.write(message(list(bytes.fromhex(w[1])), bad=w[0] == "badsum"))
            m = link.message()
            print(m.hex().upper() if m else "silent")
        sys.stdout.flush()


main()
