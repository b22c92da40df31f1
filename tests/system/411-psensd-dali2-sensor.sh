#!/bin/sh
# SPDX-License-Identifier: ISC
# psensd reading a DALI-2 multisensor (IEC 62386-103 control device 5:
# instance 1 a 304 light sensor, instance 0 a 303 occupancy sensor) while
# commanding gear on the same bus, through the Foxtron interface on a pty
# with the emulated bus (peers/dalibus.py, written from the standards'
# facts) behind it.  Checks: the sensor point reads the light sensor's
# 10-bit value as the emulator sets it, also after a change (carried by the
# sensor's event messages: no QUERY INPUT VALUE after the first reading
# while they flow);
# the occupancy input follows occupied / vacant; an override reaches the
# gear at the standard curve's level; the configuration psensd wrote
# (T_report, event scheme) reads back from the device; a sensor that falls
# silent is a fault within 2 x T_report that drives the zone to its safe
# level, and control resumes when it reports again; with an interface that
# passes no bus traffic, polling (QUERY INPUT VALUE, then its latch)
# brings the value instead.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v python3 > /dev/null || skip_all "python3 not installed"
"$BIN/psensd" -L 2>/dev/null | grep -q "^dali_usb:" || skip_all "the dali_usb driver is not compiled in"
example_results
S="$TMP/sock"
echo "light 0 400" > "$TMP/ctl"
start_bus() {
	dalibus_pty "$TMP/bus.log" --codec foxtron --gear 1:254,2:254 \
		--devices 5:0x123456 --control "$TMP/ctl" --state "$TMP/bus.state" "$@"
}
start_bus
write_conf() {
	{ psensd_section 0.5 2; cat <<EOC
[device dali]
driver = dali_usb
transport = foxtron
device = $(cat "$TMP/pty")
timeout = 0.1
EOC
dali2_light 5 2
dali2_occupancy 5 2
cat <<EOC
[point ballasts]
device = dali
role = dim
address = broadcast
[zone office]
sensor = light
dim = ballasts
input = occupancy
sensor_gain = 100
min_level = 0.1
EOC
	} > "$TMP/psensd.conf"
}
write_conf
ctl() { "$BIN/psensctl" -s "$S" "$@"; }
sensor_v() { ctl -j status | sed -n 's/.*"sensor_v":\([0-9.]*\).*/\1/p'; }
reads() { [ "$(sensor_v)" = "$1" ] || [ "$(sensor_v)" = "$1.0" ]; }
levels() { awk '$1 == "short" { print $4 }' "$TMP/bus.state" | sort -u | tr '\n' ' ' | sed 's/ $//'; }
polls() { awk '$1 == "device" && $2 == 0 { print $8 }' "$TMP/bus.state"; }

"$BIN/psensd" -n -f "$TMP/psensd.conf" > "$TMP/n.out" 2>&1
check "psensd -n accepts DALI-2 sensor and input points" grep -q "configuration OK" "$TMP/n.out"
sed 's/^device_address = 5$//' "$TMP/psensd.conf" > "$TMP/noaddr.conf"
"$BIN/psensd" -n -f "$TMP/noaddr.conf" > "$TMP/n2.out" 2>&1
check "psensd -n: a DALI sensor point without device_address is refused" \
	grep -q "noaddr.conf:[0-9]*: .*needs device_address" "$TMP/n2.out"

"$BIN/psensd" -f "$TMP/psensd.conf" -t 12:00 > "$TMP/out" 2> "$TMP/err" &
pid=$!; track_pid $pid
wait_for 10 ctl ping > /dev/null
wait_for 10 reads 400
check "the sensor point reads the 304 instance's value 400: $(sensor_v)" reads 400
p0=$(polls)
echo "light 0 700" > "$TMP/ctl"
wait_for 10 reads 700
check "the light changes to 700: the point follows: $(sensor_v)" reads 700
sleep 3
check "... by the sensor's events: no QUERY INPUT VALUE after the first reading ($p0 then $(polls))" \
	test "$(polls)" = "$p0"
