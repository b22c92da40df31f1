#!/bin/sh
# SPDX-License-Identifier: ISC
# A simulated day over DALI: psensd's set-point control (target 500 lx)
# reading the room's sensor and task meter on psvirt's Modbus module and
# dimming the room's two ballasts over psvirt's DALInet (dali_usb, transport
# = foxtron), psvirt's room at 3600x real time from 05:00 (a minute a
# period, about 13 h in 13 s).  The loop closes only through the bus: the
# gear's arc levels are the room's light.  Checked: at most 5 % of the day
# in fault, every fault cleared by itself (at 3600x a minute of room time
# passes in 17 ms, so a DALI or Modbus transaction late by a scheduling
# hiccup on a loaded machine is a fault of a minute or two); while
# the control is in range (above the minimum level, below full) the task
# meter holds the target within 6 % on average (DALI's arc levels are 2.8 %
# apart, the sensor has noise); in bright daylight the zone sits at its
# minimum; psensd's safe level on the way out reaches the gear and the room.
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/peers/common.sh"
[ -x "$BIN/psvirt" ] && [ -x "$BIN/psensd" ] || skip_all "psvirt or psensd not built"
"$BIN/psensd" -L 2>/dev/null | grep -q "^dali_usb:" || skip_all "the dali_usb driver is not compiled in"
command -v sqlite3 > /dev/null || skip_all "sqlite3 not installed"
make_results
mb=$(free_port)
psvirt_dali --tcp "127.0.0.1:$mb" \
	--date 03-18 --sunrise 06:00 --sunset 18:30 --start 05:00 --speed 3600 \
	-D gain=0.5 -D noise=0.002 -D task_noise=2 -D seed=7 -D lag_tau=0
{ printf '[psensd]\nresults = ofb.results\ndatabase = day.db\nsocket = sock\nperiod = 60\n'
psvirt_devices
cat <<EOF
[point sensor]
device = io
role = sensor
table = input_register
address = 0
[point lux]
device = io
role = task
table = holding_register
address = 100
type = u32
[point ballasts]
device = dali
role = dim
address = broadcast
[zone office]
sensor = sensor
task = lux
dim = ballasts
algorithm = setpoint
target_lux = 500
min_level = 0.1
sensor_gain = 0.5
EOF
} > "$TMP/day.conf"
timeout 13 "$BIN/psensd" -f "$TMP/day.conf" -t 05:00 -x 3600 > "$TMP/out" 2> "$TMP/err"
# psensd's last command on the way out, the safe level, reached the room through the bus
lv=$("$PY" "$PEERS/foxclient.py" "tcp:127.0.0.1:$port" "ask 16 01A0; ask 16 03A0" | tr '\n' ' ')
check "psensd stopped: both gear at the safe level, 254 ($lv)" test "$lv" = "254 254 "
out=$("$PY" "$PEERS/mbraw.py" 127.0.0.1 "$mb" send "0001 0000 0006 01 03 00ca 0001" | awk '{ print $10 $11 }')
check "... and the room at full output (register 202: 0x$out)" test "$out" = 2710
kill -TERM $pv; wait $pv
q() { sqlite3 "$TMP/day.db" "$1"; }
n=$(q "select count(*) from samples")
check "a day's samples logged ($n)" test "$n" -gt 500
f=$(q "select count(*) from samples where fault is not null")
nf=$(grep -c 'fault: ' "$TMP/err"); nc=$(grep -c 'fault cleared: control resumes' "$TMP/err")
diag "$(grep 'fault' "$TMP/err" | head -n 4)"
check "at most 5 % of the day in fault ($f of $n samples; a transaction lost at 3600x costs a minute)" \
	test "$((f * 20))" -le "$n"
check "every fault cleared by itself ($nf faults, $nc cleared)" test "$nf" -le "$((nc + 1))"
err=$(q "select printf('%.2f', 100 * avg(abs(task_lux - 500) / 500.0)) from samples where output > 0.11 and output < 0.99 and fault is null")
m=$(q "select count(*) from samples where output > 0.11 and output < 0.99 and fault is null")
check "in range ($m samples) the task holds 500 lx within $err % on average" \
	awk -v e="$err" -v m="$m" 'BEGIN { exit !(m >= 50 && e != "" && e < 6) }'
mid=$(q "select printf('%.3f', max(output)) from samples where tod_s between 11 * 3600 and 13 * 3600 and fault is null")
check "bright noon: the zone at its minimum (at most $mid)" awk -v x="$mid" 'BEGIN { exit !(x != "" && x <= 0.101) }'
done_testing
