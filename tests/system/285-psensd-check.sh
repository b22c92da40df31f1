#!/bin/sh
# SPDX-License-Identifier: ISC
# psensd -n judges what the daemon would refuse or
# mishandle later, all at once, each error with the configuration's file and
# line: sensor_min above sensor_max (the whole day at the safe level), a
# garbage results file (and its own line), a missing scene, a replay that
# is missing or does not parse; paths resolve against the configuration's
# directory, not the working directory.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
example_results
mkdir -p "$TMP/site/sub" "$TMP/elsewhere"
cp "$TMP/state/ofb.results" "$TMP/site/good.results"
printf '[psresults]\nversion = 1\n[condition x]\ntod_s = banana\n' > "$TMP/site/bad.results"
printf 'tod_s,daylight_v\n36000,0.5\n35000,0.6\n' > "$TMP/site/sub/bad.csv"
# a good configuration, its paths relative to its own directory
cat > "$TMP/site/good.conf" <<EOF2
[psensd]
results = good.results
[device room]
driver = loopback
[zone office]
device = room
EOF2
cat > "$TMP/site/bad.conf" <<EOF2
[psensd]
results = bad.results
scene = no-such.scene
sensor_min = 20
sensor_max = 9.9
[device room]
driver = loopback
replay = sub/bad.csv
replay_ratio = 400
[device room2]
driver = loopback
replay = sub/missing.csv
[zone office]
device = room
[zone hall]
device = room2
EOF2
PSENSD=$(cd "$(dirname "$BIN/psensd")" && pwd)/psensd
cd "$TMP/elsewhere"
"$PSENSD" -n -f ../site/good.conf > "$TMP/good.out" 2>&1; rc=$?
check "a good configuration passes from another directory (exit $rc): $(cat "$TMP/good.out")" test "$rc" = 0
"$PSENSD" -n -f ../site/bad.conf > "$TMP/bad.out" 2>&1; rc=$?
cd "$TOP"
diag "$(cat "$TMP/bad.out")"
check "the bad one is refused (exit $rc)" test "$rc" = 1
check "sensor_min above sensor_max, at the line of sensor_max" \
	grep -q "bad.conf:5: sensor_min 20 must be below sensor_max 9.9" "$TMP/bad.out"
check "the missing scene, at its line, resolved beside the file" \
	grep -q "bad.conf:3: scene: .*site/no-such.scene: No such file or directory" "$TMP/bad.out"
check "the garbage results, at the config's line and the file's own" \
	grep -q "bad.conf:2: results: .*site/bad.results:[0-9]*: " "$TMP/bad.out"
check "the replay that does not parse, at its line and the CSV's" \
	grep -q "bad.conf:8: replay: .*sub/bad.csv:3: " "$TMP/bad.out"
check "the missing replay, at its line" grep -q "bad.conf:12: replay: .*sub/missing.csv" "$TMP/bad.out"
check "all five at once" test "$(grep -c 'bad.conf:[0-9]*:' "$TMP/bad.out")" -ge 5
# the shipped configurations pass, as shipped: a copy of config/ with the
# build/ directory their paths name beside it (a BUILD= elsewhere leaves no
# build/ in the tree, and -n judges the directories psensd would write to)
mkdir -p "$TMP/ship/build"
cp -R config "$TMP/ship/config"
for f in config/psensd.conf config/example/site.conf config/example/dali-virtual.conf; do
	check "$f passes -n" "$BIN/psensd" -n -f "$TMP/ship/$f"
done
done_testing
