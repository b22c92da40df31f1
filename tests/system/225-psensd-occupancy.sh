#!/bin/sh
# SPDX-License-Identifier: ISC
# Occupancy in the control (psensd.conf(5) vacancy_hold, vacant_level;
# daemon/occupancy.h), on the loopback room's day of people
# (config/example/occupancy.conf: occupied 08:00-12:00 and 13:00-17:30,
# the hold 900 s, the vacant level 0, steps every 60 s):
#  - the lights reach the vacant level at the vacancy plus the hold, not a
#    step before and at most one period after, and come back under the
#    daylight control at the next occupied report (never off while occupied);
#  - the hours: 8.50 h occupied, 5.50 h vacant and 4.75 h of it at the vacant
#    level (06:15-08:00, 12:15-13:00, 17:45-20:00) with no absences; the
#    random absences replay the same with the same seed;
#  - an input that does not answer is a fault counted as occupied (the
#    daylight control), and the hold starts again when it answers;
#  - a sensor fault in a vacant room still drives the safe level, and a
#    fault at a safe level of 0 stays one while the lights are off for it;
#  - a manual off (psensctl off) holds while occupied and through the lunch
#    vacancy, and ends at the next arrival;
#  - the log's occupied and true task lux columns, and the CSV export's;
#  - accept-test's occupancy test on the day; the record's hours and shading.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v sqlite3 > /dev/null || skip_all "sqlite3 not installed"
example_results
conf() {  # conf NAME [sed script]: the shipped example, its results and log in $TMP
	sed -e "s|^scene = .*|scene = example/ofb.scene|; s|^results = .*|results = state/ofb.results|" \
	    -e "s|^database = .*|database = state/$1.db|" -e "${2:-}" config/example/occupancy.conf > "$TMP/$1.conf"
}
run() {  # run NAME [sed script]
	conf "$@"
	"$BIN/psensd" -f "$TMP/$1.conf" -s > "$TMP/$1.out" 2> "$TMP/$1.err"
}
q() { sqlite3 "$TMP/state/$1.db" "$2"; }

# vacancy_delay is the same key as vacancy_hold: one of them
conf both "s|^vacancy_hold = 900|&\nvacancy_delay = 600|"
"$BIN/psensd" -f "$TMP/both.conf" -n > /dev/null 2> "$TMP/both.err"
check "vacancy_hold and vacancy_delay together are refused, naming the line" \
	grep -q "both.conf:[0-9]*: vacancy_delay: the same as vacancy_hold: give one" "$TMP/both.err"

# the shipped example, with its absences
run day
check "the example runs (exit 0)" test -s "$TMP/day.out"
check "every sample of the zone has its occupancy" test "$(q day "select count(*) from samples where occupied is null")" = 0
check "vacant before 08:00, at lunch and after 17:30" \
	test "$(q day "select count(*) from samples where occupied = 1 and (tod_s < 28800 or (tod_s >= 43200 and tod_s < 46800) or tod_s >= 63000)")" = 0
# each vacant sample's vacancy start: the first vacant sample after the last occupied one
VSTART="(select min(v.t) from samples v where v.occupied = 0 and v.t <= s.t and v.t > coalesce((select max(o.t) from samples o where o.occupied = 1 and o.t < s.t), -1e9))"
check "never at the vacant level before the hold (900 s) has passed" \
	test "$(q day "select count(*) from samples s where occupied = 0 and output = 0 and s.t - $VSTART < 900")" = 0
check "always at the vacant level from the hold plus one period (960 s)" \
	test "$(q day "select count(*) from samples s where occupied = 0 and output > 0 and s.t - $VSTART >= 960")" = 0
check "never off while occupied: the daylight control (min_level 0.1) at each arrival and after" \
	test "$(q day "select count(*) from samples where occupied = 1 and output < 0.1")" = 0
