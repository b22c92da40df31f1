#!/bin/sh
# SPDX-License-Identifier: ISC
# `psensctl reload` carries the outcome: ok for a good configuration; for a
# refused one ok false with every reason as file:line (asked through a raw
# socket and through psensctl, which exits 1 and prints the reasons), the
# running configuration kept.  And a shutdown that leaves a zone short of
# its safe level (a pymodbus module gone before SIGTERM) exits non-zero,
# said at LOG_ERR (priority 3 on the journal stream).
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/peers/common.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
PY=/usr/bin/python3
PEERS="$TOP/tests/system/peers"
example_results
S="$TMP/sock"
sed "s|^results = .*|results = state/ofb.results|; s|^database = .*|database = state/psensd.db\nsocket = sock|; s|^period = .*|period = 1|; /^faults = /d" \
	config/psensd.conf > "$TMP/psensd.conf"
cp "$TMP/psensd.conf" "$TMP/good.conf"
"$BIN/psensd" -f "$TMP/psensd.conf" -t 12:00 > /dev/null 2> "$TMP/err" &
pid=$!; track_pid $pid
wait_for 10 sh -c "\"$BIN/psensctl\" -s \"$S\" ping > /dev/null"
target() { "$BIN/psensctl" -s "$S" -j status | sed -n 's/.*"target_lux":\([0-9.]*\).*/\1/p' | head -n 1; }

sed -i 's/^target_lux = .*/target_lux = 450/' "$TMP/psensd.conf"
r=$($PY "$PEERS/rawctl.py" "$S" send reload)
check "a good configuration: ok true ($r)" sh -c "echo '$r' | grep -q '\"ok\":true'"
check "... and in force when the reply comes (target $(target))" awk -v t="$(target)" 'BEGIN { exit !(t == 450) }'

# a bad one: a zone naming no point, at a line we know
printf '[zone other]\nsensor = nosuch\n' >> "$TMP/psensd.conf"
line=$(grep -n '^sensor = nosuch' "$TMP/psensd.conf" | cut -d: -f1)
r=$($PY "$PEERS/rawctl.py" "$S" send reload)
diag "raw reply: $r"
check "a bad configuration over a raw socket: ok false" sh -c "echo '$r' | grep -q '\"ok\":false'"
check "... with the reason at file:line ($TMP/psensd.conf:$line)" \
	sh -c "echo '$r' | grep -q '\"reasons\":\[\"$TMP/psensd.conf:$line: sensor: no \[point nosuch\]'"
"$BIN/psensctl" -s "$S" reload > "$TMP/ctl.out" 2> "$TMP/ctl.err"
rc=$?
check "psensctl reload exits 1 on a refusal (got $rc)" test "$rc" = 1
diag "psensctl: $(tr '\n' '|' < "$TMP/ctl.err")"
check "... and prints the reason with file:line" grep -q "^  $TMP/psensd.conf:$line: sensor: no \[point nosuch\]" "$TMP/ctl.err"
check "the running configuration stays (target $(target))" awk -v t="$(target)" 'BEGIN { exit !(t == 450) }'

# refused when the devices open: the new database is another daemon's
conf2=$(sed "s|^database = .*|database = state/other.db|; s|^socket = .*|socket = sock2|" "$TMP/good.conf")
printf '%s\n' "$conf2" > "$TMP/other.conf"
"$BIN/psensd" -f "$TMP/other.conf" -t 12:00 > /dev/null 2> "$TMP/other.err" &
other=$!; track_pid $other
wait_for 10 sh -c "\"$BIN/psensctl\" -s \"$TMP/sock2\" ping > /dev/null"
sed "s|^database = .*|database = state/other.db|" "$TMP/good.conf" > "$TMP/psensd.conf"
"$BIN/psensctl" -s "$S" reload > "$TMP/ctl.out" 2> "$TMP/ctl2.err"
rc=$?
diag "psensctl: $(tr '\n' '|' < "$TMP/ctl2.err")"
check "a database held by another psensd: refused, exit 1 (got $rc)" test "$rc" = 1
check "... naming the file and the other daemon's pid" \
	grep -q "^  $TMP/psensd.conf: .*state/other.db is in use by psensd pid $other" "$TMP/ctl2.err"
check "still answering with the old configuration (target $(target))" awk -v t="$(target)" 'BEGIN { exit !(t == 450) }'
kill -TERM $other $pid; wait $other; wait $pid
rc=$?
check "a clean shutdown exits 0 (got $rc)" test "$rc" = 0

# a shutdown that cannot reach the safe level: the module is gone
if "$PY" -c "import pymodbus" 2>/dev/null; then
	port=$(free_port)
	"$PY" "$PEERS/mbserver.py" "$port" "$TMP/srv.ready" ir:0=13107 2>> "$TMP/srv.err" &
	srv=$!; track_pid $srv
	wait_for 10 test -s "$TMP/srv.ready"
	{ printf '[psensd]\nresults = state/ofb.results\nsocket = sock3\nperiod = 0.5\n'
	  device_tcp "$port" timeout=0.1 retries=0 backoff_min=0.2 backoff_max=0.4
	  printf '[point s]\ndevice = io\nrole = sensor\ntable = input_register\naddress = 0\n'
	  printf '[point d]\ndevice = io\nrole = dim\ntable = holding_register\naddress = 10\n'
	  printf '[zone z]\nsensor = s\ndim = d\n'; } > "$TMP/mb.conf"
	stream() { stat -c '%d:%i' "$1"; }
	: > "$TMP/mb.err"
	JOURNAL_STREAM=$(stream "$TMP/mb.err") "$BIN/psensd" -f "$TMP/mb.conf" -t 12:00 > /dev/null 2>> "$TMP/mb.err" &
	mp=$!; track_pid $mp
	wait_for 10 sh -c "\"$BIN/psensctl\" -s \"$TMP/sock3\" ping > /dev/null"
	kill $srv; wait $srv 2>/dev/null
	wait_for 10 grep -q "cannot reach the safe level" "$TMP/mb.err"
	kill -TERM $mp; wait $mp
	rc=$?
	check "SIGTERM with the module gone: exits non-zero (got $rc)" test "$rc" != 0
	diag "$(grep 'stopped with' "$TMP/mb.err")"
	check "... said at LOG_ERR" grep -q "^<3>psensd: stopped with 1 zone(s) not at their stop level\|^<3>stopped with 1 zone(s) not at their stop level" "$TMP/mb.err"
else
	skip "pymodbus not installed: the unreachable safe level at shutdown"
	skip "pymodbus not installed: the unreachable safe level at shutdown"
fi
done_testing
