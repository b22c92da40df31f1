#!/bin/sh
# SPDX-License-Identifier: ISC
# A rooftop lux meter over Modbus: psvirt plays the overcast 5 July of the
# synthetic year ([simulate] year = yes) and serves the hour's global
# horizontal illuminance at holding registers 210-211 (u32); the real
# psensd reads it through the Modbus driver as a point with role rooftop
# and the dated estimate takes the sky class from it.  Both clocks run at
# 3600x from 10:00; one control step per 15 simulated minutes.  Checked from
# psensd's own samples: 10:30-16:00 the class is overcast, as the weather
# file's own hours there say (from its direct and diffuse), not the month's
# typical class.
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/peers/common.sh"
[ -x "$BIN/psvirt" ] || skip_all "psvirt not built"
command -v sqlite3 > /dev/null || skip_all "sqlite3 not installed"
example_results
# this test needs a known day shape: the synthetic year's overcast 5 July in
# a mostly clear July (tests/data/weather/README.md), not the example's
# measured year
cp tests/data/weather/sf-synthetic.wea "$TMP/example/ofb/weather/"
sed -i 's|^weather = .*|weather = ofb/weather/sf-synthetic.wea|' "$TMP/example/ofb.scene"
"$BIN/psscene" -q -N -o "$TMP/state/ofb.results" "$TMP/example/ofb.scene"
R=$TMP/state/ofb.results
sed "s|^results = .*|results = $R|; s|^database = .*|database = $TMP/state/virt.db|; s|^scene = .*|scene = $TMP/example/ofb.scene|; s/^faults = .*//; s/^date = .*/date = 07-05/; s/^\[simulate\]/[simulate]\nyear = yes/" \
	config/psensd.conf > "$TMP/virt.conf"
typical=$(awk '$1 == "overcast_07" || $1 == "clear_07" || $1 == "intermediate_07"' "$R" | wc -l)
check "the results carry July's ratio table" test "$typical" = 3
weather=$(awk '/^\[year_hours\]/ { f = 1; next } /^\[/ { f = 0 }
	f && /^h[0-9]/ { split($0, kv, " = "); split(kv[2], v, " ")
		if (v[1] == 7 && v[2] == 5 && v[3] >= 9.5 && v[3] <= 16.5) s = s v[6] } END { print s }' "$R")
check "the weather's own hours 09:30-16:30 are overcast ($weather)" test -n "$weather" -a -z "$(echo "$weather" | tr -d 2)"
port=$(free_port)
{ cat <<EOC
[psensd]
results = $R
database = $TMP/day.db
socket = $TMP/sock
period = 900
stale_after = 1800
estimate = dated
[simulate]
year = yes
date = 07-05
EOC
device_tcp "$port" timeout=0.5 retries=1 backoff_min=0.1 backoff_max=0.5
points
cat <<EOC
[point roof]
device = io
role = rooftop
table = holding_register
address = 210
type = u32
[zone office]
sensor = sensor
task = lux
dim = dim
rooftop = roof
target_lux = 500
sensor_gain = 0.5
min_level = 0.1
EOC
} > "$TMP/day.conf"
check "psensd -n accepts a Modbus rooftop point" sh -c "\"$BIN/psensd\" -f '$TMP/day.conf' -n > /dev/null"
# psvirt only now, psensd right after it: its clock then starts within
# moments of psvirt's (a sanitizer's slow psensd -n in between left it
# 78 room minutes behind, judging psvirt's sky by a different sun)
"$BIN/psvirt" -f "$TMP/virt.conf" --tcp "127.0.0.1:$port" --ready-file "$TMP/ready" --start 10:00 --speed 3600 \
	-o noise=0 -o task_noise=0 -o fade_rate=0 -o lag_tau=0 > "$TMP/psvirt.out" 2> "$TMP/psvirt.err" &
pv=$!; track_pid $pv
check "psvirt ready" wait_for 10 test -s "$TMP/ready"
ready_ms=$(( $(date +%s%N) / 1000000 ))
v=$(virt_now "$ready_ms" 36000 3600)
"$BIN/psensd" -f "$TMP/day.conf" -t "$(hhmm "$v")" -x 3600 > "$TMP/psensd.out" 2> "$TMP/psensd.err" &
pd=$!; track_pid $pd
wait_for 20 "$BIN/psensctl" -s "$TMP/sock" ping > /dev/null
lag=$(clock_lag "$ready_ms" 36000 3600 "$TMP/sock")
diag "psensd starts at $(hhmm "$v"), psvirt's clock $lag s of room time ahead"
wait_for 20 sh -c "[ \"\$(sqlite3 '$TMP/day.db' 'select max(tod_s) from samples' 2>/dev/null | cut -d. -f1)\" -ge 57600 ]"
kill -TERM $pd; wait $pd
kill "$pv"; wait "$pv" 2>/dev/null
q() { sqlite3 "$TMP/day.db" "$1" 2>/dev/null; }
diag "$(q "select cast(tod_s as int), condition, round(ratio, 1) from samples order by t" | tr '\n' ' ')"
# 12:25-12:35 the bright overcast reads kt 0.42, epsilon 1.246: intermediate
# (216-psensd-rooftop.sh): psvirt's 12:15-12:45, psensd's lag earlier
# (virt_now), is left out; the weather's overcast hours end at psvirt's 16:30
w="fault is null and tod_s between 37800 and min(57600, 59400 - $lag) and not tod_s between 44100 - $lag and 45900 - $lag"
n=$(q "select count(*) from samples where $w")
k=$(q "select count(*) from samples where $w and condition = 'daylight_rooftop_overcast'")
check "10:30-16:00: $k of $n steps judge the sky overcast from the Modbus rooftop" test "$n" -ge 15 -a "$k" = "$n"
# the ratio in force is July's overcast one for the hour (the results' table)
h13=$(awk '$1 == "overcast_07" { print $(3 + 13) }' "$R")
r13=$(q "select ratio from samples where fault is null and tod_s >= 46800 and tod_s < 50400 limit 1")
check "at 13:00 the ratio is July's overcast one for 13 h ($r13 = $h13)" near "$r13" "$h13" 0.001
done_testing
