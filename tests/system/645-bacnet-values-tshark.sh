#!/bin/sh
# SPDX-License-Identifier: ISC
# A second, independent check of the encoding of psensd's writable BACnet
# Values: Wireshark's dissector (tshark, Debian's package) reads a capture
# of the values peer's session (tests/peers/bacnet-values-peer.js, mode 1:
# the target lux and daylight control read, written at priorities,
# relinquished, refused) and must find no malformed packet and no error in
# its expert info, and decode what was sent: the Analog and Binary Value
# identifiers, the REALs written and read back in Present_Value and
# Priority_Array, Relinquish_Default, the NULL relinquish, the
# BACnetBinaryPV written, the Errors value-out-of-range and
# write-access-denied.  Capturing on the loopback needs root (or dumpcap's
# capabilities): the test is skipped without tshark or without the right
# to capture.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v tshark > /dev/null || skip_all "tshark is not installed (make deps: tshark)"
command -v node > /dev/null || skip_all "node is not installed (make deps: nodejs)"
[ -d "$TOP/tests/peers/node_modules/@bacnet-js/client" ] ||
	skip_all "the BACnet peer is not installed (make deps-peers, which make check runs: npm ci in tests/peers)"
[ "$(id -u)" = 0 ] || skip_all "capturing on lo needs root"
example_results
S="$TMP/sock"
port=$(free_udp_port)
sed "s|^results = .*|results = state/ofb.results|; s|^database = .*|database = state/psensd.db\nsocket = sock|; /^faults = /d" \
	config/psensd.conf > "$TMP/psensd.conf"
printf '\n[bacnet]\nbind = 127.0.0.1\nport = %s\ninstance = 2645\nwrites = lighting-output target daylighting\nrate = 100000\ntarget_min = 50\ntarget_max = 1500\n' \
	"$port" >> "$TMP/psensd.conf"
tshark -i lo -f "udp port $port" -w "$TMP/cap.pcapng" > "$TMP/tshark.out" 2>&1 &
TS=$!; track_pid $TS
wait_for 10 grep -q "Capturing on" "$TMP/tshark.out" || skip_all "tshark cannot capture on lo: $(head -n 1 "$TMP/tshark.out")"
"$BIN/psensd" -f "$TMP/psensd.conf" -t 08:00 -x 600 > "$TMP/out" 2> "$TMP/err" &
PID=$!; track_pid $PID
wait_for 10 "$BIN/psensctl" -s "$S" ping > /dev/null
elux=$("$BIN/psensctl" -s "$S" -j status | /usr/bin/python3 -c 'import json, sys
print([z for z in json.load(sys.stdin)["zones"] if z["name"] == "office"][0]["electric_task_lux"])')
PEER_PORT=$(free_udp_port) node "$TOP/tests/peers/bacnet-values-peer.js" "$port" 2645 1 "$elux" > "$TMP/peer" 2>&1
check "the peer's session passes ($(grep -c '^ok' "$TMP/peer") ok)" \
	test "$(grep -c '^not ok' "$TMP/peer")" = 0 -a "$(grep -c '^ok' "$TMP/peer")" -ge 10
sleep 1
kill "$PID"; wait "$PID" 2> /dev/null
kill "$TS"; wait "$TS" 2> /dev/null
tshark -r "$TMP/cap.pcapng" -d "udp.port==$port,bvlc" -V > "$TMP/v.txt" 2> "$TMP/v.err"
n=$(grep -c 'Building Automation and Control Network APDU' "$TMP/v.txt")
check "BACnet APDUs decoded ($n)" test "$n" -gt 50
check "no malformed packet ($(grep -c -i 'malformed' "$TMP/v.txt"))" sh -c "! grep -qi 'malformed' '$TMP/v.txt'"
check "no error in the dissector's expert info" sh -c "! grep -q 'Severity level: Error' '$TMP/v.txt'"
grep -i -m 3 -B2 -A2 'malformed\|Severity level: Error' "$TMP/v.txt" | while read -r l; do diag "$l"; done
# the dissector's own wording (Wireshark's packet-bacapp.c)
has() { grep -q -- "$1" "$TMP/v.txt"; }
check "the target lux (analog-value, 1)" has 'ObjectIdentifier: analog-value, 1$'
check "daylight control (binary-value, 1)" has 'ObjectIdentifier: binary-value, 1$'
check "the REAL 650 written and read back ($(grep -c 'Present Value (real): 650$' "$TMP/v.txt"))" \
	test "$(grep -c 'Present Value (real): 650$' "$TMP/v.txt")" -ge 2
check "Priority_Array[8] 650 and [12] 300 in the whole array" \
	sh -c "grep -q 'priority-array\[8\]: 650.000000 (Real)$' '$TMP/v.txt' && grep -q 'priority-array\[12\]: 300.000000 (Real)$' '$TMP/v.txt'"
check "Relinquish_Default 500" has 'relinquish-default: 500.000000 (Real)$'
check "a relinquish: NULL written" has 'Present Value (null): NULL$'
check "the Binary Value's inactive (0) written and read back ($(grep -c 'Present Value (enum index): 0$' "$TMP/v.txt"))" \
	test "$(grep -c 'Present Value (enum index): 0$' "$TMP/v.txt")" -ge 2
check "the Error value-out-of-range" has 'Error Code: value-out-of-range (37)$'
check "the Error write-access-denied" has 'Error Code: write-access-denied (40)$'
done_testing
