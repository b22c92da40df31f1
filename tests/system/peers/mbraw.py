#!/usr/bin/python3
# SPDX-License-Identifier: ISC
"""Raw Modbus TCP peer (python3 socket) for what no library client sends:
malformed MBAP frames, unsupported functions, a byte at a time, crowds.

  mbraw.py HOST PORT send HEX [WAIT [FRAMES]]
      send the bytes (hex, spaces ignored) on a new connection; print the
      reply as hex (FRAMES of them, default 1: requests sent in one go),
      "closed" when the server closes without replying, or "silent" when
      nothing came within WAIT seconds (default 2)
  mbraw.py HOST PORT sendclose HEX [WAIT]
      the same, closing the sending side (FIN) right after the request
  mbraw.py HOST PORT trickle HEX INTERVAL
      send the bytes one every INTERVAL seconds; print "reply HEX after N
      bytes", "closed after N bytes" or "silent after N bytes"
  mbraw.py HOST PORT hammer HEX PERIOD SECONDS
      send the frame every PERIOD seconds for SECONDS (or until SIGTERM),
      reading what comes back and reconnecting when closed; print "sent N
      replies N reconnects N"
  mbraw.py HOST PORT trickler INTERVAL SECONDS
      a slow client: a read request a byte every INTERVAL seconds, over and
      over for SECONDS, reconnecting when closed; print "bytes N closed N"
  mbraw.py HOST PORT stale N HEX
      N clients each send the frame and close at once, as clients that time
      out do; print "stale N"
  mbraw.py HOST PORT hold N SECONDS
      N clients connect and stay silent for SECONDS; print "open N of N"
      (still connected at the end)
  mbraw.py HOST PORT idle SECONDS
      connect and wait silently; print "closed after S s" when the server
      drops the connection, or "open after S s"
  mbraw.py rtu DEVICE BAUD send HEX [WAIT]
      Modbus RTU on a serial line (a pty): send the frame HEX with its CRC
      appended (computed here; frames separated by | each get theirs, sent
      in one write), the first with a wrong CRC for "sendbad", or in
      two pieces 20 ms apart for "split" (as a loaded host or a USB adapter
      may deliver it); print
      what comes back (hex, "(bad CRC)" after a reply whose CRC is wrong)
      up to a 50 ms silence, or "silent" when nothing came within WAIT
      seconds (default 0.5)
"""
import signal
import socket
import sys
import time


class Stop(Exception):
    pass


def on_term(signum, frame):
    raise Stop()


def connect(host, port, timeout=2.0):
    s = socket.create_connection((host, port), timeout=timeout)
    s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    return s


def frames_in(buf):
    n, at = 0, 0
    while len(buf) - at >= 7 and len(buf) - at >= 6 + ((buf[at + 4] << 8) | buf[at + 5]):
        at += 6 + ((buf[at + 4] << 8) | buf[at + 5])
        n += 1
    return n


def recv_reply(s, wait, frames=1):
    """Bytes of FRAMES replies: read until as many full MBAP frames, EOF or
    WAIT."""
    s.settimeout(wait)
    buf = b""
    end = time.monotonic() + wait
    while True:
        if frames_in(buf) >= frames:
            return buf, "reply"
        left = end - time.monotonic()
        if left <= 0:
            return buf, "silent"
        s.settimeout(left)
        try:
            chunk = s.recv(4096)
        except socket.timeout:
            return buf, "silent"
        except ConnectionResetError:
            return buf, "closed"
        if not chunk:
            return buf, "closed"
        buf += chunk


def show(buf, how):
    if buf:
        return buf.hex(" ")
    return how


def crc16(data):
    crc = 0xFFFF
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = (crc >> 1) ^ 0xA001 if crc & 1 else crc >> 1
    return bytes([crc & 0xFF, crc >> 8])


def rtu(device, baud, what, args):
    import serial  # pyserial, which pymodbus's serial client needs too
    frame = b""
    for i, part in enumerate(args[0].split("|")):
        f = bytes.fromhex(part.replace(" ", ""))
        frame += f + (bytes(b ^ 0xFF for b in crc16(f)) if what == "sendbad" and i == 0 else crc16(f))
    wait = float(args[1]) if len(args) > 1 else 0.5
    line = serial.Serial(device, baud, timeout=0)
    line.reset_input_buffer()
    if what == "split":
        line.write(frame[:3])
        line.flush()
        time.sleep(0.02)
        frame = frame[3:]
    line.write(frame)
    line.flush()
    buf, end, last = b"", time.monotonic() + wait, None
    while time.monotonic() < end and (last is None or time.monotonic() - last < 0.05):
        chunk = line.read(256)
        if chunk:
            buf += chunk
            last = time.monotonic()
        else:
            time.sleep(0.005)
    line.close()
    if not buf:
        print("silent")
    else:
        print(buf.hex(" ") + ("" if len(buf) >= 4 and crc16(buf[:-2]) == buf[-2:] else " (bad CRC)"))
    return 0


