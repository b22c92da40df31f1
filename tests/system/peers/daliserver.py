#!/usr/bin/env python3
# SPDX-License-Identifier: ISC
"""A daliserver emulator: a TCP server speaking the network protocol of the
daliserver daemon (a Tridonic DALI USB shared over TCP), written from the
protocol's published description (daliserver's README, "Communication
protocol"; doc/hardware.md section 9), not from psensd's codec:

  request   version 2, type 0 (send), address byte, data byte: one 16-bit
            forward frame
  reply     version 2, status, value, 0
            status 0: no backward frame; 1: the backward frame in value;
            255: the frame could not be sent
  out of band: version 2, status 2, address, data: a frame seen on the bus

Messages with another version or type get no reply (the daemon logs and
drops them).  Behind it a bus of control gear (the model of peers/dalibus.py,
imported: IEC 62386-102 DAPC, OFF, RECALL MAX/MIN, QUERY STATUS, ACTUAL
LEVEL, PHYSICAL MINIMUM, MAX/MIN LEVEL ...); --gear 1:254,2:0.  A garbled
backward frame (different answers at once) is reported as status 255: how
the daemon reports one is not documented.

The port it listens on (127.0.0.1) is written to --port-file.  Faults:
--faults N:what replaces the reply to the N-th request; --mode-file FILE is
read before every request and every 50 ms and holds one of
  ok        normal service
  silent    requests are read but never answered (nor sent to the bus)
  short     each reply cut to 2 bytes
  garbage   each reply with status 7 (no such status)
  version   each reply with version 3
  error     each reply with status 255
  observed  another frame's out-of-band message before each reply
  down      the server closes every connection and stops listening (a crash
            or a restart); leaving "down" listens again on the same port
The gear's levels are written to --state FILE after every frame, and one
line per request to stdout ("req AAAA -> what")."""
import argparse
import os
import select
import socket
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from dalibus import Bus  # noqa: E402  (the gear model, shared)

VERSION = 2
ST_DONE, ST_ANSWER, ST_SEEN, ST_ERROR = 0, 1, 2, 255


def msg(status, a=0, b=0, version=VERSION):
    return bytes((version, status, a, b))


class Server:
    def __init__(self, args):
        self.args = args
        self.bus = Bus(args.gear)
        self.faults = {}
        for item in filter(None, args.faults.split(",")):
            n, what = item.split(":")
            self.faults[int(n)] = what
        self.nreq = 0
        self.port = 0
        self.lsock = None
        self.conns = {}   # socket -> bytes not yet a whole request
        self.listen()
        with open(args.port_file + ".tmp", "w") as f:
            f.write("%d\n" % self.port)
        os.replace(args.port_file + ".tmp", args.port_file)
        if args.state:
            self.bus.dump(args.state)

    def listen(self):
        s = socket.socket()
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        s.bind(("127.0.0.1", self.port))
        s.listen(4)
        self.port = s.getsockname()[1]
        self.lsock = s

    def go_down(self):
        for c in list(self.conns):
            c.close()
        self.conns.clear()
        if self.lsock:
            self.lsock.close()
            self.lsock = None

    def mode(self):
        if not self.args.mode_file:
            return "ok"
        try:
            with open(self.args.mode_file) as f:
                return f.read().strip() or "ok"
        except OSError:
            return "ok"

    def reply(self, c, req, mode):
        """The bytes answering one 4-byte request, or None for no reply."""
        self.nreq += 1
        fault = self.faults.get(self.nreq, mode)
        version, typ, a, d = req
        if version != VERSION or typ != 0:
            print("req %02X%02X -> dropped (version %d type %d)" % (a, d, version, typ), flush=True)
            return None
        if fault == "silent":
            print("req %02X%02X -> silent" % (a, d), flush=True)
            return None
        res = self.bus.forward(16, a << 8 | d)
        if self.args.state:
            self.bus.dump(self.args.state)
        if res is None:
            out = msg(ST_DONE)
        elif res[0] == "answer":
            out = msg(ST_ANSWER, res[1])
        else:
            out = msg(ST_ERROR)
        if fault == "short":
            out = out[:2]
        elif fault == "garbage":
            out = msg(7, out[2])
        elif fault == "version":
            out = msg(out[1], out[2], version=3)
        elif fault == "error":
            out = msg(ST_ERROR)
        elif fault == "observed":
            out = msg(ST_SEEN, 0xFF, 0x05) + out   # broadcast RECALL MAX LEVEL
        elif fault == "drop":
            out = b""
        print("req %02X%02X -> %s%s" % (a, d, out.hex() or "drop",
                                        "" if fault in ("ok", None) else " (%s)" % fault), flush=True)
        return out

    def run(self):
        while True:
            mode = self.mode()
            if mode == "down" and self.lsock:
                self.go_down()
            elif mode != "down" and not self.lsock:
                self.listen()
            rd = list(self.conns) + ([self.lsock] if self.lsock else [])
            r, _, _ = select.select(rd, [], [], 0.05)
            for s in r:
                if s is self.lsock:
                    c, _ = s.accept()
                    self.conns[c] = b""
                    continue
                if s not in self.conns:
                    continue
                try:
                    data = s.recv(4096)
                except OSError:
                    data = b""
                if not data:
                    s.close()
                    del self.conns[s]
                    continue
                buf = self.conns[s] + data
                out = b""
                drop = False
                while len(buf) >= 4:
                    req, buf = buf[:4], buf[4:]
                    r1 = self.reply(s, req, self.mode())
                    if r1 == b"":
                        drop = True
                        break
                    out += r1 or b""
                self.conns[s] = buf
                if out:
                    try:
                        s.sendall(out)
                    except OSError:
                        drop = True
                if drop:
                    s.close()
                    del self.conns[s]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--port-file", required=True)
    ap.add_argument("--gear", default="")
    ap.add_argument("--faults", default="",
                    help="N:what, what one of silent short garbage version error observed drop")
    ap.add_argument("--mode-file")
    ap.add_argument("--state")
    Server(ap.parse_args()).run()


if __name__ == "__main__":
    try:
        main()
    except KeyboardInterrupt:
        sys.exit(0)
