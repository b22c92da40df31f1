#!/usr/bin/python3
# SPDX-License-Identifier: ISC
"""A stand-in for systemd's notification socket: bind a datagram socket at
argv[1] and append every message psensd's sd_notify() sends to argv[2]."""
import socket, sys
s = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
s.bind(sys.argv[1])
with open(sys.argv[2], "a", buffering=1) as out:
    while True:
        msg = s.recv(4096).decode("utf-8", "replace")
        out.write(msg.replace("\n", " ") + "\n")
