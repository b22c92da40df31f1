#!/bin/sh
# SPDX-License-Identifier: ISC
# Issue 17, verdicts: psensctl accept-test on a simulated day of the
# loopback room with a task meter.  A zone whose constants match its room is
# ACCEPTED: the estimate against the meter over the day (rms and worst, the
# number of samples and the daylight bands they span), with daylight at
# 150 % of the target the lights at or below 35 %, in the dark the task at
# 90 % of the target or more, no cycling faster than the delay.  A zone
# whose sensor has a 1.5 V offset the control does not know (as a night
# session taken in daylight would leave it) is NOT ACCEPTED, and each test
# says what it measured.  The results are stored in the database.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v sqlite3 > /dev/null || skip_all "no sqlite3"
example_results
cat > "$TMP/a.conf" <<EOF2
[psensd]
results = state/ofb.results
database = state/a.db
period = 300
[simulate]
run_year = 2026
start = 05:00
end = 20:00
[device good]
driver = loopback
gain = 0.5
noise = 0.002
task_noise = 2
[point gs]
device = good
role = sensor
[point gd]
device = good
role = dim
[point gm]
device = good
role = task
[device bad]
driver = loopback
gain = 0.5
offset = 1.5
seed = 3
[point bs]
device = bad
role = sensor
[point bd]
device = bad
role = dim
[point bm]
device = bad
role = task
[zone good]
sensor = gs
dim = gd
task = gm
sensor_gain = 0.5
[zone bad]
sensor = bs
dim = bd
task = bm
sensor_gain = 0.5
EOF2
"$BIN/psensd" -f "$TMP/a.conf" -s > /dev/null 2> "$TMP/err" || { cat "$TMP/err"; exit 1; }
"$BIN/psensctl" -d "$TMP/state/a.db" accept-test good > "$TMP/good.out" 2>&1; rc=$?
diag "$(cat "$TMP/good.out")"
check "the good zone is ACCEPTED (exit $rc)" sh -c "test $rc = 0 && grep -q '^zone good: ACCEPTED (4 of 4 tests run, 0 failed)' '$TMP/good.out'"
check "verification measured over the day's samples, three daylight bands" \
	grep -q "verification   PASS .* over [0-9]* samples (at least 30): rms [0-9.]* % (at most 10 %).*below 50 % of the target in [1-9][0-9]*, 50-150 % in [1-9][0-9]*, 150 % and more in [1-9][0-9]*" "$TMP/good.out"
check "full daylight: the output at most 10 % (the minimum level)" \
	grep -q "full daylight  PASS .* the light output was at most 10.0 % (at most 35 %)" "$TMP/good.out"
check "low daylight: the task at 90 % of the target or more" grep -q "low daylight   PASS .*the task was at least 4[5-9][0-9] lx, 9[0-9].[0-9] % of 500 lx" "$TMP/good.out"
check "cycling: none" grep -q "cycling        PASS" "$TMP/good.out"
"$BIN/psensctl" -d "$TMP/state/a.db" accept-test bad > "$TMP/bad.out" 2>&1; rc=$?
diag "$(cat "$TMP/bad.out")"
check "the zone with the unknown offset is NOT ACCEPTED (exit $rc)" sh -c "test $rc = 1 && grep -q '^zone bad: NOT ACCEPTED' '$TMP/bad.out'"
check "its estimate fails verification" grep -q "verification   FAIL" "$TMP/bad.out"
check "and in the dark the task falls short" grep -q "low daylight   FAIL" "$TMP/bad.out"
check "the results are stored (8 rows, dated)" \
	test "$(sqlite3 "$TMP/state/a.db" "select count(*) from acceptance_tests where local is not null")" = 8
check "a zone not on record is an error" sh -c "! \"$BIN/psensctl\" -d '$TMP/state/a.db' accept-test nosuch 2> /dev/null"
done_testing
