#!/bin/sh
# SPDX-License-Identifier: ISC
# BACnet ReadProperty round trips under load: psensd on the loopback room
# at 600 times real time (a control step every 0.1 s), [bacnet] on
# 127.0.0.1; a UDP client sends ReadProperty (Lighting Output 1,
# Present_Value) at 1000 a second for BACNET_SECONDS (10) and times each
# answer.  The goals: the 99th percentile at most 5 ms, every request
# answered, and the control keeping its schedule (status' late_max_s, in
# clock seconds, under one period).  A Modbus module answering late is
# bench_ctl_latency's case, not reproduced here.
BUILD=${BUILD:-build}
BIN=${BIN:-$BUILD/bin}
TMP=$(mktemp -d)
trap 'kill $PID 2> /dev/null; rm -rf "$TMP"' EXIT
mkdir -p "$TMP/example" "$TMP/state"
cp -R config/example/ofb config/example/ofb.scene "$TMP/example/"
"$BIN/psscene" -q -N -o "$TMP/state/ofb.results" "$TMP/example/ofb.scene" || exit 1
port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(socket.AF_INET, socket.SOCK_DGRAM); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')
sed "s|^results = .*|results = state/ofb.results|; s|^database = .*|database = state/psensd.db\nsocket = sock|; /^faults = /d" \
	config/psensd.conf > "$TMP/psensd.conf"
printf '\n[bacnet]\nbind = 127.0.0.1\nport = %s\ninstance = 7\nrate = 100000\n' "$port" >> "$TMP/psensd.conf"
"$BIN/psensd" -f "$TMP/psensd.conf" -t 08:00 -x 600 > "$TMP/out" 2> "$TMP/err" &
PID=$!
sleep 1
line=$(/usr/bin/python3 - "$port" "${BACNET_SECONDS:-10}" <<'EOP'
import socket, sys, time
port, secs = int(sys.argv[1]), float(sys.argv[2])
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
s.bind(("127.0.0.1", 0))
s.settimeout(0.5)
t, lost, n = [], 0, int(1000 * secs)
start = time.perf_counter()
for i in range(n):
    inv = i % 256
    req = bytes([0x81, 0x0a, 0x00, 0x11, 0x01, 0x04, 0x00, 0x05, inv, 0x0c,
                 0x0c, 0x0d, 0x80, 0x00, 0x01, 0x19, 0x55])
    while time.perf_counter() < start + i / 1000.0:
        pass
    t0 = time.perf_counter()
    s.sendto(req, ("127.0.0.1", port))
    try:
        while True:
            d, _ = s.recvfrom(2000)
            if len(d) > 7 and d[6] == 0x30 and d[7] == inv:
                break
        t.append((time.perf_counter() - t0) * 1e3)
    except socket.timeout:
        lost += 1
t.sort()
if not t:
    print("no answers")
else:
    q = lambda p: t[min(len(t) - 1, int(p * len(t)))]
    print("%d requests at 1000/s: p50 %.3f p99 %.3f max %.3f ms, %d unanswered" % (n, q(0.5), q(0.99), t[-1], lost))
EOP
)
echo "BACnet ReadProperty, loopback room at 600x: $line"
late=$("$BIN/psensctl" -s "$TMP/sock" -j status | /usr/bin/python3 -c 'import json, sys; print(json.load(sys.stdin)["late_max_s"])')
echo "  the control's worst lateness against its schedule meanwhile: $late clock s (period 60 s)"
kill $PID; wait $PID 2> /dev/null
p99=$(echo "$line" | sed -n 's/.*p99 \([0-9.]*\) .*/\1/p')
lost=$(echo "$line" | sed -n 's/.*ms, \([0-9]*\) unanswered/\1/p')
if [ -n "$p99" ] && [ -n "$lost" ] && [ -n "$late" ] &&
	awk -v p="$p99" -v l="$lost" -v x="$late" 'BEGIN { exit !(p + 0 <= 5 && l + 0 == 0 && x + 0 < 60) }'; then
	echo "goal: 99th percentile at most 5 ms, none unanswered, the control on schedule: met ($p99 ms)"
else
	echo "goal: 99th percentile at most 5 ms, none unanswered, the control on schedule: MISSED (${p99:-no measurement} ms, ${lost:-?} unanswered, late ${late:-?} s)"
	exit 1
fi