nv=$(grep -c 'zone office: [0-9: -]*vacant$' "$TMP/day.err")
check "at least one absence inside the occupied times ($nv vacancies: 06:00, 12:00, 17:30 and the absences)" test "$nv" -ge 4
check "the summary gives the occupied hours and the vacancy's savings" \
	grep -q '^  occupancy: occupied [0-9.]* h, vacant [0-9.]* h ([0-9.]* h at the vacant level 0 %, after 900 s); the vacancy saved [0-9.]* full-output hours$' "$TMP/day.out"
check "the time below target is counted over the occupied periods" grep -q 'of [0-9]* occupied periods' "$TMP/day.out"
run again
check "the same seed gives the same day of people" \
	test "$(q day "select group_concat(occupied) from samples")" = "$(q again "select group_concat(occupied) from samples")"
run seed8 "s|^seed = 7|seed = 8|"
check "another seed another day" \
	test "$(q day "select group_concat(occupied) from samples")" != "$(q seed8 "select group_concat(occupied) from samples")"

# no absences: the hours worked by hand, and the hold exact at lunch
run plain "s|^absences = .*|absences = 0|"
check "occupied 8.50 h, vacant 5.50 h, 4.75 h at the vacant level" \
	grep -q '^  occupancy: occupied 8.50 h, vacant 5.50 h (4.75 h at the vacant level 0 %' "$TMP/plain.out"
check "12:00-12:14 under the daylight control, off from 12:15 (12:00 + 900 s) to 12:59" \
	test "$(q plain "select sum(output >= 0.1) || ',' || sum(output = 0) from samples where tod_s >= 43200 and tod_s < 46800")" = "16,45"
check "back at 13:00: the daylight control at the arrival's step" \
	test "$(q plain "select min(output) >= 0.1 from samples where tod_s >= 46800 and tod_s < 48000")" = 1
check "the log holds the simulated true task lux beside the measured" \
	test "$(q plain "select count(*) from samples where true_task_lux is null or abs(true_task_lux - task_lux) > 20")" = 0
("$BIN/psensctl" -d "$TMP/state/plain.db" export --zone office --since 2026-03-18T12:14 --until 2026-03-18T12:15) > "$TMP/plain.csv"
check "CSV export: occupied and simulated_true_task_lux columns, units in the names" \
	sh -c "head -n 1 '$TMP/plain.csv' | grep -q ',task_lux,.*,fault,occupied,simulated_true_task_lux$'"
check "CSV export: 12:14 vacant at the daylight level, 12:15 at the vacant level, the truth given" \
	sh -c "sed -n 2p '$TMP/plain.csv' | grep -q ',0.1,.*,0,[0-9.]*$' && sed -n 3p '$TMP/plain.csv' | grep -q ',44100,[0-9.]*,0,.*,0,[0-9.]*$'"

"$BIN/psensctl" -d "$TMP/state/plain.db" accept-test office > "$TMP/accept.out" 2>&1
check "accept-test: the occupancy test passes, its three vacancies (06:00, 12:00, 17:30) and two arrivals judged" \
	sh -c "grep -q '^  occupancy *PASS .* in 3 of 3 vacancies .*the lights on at 2 of 2 arrivals' '$TMP/accept.out' && grep -q ' of 5 tests run' '$TMP/accept.out'"

"$BIN/psensctl" -d "$TMP/state/plain.db" report office -o "$TMP/plain.pdf" > /dev/null 2>&1
if command -v pdftotext > /dev/null; then
	pdftotext -layout "$TMP/plain.pdf" "$TMP/plain.txt"
	# the record ends at the last sample (19:59): vacant 5.50 h less a minute
	check "the record: the zone's hours occupied and vacant and the vacancies' savings" \
		grep -q "occupied 8.50 h, vacant 5.48 h, the vacancies saved [0-9.]* full-load h" "$TMP/plain.txt"
	check "the record: the zone table's occupied/vacant column (8.5/5.5 h)" grep -q "8.5/5.5 h, [0-9.]* flh" "$TMP/plain.txt"
	check "the record: vacancy shaded on the zone's charts, in their legends" \
		test "$(pdftotext -raw "$TMP/plain.pdf" - | grep -o 'vacant' | wc -l)" -ge 3