ctl -j dali dali status > "$TMP/bus.json"
check "psensctl dali status counts the sensor's events taken: $(grep -o '"inputs":\[{[^}]*}' "$TMP/bus.json" | cut -c1-160)" \
	grep -Eq '"inputs":\[\{"point":"light","device_address":5,"instance":1,"type":4,"value":700,.*"configured":true,.*"events":[1-9]' "$TMP/bus.json"
echo "occupied 0 1" > "$TMP/ctl"
wait_for 10 grep -q "zone office: .*occupied$" "$TMP/err"
check "the 303 instance reports occupied: the zone is occupied" grep -q "zone office: .*occupied$" "$TMP/err"
echo "occupied 0 0" > "$TMP/ctl"
wait_for 10 sh -c "grep 'zone office: .*\(occupied\|vacant\)$' \"$TMP/err\" | tail -n 1 | grep -q vacant"
check "... then vacant" sh -c "grep 'zone office: .*\(occupied\|vacant\)$' \"$TMP/err\" | tail -n 1 | grep -q vacant"
ctl override office 0.3 600 > /dev/null
want=$(dali_arc 0.3)
wait_for 5 sh -c "[ \"\$(awk '\$1 == \"short\" { print \$4 }' \"$TMP/bus.state\" | sort -u)\" = $want ]"
check "override 30 %: the gear at arc level $want while the sensor is read: $(levels)" test "$(levels)" = "$want"
ctl override office off > /dev/null 2>&1

echo "silent 0 1" > "$TMP/ctl"
t0=$(date +%s)
# (both instances fall silent: which one's loss is logged first is a race)
wait_for 15 grep -q "zone office: .* fault: .*device 5 instance 1: no value for" "$TMP/err"
t1=$(date +%s)
check "the sensor silent: a fault naming the lost value: $(grep -o 'fault: .*instance 1: .*' "$TMP/err" | head -n 1 | cut -c1-120)" \
	grep -q "zone office: .* fault: .*device 5 instance 1: no value for" "$TMP/err"
# 2 x T_report = 4 s, plus a period and the polls' timeouts
check "... within 2 x T_report and a period (seconds: $((t1 - t0)))" test $((t1 - t0)) -le 6
ctl -j status > "$TMP/st.json"
check "... the zone at its safe level, the fault in its status" grep -Eq '"level":1(\.0)?,.*"fault":"' "$TMP/st.json"
echo "silent 0 0" > "$TMP/ctl"
wait_for 15 grep -q "fault cleared: control resumes" "$TMP/err"
check "the sensor back: control resumes by itself" grep -q "fault cleared: control resumes" "$TMP/err"
check "the sensor's fault was reported once" test "$(grep -c 'zone office: .* fault: light: ' "$TMP/err")" = 1
# (the occupancy instance's silence may be seen too, as its own fault
# taken as occupied: not the sensor's, and not counted here)
pd=$(ctl -j ping | sed -n 's/.*"pid":\([0-9]*\).*/\1/p')
kill -TERM "$pd"
wait $pid

# an interface that passes no bus traffic: psensd polls
kill $bus; wait $bus 2>/dev/null
echo "light 0 300" > "$TMP/ctl"
start_bus --no-events
write_conf
"$BIN/psensd" -f "$TMP/psensd.conf" -t 12:00 > "$TMP/out2" 2> "$TMP/err2" &
pid=$!; track_pid $pid
wait_for 10 ctl ping > /dev/null
wait_for 10 reads 300
check "no events: the value comes by polling: $(sensor_v)" reads 300
echo "light 0 1000" > "$TMP/ctl"
wait_for 10 reads 1000
check "... and follows a change within T_report: $(sensor_v)" reads 1000
n=$(polls)
check "... QUERY INPUT VALUE answered $n times in about 5 s at T_report 2 s (at most one a second)" \
	test "$n" -ge 2 -a "$n" -le 6
pd=$(ctl -j ping | sed -n 's/.*"pid":\([0-9]*\).*/\1/p')
kill -TERM "$pd"
wait $pid
check "no fault while polling" sh -c "! grep -q 'fault: ' \"$TMP/err2\""
done_testing
