#!/bin/sh
# SPDX-License-Identifier: ISC
# Every fault the loopback room can inject, over a simulated day: psensd
# names it, drives the lights to the safe level, logs it with each sample,
# and resumes when it clears; a saturated sensor is a fault even when the
# control range reaches its saturation voltage.  Then two zones at once: a dimmed one and a
# stepped one switched by two relays with an occupancy sensor.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
example_results
run() {  # run NAME FAULT WINDOW [ZONE-KEYS]
	sed "s|^results = .*|results = state/ofb.results|; s|^database = .*|database = state/$1.db|; s|^faults = .*|faults = $2 $3|" \
		config/psensd.conf > "$TMP/$1.conf"
	[ -n "${4:-}" ] && printf "$4\n" >> "$TMP/$1.conf"
	"$BIN/psensd" -f "$TMP/$1.conf" -s > "$TMP/$1.out" 2> "$TMP/$1.err"
}
faults_logged() { sqlite3 "$TMP/state/$1.db" "select count(*) from samples where fault like '%$2%' and output = 1"; }
expect() {  # expect NAME START-HH:MM MESSAGE
	check "$1: fault at $2: $(grep -o "fault: .*" "$TMP/$1.err" | head -n 1 | cut -c1-90)" \
		grep -q "zone office: [0-9-]* *$2 fault: .*$3.*safe level 100 %" "$TMP/$1.err"
	check "$1: control resumes after the fault" grep -q "fault cleared: control resumes" "$TMP/$1.err"
	n=$(faults_logged "$1" "$3")
	check "$1: $n samples logged at full output with the reason" test "$n" -ge 1
}
run open open 12:00-12:20;           expect open 12:00 "sensor reads 0.000 V, outside 0.01 to 9.9 V"
run saturated saturated 12:00-12:20; expect saturated 12:00 "sensor saturated: reads 10.000 V, at or above its saturation 10 V"
# the control range up to the saturation voltage: the saturated reading is
# still a fault, found from the sensor's own limit (sensor_saturation)
sed "s|^results = .*|results = state/ofb.results|; s|^database = .*|database = state/satmax.db|; s|^faults = .*|faults = saturated 12:00-12:20|; s|^sensor_max = .*|sensor_max = 10|" \
	config/psensd.conf > "$TMP/satmax.conf"
"$BIN/psensd" -f "$TMP/satmax.conf" -s > "$TMP/satmax.out" 2> "$TMP/satmax.err"
expect satmax 12:00 "sensor saturated: reads 10.000 V, at or above its saturation 10 V"
printf 'sensor_saturation = 0.005\n' > "$TMP/satlow.add"
sed "/^sensor_max = /r $TMP/satlow.add" config/psensd.conf > "$TMP/satlow.conf"
check "psensd -n refuses a saturation below sensor_min, naming the line" \
	sh -c "! '$BIN/psensd' -f '$TMP/satlow.conf' -n 2>&1 | grep -q 'fine' && '$BIN/psensd' -f '$TMP/satlow.conf' -n 2>&1 | grep -q 'satlow.conf:18: sensor_saturation 0.005 must be above sensor_min 0.01'"
run stuck stuck 12:00-12:20 "stuck_after = 300"
expect stuck 12:04 "sensor stuck at"
run drop drop 12:00-12:20;           expect drop 12:02 "no reading since 11:59 (loopback room: sensor reply dropped)"
run late late 12:00-12:20;           expect late 12:02 "no reading since 11:59 (loopback room: sensor reply late)"
check "drop: missed replies within stale_after (150 s) hold the level (no fault at 12:00-12:01)" \
	test "$(sqlite3 "$TMP/state/drop.db" "select count(*) from samples where tod_s >= 43200 and tod_s < 43320 and fault is null and output < 1")" = 2
run ballast ballast 06:10-07:00 "verify_tolerance = 0.05"
expect ballast 06:[0-9][0-9] "ballast room.dim not responding"
run nostuck stuck 12:00-12:20
check "stuck detection off (stuck_after = 0): the stuck sensor passes unnoticed" sh -c "! grep -q 'fault:' '$TMP/nostuck.err'"

# two zones: one dimmed, one stepped by two relays, vacant at lunch
sed "s|^results = .*|results = state/ofb.results|; s|^database = .*|database = state/two.db|; /^faults = /d" config/psensd.conf > "$TMP/two.conf"
cat >> "$TMP/two.conf" <<'CONF'
[device room2]
driver = loopback
gain = 0.5
noise = 0.002
seed = 9
[point room2.sensor]
device = room2
role = sensor
[point step1]
device = room2
role = relay
[point step2]
device = room2
role = relay
[point pir]
device = room2
role = input
action = occupancy
occupied = 07:00-12:00, 13:00-19:00
[zone open-plan]
sensor = room2.sensor
relay = step1 step2
input = pir
vacancy_delay = 600
algorithm = switching
s_off = 3.2
s_on = 2.2
delay = 600
steps = 2
CONF
"$BIN/psensd" -f "$TMP/two.conf" -s > "$TMP/two.out" 2> "$TMP/two.err"
check "-n counts two zones" sh -c "\"$BIN/psensd\" -f '$TMP/two.conf' -n | grep -q '2 zone(s)'"
check "two zones summarised" test "$(grep -c 'control, target' "$TMP/two.out")" = 2
q() { sqlite3 "$TMP/state/two.db" "$1"; }
ev=$(grep -c 'zone open-plan: [0-9: -]*\(vacant\|occupied\)$' "$TMP/two.err")
check "each zone logs its 840 periodic samples, the stepped one $ev more, one per occupancy event" \
	test "$(q "select group_concat(n) from (select count(*) n from samples group by zone order by zone)")" = "840,$((840 + ev))"
check "the stepped zone uses only 0, 1/2 and 1" test "$(q "select count(*) from samples where zone = 'open-plan' and output not in (0, 0.5, 1)")" = 0
check "it steps down to half in daylight" test "$(q "select count(*) from samples where zone = 'open-plan' and output = 0.5")" -gt 10
check "vacant from 12:00: lights off after the 10-minute delay (12:10-12:59)" \
	test "$(q "select count(*) from samples where zone = 'open-plan' and tod_s >= 43800 and tod_s < 46800 and output > 0")" = 0
check "occupancy reported at 12:00 and 13:00" test "$(grep -c 'zone open-plan: [0-9: -]*\(vacant\|occupied\)$' "$TMP/two.err")" -ge 2
check "the dimmed zone is unaffected by the other's occupancy" \
	test "$(q "select count(*) from samples where zone = 'office' and tod_s >= 43800 and tod_s < 46800 and output = 0")" = 0
# a point used by two zones is refused
printf '[zone dup]\nsensor = room2.sensor\nrelay = step1\n' >> "$TMP/two.conf"
"$BIN/psensd" -f "$TMP/two.conf" -n 2> "$TMP/dup.err" > /dev/null
check "an output shared by two zones is refused" grep -q "output step1 already belongs to zone open-plan" "$TMP/dup.err"
done_testing
