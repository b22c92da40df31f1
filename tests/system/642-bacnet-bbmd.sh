#!/bin/sh
# SPDX-License-Identifier: ISC
# psensd as a BACnet foreign device ([bacnet] bbmd, bbmd_ttl): against a
# tiny BBMD written for the test (tests/peers/bbmd-peer.js, raw UDP in
# Node.js), which checks the Register-Foreign-Device frame octet by octet,
# refuses the first (BVLC-Result NAK 0x0030: psensd logs it and tries
# again after a backoff), takes the next, expects the I-Am as a
# Distribute-Broadcast-To-Network and the renewal at half the TTL (10 s),
# and forwards a Who-Is whose I-Am must come back through it.  Then a
# BBMD that never answers: logged, tried again, control goes on; a bad
# bbmd key is refused with its line.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v node > /dev/null || skip_all "node is not installed (make deps: nodejs)"
example_results
S="$TMP/sock"
conf() {   # conf BBMD: psensd with [bacnet] on a free port, a foreign device of BBMD
	port=$(free_udp_port)
	sed "s|^results = .*|results = state/ofb.results|; s|^database = .*|database = state/psensd.db\nsocket = sock|; /^faults = /d" \
		config/psensd.conf > "$TMP/psensd.conf"
	printf '\n[bacnet]\nbind = 127.0.0.1\nport = %s\ninstance = 2642\nbbmd = %s\nbbmd_ttl = 10\n' "$port" "$1" >> "$TMP/psensd.conf"
}

bport=$(free_udp_port)
node "$TOP/tests/peers/bbmd-peer.js" "$bport" 2642 10 > "$TMP/peer" 2>&1 &
PEER=$!; track_pid $PEER
sleep 0.3
conf "127.0.0.1:$bport"
"$BIN/psensd" -f "$TMP/psensd.conf" -t 08:00 > "$TMP/out" 2> "$TMP/err" &
PID=$!; track_pid $PID
wait $PEER
rc=$?
sed -n 's/^\(not \)\{0,1\}ok [0-9]* - /peer: /p' "$TMP/peer" | while read -r l; do diag "$l"; done
check "the BBMD's checks all pass ($(grep -c '^ok' "$TMP/peer") ok, $(grep -c '^not ok' "$TMP/peer") not ok)" \
	test "$rc" = 0 -a "$(grep -c '^not ok' "$TMP/peer")" = 0 -a "$(grep -c '^ok' "$TMP/peer")" -ge 7
check "psensd logged the NAK" grep -q "bacnet: BBMD 127.0.0.1:$bport: Register-Foreign-Device refused (BVLC-Result 0x0030)" "$TMP/err"
check "and the registration" grep -q "bacnet: registered as a foreign device with BBMD 127.0.0.1:$bport for 10 s" "$TMP/err"
check "psensd still answers the control socket" sh -c "\"$BIN/psensctl\" -s \"$S\" ping > /dev/null"
kill "$PID"; wait "$PID" 2> /dev/null

# a BBMD that never answers (nothing listens on its port)
conf "127.0.0.1:$(free_udp_port)"
"$BIN/psensd" -f "$TMP/psensd.conf" -t 08:00 > "$TMP/out2" 2> "$TMP/err2" &
PID=$!; track_pid $PID
wait_for 10 "$BIN/psensctl" -s "$S" ping > /dev/null
sleep 6
check "no answer: logged ($(grep -c 'no answer to Register-Foreign-Device' "$TMP/err2") line(s) for the tries in 6 s)" \
	test "$(grep -c 'no answer to Register-Foreign-Device' "$TMP/err2")" = 1
check "and psensd still controls and answers" sh -c "\"$BIN/psensctl\" -s \"$S\" ping > /dev/null"
kill "$PID"; wait "$PID" 2> /dev/null

sed 's/^bbmd = .*/bbmd = 10.0.0.300:47808/' "$TMP/psensd.conf" > "$TMP/bad.conf"
"$BIN/psensd" -n -f "$TMP/bad.conf" > "$TMP/bad.out" 2>&1
check "a bbmd that is not IPv4[:PORT] is refused with its line" grep -q "bad.conf:[0-9]*: bbmd: '10.0.0.300' is not an IPv4 address" "$TMP/bad.out"
done_testing
