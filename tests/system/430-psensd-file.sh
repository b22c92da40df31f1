#!/bin/sh
# SPDX-License-Identifier: ISC
# The skeleton driver (drivers/file.c) under the real psensd: a sensor
# reading written to a file, the level written to another, every sample in
# the database as psensd read and commanded it; a missing file is a fault
# that drives the output file to the safe level.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v sqlite3 > /dev/null || skip_all "sqlite3 not installed"
example_results
mkdir -p "$TMP/files"
conf() {  # conf NAME: a simulated hour on the file driver
	cat > "$TMP/$1.conf" <<CONF
[psensd]
results = state/ofb.results
database = state/$1.db
period = 60
safe_level = 1
[simulate]
start = 06:00
end = 07:00
[device files]
driver = file
dir = files
[point light]
device = files
role = sensor
path = $1.sensor
[point lamps]
device = files
role = dim
path = $1.dim
[zone office]
sensor = light
dim = lamps
target_lux = 500
sensor_gain = 0.5
CONF
}
conf day
check "psensd -n: the file driver's keys pass" sh -c "'$BIN/psensd' -f '$TMP/day.conf' -n | grep -q 'configuration OK'"
echo 1.25 > "$TMP/files/day.sensor"
"$BIN/psensd" -f "$TMP/day.conf" -s > "$TMP/day.out" 2> "$TMP/day.err"
q() { sqlite3 "$TMP/state/$1.db" "$2"; }
check "60 samples logged" test "$(q day 'select count(*) from samples')" = 60
check "each with the volts written in the file" test "$(q day 'select count(*) from samples where sensor_v = 1.25 and fault is null')" = 60
# the last sample's command was written; at the end psensd drives the
# lights to the safe level, which is what the file holds now
last=$(q day 'select output from samples order by rowid desc limit 1')
check "the control dimmed (last level $last)" awk -v l="$last" 'BEGIN { exit !(l > 0 && l < 1) }'
check "at exit the file holds the safe level: $(cat "$TMP/files/day.dim")" test "$(cat "$TMP/files/day.dim")" = 1

# no sensor file: a fault at once, the output file at the safe level, and
# the reason in each sample
conf gone
"$BIN/psensd" -f "$TMP/gone.conf" -s > /dev/null 2> "$TMP/gone.err"
check "a missing file is a fault at once: $(grep -o 'fault: .*' "$TMP/gone.err" | head -n 1)" \
	grep -q "06:00 fault: file $TMP/files/gone.sensor: No such file or directory: lights to the safe level 100 %" "$TMP/gone.err"
check "every sample at the safe level with the reason" \
	test "$(q gone "select count(*) from samples where output = 1 and fault like 'file %No such file%'")" = 60
check "the output file holds it" test "$(cat "$TMP/files/gone.dim")" = 1
done_testing
