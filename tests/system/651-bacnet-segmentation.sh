#!/bin/sh
# SPDX-License-Identifier: ISC
# Segmented answers from psensd's BACnet/IP server (doc/bacnet-pics.md,
# ASHRAE 135 clause 5.4.5) at the size psensd is built for: 100 zones on
# the file driver (1101 objects, an Object_List of some 5 kB).  The outside
# peer, @bacnet-js/client (tests/peers/bacnet-seg-peer.js), reads the whole
# Object_List in one ReadProperty at max-APDU 1476 and 480 (it acks the
# segments itself) and must get the list it reads an element at a time;
# RPM ALL on the Device and on 60 objects at once; the segmentation
# properties; Abort buffer-overflow
# for a client taking 2 segments.  Then a client written here at the
# BVLL/APDU level: SA clear gets Abort segmentation-not-supported, a
# segmented request too; a window of 3 acked, then the ack withheld: the
# same window again after APDU_Segment_Timeout (2 s); a negative ack resends
# from the segment after the one it names; an ack from another port moves
# nothing; the list reassembled holds all 1101 identifiers; and the
# control loop kept its schedule throughout.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v node > /dev/null || skip_all "node is not installed (make deps: nodejs)"
[ -d "$TOP/tests/peers/node_modules/@bacnet-js/client" ] ||
	skip_all "the BACnet peer is not installed (make deps-peers, which make check runs: npm ci in tests/peers)"
example_results
S="$TMP/sock"
port=$(free_udp_port)
{
	file_zones 100
	printf '[bacnet]\nbind = 127.0.0.1\nport = %s\ninstance = 651\nrate = 100000\n' "$port"
} > "$TMP/many.conf"
"$BIN/psensd" -f "$TMP/many.conf" -t 08:00 -x 10 > "$TMP/out" 2> "$TMP/err" &
PID=$!; track_pid $PID
wait_for 10 "$BIN/psensctl" -s "$S" ping > /dev/null
PEER_PORT=$(free_udp_port) node "$TOP/tests/peers/bacnet-seg-peer.js" "$port" 651 1000 > "$TMP/peer" 2>&1
check "the peer's session passes ($(grep -c '^ok' "$TMP/peer") ok)" \
	sh -c "grep -q '^ok' '$TMP/peer' && ! grep -q '^not ok' '$TMP/peer'"
grep '^not ok\|^#' "$TMP/peer" > "$TMP/peer.diag"
while read -r l; do diag "${l#\# }"; done < "$TMP/peer.diag"

/usr/bin/python3 - "$port" > "$TMP/raw" 2>&1 <<'EOP'
import socket, struct, sys, time
port = int(sys.argv[1])
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
s.bind(('127.0.0.1', 0))
spoof = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
spoof.bind(('127.0.0.1', 0))
srv = ('127.0.0.1', port)
def send(apdu, sock=s):
    sock.sendto(bytes([0x81, 0x0a]) + struct.pack('>H', 6 + len(apdu)) + bytes([1, 4]) + apdu, srv)
def recv(timeout):
    s.settimeout(timeout)
    try:
        d, _ = s.recvfrom(2000)
    except socket.timeout:
        return None
    assert d[0] == 0x81 and d[1] == 0x0a and struct.unpack('>H', d[2:4])[0] == len(d), d
    return d[6:]
def drain(timeout=0.3):
    got = []
    while True:
        a = recv(timeout)
        if a is None:
            return got
        got.append(a)
def ack(inv, seq, win, nak=False, sock=s):
    send(bytes([0x42 if nak else 0x40, inv, seq, win]), sock)
def check(cond, what):
    print(('ok - ' if cond else 'not ok - ') + what)
dev = bytes([0x0c, 0x02, 0x00, 0x02, 0x8b])          # (device, 651)
rp_list = dev + bytes([0x19, 0x4c])                   # Object_List
# SA clear, max APDU 1476: Abort (server) segmentation-not-supported
send(bytes([0x00, 0x05, 0x11, 0x0c]) + rp_list)
a = recv(2)
check(a == bytes([0x71, 0x11, 0x04]), 'SA clear: Abort segmentation-not-supported (%s)' % (a.hex() if a else None))
# a segmented request (SEG set): Abort segmentation-not-supported
send(bytes([0x0e, 0x05, 0x12, 0x00, 0x01, 0x0c]) + rp_list)
a = recv(2)
check(a == bytes([0x71, 0x12, 0x04]), 'a segmented request: Abort segmentation-not-supported (%s)' % (a.hex() if a else None))
# SA set, max APDU 206 (code 2): segments of 201 octets
send(bytes([0x02, 0x02, 0x13, 0x0c]) + rp_list)
segs = {}
first = drain()
check(len(first) == 1 and first[0][0] == 0x3c and first[0][2] == 0 and first[0][4] == 0x0c,
      'the first segment alone, more follows (%d datagram(s))' % len(first))
