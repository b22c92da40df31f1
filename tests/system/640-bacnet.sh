#!/bin/sh
# SPDX-License-Identifier: ISC
# psensd's BACnet/IP server (psensd.conf(5) [bacnet]) against an outside BACnet
# stack: @bacnet-js/client (tests/peers/package.json) on loopback, psensd
# in real time sped up 600 times on the loopback room.  Discovery with and
# without a range, the Device's Object_List, every object's properties by
# ReadPropertyMultiple, Who-Has by name and identifier, a Lighting
# Output's Present_Value, a write at priority 8 and its relinquish (the
# engine's override and release, seen in psensd's log), COV subscriptions
# and the notification a write causes, the
# errors for an unknown object and property;
# then with writes off, the refusal; then a zone in a sensor fault: a BMS
# write at priority 1 is taken but the light stays at the safe level; a
# flood from one source is cut to its rate; a [bacnet] section without
# bind is refused with its line.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v node > /dev/null || skip_all "node is not installed (make deps: nodejs)"
[ -d "$TOP/tests/peers/node_modules/@bacnet-js/client" ] ||
	skip_all "the BACnet peer is not installed (make deps-peers, which make check runs: npm ci in tests/peers)"
PEER="$TOP/tests/peers/bacnet-peer.js"
example_results
S="$TMP/sock"
ctl() { "$BIN/psensctl" -s "$S" "$@"; }

# run WRITES: psensd with [bacnet] on a free port, the peer against it
# (WRITES 2: writes on, the sensor open from 08:01 to 11:00)
run() {
	port=$(free_udp_port)
	f="/^faults = /d"; [ "$1" = 2 ] && f="s|^faults = .*|faults = open 08:01-11:00|"
	sed "s|^results = .*|results = state/ofb.results|; s|^database = .*|database = state/psensd$1.db\nsocket = sock|; $f" \
		config/psensd.conf > "$TMP/psensd.conf"
	w=none; [ "$1" != 0 ] && w=lighting-output
	printf '\n[bacnet]\nbind = 127.0.0.1\nport = %s\ninstance = 2601\nname = psensd test site\nwrites = %s\nrate = %s\n' \
		"$port" "$w" "${RATE:-100000}" >> "$TMP/psensd.conf"
	"$BIN/psensd" -f "$TMP/psensd.conf" -t 08:00 -x 600 > "$TMP/out$1" 2> "$TMP/err$1" &
	PID=$!; track_pid $PID
	wait_for 10 ctl ping > /dev/null
	check "psensd logs its BACnet device (writes=$w)" grep -q "bacnet: device 2601 'psensd test site' on udp 127.0.0.1:$port" "$TMP/err$1"
	[ -z "${FLOOD:-}" ] || return 0
	PEER_PORT=$(free_udp_port) node "$PEER" "$port" 2601 "$1" > "$TMP/peer$1" 2>&1
	rc=$?
	sed -n 's/^\(not \)\{0,1\}ok [0-9]* - /peer: /p' "$TMP/peer$1" | while read -r l; do diag "$l"; done
	grep -E '^# (rp|cov)_ms' "$TMP/peer$1"
	check "the peer's checks all pass (writes=$w; $(grep -c '^ok' "$TMP/peer$1") ok, $(grep -c '^not ok' "$TMP/peer$1") not ok)" \
		test "$rc" = 0 -a "$(grep -c '^not ok' "$TMP/peer$1")" = 0 -a "$(grep -c '^ok' "$TMP/peer$1")" -ge 5
	grep '^not ok' "$TMP/peer$1" | while read -r l; do diag "$l"; done
	check "psensd still answers the control socket" sh -c "\"$BIN/psensctl\" -s \"$S\" ping > /dev/null"
	kill "$PID"; wait "$PID" 2> /dev/null
}
run 1
check "the write became the engine's override at 42.5 %" grep -q "zone office: override 42 % for 3600 s" "$TMP/err1"
check "the relinquish became its release" grep -q "zone office: override released" "$TMP/err1"
check "the BACnet room said who set what" grep -q "bacnet: zone office: level 42.5 % at priority 8" "$TMP/err1"
run 0
check "writes off: no override reached the engine" sh -c "! grep -q 'override' '$TMP/err0'"
run 2
check "the fault was the engine's: the zone went to its safe level" grep -q "zone office: .*lights at the safe level" "$TMP/err2"

# a flood from one source at rate = 100: at most 100 at once and 100 a
# second are answered, the rest dropped (logged once); control goes on
FLOOD=1 RATE=100 run 3
/usr/bin/python3 - "$port" > "$TMP/flood" <<'EOP'
import socket, sys, time
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
s.bind(("127.0.0.1", 0))
who_is = bytes([0x81, 0x0a, 0x00, 0x08, 0x01, 0x00, 0x10, 0x08])
t0 = time.monotonic()
for i in range(2000):
    s.sendto(who_is, ("127.0.0.1", int(sys.argv[1])))
t1 = time.monotonic()
s.settimeout(0.5)
n = 0
try:
    while True:
        s.recvfrom(2000)
        n += 1
except socket.timeout:
    pass
print(n, round(time.monotonic() - t0, 3))
EOP
read -r got secs < "$TMP/flood"
bound=$(awk -v s="$secs" 'BEGIN { printf "%d", 100 + 100 * s + 1 }')
check "2000 Who-Is from one source: $got I-Am in $secs s, at most 100 + 100/s ($bound)" \
	test "$got" -ge 100 -a "$got" -le "$bound"
check "the excess is logged once" test "$(grep -c 'bacnet: a source sends more than 100 datagrams a second' "$TMP/err3")" = 1
check "psensd still answers the control socket after the flood" sh -c "\"$BIN/psensctl\" -s \"$S\" ping > /dev/null"
kill "$PID"; wait "$PID" 2> /dev/null

# the port taken by another socket: psensd refuses to start, saying which
/usr/bin/python3 -c 'import socket, sys, time
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
s.bind(("127.0.0.1", int(sys.argv[1])))
time.sleep(15)' "$port" & track_pid $!
sleep 0.5
timeout 20 "$BIN/psensd" -f "$TMP/psensd.conf" -t 08:00 -x 600 > /dev/null 2> "$TMP/busy.err"
rc=$?
check "a BACnet port in use: psensd stops at start (exit $rc) naming it" \
	sh -c "[ $rc -ne 0 ] && [ $rc -ne 124 ] && grep -q 'bacnet: udp 127.0.0.1:$port: Address already in use' '$TMP/busy.err'"

sed '/^bind = /d' "$TMP/psensd.conf" > "$TMP/bad.conf"
"$BIN/psensd" -n -f "$TMP/bad.conf" > "$TMP/bad.out" 2>&1
check "a [bacnet] without bind is refused with its line" grep -q "bad.conf:[0-9]*: \[bacnet\] needs 'bind'" "$TMP/bad.out"
done_testing
