#!/bin/sh
# SPDX-License-Identifier: ISC
# psensd's BACnet writes from a hand-built peer (python3 sockets, APDUs
# per ANSI/ASHRAE 135 clause 20): the target lux (analog-value, 1) written
# 350 lx at priority 8 fifty times is taken once (one engine log line, the
# other 49 acknowledged and nothing done); a REAL NaN and +infinity at
# priority 8 are Error property (2) / value-out-of-range (37), never a
# relinquish: the 350 lx stays (doc/bacnet-pics.md).
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
example_results
S="$TMP/sock"
port=$(free_udp_port)
sed "s|^results = .*|results = state/ofb.results|; s|^database = .*|database = state/psensd.db\nsocket = sock|; /^faults = /d" \
	config/psensd.conf > "$TMP/psensd.conf"
printf '\n[bacnet]\nbind = 127.0.0.1\nport = %s\ninstance = 2646\nwrites = target\nrate = 100000\n' "$port" >> "$TMP/psensd.conf"
"$BIN/psensd" -f "$TMP/psensd.conf" -t 08:00 -x 600 > "$TMP/out" 2>> "$TMP/err" &
track_pid $!
wait_for 10 "$BIN/psensctl" -s "$S" ping > /dev/null

# peer REALHEX COUNT: COUNT WriteProperty (analog-value, 1) Present_Value
# REAL REALHEX at priority 8; each reply's APDU in hex, one a line
peer() {
	/usr/bin/python3 - "$port" "$1" "$2" <<'PY'
import socket, sys
port, real, count = int(sys.argv[1]), bytes.fromhex(sys.argv[2]), int(sys.argv[3])
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
s.settimeout(5)
for i in range(count):
    # confirmed request, max APDU 1476, invoke i, writeProperty (15):
    # [0] (analog-value, 1) [1] present-value (85) [3] REAL [3] [4] 8
    apdu = bytes([0x00, 0x05, i & 255, 0x0f, 0x0c, 0x00, 0x80, 0x00, 0x01, 0x19, 0x55, 0x3e, 0x44]) + real + bytes([0x3f, 0x49, 0x08])
    npdu = bytes([0x01, 0x04])
    n = 4 + len(npdu) + len(apdu)
    s.sendto(bytes([0x81, 0x0a, n >> 8, n & 255]) + npdu + apdu, ("127.0.0.1", port))
    print(s.recv(1500)[6:].hex())
PY
}
peer 43af0000 50 > "$TMP/same"
check "fifty writes of 350 lx: fifty SimpleACKs" test "$(grep -c '^20..0f$' "$TMP/same")" = 50
sleep 1
n=$(grep -c 'bacnet: zone office: target_lux 350 at priority 8' "$TMP/err")
check "the engine took 350 lx once, not fifty times (took it $n times)" test "$n" = 1
peer 7fc00000 1 > "$TMP/nan"
check "a REAL NaN: Error property/value-out-of-range" grep -q '^50000f91029125$' "$TMP/nan"
peer 7f800000 1 > "$TMP/inf"
check "a REAL +infinity: Error property/value-out-of-range" grep -q '^50000f91029125$' "$TMP/inf"
sleep 1
check "no relinquish logged" sh -c "! grep -q 'target_lux: every priority relinquished' '$TMP/err'"
check "the target is still 350 lx" test "$("$BIN/psensctl" -s "$S" -j status | /usr/bin/python3 -c 'import json,sys
v = [z for z in json.load(sys.stdin)["zones"] if z.get("name") == "office"][0]["points"]["target_lux"]
print(int(v) if v == int(v) else v)')" = 350
done_testing
