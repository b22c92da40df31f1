#!/bin/sh
# SPDX-License-Identifier: ISC
# doc/site.md's DALI dry run with the gear read back (verify_tolerance =
# 0.05, the way to detect silent gear) on a loaded machine: four busy loops
# beside psvirt and psensd.  psensd's DALI read is asynchronous; an answer
# to a QUERY ACTUAL LEVEL sent before the step's level change is the level
# from before the command, and must never be judged against the new one.
# Checked: over 40 periods of 0.5 s with the level changed by the control
# (100 % -> the 10 % minimum at noon) and by five overrides, no fault at all
# (no "not responding", no "no answer ... yet"), and the gear at the zone's
# last level on the standard's curve (read by a second Foxtron client);
# then every gear silent (psvirt's --dali-fault silent, SIGUSR1) is still a
# fault naming the unanswered query, and SIGUSR2 a recovery.
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/peers/common.sh"
[ -x "$BIN/psvirt" ] && [ -x "$BIN/psensd" ] || skip_all "psvirt or psensd not built"
"$BIN/psensd" -L 2>/dev/null | grep -q "^dali_usb:" || skip_all "the dali_usb driver is not compiled in"
make_results
S="$TMP/sock"
mb=$(free_port)
psvirt_dali --tcp "127.0.0.1:$mb" --dali-fault silent --start 12:00 -D gain=0.5 -D noise=0.002
{ printf '[psensd]\nresults = ofb.results\ndatabase = psensd.db\nsocket = sock\nperiod = 0.5\nsafe_level = 1.0\n'
cat <<EOF
[device io]
driver = modbus
host = 127.0.0.1
port = $mb
timeout = 0.2
retries = 1
[device dali]
driver = dali_usb
transport = foxtron
device = 127.0.0.1:$port
timeout = 0.5
[point sensor]
device = io
role = sensor
table = input_register
address = 0
[point ballasts]
device = dali
role = dim
address = broadcast
[zone office]
sensor = sensor
dim = ballasts
min_level = 0.1
sensor_gain = 0.5
verify_tolerance = 0.05
EOF
} > "$TMP/psensd.conf"
ctl() { "$BIN/psensctl" -s "$S" "$@"; }
fox() { "$PY" "$PEERS/foxclient.py" "tcp:127.0.0.1:$port" "$@"; }
levels() { fox "ask 16 01A0; ask 16 03A0" | tr '\n' ' ' | sed 's/ $//'; }
at_level() { [ "$(levels)" = "$1 $1" ]; }
faults() { grep -c "zone office: .* fault: " "$TMP/err"; }

# the load: four busy loops, each bounded (stopped on exit in any case)
for i in 1 2 3 4; do
	timeout 300 sh -c 'while :; do :; done' &
	track_pid $!
done
"$BIN/psensd" -f "$TMP/psensd.conf" -t 12:00 > "$TMP/out" 2> "$TMP/err" &
ps=$!; track_pid $ps
wait_for 10 ctl ping > /dev/null || not_ok "psensd did not start: $(cat "$TMP/err")"
# 40 periods: 10 s at the control's level, then five overrides of 2 s each
sleep 10
for u in 0.3 0.6 0.2 0.9 0.4; do
	ctl override office "$u" 600 > /dev/null
	sleep 2
done
check "no fault in 40 periods with no fault present: $(faults) ($(grep -m 1 -o 'fault: .*' "$TMP/err" | cut -c1-110))" \
	test "$(faults)" = 0
check "... and none cleared: $(grep -c 'fault cleared' "$TMP/err")" test "$(grep -c 'fault cleared' "$TMP/err")" = 0
want=$(dali_arc 0.4)
wait_for 10 at_level "$want"
check "the gear at the last override's level, arc $want ($(levels))" at_level "$want"

# a real fault: every gear silent
n0=$(faults)
c0=$(grep -c "fault cleared" "$TMP/err")
kill -USR1 $pv
wait_for 15 test "$(faults)" -gt "$n0"
f=$(grep "zone office: .* fault: " "$TMP/err" | sed -n "$((n0 + 1))p")
check "every gear silent: a fault naming the unanswered query: $(echo "$f" | grep -o 'fault: .*' | cut -c1-110)" \
	sh -c 'echo "$1" | grep -q "fault: .*QUERY ACTUAL LEVEL"' sh "$f"
kill -USR2 $pv
wait_for 20 test "$(grep -c "fault cleared" "$TMP/err")" -gt "$c0"
check "the gear answer again: psensd resumes by itself" test "$(grep -c "fault cleared: control resumes" "$TMP/err")" -gt "$c0"
wait_for 10 at_level "$want"
check "... the gear at the override's level again ($want): $(levels)" at_level "$want"
check "one fault in all, the real one ($(faults))" test "$(faults)" = 1
pd=$(ctl -j ping | sed -n 's/.*"pid":\([0-9]*\).*/\1/p')
kill -TERM "$pd"
wait $ps
kill -TERM $pv
wait $pv
done_testing
