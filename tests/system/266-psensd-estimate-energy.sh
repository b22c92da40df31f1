#!/bin/sh
# SPDX-License-Identifier: ISC
# The estimate during a session and the energy over a reload, on the
# loopback room in real time at 600x.
# 1: while a day session holds the lights, the logged estimate follows the
#    room (it must not freeze at the value before the session): every logged
#    estimate of the session within 10 % of the task meter, and the
#    estimates move as the meter does.
# 2: the exit summary's energy after a SIGHUP reload is over the same span
#    as its hours: it agrees with the commanded output in the sample log
#    weighted by time, from the run's start event (within 3 points: the
#    lamp's fade), as it does without a reload.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v sqlite3 > /dev/null || skip_all "no sqlite3"
example_results
S="$TMP/sock"
conf() {  # conf DB
	cat <<EOF2
[psensd]
results = state/ofb.results
database = $1
socket = sock
period = 60
[simulate]
sunrise = 06:00
sunset = 18:30
[device room]
driver = loopback
gain = 0.5
offset = 0.05
noise = 0.002
task_noise = 2
seed = 11
fade_rate = 0.2
[point sensor]
device = room
role = sensor
[point lamp]
device = room
role = dim
[point meter]
device = room
role = task
[zone office]
sensor = sensor
dim = lamp
task = meter
sensor_gain = 0.5
min_level = 0.1
EOF2
}
ctl() { "$BIN/psensctl" -s "$S" "$@"; }
start() {  # start CONF HH:MM
	"$BIN/psensd" -f "$1" -t "$2" -x 600 > "$TMP/out" 2>> "$TMP/err" &
	PID=$!; track_pid $PID
	wait_for 10 sh -c "\"$BIN/psensctl\" -s \"$S\" ping > /dev/null"
}
stop() { kill -TERM $PID; wait $PID 2>/dev/null; }
q() { sqlite3 "$1" "$2"; }

## 1. the estimate during a day session
conf state/a.db > "$TMP/a.conf"
start "$TMP/a.conf" 09:00
ctl calibrate office day 0.3 > /dev/null
wait_for 30 sh -c "\"$BIN/psensctl\" -s \"$S\" calibrate office status | grep -q 'state: done'"
stop
DB="$TMP/state/a.db"
# from 10 s of room time after the session's start: the lamp fades to the
# session's level at 20 % a second (fade_rate), and a sample inside the fade
# reads a lamp the estimate (which knows the command) has not yet seen
span="(select started + 10 from cal_sessions where id = 1) and (select ended from cal_sessions where id = 1)"
n=$(q "$DB" "select count(*) from samples where t between $span and est_task_lux is not null and task_lux > 0")
worst=$(q "$DB" "select printf('%.2f', max(abs(est_task_lux - task_lux) / task_lux) * 100) from samples where t between $span and est_task_lux is not null and task_lux > 0")
est=$(q "$DB" "select printf('%.0f to %.0f', min(est_task_lux), max(est_task_lux)) from samples where t between $span")
lux=$(q "$DB" "select printf('%.0f to %.0f', min(task_lux), max(task_lux)) from samples where t between $span")
check "the session logged samples ($n)" test "$n" -ge 20
check "during the session the estimate ($est lx) follows the meter ($lux lx): worst $worst %" \
	awk -v w="$worst" 'BEGIN { exit !(w != "" && w <= 10) }'
distinct=$(q "$DB" "select count(distinct round(est_task_lux)) from samples where t between $span")
check "and moves ($distinct distinct values)" test "$distinct" -ge 5

## 2. energy over a reload
energy() { sed -n 's/^  energy: \([0-9.]*\) %.*/\1/p' "$TMP/out"; }
# the log's energy over the same span: full output from the start (the
# start event) to the first step, then each sample's output until the next
logmean() { q "$1" "with s as (select t, output, lead(t) over (order by t) as tn from samples),
	st as (select min(t) as t0 from events where kind = 'start')
	select printf('%.2f', 100 * ((select min(t) from samples) - t0 + sum(output * (tn - t)))
	                      / ((select max(t) from samples) - t0)) from s, st where tn is not null"; }
for reload in no yes; do
	conf "state/e-$reload.db" > "$TMP/e.conf"
	start "$TMP/e.conf" 06:30
	sleep 3
	if [ $reload = yes ]; then
		kill -HUP $PID
		wait_for 5 grep -q reloaded "$TMP/err"
	fi
	sleep 3
	stop
	e=$(energy); m=$(logmean "$TMP/state/e-$reload.db")
	check "reload $reload: the summary's energy $e % of full output agrees with the log's time-weighted output $m %" \
		awk -v a="$e" -v b="$m" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(a != "" && d <= 3) }'
done
done_testing
