#!/bin/sh
# SPDX-License-Identifier: ISC
# A DALI-2 light sensor under faults, psensd against the emulated bus of
# peers/dalibus.py.  Checks: on the AtxLED HAT, our 24-bit frames colliding
# with another master's (the HAT's Z) are sent again after the random wait
# and the sensor is configured and read all the same, without a fault; on
# the Foxtron interface with no bus traffic passed (polling), a device that
# answers garbage (its backward frames garbled) is a fault once its value is
# older than 2 x T_report, naming the garbled answer, the zone at its safe
# level; when it answers cleanly again control resumes by itself; a
# malformed reply from the interface to one poll costs a retry, not a fault.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v python3 > /dev/null || skip_all "python3 not installed"
"$BIN/psensd" -L 2>/dev/null | grep -q "^dali_usb:" || skip_all "the dali_usb driver is not compiled in"
example_results
S="$TMP/sock"
ctl() { "$BIN/psensctl" -s "$S" "$@"; }
sensor_v() { ctl -j status | sed -n 's/.*"sensor_v":\([0-9.]*\).*/\1/p'; }
reads() { [ "$(sensor_v)" = "$1.0" ]; }
start() {
	codec=$1; shift
	dalibus_pty "$TMP/bus.log" --codec "$codec" --gear 1:254 \
		--devices 5:0x123456 --control "$TMP/ctl" --state "$TMP/bus.state" "$@"
	{ psensd_section 0.5 2; cat <<EOC
[device dali]
driver = dali_usb
transport = $codec
device = $(cat "$TMP/pty")
timeout = 0.1
EOC
dali2_light 5 2
cat <<EOC
[point ballasts]
device = dali
role = dim
address = broadcast
[zone office]
sensor = light
dim = ballasts
sensor_gain = 100
min_level = 0.1
EOC
	} > "$TMP/psensd.conf"
	"$BIN/psensd" -f "$TMP/psensd.conf" -t 12:00 > "$TMP/out" 2> "$TMP/err" &
	pid=$!; track_pid $pid
	wait_for 10 ctl ping > /dev/null
}
stop() {
	pd=$(ctl -j ping | sed -n 's/.*"pid":\([0-9]*\).*/\1/p')
	kill -TERM "$pd"; wait $pid
	kill $bus; wait $bus 2>/dev/null
}

# collisions during the configuration: frames 3, 4 (in a row) and 9
echo "light 0 512" > "$TMP/ctl"
start atx --faults 3:collision,4:collision,9:collision
wait_for 10 reads 512
check "atx, three of our frames collided: the sensor read all the same: $(sensor_v)" reads 512
polls() { awk '$1 == "device" && $2 == 0 { print $8 }' "$TMP/bus.state"; }
p0=$(polls); echo "light 0 900" > "$TMP/ctl"
wait_for 10 reads 900
sleep 3
check "... and configured: a change came by its events, no poll ($p0 then $(polls))" test "$(polls)" = "$p0"
check "... no fault" sh -c "! grep -q 'fault: ' \"$TMP/err\""
stop

# garbage answers, polling
echo "light 0 300" > "$TMP/ctl"
start foxtron --no-events --faults 40:malformed
wait_for 10 reads 300
check "polling: the value read: $(sensor_v)" reads 300
sleep 4
check "a malformed reply to one frame: no fault" sh -c "! grep -q 'fault: ' \"$TMP/err\""
echo "garbage 0 1" > "$TMP/ctl"
t0=$(date +%s)
wait_for 15 grep -q "zone office: .* fault: " "$TMP/err"
t1=$(date +%s)
check "garbled answers: a fault: $(grep -o 'fault: .*' "$TMP/err" | head -n 1 | cut -c1-140)" \
	grep -q "zone office: .* fault: .*no value for .*a garbled answer to QUERY INPUT VALUE" "$TMP/err"
check "... within 2 x T_report and a period (seconds: $((t1 - t0)))" test $((t1 - t0)) -le 6
ctl -j status > "$TMP/st.json"
check "... the zone at its safe level" grep -Eq '"level":1(\.0)?,.*"fault":"' "$TMP/st.json"
echo "light 0 350" > "$TMP/ctl"
sleep 0.2
echo "garbage 0 0" >> "$TMP/ctl"
wait_for 15 grep -q "fault cleared: control resumes" "$TMP/err"
check "clean answers again: control resumes" grep -q "fault cleared: control resumes" "$TMP/err"
wait_for 10 reads 350
check "... with the new value: $(sensor_v)" reads 350
stop
done_testing
