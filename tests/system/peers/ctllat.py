#!/usr/bin/python3
# SPDX-License-Identifier: ISC
"""Control-socket latency from a client's side, as psensctl sees it: a new
connection per request (connect, send, read the reply line), one after the
other for SECONDS, a pause of INTERVAL s between.

  ctllat.py SOCKET SECONDS INTERVAL [REQUEST]

Prints one line: requests, answered, over5 (requests that took 5 s or got no
reply: psensctl's limit), then median, p90, p99 and max in milliseconds."""
import socket, sys, time

path, seconds, interval = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
request = (sys.argv[4] if len(sys.argv) > 4 else "status") + "\n"
lat, over, n = [], 0, 0
end = time.monotonic() + seconds
while time.monotonic() < end:
    t0 = time.monotonic()
    n += 1
    try:
        s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        s.settimeout(5)
        s.connect(path)
        s.sendall(request.encode())
        buf = b""
        while not buf.endswith(b"\n"):
            chunk = s.recv(65536)
            if not chunk:
                break
            buf += chunk
        s.close()
        dt = time.monotonic() - t0
        if not buf.endswith(b"\n") or dt >= 5:
            over += 1
        else:
            lat.append(dt * 1000)
    except OSError:
        over += 1
    time.sleep(interval)
lat.sort()
def pct(p):
    return lat[min(len(lat) - 1, int(p * len(lat)))] if lat else float("nan")
print("%d %d %d %.1f %.1f %.1f %.1f" % (n, len(lat), over, pct(0.5), pct(0.9), pct(0.99), lat[-1] if lat else float("nan")))
