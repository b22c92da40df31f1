#!/bin/sh
# SPDX-License-Identifier: ISC
# Dates.  Two simulated days of the example room into
# one database: the first is dated 03-18 of [simulate] run_year, the second,
# finding that date on record, the next day (no overdraw); every sample,
# event and session row carries UTC and the local date and time; the
# summary shows dates and the duration; -d sets the date, and a date
# before the last sample on record is refused with the overlap named (its
# rows would interleave with those logged); a run over
# midnight in real time (-t 23:30 -x 3600) summarises across the day
# boundary with both dates.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v sqlite3 > /dev/null || skip_all "no sqlite3"
example_results
export TZ=UTC0   # the local texts checked below against UTC
cat > "$TMP/day.conf" <<EOF2
[psensd]
results = state/ofb.results
database = state/d.db
period = 300
[simulate]
date = 03-18
run_year = 2026
start = 06:00
end = 20:00
[device room]
driver = loopback
gain = 0.5
faults = open 12:00-12:20
[zone office]
device = room
sensor_gain = 0.5
EOF2
q() { sqlite3 "$TMP/state/d.db" "$1"; }
"$BIN/psensd" -f "$TMP/day.conf" -s > "$TMP/out1" 2> "$TMP/err1"
"$BIN/psensd" -f "$TMP/day.conf" -s > "$TMP/out2" 2> "$TMP/err2"
check "the first run's summary: $(head -n 1 "$TMP/out1" | cut -c1-80)" \
	grep -q "^psensd: simulated 2026-03-18 06:00 to 2026-03-18 20:00 (14 h 0 min" "$TMP/out1"
check "the second run is the next day: $(grep 'this run starts' "$TMP/err2")" \
	grep -q "this run starts 2026-03-19 06:00, not 2026-03-18 06:00" "$TMP/err2"
check "and its summary says so" grep -q "^psensd: simulated 2026-03-19 06:00 to 2026-03-19 20:00" "$TMP/out2"
check "fault lines carry the date" grep -q "zone office: 2026-03-19 12:00 fault: sensor reads" "$TMP/err2"
days=$(q "select group_concat(d) from (select distinct substr(local, 1, 10) d from samples order by d)")
check "two distinct days on record ($days)" test "$days" = "2026-03-18,2026-03-19"
check "no two samples of a zone share a UTC" \
	test "$(q "select count(*) from (select zone, utc from samples group by zone, utc having count(*) > 1)")" = 0
check "every sample's UTC is its day's midnight + t" \
	test "$(q "select count(*) from samples where utc - t not in (1773792000, 1773878400)")" = 0
check "and its local text that UTC's" \
	test "$(q "select count(*) from samples where local != strftime('%Y-%m-%d %H:%M:%S', utc, 'unixepoch')")" = 0
check "the faults are events with dates ($(q "select group_concat(local, ', ') from events where kind = 'fault'"))" \
	test "$(q "select group_concat(local, ',') from events where kind = 'fault'")" = "2026-03-18 12:00:00,2026-03-19 12:00:00"
# -d: a stated date
"$BIN/psensd" -f "$TMP/day.conf" -s -d 2026-06-21 > "$TMP/out3" 2> "$TMP/err3"
check "-d 2026-06-21 dates the run" grep -q "^psensd: simulated 2026-06-21 06:00 to 2026-06-21 20:00" "$TMP/out3"
check "-d refuses a non-date" sh -c "! \"$BIN/psensd\" -f \"$TMP/day.conf\" -s -d 2026-02-30 2> /dev/null"
# -d back onto days on record: refused, the overlap named, nothing logged
n=$(q "select count(*) from samples")
"$BIN/psensd" -f "$TMP/day.conf" -s -d 2026-03-19 > "$TMP/out4" 2> "$TMP/err4"; rc=$?
check "-d 2026-03-19 with 2026-06-21 on record: refused (exit $rc)" test "$rc" = 1
check "the overlap named: $(grep 'before the last sample' "$TMP/err4" | cut -c1-120)" \
	grep -q "this run would start 2026-03-19 06:00, before the last sample on record (2026-06-21 19:55): its samples would interleave with those logged from 2026-03-19 06:00 to 2026-06-21 19:55" "$TMP/err4"
check "no sample was added ($n, then $(q "select count(*) from samples"))" test "$(q "select count(*) from samples")" = "$n"
"$BIN/psensd" -f "$TMP/day.conf" -s -d 2026-06-22 > /dev/null 2> "$TMP/err5"; rc=$?
check "-d 2026-06-22, after the log's end: runs (exit $rc)" test "$rc" = 0
# over midnight in real time: 23:30 at 3600x, stopped after 1.5 s (about 90 min)
sed -e 's|^database = .*|database = state/m.db|' -e 's|^period = 300|period = 60\nsocket = sock|' "$TMP/day.conf" > "$TMP/m.conf"
"$BIN/psensd" -f "$TMP/m.conf" -t 23:30 -x 3600 > "$TMP/outm" 2> "$TMP/errm" &
PID=$!; track_pid $PID
sleep 1.5
kill -TERM $PID; wait $PID
check "over midnight: $(head -n 1 "$TMP/outm" | cut -c1-70)" \
	grep -q "^psensd: ran 2026-03-18 23:30 to 2026-03-19 0[01]:[0-9][0-9] ([0-9]* h [0-9]* min\|[0-9]* min" "$TMP/outm"
check "the samples after midnight are dated the next day" \
	test "$(sqlite3 "$TMP/state/m.db" "select count(*) from samples where t >= 86400 and substr(local, 1, 10) != '2026-03-19'")" = 0
# the site's time zone: [psensd] timezone (a POSIX rule here: no tzdata
# needed), whatever the process's TZ (UTC above)
sed -e 's|^database = .*|database = state/tz.db\ntimezone = CET-1CEST,M3.5.0,M10.5.0/3|' "$TMP/day.conf" > "$TMP/tz.conf"
"$BIN/psensd" -f "$TMP/tz.conf" -s > "$TMP/outz" 2> "$TMP/errz"
check "timezone: the run is dated in the site's zone ($(head -n 1 "$TMP/outz" | cut -c1-60))" \
	grep -q "^psensd: simulated 2026-03-18 06:00 to 2026-03-18 20:00" "$TMP/outz"
check "its clock 0 is the site's midnight, 2026-03-17 23:00 UTC" \
	test "$(sqlite3 "$TMP/state/tz.db" "select count(*) from samples where utc - t != 1773788400")" = 0
check "and the local text is the site's" \
	test "$(sqlite3 "$TMP/state/tz.db" "select local from samples order by t limit 1")" = "2026-03-18 06:00:00"
printf '[psensd]\nresults = r\ntimezone = Nowhere/Atlantis\n[device x]\ndriver = loopback\n[zone z]\ndevice = x\n' > "$TMP/badtz.conf"
check "an unknown zone is refused at its line: $("$BIN/psensd" -n -f "$TMP/badtz.conf" 2>&1 | grep timezone)" \
	sh -c "\"$BIN/psensd\" -n -f '$TMP/badtz.conf' 2>&1 | grep -q 'badtz.conf:3: timezone: .Nowhere/Atlantis. is neither'"
done_testing
