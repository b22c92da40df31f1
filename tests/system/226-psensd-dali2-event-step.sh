#!/bin/sh
# SPDX-License-Identifier: ISC
# A DALI-2 light sensor's event steps its zone at once: psvirt's virtual
# bus behind a Foxtron DALInet carries the room's multisensor (the 304
# instance reports a change beyond its hysteresis as an event) and the
# room's gear; psvirt's room runs at 600x from 06:10, so the morning's
# daylight rises by about 10 room minutes a second, while psensd runs in
# real time with a zone period of 10 minutes: its only scheduled step is
# the first.  Checked: every further step (each a sample in the log) comes
# from a sensor event, several come within 6 s carrying new readings, and
# the zone dims the gear as the daylight rises (the level it commands
# falls), so the gear follows the sensor between periods.
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/peers/common.sh"
[ -x "$BIN/psvirt" ] && [ -x "$BIN/psensd" ] || skip_all "psvirt or psensd not built"
"$BIN/psensd" -L 2>/dev/null | grep -q "^dali_usb:" || skip_all "the dali_usb driver is not compiled in"
command -v sqlite3 > /dev/null || skip_all "sqlite3 not installed"
make_results
mb=$(free_port)
psvirt_dali --tcp "127.0.0.1:$mb" \
	--date 03-18 --sunrise 06:00 --sunset 18:30 --start 06:10 --speed 600 --dali-occupancy 00:00-23:59 \
	-D gain=0.5 -D noise=0 -D seed=7 -D lag_tau=0
{ cat <<EOF2
[psensd]
results = ofb.results
database = ev.db
socket = sock
period = 600
[device dali]
driver = dali_usb
simulated = psvirt
transport = foxtron
device = 127.0.0.1:$port
timeout = 0.5
EOF2
dali2_light 0 30
cat <<EOF2
[point ballasts]
device = dali
role = dim
address = broadcast
[zone office]
sensor = light
dim = ballasts
algorithm = setpoint
target_lux = 500
min_level = 0.1
sensor_gain = 51.15
EOF2
} > "$TMP/ev.conf"
timeout 6 "$BIN/psensd" -f "$TMP/ev.conf" -t 06:10 > "$TMP/out" 2> "$TMP/err"
q() { sqlite3 "$TMP/ev.db" "$1"; }
n=$(q "select count(*) from samples")
check "steps in 6 s at a 10 min period: $n (1 scheduled, the rest on the sensor's events)" test "$n" -ge 4
r=$(q "select count(distinct sensor_v) from samples where sensor_v is not null")
k=$(q "select count(*) from samples where sensor_v is not null")
check "the event steps carry the sensor's new readings: $r distinct in $k steps" test "$r" -ge 3
first=$(q "select output from samples where sensor_v is not null order by tod_s limit 1")
last=$(q "select output from samples where sensor_v is not null order by tod_s desc limit 1")
lv=$(q "select count(distinct output) from samples where sensor_v is not null")
check "the gear dimmed between periods as the daylight rose: level $first then $last ($lv levels)" \
	awk -v a="$first" -v b="$last" -v n="$lv" 'BEGIN { exit !(n >= 2 && b < a) }'
check "no fault once the sensor reported" sh -c "! grep 'fault' '$TMP/err' | grep -v 'no reading since\|no value yet\|fault cleared' | grep -q ."
done_testing
