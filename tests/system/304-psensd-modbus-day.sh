#!/bin/sh
# SPDX-License-Identifier: ISC
# The real psensd over Modbus TCP through psvirt: both clocks at 3600x real
# time from 05:00 (a day in about 14 s), one control step per 15 simulated
# minutes, the ADAM-6024-style register map of psensd-modbus(5).  Checked
# from psensd's own log: before sunrise the level is target / electric task
# lux; in daylight the minimum level; psvirt's open-circuit window is a fault
# at the safe level; psvirt killed is a lost device at the safe level, and
# psensd resumes by itself when psvirt is back on the same port.
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/peers/common.sh"
[ -x "$BIN/psvirt" ] || skip_all "psvirt not built"
make_results
L=$(summary electric_task_lux)
port=$(free_port)
virt() {  # virt START: psvirt from START, room time at 3600x
	rm -f "$TMP/ready"
	"$BIN/psvirt" --results "$TMP/ofb.results" --tcp "127.0.0.1:$port" --ready-file "$TMP/ready" \
		--date 03-18 --sunrise 06:00 --sunset 18:30 --start "$1" --speed 3600 \
		-D gain=0.5 -D noise=0.002 -D task_noise=2 -D seed=7 -D fade_rate=0 -D lag_tau=0 -D min_level=0.1 \
		-o "faults=open 12:00-12:30" >> "$TMP/psvirt.out" 2>> "$TMP/psvirt.err" &
	pv=$!; track_pid $pv
	wait_for 10 test -s "$TMP/ready"
	ready_ms=$(( $(date +%s%N) / 1000000 ))
}
# from 03:00: at 3600x a second of start-up is an hour of room time, and
# the night check needs samples well before psvirt's sunrise (06:00)
{ cat <<EOC
[psensd]
results = $TMP/ofb.results
database = $TMP/day.db
socket = $TMP/sock
period = 900
stale_after = 1800
EOC
device_tcp "$port" timeout=0.2 retries=1 backoff_min=0.1 backoff_max=0.5
points
cat <<EOC
[zone office]
sensor = sensor
task = lux
dim = dim
target_lux = 500
sensor_gain = 0.5
min_level = 0.1
EOC
} > "$TMP/day.conf"
check "psensd -n accepts the Modbus configuration" sh -c "\"$BIN/psensd\" -f '$TMP/day.conf' -n > /dev/null"
# psvirt only now, psensd right after it: their clocks start together
virt 03:00
check "psvirt ready" test -s "$TMP/ready"
v=$(virt_now "$ready_ms" 10800 3600)
"$BIN/psensd" -f "$TMP/day.conf" -t "$(hhmm "$v")" -x 3600 > "$TMP/psensd.out" 2> "$TMP/psensd.err" &
pd=$!; track_pid $pd
wait_for 20 "$BIN/psensctl" -s "$TMP/sock" ping > /dev/null
lag=$(clock_lag "$ready_ms" 10800 3600 "$TMP/sock")
# psvirt's 12:00 is psensd's 12:00 - lag
diag "psensd starts at $(hhmm "$v"), psvirt's clock $lag s of room time ahead"
q() { sqlite3 "$TMP/day.db" "$1" 2>/dev/null; }
# 15:00 room time (12 s): stop psvirt, a lost device; start it again 2 s later
wait_for 40 sh -c "[ \"\$(sqlite3 '$TMP/day.db' 'select max(tod_s) from samples' 2>/dev/null | cut -d. -f1)\" -ge 54000 ]"
kill "$pv"; wait "$pv" 2>/dev/null
sleep 2
virt 17:00
wait_for 10 grep -q "fault cleared" "$TMP/psensd.err" && sleep 0.5
kill -TERM $pd; wait $pd
kill "$pv"; wait "$pv" 2>/dev/null
diag "$(grep -e fault -e cleared "$TMP/psensd.err" | head -n 6)"
want=$(awk -v l="$L" 'BEGIN { print 500 / l }')
night=$(q "select output from samples where tod_s < 21000 and fault is null order by t limit 1 offset 1")
check "before sunrise the level is 500 lx / $L lx = $want ($night)" near "$night" "$want" 0.01
noon=$(q "select max(output) from samples where tod_s >= 36000 and tod_s < 43200 - $lag and fault is null")
check "10:00-12:00 the daylight is enough: the minimum level 0.1 (highest $noon)" near "$noon" 0.1 1e-6
check "the open circuit at 12:00 is a fault at the safe level" \
	test "$(q "select count(*) from samples where tod_s >= 43200 - $lag and tod_s < 45000 - $lag and output = 1 and fault like '%outside%'")" -ge 1
check "after 12:30 control resumes" test "$(q "select count(*) from samples where tod_s >= 45900 - $lag and tod_s < 54000 and fault is null and output < 0.2")" -ge 5
check "psvirt gone: the lights go to the safe level, the log names the device" \
	test "$(q "select count(*) from samples where output = 1 and fault like 'modbus io%'")" -ge 1
check "psvirt back: psensd resumes by itself" grep -q "fault cleared: control resumes" "$TMP/psensd.err"
check "the task meter's lux is logged beside the estimate" test "$(q "select count(*) from samples where task_lux > 0 and est_task_lux > 0")" -ge 20
mean=$(q "select avg(abs(est_task_lux - task_lux) / task_lux) from samples where fault is null and task_lux > 100")
check "estimated against the meter: mean relative difference $mean (< 3 %)" awk -v m="$mean" 'BEGIN { exit !(m < 0.03) }'
check "SIGTERM: lights at the safe level" grep -q "lights at the safe level 100 %" "$TMP/psensd.err"
done_testing
