#!/bin/sh
# SPDX-License-Identifier: ISC
# Device groups of DALI-2 control devices (IEC 62386-103) through psensctl
# dali, against psvirt's virtual bus (its room's multisensor is control
# device 0) behind a Foxtron DALInet: psensctl dali DEVICE group device
# SHORT add|remove GROUP sends DTR1/DTR2 with the group's bit and ADD TO /
# REMOVE FROM DEVICE GROUPS (0-15 or 16-31) twice, then reads the four
# QUERY DEVICE GROUPS bytes back.  Checked: groups 5 and 20 added and 5
# removed, each reported from the device's own answer and confirmed by a
# second client asking the bus directly; a device that is not there, a
# group past 31 and a short address past 63 are refused with a reason.
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/peers/common.sh"
[ -x "$BIN/psvirt" ] && [ -x "$BIN/psensd" ] || skip_all "psvirt or psensd not built"
"$BIN/psensd" -L 2>/dev/null | grep -q "^dali_usb:" || skip_all "the dali_usb driver is not compiled in"
PY=/usr/bin/python3
PEERS="$(dirname "$0")/peers"
make_results
S="$TMP/sock"
mb=$(free_port)
psvirt_dali --tcp "127.0.0.1:$mb" --start 12:00
{ printf '[psensd]\nresults = ofb.results\ndatabase = psensd.db\nsocket = sock\nperiod = 1\n'
psvirt_devices
cat <<EOF2
[point sensor]
device = io
role = sensor
table = input_register
address = 0
[point lamps]
device = dali
role = dim
address = broadcast
[zone office]
sensor = sensor
dim = lamps
sensor_gain = 0.5
min_level = 0.1
EOF2
} > "$TMP/psensd.conf"
"$BIN/psensd" -f "$TMP/psensd.conf" -t 12:00 > "$TMP/out" 2> "$TMP/err" &
ps=$!; track_pid $ps
ctl() { "$BIN/psensctl" -s "$S" "$@"; }
fox() { "$PY" "$PEERS/foxclient.py" "tcp:127.0.0.1:$port" "$@"; }
# QUERY DEVICE GROUPS 0-7 .. 24-31 of control device 0 (address byte 0x01,
# instance byte 0xFE: the device), asked by a second client
groups() { fox "send 24 01FE41; send 24 01FE42; send 24 01FE43; send 24 01FE44" | awk '{ printf "%s", $2 }'; }
wait_for 10 ctl ping > /dev/null || not_ok "psensd did not start: $(cat "$TMP/err")"
ctl dali dali group device 0 add 5 > "$TMP/g1" 2>&1
check "group device 0 add 5: $(sed -n '2,$p' "$TMP/g1" | tr -s ' \n' ' ')" grep -q "control device 0 is in device group 5" "$TMP/g1"
check "... the bus says so: device groups 0-31 bytes $(groups) = 20000000" test "$(groups)" = 20000000
ctl dali dali group device 0 add 20 > "$TMP/g2" 2>&1
check "... psensctl prints its groups" grep -q "control device 0: device groups 5$" "$TMP/g1"
check "group device 0 add 20: $(sed -n '2,$p' "$TMP/g2" | tr -s ' \n' ' ')" grep -q "control device 0 is in device group 20" "$TMP/g2"
check "... the bus: $(groups) = 20001000 (groups 5 and 20)" test "$(groups)" = 20001000
ctl -j dali dali status > "$TMP/st.json"
check "psensctl dali status lists the device's groups: $(grep -o '"device_groups":[^]]*]' "$TMP/st.json")" \
	grep -q '"device_groups":\[5,20\]' "$TMP/st.json"
ctl dali dali group device 0 remove 5 > "$TMP/g3" 2>&1
check "group device 0 remove 5: $(sed -n '2,$p' "$TMP/g3" | tr -s ' \n' ' ')" grep -q "control device 0 is out of device group 5" "$TMP/g3"
check "... the bus: $(groups) = 00001000 (group 20 only)" test "$(groups)" = 00001000
ctl dali dali group device 9 add 1 > "$TMP/g4" 2>&1
check "a device that is not there: $(sed -n '2,$p' "$TMP/g4" | tr -s ' \n' ' ')" grep -q "control device 9: no answer to QUERY DEVICE GROUPS" "$TMP/g4"
check "... its groups unknown, not empty" grep -q "control device 9: device groups -$" "$TMP/g4"
check "a device group past 31 is refused" sh -c "! \"$BIN/psensctl\" -s \"$S\" dali dali group device 0 add 32 2> '$TMP/e1' && grep -q 'not a device group 0 to 31' '$TMP/e1'"
check "a short address past 63 is refused" sh -c "! \"$BIN/psensctl\" -s \"$S\" dali dali group device 64 add 1 2> '$TMP/e2' && grep -q 'not a short address 0 to 63' '$TMP/e2'"
done_testing
