#!/bin/sh
# SPDX-License-Identifier: ISC
# A second, independent check of psensd's BACnet encoding: Wireshark's
# dissector (tshark, Debian's package) reads a capture of the outside
# peer's session (tests/peers/bacnet-peer.js: discovery, Object_List, every
# object's properties, a write at priority 8, COV) plus a Lighting_Command
# write and reads of the point model's Binary and Multi-state Inputs, sent
# from Python, and must find no malformed packet and no error in its
# expert info, and decode the object identifiers and values sent: the
# device's instance, the Lighting Output, a Binary and a Multi-state Input,
# the REAL 42.5 written and read back, the Lighting_Command's fade-to.
# Capturing on the loopback needs root (or dumpcap's capabilities): the
# test is skipped without tshark or without the right to capture.
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
printf '\n[bacnet]\nbind = 127.0.0.1\nport = %s\ninstance = 2643\nwrites = lighting-output\nrate = 100000\n' "$port" >> "$TMP/psensd.conf"
tshark -i lo -f "udp port $port" -w "$TMP/cap.pcapng" > "$TMP/tshark.out" 2>&1 &
TS=$!; track_pid $TS
wait_for 10 grep -q "Capturing on" "$TMP/tshark.out" || skip_all "tshark cannot capture on lo: $(head -n 1 "$TMP/tshark.out")"
"$BIN/psensd" -f "$TMP/psensd.conf" -t 08:00 -x 600 > "$TMP/out" 2> "$TMP/err" &
PID=$!; track_pid $PID
wait_for 10 "$BIN/psensctl" -s "$S" ping > /dev/null
PEER_PORT=$(free_udp_port) node "$TOP/tests/peers/bacnet-peer.js" "$port" 2643 1 > "$TMP/peer" 2>&1
check "the peer's session passes ($(grep -c '^ok' "$TMP/peer") ok)" test "$(grep -c '^not ok' "$TMP/peer")" = 0
# a Lighting_Command fade-to 30.0 at priority 9 on (lighting-output, 1);
# ReadProperty Present_Value of (binary-input, 1) and (multi-state-input, 1)
/usr/bin/python3 - "$port" <<'EOP'
import socket, struct, sys
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
s.settimeout(2)
def ask(apdu):
    msg = bytes([0x81, 0x0a]) + struct.pack('>H', 6 + len(apdu)) + bytes([0x01, 0x04]) + apdu
    s.sendto(msg, ('127.0.0.1', int(sys.argv[1])))
    s.recvfrom(2000)
lo1 = bytes([0x0c, 0x0d, 0x80, 0x00, 0x01])
ask(bytes([0x00, 0x05, 0x31, 0x0f]) + lo1 + bytes([0x1a, 0x01, 0x7c, 0x3e, 0x09, 0x01, 0x1c]) +
    struct.pack('>f', 30.0) + bytes([0x59, 0x09, 0x3f]))
ask(bytes([0x00, 0x05, 0x32, 0x0c, 0x0c, 0x00, 0xc0, 0x00, 0x01, 0x19, 0x55]))
ask(bytes([0x00, 0x05, 0x33, 0x0c, 0x0c, 0x03, 0x40, 0x00, 0x01, 0x19, 0x55]))
ask(bytes([0x00, 0x05, 0x34, 0x0c]) + lo1 + bytes([0x1a, 0x01, 0x7c]))
EOP
sleep 1
kill "$PID"; wait "$PID" 2> /dev/null
kill "$TS"; wait "$TS" 2> /dev/null
tshark -r "$TMP/cap.pcapng" -d "udp.port==$port,bvlc" -V > "$TMP/v.txt" 2> "$TMP/v.err"
tshark -r "$TMP/cap.pcapng" -d "udp.port==$port,bvlc" > "$TMP/summary.txt" 2>&1
n=$(wc -l < "$TMP/summary.txt")
check "the capture holds the session ($n packets)" test "$n" -gt 100
check "no malformed packet ($(grep -c -i 'malformed' "$TMP/v.txt"))" sh -c "! grep -qi 'malformed' '$TMP/v.txt'"
check "no error in the dissector's expert info" sh -c "! grep -q 'Severity level: Error' '$TMP/v.txt'"
grep -i -m 3 -B2 -A2 'malformed\|Severity level: Error' "$TMP/v.txt" | while read -r l; do diag "$l"; done
check "BACnet APDUs decoded ($(grep -c 'Building Automation and Control Network APDU' "$TMP/v.txt"))" \
	test "$(grep -c 'Building Automation and Control Network APDU' "$TMP/v.txt")" -gt 100
# the dissector's own wording (Wireshark's packet-bacapp.c)
has() { grep -q -- "$1" "$TMP/v.txt"; }
check "the device's identifier (device, 2643)" has 'ObjectIdentifier: device, 2643$'
check "the Lighting Output (lighting-output, 1)" has 'ObjectIdentifier: lighting-output, 1$'
check "a Binary Input (binary-input, 1)" has 'ObjectIdentifier: binary-input, 1$'
check "a Multi-state Input (multi-state-input, 1)" has 'ObjectIdentifier: multi-state-input, 1$'
check "the REAL 42.5 written and read back ($(grep -c 'Present Value (real): 42.5$' "$TMP/v.txt"))" \
	test "$(grep -c 'Present Value (real): 42.5$' "$TMP/v.txt")" -ge 2
check "Priority_Array[8] 42.5" has 'priority-array\[8\]: 42.500000 (Real)$'
check "the Lighting_Command: fade-to" has 'operation: *fade-to (1)$'
check "its target level 30.0" has 'target-level: 30.000000 (Real)$'
done_testing
