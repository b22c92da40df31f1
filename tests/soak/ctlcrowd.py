#!/usr/bin/python3
# SPDX-License-Identifier: ISC
"""A crowd on psensd's control socket for the soak: N connections at once for
SECONDS, each asking status, ping or a bad line in turn; one in ten
reconnects after its reply (so connections come and go all the time).

  ctlcrowd.py SOCKET SECONDS N

Prints: replies, errors (error replies), reconnects, failures (refused or
lost connections)."""
import random, selectors, socket, sys, time

path, seconds, n = sys.argv[1], float(sys.argv[2]), int(sys.argv[3])
rnd = random.Random(7)
sel = selectors.DefaultSelector()
replies = errors = reconnects = failures = 0
REQ = [b"status\n", b"ping\n", b"status office\n", b"nosuch request\n", b"target\n", b"ratios\n"]

def open_one():
    global failures
    try:
        s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        s.connect(path)
        s.setblocking(False)
        s.sendall(rnd.choice(REQ))
        sel.register(s, selectors.EVENT_READ, [b""])
    except OSError:
        failures += 1

for _ in range(n):
    open_one()
end = time.monotonic() + seconds
while time.monotonic() < end:
    for key, _ in sel.select(timeout=0.5):
        s, buf = key.fileobj, key.data
        try:
            chunk = s.recv(65536)
        except OSError:
            chunk = b""
        if not chunk:
            sel.unregister(s); s.close(); failures += 1; open_one(); continue
        buf[0] += chunk
        while b"\n" in buf[0]:
            line, buf[0] = buf[0].split(b"\n", 1)
            replies += 1
            if b'"ok":false' in line:
                errors += 1
            if rnd.random() < 0.1:
                sel.unregister(s); s.close(); reconnects += 1; open_one(); break
            try:
                s.sendall(rnd.choice(REQ))
            except OSError:
                sel.unregister(s); s.close(); failures += 1; open_one(); break
    if not sel.get_map():
        time.sleep(0.1)
        for _ in range(n):
            open_one()
print(replies, errors, reconnects, failures)