def main():
    if sys.argv[1] == "rtu":
        return rtu(sys.argv[2], int(sys.argv[3]), sys.argv[4], sys.argv[5:])
    host, port, what = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    args = sys.argv[4:]
    if what in ("send", "sendclose"):
        frame = bytes.fromhex(args[0].replace(" ", ""))
        wait = float(args[1]) if len(args) > 1 else 2.0
        frames = int(args[2]) if len(args) > 2 else 1
        s = connect(host, port)
        s.sendall(frame)
        if what == "sendclose":
            s.shutdown(socket.SHUT_WR)
        buf, how = recv_reply(s, wait, frames)
        print(show(buf, how))
    elif what == "trickle":
        frame = bytes.fromhex(args[0].replace(" ", ""))
        interval = float(args[1])
        s = connect(host, port)
        sent = 0
        for b in frame:
            try:
                s.sendall(bytes([b]))
            except (BrokenPipeError, ConnectionResetError):
                print(f"closed after {sent} bytes")
                return 0
            sent += 1
            buf, how = recv_reply(s, interval)
            if buf:
                print(f"reply {buf.hex(' ')} after {sent} bytes")
                return 0
            if how == "closed":
                print(f"closed after {sent} bytes")
                return 0
        buf, how = recv_reply(s, 2.0)
        print(f"reply {buf.hex(' ')} after {sent} bytes" if buf else f"{how} after {sent} bytes")
    elif what == "hammer":
        frame = bytes.fromhex(args[0].replace(" ", ""))
        period, seconds = float(args[1]), float(args[2])
        end = time.monotonic() + seconds
        sent = replies = reconnects = 0
        s = connect(host, port)
        signal.signal(signal.SIGTERM, on_term)
        try:
            while time.monotonic() < end:
                t0 = time.monotonic()
                try:
                    s.sendall(frame)
                    sent += 1
                    buf, how = recv_reply(s, period)
                except OSError:
                    buf, how = b"", "closed"
                if buf:
                    replies += 1
                if how == "closed":
                    s.close()
                    s = connect(host, port)
                    reconnects += 1
                rest = period - (time.monotonic() - t0)
                if rest > 0:
                    time.sleep(rest)
        except Stop:
            pass
        print(f"sent {sent} replies {replies} reconnects {reconnects}")
    elif what == "trickler":
        interval, seconds = float(args[0]), float(args[1])
        frame = bytes.fromhex("000100000006010400000001")
        end = time.monotonic() + seconds
        nbytes = closed = 0
        s = connect(host, port)
        i = 0
        signal.signal(signal.SIGTERM, on_term)
        try:
            while time.monotonic() < end:
                try:
                    s.sendall(frame[i:i + 1])
                    nbytes += 1
                    i = (i + 1) % len(frame)
                    s.settimeout(interval)
                    if s.recv(4096) == b"":
                        raise ConnectionResetError
                except socket.timeout:
                    pass
                except OSError:
                    closed += 1
                    s.close()
                    s = connect(host, port)
                    i = 0
        except Stop:
            pass
        print(f"bytes {nbytes} closed {closed}")
    elif what == "stale":
        n, frame = int(args[0]), bytes.fromhex(args[1].replace(" ", ""))
        for _ in range(n):
            s = connect(host, port)
            s.sendall(frame)
            s.close()
        print(f"stale {n}")
    elif what == "hold":
        n, seconds = int(args[0]), float(args[1])
        socks = [connect(host, port) for _ in range(n)]
        time.sleep(seconds)
        still = 0
        for s in socks:
            s.setblocking(False)
            try:
                still += s.recv(1) != b""
            except BlockingIOError:
                still += 1
            except OSError:
                pass
        print(f"open {still} of {n}")
    elif what == "idle":
        seconds = float(args[0])
        s = connect(host, port)
        t0 = time.monotonic()
        buf, how = recv_reply(s, seconds)
        t = time.monotonic() - t0
        print(f"closed after {t:.1f} s" if how == "closed" else f"open after {t:.1f} s")
    else:
        print(__doc__)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
