#!/bin/sh
# SPDX-License-Identifier: ISC
# A simulation per zone.  Three loopback zones on a
# simulated day: office and office2 on [psensd]'s scene (the example
# office, cosine sensor), hall with `scene = ofb-cone.scene` (the same room
# and pictures, a shielded sensor: a very different task/sensor ratio).
# psscene runs once per distinct scene; each zone's room, estimate and
# logged ratio are its own scene's: the summary quotes each zone's ratios,
# the hall's estimate of its room's true task lux is as good as the
# office's, and each zone's sample log carries its own ratio.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v sqlite3 > /dev/null || skip_all "no sqlite3"
mkdir -p "$TMP/site/build"
cp -R config/example/ofb config/example/ofb.scene config/example/ofb-cone.scene "$TMP/site/"
cat > "$TMP/site/z.conf" <<EOF2
[psensd]
scene = ofb.scene
results = build/ofb.results
database = build/z.db
period = 300
[simulate]
start = 06:00
end = 20:00
[device r1]
driver = loopback
gain = 0.5
[device r2]
driver = loopback
gain = 0.5
seed = 2
[device r3]
driver = loopback
gain = 0.5
seed = 3
[zone office]
device = r1
sensor_gain = 0.5
[zone office2]
device = r2
sensor_gain = 0.5
[zone hall]
device = r3
sensor_gain = 0.5
scene = ofb-cone.scene
EOF2
check "psensd -n accepts a zone's scene" "$BIN/psensd" -n -f "$TMP/site/z.conf"
"$BIN/psensd" -f "$TMP/site/z.conf" -s > "$TMP/out" 2> "$TMP/err"; rc=$?
check "the day runs (exit $rc)" test "$rc" = 0
check "psscene ran twice, once per distinct scene ($(grep -c 'running .*psscene' "$TMP/err"))" \
	test "$(grep -c 'running .*psscene' "$TMP/err")" = 2
check "the hall's results are named after its scene, beside [psensd]'s" test -s "$TMP/site/build/ofb-cone.results"
block() { awk -v z="zone $1 every" 'index($0, z) { p = 1; print; next } /^psensd:/ { p = 0 } p' "$TMP/out"; }
ratio() { block "$1" | sed -n 's/.*simulated ratios: daylight \([0-9.]*\),.*/\1/p'; }
rms() { block "$1" | sed -n 's/.*rms \([0-9.]*\) %.*/\1/p'; }
res() { awk -v k="$2" '/^\[/ { s = ($0 == "[summary]") } s && $1 == k { print $3; exit }' "$1"; }
want_o=$(res "$TMP/site/build/ofb.results" daylight_ratio_mean)
want_h=$(res "$TMP/site/build/ofb-cone.results" daylight_ratio_mean)
near() { awk -v a="$1" -v b="$2" -v t="$3" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(a != "" && d <= t) }'; }
check "office's ratio is its scene's ($(ratio office) against $want_o)" near "$(ratio office)" "$want_o" 0.01
check "office2 shares it ($(ratio office2))" near "$(ratio office2)" "$want_o" 0.01
check "hall's is the cone sensor's ($(ratio hall) against $want_h)" near "$(ratio hall)" "$want_h" 0.01
check "and differs from office's by far" awk -v a="$(ratio hall)" -v b="$want_o" 'BEGIN { exit !(a > 4 * b) }'
# the control runs on the mean of the scene's daylight ratios, the room on
# each date's: the estimate's error is bounded by their spread (the cone's
# is wider than the cosine's); on office's ratios it would be about 700 %
lo=$(res "$TMP/site/build/ofb-cone.results" daylight_ratio_min)
hi=$(res "$TMP/site/build/ofb-cone.results" daylight_ratio_max)
spread=$(awk -v a="$lo" -v b="$hi" -v m="$want_h" 'BEGIN { printf "%.2f", 100 * (b - a) / m }')
check "hall's estimate of its own room: rms $(rms hall) % (office's $(rms office) %), within its ratios' spread $spread %" \
	awk -v h="$(rms hall)" -v s="$spread" 'BEGIN { exit !(h != "" && h <= s) }'
q() { sqlite3 "$TMP/site/build/z.db" "$1"; }
check "each zone's log carries its ratio" \
	test "$(q "select count(distinct zone) from samples where abs(ratio - $want_h) < 0.01")" = 1
check "and it is the hall's" test "$(q "select distinct zone from samples where abs(ratio - $want_h) < 0.01")" = hall
# the socket's ratios request names the zone's own simulation
sed -e 's|^period = 300|period = 300\nsocket = sock|' "$TMP/site/z.conf" > "$TMP/site/zs.conf"
"$BIN/psensd" -f "$TMP/site/zs.conf" -t 10:00 -x 60 > /dev/null 2>&1 &
PID=$!; track_pid $PID
wait_for 10 sh -c "\"$BIN/psensctl\" -s '$TMP/site/sock' ping > /dev/null"
"$BIN/psensctl" -s "$TMP/site/sock" ratios hall > "$TMP/rh.out" 2>&1
"$BIN/psensctl" -s "$TMP/site/sock" ratios > "$TMP/r.out" 2>&1
"$BIN/psensctl" -s "$TMP/site/sock" ratios nosuch > /dev/null 2> "$TMP/rn.err"
kill -TERM $PID; wait $PID
check "ratios hall: the cone scene's results" grep -q "results: .*build/ofb-cone.results" "$TMP/rh.out"
check "ratios: [psensd]'s" grep -q "results: .*build/ofb.results" "$TMP/r.out"
check "ratios nosuch: an error ($(cat "$TMP/rn.err"))" grep -q "no zone 'nosuch'" "$TMP/rn.err"
done_testing
