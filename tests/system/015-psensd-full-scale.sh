#!/bin/sh
# SPDX-License-Identifier: ISC
# A sensor reading at its driver's full scale (the top of the input's range:
# a file point's full_scale, the loopback sensor's clipping voltage) is a
# saturation fault that drives the lights to the safe level, even when the
# control range and sensor_saturation let the reading through: it says
# only "this much daylight or more", and taken as daylight it would dim the
# lights too far.  A reading below the full scale is taken as it is.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v sqlite3 > /dev/null || skip_all "sqlite3 not installed"
example_results
mkdir -p "$TMP/files"
conf() {  # conf NAME: a simulated hour on a file sensor whose input tops out at 5 V
	cat > "$TMP/$1.conf" <<CONF
[psensd]
results = state/ofb.results
database = state/$1.db
period = 60
safe_level = 1
sensor_max = 9.9
sensor_saturation = 10
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
full_scale = 5
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
q() { sqlite3 "$TMP/state/$1.db" "$2"; }
conf pegged
check "psensd -n: full_scale is a file sensor's key" \
	sh -c "'$BIN/psensd' -f '$TMP/pegged.conf' -n | grep -q 'configuration OK'"
echo 5 > "$TMP/files/pegged.sensor"
"$BIN/psensd" -f "$TMP/pegged.conf" -s > /dev/null 2> "$TMP/pegged.err"
check "a reading at the full scale is a fault: $(grep -o 'fault: .*' "$TMP/pegged.err" | head -n 1 | cut -c1-90)" \
	grep -q "06:00 fault: sensor saturated: reads 5.000 V, at its input's full scale 5 V (file): lights to the safe level 100 %" \
	"$TMP/pegged.err"
check "every sample at the safe level with the reason" \
	test "$(q pegged "select count(*) from samples where output = 1 and fault like 'sensor saturated%'")" = 60
check "at exit the output file holds the safe level" test "$(cat "$TMP/files/pegged.dim")" = 1
# just below the full scale: daylight, no fault
conf below
echo 4.99 > "$TMP/files/below.sensor"
"$BIN/psensd" -f "$TMP/below.conf" -s > /dev/null 2> "$TMP/below.err"
check "a reading below the full scale is taken" sh -c "! grep -q 'fault:' '$TMP/below.err'"
check "every sample with its reading, no fault" \
	test "$(q below "select count(*) from samples where sensor_v = 4.99 and fault is null")" = 60
# the loopback sensor clips at its saturation (10 V): with sensor_saturation
# = 0 (unknown) and the control range up to 10 V the clipped reading is
# still a fault, found from the driver's own limit
sed "s|^results = .*|results = state/ofb.results|; s|^database = .*|database = state/clip.db|; s|^faults = .*|faults = saturated 12:00-12:20|; s|^sensor_max = .*|sensor_max = 10\nsensor_saturation = 0|" \
	config/psensd.conf > "$TMP/clip.conf"
"$BIN/psensd" -f "$TMP/clip.conf" -s > /dev/null 2> "$TMP/clip.err"
check "loopback clipping at 10 V is a fault: $(grep -o 'fault: .*' "$TMP/clip.err" | head -n 1 | cut -c1-90)" \
	grep -q "12:00 fault: sensor saturated: reads 10.000 V, at its input's full scale 10 V (loopback)" "$TMP/clip.err"
check "the loopback: control resumes after the fault" grep -q "fault cleared: control resumes" "$TMP/clip.err"
done_testing
