#!/bin/sh
# SPDX-License-Identifier: ISC
# The acceptance verdicts: psensctl accept-test on a simulated day of the
# loopback room with a task meter.  A zone whose constants match its room is
# ACCEPTED: the estimate against the meter over the day (rms and worst, the
# number of samples and the daylight bands they span), with daylight at
# 150 % of the target the lights at or below 35 %, in the dark the task at
# 90 % of the target or more, no cycling faster than the delay.  A zone
# whose sensor has a 1.5 V offset the control does not know (as a night
# session taken in daylight would leave it) is NOT ACCEPTED, and each test
# says what it measured.  The results are stored in the database.
# While psensd runs it holds the database (one writer): psensctl without
# -d asks psensd to run the tests on its own log; with -d the file must be
# psensd's, and is never created or changed otherwise.
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

# psensd running on the same log: the socket route
sed 's|^period = 300|period = 300\nsocket = state/a.sock|' "$TMP/a.conf" > "$TMP/live.conf"
# (started in its directory with a relative -f: every path it names is relative to that)
ABSBIN=$(cd "$BIN" && pwd)
(cd "$TMP" && exec "$ABSBIN/psensd" -f live.conf -t 10:00 -x 600 2> "$TMP/live.err") & LIVE=$!
wait_for 20 "$BIN/psensctl" -s "$TMP/state/a.sock" ping
# the point model's acceptance: the last run on record when psensd started
acc() { "$BIN/psensctl" -s "$TMP/state/a.sock" -j status "$1" | /usr/bin/python3 -c 'import json, sys; print(json.load(sys.stdin)["zones"][0]["points"].get("acceptance"))'; }
ag=$(acc good); ab=$(acc bad)
check "status' acceptance point: the verdicts on record (good $ag, bad $ab)" test "$ag" = accepted -a "$ab" = "not accepted"
(cd / && "$ABSBIN/psensctl" -s "$TMP/state/a.sock" log good -n 2) > "$TMP/log.out" 2>&1; rc=$?
diag "$(cat "$TMP/log.out")"
check "psensctl in another directory reads the log psensd names (exit $rc)" \
	sh -c "test $rc = 0 && test \$(grep -c ' good ' '$TMP/log.out') = 2"
"$BIN/psensctl" -s "$TMP/state/a.sock" accept-test good > "$TMP/live.out" 2>&1; rc=$?
diag "$(cat "$TMP/live.out")"
check "psensd runs the tests on its own log while it runs (exit $rc)" \
	sh -c "test $rc = 0 && grep -q '^zone good: ACCEPTED (4 of 4 tests run, 0 failed)' '$TMP/live.out'"
check "and stores them where a report reads them (12 rows)" \
	test "$(sqlite3 "$TMP/state/a.db" "select count(*) from acceptance_tests where local is not null")" = 12
"$BIN/psensctl" -s "$TMP/state/a.sock" -j accept-test bad --samples 40 > "$TMP/live.json" 2>&1; rc=$?
check "-j gives psensd's JSON reply, the verdict and each test (exit $rc)" \
	sh -c "test $rc = 1 && grep -q '\"verdict\":\"NOT ACCEPTED\"' '$TMP/live.json' && grep -q '(at least 40)' '$TMP/live.json'"
"$BIN/psensctl" -s "$TMP/state/a.sock" accept-test nosuch > /dev/null 2> "$TMP/nosuch.err"; rc=$?
check "a zone psensd does not run is an error (exit $rc)" sh -c "test $rc = 1 && grep -q \"no zone 'nosuch'\" '$TMP/nosuch.err'"
"$BIN/psensctl" -d "$TMP/state/a.db" accept-test good > /dev/null 2> "$TMP/held.err"; rc=$?
diag "$(cat "$TMP/held.err")"
check "-d on the file psensd holds says to ask psensd (exit $rc)" \
	sh -c "test $rc = 1 && grep -q 'in use by psensd pid $LIVE.*without -d, psensctl asks psensd' '$TMP/held.err'"
if command -v pdftotext > /dev/null; then
	(cd / && "$ABSBIN/psensctl" -s "$TMP/state/a.sock" report good -o "$TMP/live.pdf") > /dev/null 2>&1
	pdftotext "$TMP/live.pdf" "$TMP/live.txt" 2> /dev/null
	check "the report through the socket, from another directory, names psensd's configuration and its SHA-256" \
		grep -q "$(sha256sum "$TMP/live.conf" | cut -d' ' -f1)" "$TMP/live.txt"
else
	skip "the report's configuration" "no pdftotext"
fi
kill $LIVE; wait $LIVE

# -d never makes or changes a file that is not psensd's
"$BIN/psensctl" -d "$TMP/none.db" accept-test good 2> "$TMP/none.err"; rc=$?
check "-d on a missing file: an error naming it, no file made (exit $rc)" \
	sh -c "test $rc = 1 && grep -q '$TMP/none.db' '$TMP/none.err' && ! test -e '$TMP/none.db' && ! test -e '$TMP/none.db.lock'"
sqlite3 "$TMP/other.db" "create table parts(a); insert into parts values(1);"
"$BIN/psensctl" -d "$TMP/other.db" accept-test good 2> "$TMP/other.err"; rc=$?
diag "$(cat "$TMP/other.err")"
check "-d on another program's database: refused naming it, left as it was (exit $rc)" \
	sh -c "test $rc = 1 && grep -q '$TMP/other.db: not a psensd database' '$TMP/other.err' && test \"\$(sqlite3 '$TMP/other.db' 'select count(*) from sqlite_master')\" = 1"
done_testing
