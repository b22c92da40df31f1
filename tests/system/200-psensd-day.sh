#!/bin/sh
# SPDX-License-Identifier: ISC
# psensd on the loopback room over a simulated day: the real binary, a
# configuration in a temporary directory, results recomputed by psscene when
# stale, the set-point control's summary against what it must be, and a
# sensor fault that drives the lights to the safe level and clears.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
mkdir -p "$TMP/example"
cp -R config/example/ofb config/example/ofb.scene "$TMP/example/"
sed "s|^results = .*|results = state/ofb.results|; s|^database = .*|database = state/psensd.db|" config/psensd.conf > "$TMP/psensd.conf"
mkdir -p "$TMP/state"
PATH="$TOP/$BIN:$PATH" "$BIN/psensd" -f "$TMP/psensd.conf" -n > "$TMP/n.out" 2>&1
check "-n checks the config" grep -q "configuration OK" "$TMP/n.out"
PATH="$TOP/$BIN:$PATH" "$BIN/psensd" -f "$TMP/psensd.conf" -s > "$TMP/out" 2> "$TMP/err"
check "psensd ran psscene for the missing results" grep -q "running" "$TMP/err"
check "results written" test -s "$TMP/state/ofb.results"
num() { sed -n "s/.*$1[^0-9-]*\([-0-9.]*\).*/\1/p" "$TMP/out" | head -n 1; }
check "never below the 500 lx target by more than 2 %: $(grep 'below' "$TMP/out")" \
	grep -q "time below target (by more than 2 %): 0.0 %" "$TMP/out"
energy=$(num "energy:")
golden=$(sed -n 's/.*energy: \([0-9.]*\) %.*/\1/p' tests/data/golden-day.summary)
check "energy $energy % of full, the golden day's $golden % (make golden explains a change)" \
	test "$energy" = "$golden"
check "the estimate tracks the truth: $(grep estimated "$TMP/out")" \
	awk -v r="$(sed -n 's/.*rms \([0-9.]*\) %.*/\1/p' "$TMP/out")" 'BEGIN { exit !(r < 1.0) }'
check "the open-circuit fault at 12:00 drives the lights to 100 %" grep -q "12:00 fault: sensor reads 0.000 V.*safe level 100 %" "$TMP/err"
check "and control resumes at 12:20" grep -q "12:20 fault cleared" "$TMP/err"
check "20 periods at the safe level" grep -q "periods at the safe level after a fault: 20" "$TMP/out"
# every sample is in the log, and psensctl exports it (sqlite3 is the peer)
check "840 samples in the database" test "$(sqlite3 "$TMP/state/psensd.db" 'select count(*) from samples')" = 840
check "integrity check" test "$(sqlite3 "$TMP/state/psensd.db" 'pragma integrity_check')" = ok
check "WAL journal" test "$(sqlite3 "$TMP/state/psensd.db" 'pragma journal_mode')" = wal
"$BIN/psensctl" -d "$TMP/state/psensd.db" export --csv > "$TMP/log.csv"
check "export: header and 840 rows" test "$(wc -l < "$TMP/log.csv")" = 841
check "export --csv header (the old form)" test "$(head -n 1 "$TMP/log.csv")" = "t,tod_s,sensor_v,output,est_task_lux,task_lux,daylight_v,daylight_lux,condition,ratio,fault,zone"
# the dates: psensctl export (its time and utc), and the local column in the database
"$BIN/psensctl" -d "$TMP/state/psensd.db" export > "$TMP/dated.csv"
check "export: every sample dated (time and utc)" test "$(awk -F, 'NR > 1 && $2 ~ /^20[0-9][0-9]-[01][0-9]-[0-3][0-9]T/ && $3 > 0' "$TMP/dated.csv" | wc -l)" = 840
check "every sample has its local date and time" test "$(sqlite3 "$TMP/state/psensd.db" "select count(*) from samples where local = strftime('%Y-%m-%d %H:%M:%S', utc, 'unixepoch', 'localtime')")" = 840
check "the 20 fault samples carry their reason and full output" \
	test "$(grep -c ',1,.*outside 0.01 to 9.9 V' "$TMP/log.csv")" = 20
# every sample against the golden day, column by column within the
# tolerances of tests/golden/compare.py (tests/golden/README.md says why)
/usr/bin/python3 tests/golden/compare.py tests/data/golden-day.csv "$TMP/log.csv" > "$TMP/golden.out"
check "every sample is the golden day's: $(tail -n 1 "$TMP/golden.out")" \
	grep -q "the same within the tolerances" "$TMP/golden.out"
grep -q "the same within the tolerances" "$TMP/golden.out" || sed 's/^/# /' "$TMP/golden.out"
"$BIN/psensctl" -d "$TMP/nonexistent.db" export --csv > /dev/null 2> "$TMP/ctl.err"
check "a missing database is a clear error" grep -q "nonexistent.db" "$TMP/ctl.err"
# the exported day replayed through the loopback room gives the same day
sed "s|^seed = .*|seed = 7\nreplay = $TMP/log.csv|; /^database = /d" "$TMP/psensd.conf" > "$TMP/replay.conf"
"$BIN/psensd" -f "$TMP/replay.conf" -s > "$TMP/replay.out" 2>&1
e1=$(sed -n 's/.*energy: \([0-9.]*\) %.*/\1/p' "$TMP/out"); e2=$(sed -n 's/.*energy: \([0-9.]*\) %.*/\1/p' "$TMP/replay.out")
check "the replayed day costs the same energy ($e1 % vs $e2 %, within 0.5 points)" \
	awk -v a="$e1" -v b="$e2" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d <= 0.5) }'
printf 'tod_s,daylight_v,daylight_lux\n5,1,100\n1,1,100\n' > "$TMP/bad.csv"
sed "s|^seed = .*|seed = 7\nreplay = $TMP/bad.csv|; /^database = /d" "$TMP/psensd.conf" > "$TMP/badreplay.conf"
"$BIN/psensd" -f "$TMP/badreplay.conf" -s > /dev/null 2> "$TMP/badreplay.err"
check "a bad replay file is named with its line" grep -q "bad.csv:3: tod_s 1 does not follow 5" "$TMP/badreplay.err"
# the second run reuses the results
PATH="$TOP/$BIN:$PATH" "$BIN/psensd" -f "$TMP/psensd.conf" -s > /dev/null 2> "$TMP/err2"
check "fresh results are not recomputed" sh -c "! grep -q running '$TMP/err2'"
# bad configs: every error with file:line, in one pass
printf '[psensd]\nperiod = -1\n[zone a]\ndevice = nosuch\nalgorithm = magic\n' > "$TMP/bad.conf"
"$BIN/psensd" -f "$TMP/bad.conf" -n 2> "$TMP/bad.err" && not_ok "bad config accepted" || ok "bad config refused"
check "period error at line 2" grep -q "bad.conf:2: period: -1 is outside" "$TMP/bad.err"
check "missing device at line 4" grep -q "bad.conf:4: device: no \[device nosuch\]" "$TMP/bad.err"
check "bad algorithm at line 5" grep -q "bad.conf:5: algorithm: 'magic' is not one of" "$TMP/bad.err"
check "missing results key" grep -q "needs 'results'" "$TMP/bad.err"
done_testing
