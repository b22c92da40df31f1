#!/bin/sh
# SPDX-License-Identifier: ISC
# Load: 100 control-socket clients connected at once, 20 status requests
# each, and a burst of 1000 bad requests, five times over, while psensd controls at 10 Hz in
# real time.  Every good request is answered, every bad one refused, and the
# control keeps its schedule: no step is skipped (the steps taken match the
# time elapsed) and the worst lateness of a step is reported.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
PY=/usr/bin/python3
PEERS="$TOP/tests/system/peers"
example_results
S="$TMP/sock"
sed "s|^results = .*|results = state/ofb.results|; s|^database = .*|database = state/psensd.db\nsocket = sock\nmax_clients = 128|; s|^period = .*|period = 0.1|; /^faults = /d" \
	config/psensd.conf > "$TMP/psensd.conf"
"$BIN/psensd" -f "$TMP/psensd.conf" -t 12:00 > /dev/null 2> "$TMP/err" &
pid=$!; track_pid $pid
wait_for 10 sh -c "\"$BIN/psensctl\" -s \"$S\" ping > /dev/null"
steps() { "$BIN/psensctl" -s "$S" -j status | sed -n 's/.*"steps":\([0-9]*\).*/\1/p'; }
s0=$(steps); t0=$(date +%s.%N)
good=0; bad=0; r=0
while [ $r -lt 5 ]; do   # five rounds, to hold the load for a second or more
	n=$($PY "$PEERS/rawctl.py" "$S" crowd 100 20); good=$((good + ${n:-0}))
	n=$($PY "$PEERS/rawctl.py" "$S" burst 1000); bad=$((bad + ${n:-0}))
	r=$((r + 1))
done
t1=$(date +%s.%N); s1=$(steps)
"$BIN/psensctl" -s "$S" -j status > "$TMP/st.json"
late=$(sed -n 's/.*"late_max_s":\([0-9.e-]*\).*/\1/p' "$TMP/st.json")
diag "5 rounds of 100 clients x 20 requests and 1000 bad requests in $(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.2f", b - a }') s; worst step lateness $(awk -v l="$late" 'BEGIN { printf "%.1f", 1000 * l }') ms at a 100 ms period"
check "100 clients at once, 5 times: all 10000 status requests answered ($good)" test "$good" = 10000
check "5 bursts of 1000 bad requests: 5000 error replies ($bad)" test "$bad" = 5000
expect=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%d", (b - a) / 0.1 }')
check "the control kept its 10 Hz schedule: $((s1 - s0)) steps in the time of $expect" \
	awk -v d="$((s1 - s0))" -v e="$expect" 'BEGIN { exit !(d >= e - 2 && d <= e + 3) }'
check "psensd still answers" sh -c "\"$BIN/psensctl\" -s \"$S\" ping > /dev/null"
check "no client refused (max_clients = 128)" grep -q '"rejected":0' "$TMP/st.json"
done_testing
