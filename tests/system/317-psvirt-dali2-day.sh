#!/bin/sh
# SPDX-License-Identifier: ISC
# A DALI-2 morning with no hardware: psvirt's virtual bus behind a Foxtron
# DALInet carries the room's multisensor (a 304 light sensor, instance 1,
# the room's ceiling signal at 1023 = 10 V; a 303 occupancy sensor,
# instance 0, occupied from 08:00) and its two ballasts; psensd reads the
# 304 as the zone's sensor and the 303 as its occupancy input, both over
# the bus, and dims the gear (the task meter stays on psvirt's Modbus
# module, for the log's truth).  The room at 600x real time from 07:30 to
# about 08:50, every 10 s: the bus keeps real time (its timeouts, frame
# gaps and the sensors' 5 s T_report run on the monotonic clock, not the
# room's), so the sped-up room neither loses the sensor (a 5 s report
# timer read on the room's clock would be 8 ms of bus time) nor flaps the
# occupancy.  Checked: the occupancy reaches the log (vacant before 08:00,
# occupied after, and it changes exactly once), the lights go off once the
# room has been vacant for the hold and come back under daylight control
# at 08:00, the 304 sees the lights go out, the light sensor is never
# lost, and the record of the run says SIMULATED.
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/peers/common.sh"
[ -x "$BIN/psvirt" ] && [ -x "$BIN/psensd" ] || skip_all "psvirt or psensd not built"
"$BIN/psensd" -L 2>/dev/null | grep -q "^dali_usb:" || skip_all "the dali_usb driver is not compiled in"
command -v sqlite3 > /dev/null || skip_all "sqlite3 not installed"
make_results
mb=$(free_port)
psvirt_dali --tcp "127.0.0.1:$mb" \
	--date 03-18 --sunrise 06:00 --sunset 18:30 --start 07:30 --speed 600 --dali-occupancy 08:00-12:00 \
	-D gain=0.5 -D noise=0.002 -D task_noise=2 -D seed=7 -D lag_tau=0
{ printf '[psensd]\nresults = ofb.results\ndatabase = day.db\nsocket = sock\nperiod = 10\n'
psvirt_devices psvirt
dali2_light 0 5
dali2_occupancy 0 5
dali2_office
echo 'vacancy_hold = 120'
} > "$TMP/day.conf"
timeout 8 "$BIN/psensd" -f "$TMP/day.conf" -t 07:30 -x 600 > "$TMP/out" 2> "$TMP/err"
q() { sqlite3 "$TMP/day.db" "$1"; }
n=$(q "select count(*) from samples")
check "07:30 to past 08:30 logged every 10 s: $n samples" test "$n" -ge 400
vac=$(q "select count(*) from samples where tod_s between 27900 and 28680 and occupied = 0")
all=$(q "select count(*) from samples where tod_s between 27900 and 28680")
check "the 303's vacancy logged 07:45-07:58 ($vac of $all samples)" test "$vac" -ge 70 -a "$vac" = "$all"
occ=$(q "select count(*) from samples where tod_s between 28860 and 30600 and occupied = 1")
all=$(q "select count(*) from samples where tod_s between 28860 and 30600")
check "the 303's occupancy logged 08:01-08:30 ($occ of $all samples)" test "$occ" -ge 150 -a "$occ" = "$all"
flips=$(q "select count(*) from (select occupied, lag(occupied) over (order by tod_s) as prev from samples
	where tod_s >= 27900) where occupied != prev")
check "the occupancy changes once from 07:45 on, at 08:00 (no flapping): $flips changes" test "$flips" = 1
off=$(q "select count(*) from samples where tod_s between 27900 and 28680 and output > 0")
check "vacant past the 2 min hold: the lights off 07:45-07:58 ($off samples lit)" test "$off" = 0
lit=$(q "select count(*) from samples where tod_s between 28860 and 30600 and output >= 0.099")
check "occupied: under daylight control, at 10 % or more ($lit of $all samples)" test "$lit" = "$all"
# the loop closes through the bus: the 304 sees the gear's light go out
# although the daylight rises (psvirt's ceiling signal, 1023 = 10 V); the
# sensor's reports take real seconds, so the lit reading is its last
# while the lights were on and the dark one is 07:53-07:58
on=$(q "select sensor_v from samples where tod_s < 28680 and output > 0 and sensor_v is not null
	order by tod_s desc limit 1")
dark=$(q "select avg(sensor_v) from samples where tod_s between 28380 and 28680")
check "the 304 sees the lights go out: $on counts lit, $dark dark at 07:53-07:58" \
	awk -v a="$on" -v b="$dark" 'BEGIN { exit !(a > 50 && b < a - 2 && b > 0.5 * a) }'
check "the light sensor never lost" sh -c "! grep -q 'fault: light' '$TMP/err'"
"$BIN/psensctl" -d "$TMP/day.db" report -o "$TMP/rec.pdf" > /dev/null 2>&1
check "the record of the run says SIMULATED" sh -c "pdftotext '$TMP/rec.pdf' - 2>/dev/null | grep -q SIMULATED"
done_testing
