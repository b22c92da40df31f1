#!/usr/bin/python3
# SPDX-License-Identifier: ISC
"""systemd's notification socket, timing the watchdog: bind a datagram
socket at SOCKET, for SECONDS after the first WATCHDOG=1 note when each
arrives, then print: count, and the largest gap between two in ms.

  wdgap.py SOCKET SECONDS"""
import socket, sys, time
s = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
s.bind(sys.argv[1])
s.settimeout(1)
seconds, times, end = float(sys.argv[2]), [], None
while end is None or time.monotonic() < end:
    try:
        msg = s.recv(4096).decode("utf-8", "replace")
    except socket.timeout:
        continue
    if "WATCHDOG=1" in msg.split("\n"):
        times.append(time.monotonic())
        if end is None:
            end = times[0] + seconds
gaps = [b - a for a, b in zip(times, times[1:])]
print(len(times), "%.1f" % (1000 * max(gaps)) if gaps else "nan")
