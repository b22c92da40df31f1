# SPDX-License-Identifier: ISC
# Shared by the 3xx Modbus tests (sourced after lib.sh): the tools they need,
# and a psensd-modbus(5) device and points for mbdrive.
MBDRIVE=$BUILD/tests/mbdrive
PEERS=$TOP/tests/system/peers
PY=/usr/bin/python3
[ -x "$MBDRIVE" ] || skip_all "the modbus driver is not compiled in (no $MBDRIVE; WITH_MODBUS)"
need_pymodbus() { "$PY" -c 'import pymodbus' 2>/dev/null || skip_all "python3-pymodbus missing"; }
need() { command -v "$1" >/dev/null 2>&1 || skip_all "$1 missing"; }
# results of the example scene, for psvirt
make_results() {
	mkdir -p "$TMP/example"
	cp -R "$TOP/config/example/ofb" "$TOP/config/example/ofb.scene" "$TMP/example/"
	"$BIN/psscene" -q -o "$TMP/ofb.results" "$TMP/example/ofb.scene" >/dev/null 2>&1
}
# value of KEY in the results' [summary] (electric_sensor_response, electric_task_lux, ...)
summary() { awk -v k="$1" '/^\[/ { s = ($0 == "[summary]") } s && $1 == k { print $3; exit }' "$TMP/ofb.results"; }
# points: the ADAM-6024-style map (psvirt(1), tests/system/peers/mbserver.py)
points() {
	cat <<EOP
[point sensor]
device = io
role = sensor
table = input_register
address = 0
[point dim]
device = io
role = dim
table = holding_register
address = 10
raw_max = 4095
[point lux]
device = io
role = task
table = holding_register
address = 100
type = u32
[point clock]
device = io
role = task
table = holding_register
address = 200
type = u32
[point truth]
device = io
role = task
table = holding_register
address = 203
type = f32
EOP
}
# device_tcp PORT [KEY=VALUE...]: a TCP device section
device_tcp() {
	_p=$1; shift
	printf '[device io]\ndriver = modbus\nhost = 127.0.0.1\nport = %s\n' "$_p"
	for kv in "$@"; do printf '%s\n' "$kv" | sed 's/=/ = /'; done
}
# near A B TOL: |A - B| <= TOL
near() { awk -v a="$1" -v b="$2" -v t="$3" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d <= t) }'; }
