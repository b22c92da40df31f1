#!/bin/sh
# SPDX-License-Identifier: ISC
# check: long
# psensd in real time (speed 1, a 0.5 s period) dated by the wall clock,
# whose steps are injected through the tests' hook (PSENSD_TEST_WALL_OFFSET:
# a file of seconds added to every wall reading, psensd(8)):
# - an NTP-like step of +3600 s, then back: each is logged with its size and
#   recorded as a clock_step event; the samples' utc follows the wall clock
#   (one gap of 3600 s plus a period, the rest a period apart) while their
#   t, the monotonic clock, keeps its period across the step; a start on a
#   wall clock behind the log's last sample runs, with the overlap warned;
# - a spring and an autumn daylight-saving change in Europe/Berlin: utc
#   advances by the period throughout, and every row's local column is the
#   zone's local time of its utc (Python's time.localtime under the same TZ):
#   01:59 to 03:00 in March, 02:59 back to 02:00 in October; and the dated
#   estimate's month and day of the year are that wall-clock date's.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v sqlite3 > /dev/null || skip_all "sqlite3 not installed"
PY=/usr/bin/python3
example_results
OFF="$TMP/offset"
conf() {   # conf DB
	sed "s|^results = .*|results = $TMP/state/ofb.results|; s|^database = .*|database = $TMP/$1\nsocket = $TMP/sock|; /^faults = /d; s|^period = .*|period = 0.5|" \
		config/psensd.conf > "$TMP/psensd.conf"
}
rows() { sqlite3 "$1" "SELECT count(*) FROM samples"; }
run() {   # run DB: psensd on the wall clock, its offset from $OFF
	conf "$1"
	PSENSD_TEST_WALL_OFFSET="$OFF" "$BIN/psensd" -f "$TMP/psensd.conf" > /dev/null 2> "$TMP/err" &
	PID=$!; track_pid $PID
}
# consecutive samples: utc and t differences, and local against Python's
# local time of utc (the TZ psensd ran under)
deltas() {
	sqlite3 -separator ' ' "$1" "SELECT t, utc, local FROM samples ORDER BY rowid" |
	$PY -c '
import math, sys, time
prev = None
for line in sys.stdin:
    t, u, date, hms = line.split()
    t, u = float(t), float(u)
    want = time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(math.floor(u)))
    if want != date + " " + hms:
        print("local", date, hms, "!=", want)
    if prev:
        print("dt %.3f du %.3f" % (t - prev[0], u - prev[1]))
    prev = (t, u)
'
}

# ---- a step of the wall clock
echo 0 > "$OFF"
TZ=UTC; export TZ
run step.db
wait_for 20 sh -c "[ \$(rows '$TMP/step.db') -ge 6 ]"
echo 3600 > "$OFF"
wait_for 10 grep -q "wall clock stepped" "$TMP/err"
n=$(rows "$TMP/step.db")
wait_for 20 sh -c "[ \$(rows '$TMP/step.db') -ge $((n + 6)) ]"
check "the step is logged with its size ($(grep -o 'wall clock stepped by [-+0-9.]* s' "$TMP/err" | head -n 1))" \
	grep -q 'the wall clock stepped by +3600.0[0-9]* s: ' "$TMP/err"
check "and recorded as a clock_step event" \
	test "$(sqlite3 "$TMP/step.db" "SELECT count(*) FROM events WHERE kind = 'clock_step' AND text LIKE '%+3600.%'")" = 1
deltas "$TMP/step.db" > "$TMP/d1"
check "every local column is the local time of its utc" sh -c "! grep -q '^local' '$TMP/d1'"
check "one utc gap of 3600 s plus a period ($(awk '$4 > 1000 { print $4 }' "$TMP/d1"))" \
	test "$(awk '$4 > 3600 && $4 < 3601.5' "$TMP/d1" | wc -l)" = 1
check "the other samples a period apart in utc (0.5 s, at most 1.5)" \
	test "$(awk '$4 < 0 || ($4 > 1.5 && $4 < 3600)' "$TMP/d1" | wc -l)" = 0
check "t, the monotonic clock, kept its period across the step (largest $(awk 'BEGIN { m = 0 } $2 > m { m = $2 } END { print m }' "$TMP/d1") s)" \
	test "$(awk '$2 <= 0 || $2 > 1.5' "$TMP/d1" | wc -l)" = 0
