#!/bin/sh
# SPDX-License-Identifier: ISC
# psvirt's virtual DALI bus as a Foxtron DALInet on TCP, answered by
# psensd's own DALI driver (dali_usb, transport = foxtron): psensd reads the
# room's sensor on psvirt's Modbus module and dims two virtual ballasts over
# DALI.  Checked: the gear's arc level (read back by a second Foxtron client,
# peers/foxclient.py) is the zone's level on the standard's curve
# X(n) = 10^((n-1)/(253/3)-1) %, and the room's light output (holding
# register 202, x 10000) is that curve's value, so the gear drive the room;
# every gear silent (SIGUSR1 with --dali-fault silent) is a fault naming the
# unanswered query (verify_tolerance reads the gear back), the zone to its
# safe level; SIGUSR2 and psensd resumes by itself, the gear back at the
# zone's level; a bus short (Modbus registers 904/905) is a fault too, and
# its end a recovery.
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/peers/common.sh"
[ -x "$BIN/psvirt" ] && [ -x "$BIN/psensd" ] || skip_all "psvirt or psensd not built"
"$BIN/psensd" -L 2>/dev/null | grep -q "^dali_usb:" || skip_all "the dali_usb driver is not compiled in"
make_results
S="$TMP/sock"
mb=$(free_port)
psvirt_dali --tcp "127.0.0.1:$mb" \
	--dali-fault silent --start 12:00 -D gain=0.5 -D noise=0 -D lag_tau=0
check "psvirt says where its DALInet listens (port $port)" grep -q "DALI bus (Foxtron DALInet) on port $port" "$TMP/pv.out"
{ printf '[psensd]\nresults = ofb.results\ndatabase = psensd.db\nsocket = sock\nperiod = 0.5\nstale_after = 2\n'
cat <<EOF
[device io]
driver = modbus
host = 127.0.0.1
port = $mb
timeout = 0.2
[device dali]
driver = dali_usb
transport = foxtron
device = 127.0.0.1:$port
timeout = 0.2
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
sensor_gain = 0.5
min_level = 0.1
verify_tolerance = 0.05
EOF
} > "$TMP/psensd.conf"
ctl() { "$BIN/psensctl" -s "$S" "$@"; }
fox() { "$PY" "$PEERS/foxclient.py" "tcp:127.0.0.1:$port" "$@"; }
# the two gear's levels (short 0 and 1)
levels() { fox "ask 16 01A0; ask 16 03A0" | tr '\n' ' ' | sed 's/ $//'; }
at_level() { [ "$(levels)" = "$1 $1" ]; }
# holding register N of psvirt's Modbus map
hr() { "$PY" "$PEERS/mbraw.py" 127.0.0.1 "$mb" send "0001 0000 0006 01 03 $(printf %04x "$1") 0001" | awk '{ print $10 $11 }' | { read -r h; printf '%d\n' "0x$h"; }; }
whr() { "$PY" "$PEERS/mbraw.py" 127.0.0.1 "$mb" send "0002 0000 0006 01 06 $(printf %04x "$1") $(printf %04x "$2")" > /dev/null; }

check "before psensd: both gear at 254, as gear power up ($(levels))" at_level 254
check "... and the room at full output (register 202: $(hr 202))" test "$(hr 202)" = 10000
"$BIN/psensd" -f "$TMP/psensd.conf" -t 12:00 > "$TMP/out" 2> "$TMP/err" &
ps=$!; track_pid $ps
wait_for 10 ctl ping > /dev/null || not_ok "psensd did not start: $(cat "$TMP/err")"
want=$(dali_arc 0.1)
wait_for 10 at_level "$want"
check "noon, the zone at its minimum 10 %: both gear at arc level $want ($(levels))" at_level "$want"
ctl override office 0.3 600 > /dev/null
want=$(dali_arc 0.3)
wait_for 10 at_level "$want"
check "override 30 %: both gear at arc level $want ($(levels))" at_level "$want"
# the room's output is the curve's value at that level, to the register's 1e-4
out=$(hr 202)
exp=$(awk -v n="$want" 'BEGIN { printf "%d", 10000 * exp(log(10) * ((n - 1) * 3 / 253 - 3)) + 0.5 }')
check "the gear drive the room: light output $out / 10000 = X($want) ($exp)" test "$out" = "$exp"

kill -USR1 $pv
wait_for 15 grep -q "zone office: .* fault: " "$TMP/err"
check "every gear silent: a fault naming the unanswered query: $(grep -o 'fault: .*' "$TMP/err" | head -n 1 | cut -c1-120)" \
	grep -q "zone office: .* fault: .*QUERY ACTUAL LEVEL" "$TMP/err"
ctl -j status > "$TMP/st.json"
check "... the zone at its safe level, the fault in its status" grep -Eq '"level":1(\.0)?,.*"fault":"' "$TMP/st.json"
kill -USR2 $pv
wait_for 20 grep -q "fault cleared: control resumes" "$TMP/err"
check "the gear answer again: psensd resumes by itself" grep -q "fault cleared: control resumes" "$TMP/err"
want=$(dali_arc 0.3)
wait_for 10 at_level "$want"
check "the override's level is back on the gear ($want): $(levels)" at_level "$want"

# a bus short through the fault registers: power lost, then back
whr 905 255
whr 904 3
check "the bus shorted: a query gets 'power lost' ($(fox 'send 16 01A0'))" test "$(fox 'send 16 01A0')" = "power lost"
wait_for 15 test "$(grep -c 'zone office: .* fault: ' "$TMP/err")" -ge 2
check "... psensd: a fault: $(grep -o 'fault: .*' "$TMP/err" | sed -n 2p | cut -c1-120)" \
	test "$(grep -c 'zone office: .* fault: ' "$TMP/err")" -ge 2
whr 904 0
wait_for 20 test "$(grep -c 'fault cleared: control resumes' "$TMP/err")" -ge 2
check "the short cleared: psensd resumes" test "$(grep -c 'fault cleared: control resumes' "$TMP/err")" -ge 2
wait_for 10 at_level "$want"
check "... and the gear are at the zone's level again ($want): $(levels)" at_level "$want"
pd=$(ctl -j ping | sed -n 's/.*"pid":\([0-9]*\).*/\1/p')
kill -TERM "$pd"
wait $ps
check "SIGTERM: psensd left the gear at the safe level, 254: $(levels)" at_level 254
kill -TERM $pv
wait $pv
check "psvirt counted the DALI frames: $(grep 'DALI frames' "$TMP/pv.out")" grep -Eq "psvirt: [1-9][0-9]* DALI frames" "$TMP/pv.out"
done_testing
