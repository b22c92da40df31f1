#!/bin/sh
# SPDX-License-Identifier: ISC
# psensd's segmented answers read by an independent decoder: Wireshark's
# BACnet dissector (tshark, Debian's package) on a capture of the outside
# peer (tests/peers/bacnet-seg-peer.js) reading the whole Object_List of a
# 100-zone psensd (1101 objects) in one ReadProperty at max-APDU 1476 and
# 480, with RPM ALL on the Device and on 60 objects, and a 2-segment
# refusal.  tshark must
# find no malformed packet and no error in its expert info, see segmented
# ComplexACKs and SegmentACKs, reassemble the segments into whole
# messages, and decode in them the first and the last object identifier
# of the list (device, 652) and (binary-value, 9901: the 100th zone's
# last object) at the end of a reassembled list.  Capturing on the loopback needs root (or dumpcap's
# capabilities): the test is skipped without tshark or that right.
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
{
	file_zones 100
	printf '[bacnet]\nbind = 127.0.0.1\nport = %s\ninstance = 652\nrate = 100000\n' "$port"
} > "$TMP/many.conf"
tshark -i lo -f "udp port $port" -w "$TMP/cap.pcapng" > "$TMP/tshark.out" 2>&1 &
TS=$!; track_pid $TS
wait_for 10 grep -q "Capturing on" "$TMP/tshark.out" || skip_all "tshark cannot capture on lo: $(head -n 1 "$TMP/tshark.out")"
"$BIN/psensd" -f "$TMP/many.conf" -t 08:00 -x 10 > "$TMP/out" 2> "$TMP/err" &
PID=$!; track_pid $PID
wait_for 10 "$BIN/psensctl" -s "$S" ping > /dev/null
PEER_PORT=$(free_udp_port) node "$TOP/tests/peers/bacnet-seg-peer.js" "$port" 652 1000 > "$TMP/peer" 2>&1
check "the peer's session passes ($(grep -c '^ok' "$TMP/peer") ok)" \
	sh -c "grep -q '^ok' '$TMP/peer' && ! grep -q '^not ok' '$TMP/peer'"
sleep 1
kill "$PID"; wait "$PID" 2> /dev/null
kill "$TS"; wait "$TS" 2> /dev/null
tshark -r "$TMP/cap.pcapng" -d "udp.port==$port,bvlc" -V > "$TMP/v.txt" 2> "$TMP/v.err"
tshark -r "$TMP/cap.pcapng" -d "udp.port==$port,bvlc" > "$TMP/summary.txt" 2>&1
n=$(wc -l < "$TMP/summary.txt")
check "the capture holds the session ($n packets)" test "$n" -gt 1000
check "no malformed packet ($(grep -c -i 'malformed' "$TMP/v.txt"))" sh -c "! grep -qi 'malformed' '$TMP/v.txt'"
check "no error in the dissector's expert info" sh -c "! grep -q 'Severity level: Error' '$TMP/v.txt'"
grep -i -m 3 -B2 -A2 'malformed\|Severity level: Error' "$TMP/v.txt" > "$TMP/bad.txt"
while read -r l; do diag "$l"; done < "$TMP/bad.txt"
# the dissector names the SEG bit "Segmented Request" in every PDU type
segs=$(grep -c '^ *\.\.\.\. 1\.\.\. = Segmented Request' "$TMP/v.txt")
check "segmented ComplexACKs in the capture ($segs)" test "$segs" -gt 10
sacks=$(grep -c -i 'Segment-ACK\|SegmentACK\|segment-ack' "$TMP/summary.txt")
check "SegmentACKs in the capture ($sacks)" test "$sacks" -gt 5
reas=$(grep -c 'Reassembled BACapp length' "$TMP/v.txt")
check "messages reassembled from their segments ($reas)" test "$reas" -ge 3
has() { grep -q -- "$1" "$TMP/v.txt"; }
check "the device (device, 652) in the list" has 'ObjectIdentifier: device, 652$'
check "the 100th zone's last object (binary-value, 9901) ends a reassembled list" \
	sh -c "grep -B8 'Message fragments' '$TMP/v.txt' | grep -A2 'binary-value' | grep -q 'Instance Number: 9901$'"
check "the Abort buffer-overflow" grep -qi 'abort.*buffer.overflow\|buffer-overflow' "$TMP/v.txt"
done_testing