proposed = first[0][3] if first else 0
check(1 <= proposed <= 127, 'a proposed window size of %d' % proposed)
for a in first:
    segs[a[2]] = a
# an ack from another port: nothing
ack(0x13, 0, 3, sock=spoof)
check(drain() == [], 'a SegmentACK from another port: nothing sent')
ack(0x13, 0, 3)
w = drain()
check([a[2] for a in w] == [1, 2, 3], 'ack 0 window 3: segments 1-3 (%s)' % [a[2] for a in w])
for a in w:
    segs[a[2]] = a
# the ack withheld: the window again after APDU_Segment_Timeout
t0 = time.monotonic()
a = recv(3.5)
dt = time.monotonic() - t0
again = ([a] if a else []) + drain(0.3)
check([a[2] for a in again] == [1, 2, 3] and 1.5 < dt,
      'no ack: segments 1-3 again after the segment timeout (%s, waited %.1f s)' % ([a[2] for a in again], dt))
print('# resend after %.2f s' % dt)
# a negative ack naming 1: from 2 onwards, window 3
ack(0x13, 1, 3, nak=True)
w = drain()
check([a[2] for a in w] == [2, 3, 4], 'negative ack 1: segments 2-4 (%s)' % [a[2] for a in w])
for a in w:
    segs[a[2]] = a
last, more = 4, True
while more:
    ack(0x13, last, 16)
    w = drain()
    if not w:
        break
    for a in w:
        segs[a[2]] = a
        last = a[2]
        more = bool(a[0] & 0x04)
ack(0x13, last, 16)
n = len(segs)
check(not more and sorted(segs) == list(range(n)), '%d segments, the last without more-follows' % n)
check(all(len(segs[k]) <= 206 for k in segs), 'every segment within max APDU 206')
body = b''.join(segs[k][5:] for k in range(n))
check(drain() == [], 'the final ack ends it: nothing more')
# the whole: [0] device, [1] 76, [3] identifiers [3]
p = 0
assert body[p:p + 5] == bytes([0x0c, 0x02, 0x00, 0x02, 0x8b]); p += 5
assert body[p:p + 2] == bytes([0x19, 0x4c]); p += 2
assert body[p] == 0x3e; p += 1
ids = []
while body[p] == 0xc4:
    ids.append(struct.unpack('>I', body[p + 1:p + 5])[0]); p += 5
check(body[p:] == bytes([0x3f]), 'the reassembled answer ends with its closing tag')
print('# ids %d' % len(ids))
print('ids ' + ' '.join('%d:%d' % (i >> 22, i & 0x3fffff) for i in ids))
EOP
grep -v '^ids ' "$TMP/raw" > "$TMP/raw.tap"
while read -r l; do
	case "$l" in
	ok*) ok "${l#ok - }" ;;
	"not ok"*) not_ok "${l#not ok - }" ;;
	*) diag "${l#\# }" ;;
	esac
done < "$TMP/raw.tap"
n=$(sed -n 's/^# ids //p' "$TMP/raw")
diag "the last identifiers: $(sed -n "s/^ids //p" "$TMP/raw" | tr " " "\n" | tail -12 | tr "\n" " ")"
# a Device and, per zone, 11 objects: the Lighting Output, seven Inputs and
# three Values (doc/bacnet-pics.md)
check "the reassembled Object_List holds 1 + 100 x 11 identifiers (${n:-none})" test "${n:-0}" = 1101
late=$("$BIN/psensctl" -s "$S" -j status z0 | /usr/bin/python3 -c 'import json, sys; print(json.load(sys.stdin)["late_max_s"])')
check "the control loop on schedule meanwhile (late at most $late s of a 60 s period)" \
	awk -v x="$late" 'BEGIN { exit !(x + 0 < 60) }'
check "psensd still answers" "$BIN/psensctl" -s "$S" ping
kill $PID; wait $PID 2> /dev/null
done_testing
