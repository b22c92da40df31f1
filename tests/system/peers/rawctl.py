#!/usr/bin/python3
# SPDX-License-Identifier: ISC
"""Raw control-socket client for tests: send bytes, print the reply lines.
  rawctl.py SOCKET send TEXT          one request (\\n added), print the reply
  rawctl.py SOCKET bytes N            N bytes of 'x' with no newline: print the reply
  rawctl.py SOCKET hold N             open N connections at once, send ping on each,
                                      print one reply per connection (or 'closed')
  rawctl.py SOCKET burst N            N bad requests on one connection, print the count of error replies
"""
import socket, sys, time

def conn(path):
    # A socket with a timeout is non-blocking underneath: a full listen
    # backlog gives EAGAIN, which a client retries until its timeout.
    end = time.monotonic() + 5
    while True:
        s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        s.settimeout(5)
        try:
            s.connect(path)
            return s
        except BlockingIOError:
            s.close()
            if time.monotonic() > end:
                raise
            time.sleep(0.01)

def line(s):
    buf = b""
    while not buf.endswith(b"\n"):
        try:
            chunk = s.recv(65536)
        except (ConnectionResetError, socket.timeout):
            break
        if not chunk:
            break
        buf += chunk
    return buf.decode("utf-8", "replace").strip() or "closed"

path, what = sys.argv[1], sys.argv[2]
if what == "send":
    s = conn(path); s.sendall(sys.argv[3].encode("utf-8", "surrogateescape") + b"\n"); print(line(s))
elif what == "bytes":
    s = conn(path)
    try:
        s.sendall(b"x" * int(sys.argv[3]))
    except (BrokenPipeError, ConnectionResetError):
        pass
    print(line(s))
elif what == "hold":
    socks = [conn(path) for _ in range(int(sys.argv[3]))]
    for s in socks:
        try:
            s.sendall(b"ping\n")
        except (BrokenPipeError, ConnectionResetError):
            pass
    for s in socks:
        print(line(s))
elif what == "burst":
    s = conn(path); n = int(sys.argv[3])
    s.sendall(b"".join(b"nonsense %d \x01\n" % i if i % 2 else b"target nowhere abc\n" for i in range(n)))
    got = 0
    buf = b""
    while got < n:
        chunk = s.recv(65536)
        if not chunk:
            break
        buf += chunk
        got = buf.count(b"\n")
    print(sum(1 for l in buf.split(b"\n") if b'"ok":false' in l))
elif what == "crowd":
    # N clients connected at once, each sending M status requests in turn;
    # print how many replies were ok
    import threading
    n, m = int(sys.argv[3]), int(sys.argv[4])
    socks = [conn(path) for _ in range(n)]
    good = [0] * n
    def run(i):
        f = socks[i].makefile("rb")
        for _ in range(m):
            socks[i].sendall(b"status\n")
            if b'"ok":true' in f.readline():
                good[i] += 1
    threads = [threading.Thread(target=run, args=(i,)) for i in range(n)]
    for t in threads: t.start()
    for t in threads: t.join()
    print(sum(good))
