#!/bin/sh
# SPDX-License-Identifier: ISC
# Calibration sessions on a DALI-2 site with no hardware: psvirt's virtual
# bus behind a Foxtron DALInet carries the room's multisensor (the 304
# light sensor's 10-bit reading is the room's ceiling signal, 1023 = 10 V;
# the 303 reports occupied all day) and its two ballasts; psensd reads the
# 304 as the zone's sensor and the 303 as its occupancy input, dims the
# gear over the bus, and takes the task meter from psvirt's Modbus module.
# The bus keeps real time while both clocks run at 300x: the 304's
# periodic report (T_report 2 s) is ten minutes of the room's clock apart,
# and with a 1 % hysteresis its events come thick and some are lost, so a
# value handed up may be minutes of sun old, or the last level's; the
# sessions count each measurement once and poll the sensor for a fresh one
# (a session taking the value as of now aborted its night: the 10 % level's
# reading taken at 0 % looked like daylight).  Checked: the night
# session's fitted gain, in 304 counts at full output, is the room's 0.5 V
# per unit of the simulated electric response times 102.3 counts per
# volt, within 1 % (the reading is whole counts);
# its offset is within 1 count of the room's dark 0.05 V (5.1 counts); the
# fit is linear; the accepted sensor gain is 51.15 counts per unit; the
# day session's measured lux per count meets the simulation's within 3 %;
# both are accepted, the sensor is never lost, and the record of the run
# says the zone is calibrated.
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/peers/common.sh"
[ -x "$BIN/psvirt" ] && [ -x "$BIN/psensd" ] || skip_all "psvirt or psensd not built"
"$BIN/psensd" -L 2>/dev/null | grep -q "^dali_usb:" || skip_all "the dali_usb driver is not compiled in"
command -v sqlite3 > /dev/null || skip_all "sqlite3 not installed"
PY=/usr/bin/python3
make_results
ES=$(summary electric_sensor_response)
S="$TMP/sock"
mb=$(free_port)
virt() {  # virt START SPEED: psvirt's room from START
	psvirt_dali --tcp "127.0.0.1:$mb" \
		--date 03-18 --sunrise 06:00 --sunset 18:30 --start "$1" --speed "$2" --dali-occupancy 00:00-23:59 \
		-D gain=0.5 -D offset=0.05 -D noise=0 -D task_noise=2 -D seed=7 -D lag_tau=0 -D fade_rate=0
}
conf() {
	printf '[psensd]\nresults = ofb.results\ndatabase = cal.db\nsocket = sock\nperiod = 60\n'
	psvirt_devices psvirt
	dali2_light 0 2 "deadtime = 0.1" "hysteresis = 1"
	dali2_occupancy 0 2
	dali2_office
	cat <<EOF2
cal_window = 600
cal_day_interval = 120
EOF2
}
ctl() { "$BIN/psensctl" -s "$S" "$@"; }
start() {  # start HH:MM SPEED: psvirt and psensd from HH:MM
	virt "$1" "$2"
	conf > "$TMP/cal.conf"
	"$BIN/psensd" -f "$TMP/cal.conf" -t "$1" -x "$2" >> "$TMP/out" 2>> "$TMP/err" &
	pd=$!; track_pid $pd
	wait_for 10 sh -c "\"$BIN/psensctl\" -s \"$S\" ping > /dev/null"
	wait_for 10 sh -c "\"$BIN/psensctl\" -s \"$S\" -j status | grep -q '\"sensor_v\":[0-9]'"
}
stop() { kill -TERM $pd; wait $pd 2>/dev/null; kill $pv; wait $pv 2>/dev/null; }
calj() { ctl -j calibrate office status | $PY -c "import json,sys; c=json.load(sys.stdin)['calibration']; v=eval(sys.argv[1]); print(*v) if isinstance(v, tuple) else print(v)" "$1"; }
state_is() { [ "$(calj "c['state']")" = "$1" ]; }
within() { awk -v a="$1" -v b="$2" -v s="$3" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d <= s) }'; }

# the night: six levels, the 304's counts against the gear's output
start 21:00 300
check "calibrate office night starts a session over the DALI-2 bus" sh -c "\"$BIN/psensctl\" -s \"$S\" calibrate office night > /dev/null"
wait_for 40 state_is done
check "the night session finished: $(calj "c['message']" | cut -c1-100)" state_is done
set -- $(calj "c['gain'], c['gain_se'], c['offset'], c['r2'], len(c['levels'])")
g=$1; off=$3; r2=$4; nl=$5
want=$(awk -v e="$ES" 'BEGIN { print 0.5 * e * 102.3 }')
check "6 levels settled ($nl)" test "$nl" = 6
check "the 304's gain $g counts at full output = 0.5 V x $ES x 102.3 counts/V = $want within 1 %" \
	within "$g" "$want" "$(awk -v w="$want" 'BEGIN { print 0.01 * w }')"
check "its offset $off counts = the room's 0.05 V x 102.3 = 5.1 counts within 1 count" within "$off" 5.115 2
check "linear: R2 $r2 > 0.9999" awk -v r="$r2" 'BEGIN { exit !(r > 0.9999) }'
check "accept the night session" sh -c "\"$BIN/psensctl\" -s \"$S\" calibrate office accept > /dev/null"
sg=$(ctl -j status | sed -n 's/.*"sensor_gain":\([0-9.e-]*\).*/\1/p')
check "the accepted sensor gain $sg = the room's 0.5 V x 102.3 = 51.15 counts per unit of the simulated response, within 1 %" \
	within "$sg" 51.15 0.51
stop

# the day: five task meter samples two minutes apart at 30 %, the sun
# rising 300 times as fast as on site
start 10:00 300
check "calibrate office day 0.3" sh -c "\"$BIN/psensctl\" -s \"$S\" calibrate office day 0.3 > /dev/null"
wait_for 90 state_is done
set -- $(calj "c['ratio'], c['sim_ratio'], c['error_pct'], len(c['samples']), c['pair_skew_s']")
diag "$(calj "c['message']")"
check "day session: $4 samples, measured $1 lx per count, simulated $2: $3 %" test "$4" = 5
check "the measured ratio meets the simulated one within 3 %" awk -v e="$3" 'BEGIN { exit !(e > -3 && e < 3) }'
check "each sample's sensor value and meter reading at most $5 s of the room's clock apart: under 60 s (0.2 s real), where a periodic report is up to 600 s old" \
	awk -v s="$5" 'BEGIN { exit !(s >= 0 && s < 60) }'
check "accept the day session" sh -c "\"$BIN/psensctl\" -s \"$S\" calibrate office accept > /dev/null"
stop
check "the light sensor never lost (no value older than 2 x T_report)" sh -c "! grep -q 'instance 1: no value for' '$TMP/err'"

"$BIN/psensctl" -d "$TMP/cal.db" report office -o "$TMP/rec.pdf" > "$TMP/rec.out" 2>&1
check "the record: $(cat "$TMP/rec.out")" grep -q "rec.pdf: zone office: calibrated" "$TMP/rec.out"
done_testing