last=$(sqlite3 "$TMP/step.db" "SELECT utc FROM samples ORDER BY rowid DESC LIMIT 1")
check "the last sample is dated by the stepped wall clock (utc $last, now + 3600 = $(( $(date +%s) + 3600 )))" \
	awk -v u="$last" -v n="$(date +%s)" 'BEGIN { d = u - (n + 3600); exit !(d > -5 && d < 2) }'
echo 0 > "$OFF"
wait_for 10 grep -q "wall clock stepped by -3600" "$TMP/err"
check "the step back is logged too ($(grep -o 'wall clock stepped by -[0-9.]* s' "$TMP/err"))" \
	grep -q 'the wall clock stepped by -3[56][0-9][0-9]\.[0-9]* s' "$TMP/err"
check "psensd still answers" "$BIN/psensctl" -s "$TMP/sock" ping
kill $PID; wait $PID; rc=$?
check "psensd exits 0 on SIGTERM" test "$rc" = 0
# a start on a wall clock an hour behind the log: controlled all the same, the overlap warned
echo -3600 > "$OFF"
run step.db
wait_for 10 "$BIN/psensctl" -s "$TMP/sock" ping > /dev/null
check "a wall clock behind the log: warned with the overlap ($(grep -o 'this run starts .*' "$TMP/err" | cut -c1-90))" \
	grep -q 'the wall clock is behind the log: this run starts .*, before the last sample on record (.*); the samples from .* to .* will interleave' "$TMP/err"
check "and psensd runs" "$BIN/psensctl" -s "$TMP/sock" ping
kill $PID; wait $PID

# ---- daylight-saving changes in a named zone: the wall clock set 15 s before
# each (room for a slow start: a sanitized psensd on a loaded machine took
# more than 4 s to log its first sample)
TZ=Europe/Berlin; export TZ
dst() {   # dst NAME UTC-OF-THE-CHANGE
	at=$(date -u -d "$2" +%s)
	echo $((at - 15 - $(date +%s))) > "$OFF"
	run "$1.db"
	wait_for 40 sh -c "[ \$(rows '$TMP/$1.db') -ge 30 ]"
	kill $PID; wait $PID
	deltas "$TMP/$1.db" > "$TMP/$1.d"
	sqlite3 "$TMP/$1.db" "SELECT local FROM samples ORDER BY rowid" > "$TMP/$1.local"
}
dst spring 2026-03-29T01:00:00Z
check "spring: local time goes from 01:59 to 03:00 ($(head -n 1 "$TMP/spring.local") .. $(tail -n 1 "$TMP/spring.local"))" \
	sh -c "grep -q '^2026-03-29 01:59:5' '$TMP/spring.local' && grep -q '^2026-03-29 03:00:0' '$TMP/spring.local' && ! grep -q '^2026-03-29 02:' '$TMP/spring.local'"
check "spring: every local column is the zone's time of its utc" sh -c "! grep -q '^local' '$TMP/spring.d'"
check "spring: utc a period apart throughout" test "$(awk '$4 <= 0 || $4 > 1.5' "$TMP/spring.d" | wc -l)" = 0
check "spring: the dated estimate is the wall clock's date (March 29: month 3, day 31 + 28 + 29 = 88)" \
	grep -q 'the dated estimate: 2026-03-29, month 3, day 88 of the year' "$TMP/err"
dst autumn 2026-10-25T01:00:00Z
check "autumn: local time goes from 02:59 back to 02:00 ($(head -n 1 "$TMP/autumn.local") .. $(tail -n 1 "$TMP/autumn.local"))" \
	sh -c "grep -q '^2026-10-25 02:59:5' '$TMP/autumn.local' && grep -q '^2026-10-25 02:00:0' '$TMP/autumn.local'"
check "autumn: every local column is the zone's time of its utc" sh -c "! grep -q '^local' '$TMP/autumn.d'"
check "autumn: utc a period apart throughout" test "$(awk '$4 <= 0 || $4 > 1.5' "$TMP/autumn.d" | wc -l)" = 0
check "autumn: the dated estimate's date (October 25: month 10, day 273 + 25 = 298)" \
	grep -q 'the dated estimate: 2026-10-25, month 10, day 298 of the year' "$TMP/err"
check "no step was seen in either" sh -c "! grep -q 'wall clock stepped' '$TMP/err'"
done_testing
