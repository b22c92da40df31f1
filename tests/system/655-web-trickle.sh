#!/bin/sh
# SPDX-License-Identifier: ISC
# Connections that trickle a request a byte a second (psensd.conf(5)
# [web]): 64 of them, 16 from each of four loopback addresses (as many as
# the console takes at once), do not lock out a new client, and none of
# them is kept past the bound on a request's total time however often its
# bytes come (a python3 client holds the sockets).
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
"$BIN/psensd" -h 2>&1 | grep -q "web:.*not compiled in" && skip_all "psensd is built without the web console"
command -v python3 > /dev/null || skip_all "python3 is not installed"
command -v curl > /dev/null || skip_all "curl is not installed"
B=$(cd "$BIN" && pwd)
PORT=$(free_port)
example_results
printf 'lux meter 42\n' | "$BIN/psensctl" web-passwd "$TMP/web.pass" > /dev/null
{ psensd_section 1; loopback_office; cat <<EOC
[web]
bind = 127.0.0.1:$PORT
password_file = web.pass
EOC
} > "$TMP/psensd.conf"
cd "$TMP" || exit 1
"$B/psensd" -f psensd.conf > psensd.log 2>&1 &
track_pid $!
wait_for 20 curl -s -o /dev/null "http://127.0.0.1:$PORT/" || { cat psensd.log; skip_all "psensd's console did not answer"; }
# trickle.py PORT SECONDS: 64 connections, each a request line then one
# header byte a second; after 3 s it writes "ready" to the file ready, and
# at the end how many of them the server closed
cat > trickle.py <<'EOP'
import socket, sys, time
port, secs = int(sys.argv[1]), float(sys.argv[2])
conns = []
for a in range(2, 6):
    for _ in range(16):
        s = socket.socket()
        s.bind(("127.0.0.%d" % a, 0))
        s.connect(("127.0.0.1", port))
        s.sendall(b"GET /api/session HTTP/1.1\r\nX-Slow: ")
        s.setblocking(False)
        conns.append(s)
closed = set()
t0 = time.monotonic()
told = False
while time.monotonic() - t0 < secs and len(closed) < len(conns):
    for i, s in enumerate(conns):
        if i in closed:
            continue
        try:
            if s.recv(4096) == b"":
                closed.add(i)
                continue
        except BlockingIOError:
            pass
        except OSError:
            closed.add(i)
            continue
        try:
            s.send(b"x")
        except OSError:
            closed.add(i)
    if not told and time.monotonic() - t0 >= 3:
        open("ready", "w").write("ready\n")
        told = True
    time.sleep(1)
open("ready", "a").write("closed %d of %d\n" % (len(closed), len(conns)))
EOP
python3 trickle.py "$PORT" 60 &
TP=$!
track_pid $TP
wait_for 30 grep -q ready ready
code=$(curl -s -o session.out -w '%{http_code}' --max-time 10 "http://127.0.0.1:$PORT/api/session")
check "a new client gets an answer beside 64 trickling connections (HTTP $code)" [ "$code" = 401 ]
check "... the console's own: log in" grep -q "log in" session.out
wait $TP
diag "$(tail -1 ready)"
check "the server ends every trickling connection before 60 s" grep -q "closed 64 of 64" ready
check "psensd says why" grep -q "web: .*request .*not received within" psensd.log
done_testing