else
	skip "pdftotext (poppler-utils) not installed: the record's text not read"
fi

# the input does not answer 12:20-12:40, in the lunch vacancy
run dead "s|^absences = .*|absences = 0\ndead = 12:20-12:40|"
check "the input's fault is logged, counted as occupied" \
	grep -q 'zone office: .*12:20 fault: occupancy input pir: .*does not answer: taken as occupied' "$TMP/dead.err"
check "its fault and its end are in the events" \
	test "$(q dead "select group_concat(kind) from events where zone = 'office' and text like 'occupancy input%'")" = "fault,fault cleared"
check "12:20-12:39: occupied, the daylight control" \
	test "$(q dead "select sum(occupied = 1 and output >= 0.1) from samples where tod_s >= 44400 and tod_s < 45600")" = 20
check "from 12:40 the hold again: off from 12:55, not before" \
	test "$(q dead "select sum(output >= 0.1) || ',' || sum(output = 0) from samples where tod_s >= 45600 and tod_s < 46800")" = "15,5"

# the sensor's replies drop 12:30-12:40 while the room is vacant
run drop "s|^absences = .*|absences = 0|; s|^lag_tau = .*|&\nfaults = drop 12:30-12:40|"
check "a sensor fault in a vacant room drives the safe level (100 %)" \
	sh -c "grep -q 'zone office: .*12:3[0-9] fault: no reading since' '$TMP/drop.err' && test \"\$(sqlite3 '$TMP/state/drop.db' \"select count(*) from samples where fault is not null and output = 1 and occupied = 0\")\" -ge 5"
check "and back at the vacant level after it (12:40-12:59)" \
	test "$(q drop "select count(*) from samples where tod_s >= 45600 and tod_s < 46800 and output > 0")" = 0

# a safe level of 0: an open sensor at 12:00 stays a fault while the lights
# are off for it (below the range is the dark room only when nothing failed)
run safe0 "s|^absences = .*|absences = 0|; s|^safe_level = .*|safe_level = 0|; s|^lag_tau = .*|&\nfaults = open 12:00-12:20|"
check "safe level 0: one fault 12:00-12:20, no fault and clearing each step" \
	sh -c "test \"\$(grep -c 'fault cleared' '$TMP/safe0.err')\" = 1 && test \"\$(sqlite3 '$TMP/state/safe0.db' \"select count(distinct tod_s) from samples where fault is not null\")\" = 20"

# a manual off at 11:5x, real time at 300x with the control socket
conf off "s|^absences = .*|absences = 0|; s|^period = 60|&\nsocket = sock|"
"$BIN/psensd" -f "$TMP/off.conf" -t 11:50 -x 300 > "$TMP/off.out" 2> "$TMP/off.err" &
pid=$!; track_pid $pid
export PSENSD_SOCKET="$TMP/sock"
wait_for 20 "$BIN/psensctl" ping > /dev/null
check "psensctl off is accepted" "$BIN/psensctl" off office
check "the manual off ends at the arrival after lunch" wait_for 60 grep -q 'zone office: the manual off ends: occupied again' "$TMP/off.err"
wait_for 10 sh -c "test \"\$(sqlite3 '$TMP/state/off.db' 'select count(*) from samples where tod_s > 46900')\" -ge 2"
kill "$pid"; wait "$pid" 2>/dev/null
off=$(q off "select min(t) from samples where output = 0")
check "off while occupied (before 12:00)" test "$(q off "select count(*) from samples where output = 0 and occupied = 1 and tod_s < 43200")" -ge 1
check "off from the command through the vacancy to 13:00" \
	test "$(q off "select count(*) from samples where t >= $off and tod_s < 46800 and output > 0")" = 0
check "the daylight control again from the arrival at 13:00" \
	test "$(q off "select count(*) from samples where tod_s >= 46800 and output < 0.1")" = 0
done_testing
