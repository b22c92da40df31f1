#!/bin/sh
# SPDX-License-Identifier: ISC
# psensctl dali DEVICE scan on a bus with gear and DALI-2 control devices,
# through the LUBA interface on a pty and the emulated bus of
# peers/dalibus.py (IEC 62386-103 multisensors: instance 0 occupancy, type
# 3; instance 1 light, type 4).  Checks: the gear at short addresses 1 and 2
# are listed as before; the control devices at 5 and 9 of the device space
# are listed apart from the gear, each with its two instances, their
# numbers and types; a control device without a short address is noticed;
# and the same bus read through the AtxLED HAT (whose 24-bit frames have
# no send-twice form) still lets psensd configure a light sensor and read it.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v python3 > /dev/null || skip_all "python3 not installed"
"$BIN/psensd" -L 2>/dev/null | grep -q "^dali_usb:" || skip_all "the dali_usb driver is not compiled in"
example_results
S="$TMP/sock"
ctl() { "$BIN/psensctl" -s "$S" "$@"; }
run_bus() {
	dalibus_pty "$TMP/bus-$1.log" --codec "$1" --gear 1:254,2:254 \
		--devices 5:0x123456,9:0x222222,-:0x333333 --control "$TMP/ctl" --state "$TMP/bus.state"
}
conf() {
	{ psensd_section 0.5; cat <<EOC
[device dali]
driver = dali_usb
transport = $1
device = $(cat "$TMP/pty")
timeout = 0.1
EOC
dali2_light 9 5
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
}
echo "light 1 250" > "$TMP/ctl"
run_bus luba
conf luba
"$BIN/psensd" -f "$TMP/psensd.conf" -t 12:00 > "$TMP/out" 2> "$TMP/err" &
pid=$!; track_pid $pid
wait_for 10 ctl ping > /dev/null
ctl dali dali scan > "$TMP/scan" 2> "$TMP/scan.err"
check "scan: exit 0" test $? = 0
diag "$(head -n 1 "$TMP/scan")"
check "scan: the gear and the control devices counted" \
	grep -q "scan done .*: 2 short addresses answer; gear without a short address: none; 2 control devices, without a short address: yes" "$TMP/scan"
check "scan: gear 1 and 2 listed" test "$(grep -cE '^ +[12] +one ' "$TMP/scan")" = 2
check "scan: control device 5 with its instances" \
	grep -Eq '^ +5 +one +0: 3 occupancy sensor \(303\); 1: 4 light sensor \(304\)$' "$TMP/scan"
check "scan: control device 9 with its instances" \
	grep -Eq '^ +9 +one +0: 3 occupancy sensor \(303\); 1: 4 light sensor \(304\)$' "$TMP/scan"
check "scan: no control device listed at a gear's address" sh -c "! grep -Eq '^ +[12] +one +0: ' \"$TMP/scan\""
ctl -j dali dali status > "$TMP/scan.json"
check "scan JSON: devices with instance numbers and types" \
	grep -q '"devices":\[{"address":5,"devices":"one","instances":\[{"number":0,"type":3' "$TMP/scan.json"
sensor_v() { ctl -j status | sed -n 's/.*"sensor_v":\([0-9.]*\).*/\1/p'; }
wait_for 10 sh -c "[ \"\$(\"$BIN/psensctl\" -s \"$S\" -j status | sed -n 's/.*\"sensor_v\":\([0-9.]*\).*/\1/p')\" = 250.0 ]"
check "luba: device 9's light sensor read: $(sensor_v)" test "$(sensor_v)" = 250.0
pd=$(ctl -j ping | sed -n 's/.*"pid":\([0-9]*\).*/\1/p')
kill -TERM "$pd"; wait $pid
kill $bus; wait $bus 2>/dev/null

echo "light 1 820" > "$TMP/ctl"
run_bus atx
conf atx
"$BIN/psensd" -f "$TMP/psensd.conf" -t 12:00 > "$TMP/out2" 2> "$TMP/err2" &
pid=$!; track_pid $pid
wait_for 10 ctl ping > /dev/null
wait_for 10 sh -c "[ \"\$(\"$BIN/psensctl\" -s \"$S\" -j status | sed -n 's/.*\"sensor_v\":\([0-9.]*\).*/\1/p')\" = 820.0 ]"
check "atx: device 9's light sensor read: $(sensor_v)" test "$(sensor_v)" = 820.0
echo "light 1 400" > "$TMP/ctl"
wait_for 10 sh -c "[ \"\$(\"$BIN/psensctl\" -s \"$S\" -j status | sed -n 's/.*\"sensor_v\":\([0-9.]*\).*/\1/p')\" = 400.0 ]"
check "atx: a change arrives: $(sensor_v)" test "$(sensor_v)" = 400.0
# had the event scheme and filter not taken (send-twice as two frames), the
# events would not name device 9 and psensd would poll every 6.25 s
polls() { awk '$1 == "device" && $2 == 1 { print $8 }' "$TMP/bus.state"; }
p0=$(polls); sleep 8
check "atx: by events, no poll in 8 s (the configuration sent as two frames took): $p0 then $(polls)" \
	test "$(polls)" = "$p0"
pd=$(ctl -j ping | sed -n 's/.*"pid":\([0-9]*\).*/\1/p')
kill -TERM "$pd"; wait $pid
check "no fault on the way" sh -c "! grep -q 'fault: ' \"$TMP/err\" \"$TMP/err2\""
done_testing
