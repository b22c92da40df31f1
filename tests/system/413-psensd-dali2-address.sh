#!/bin/sh
# SPDX-License-Identifier: ISC
# Short addresses for DALI-2 control devices by the random-address search
# in the device space (IEC 62386-103: INITIALISE, RANDOMISE, SEARCHADDRH/M/L,
# COMPARE, PROGRAM / VERIFY / QUERY SHORT ADDRESS, WITHDRAW under 0xC1),
# through psensd and psensctl on the Foxtron interface with the emulated
# bus of peers/dalibus.py: two multisensors without a short address and one
# at 5, gear at short 1.  Checks: the two new devices get 0 and 1 (the
# lowest free, in the order of the random addresses they drew), device 5 keeps its address, the gear keep theirs; the
# emulator's own state says so (not psensd's report); a scan then lists the
# three devices and none without an address; a second run has nothing to do;
# identify device sends IDENTIFY DEVICE twice, which the device obeys once,
# and names a short address where no device answers.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v python3 > /dev/null || skip_all "python3 not installed"
"$BIN/psensd" -L 2>/dev/null | grep -q "^dali_usb:" || skip_all "the dali_usb driver is not compiled in"
example_results
S="$TMP/sock"
ctl() { "$BIN/psensctl" -s "$S" "$@"; }
dalibus_pty "$TMP/bus.log" --codec foxtron --gear 1:254 \
	--devices=-:0x9D5BC6,5:0x123456,-:0x0C357B --state "$TMP/bus.state"
{ psensd_section 0.5; cat <<EOC
[device room]
driver = loopback
[point sensor]
device = room
role = sensor
[device dali]
driver = dali_usb
transport = foxtron
device = $(cat "$TMP/pty")
timeout = 0.1
[point ballasts]
device = dali
role = dim
address = 1
[zone office]
sensor = sensor
dim = ballasts
EOC
} > "$TMP/psensd.conf"
"$BIN/psensd" -f "$TMP/psensd.conf" -t 12:00 > "$TMP/out" 2> "$TMP/err" &
pid=$!; track_pid $pid
wait_for 10 ctl ping > /dev/null
short_of() { awk -v r="$1" '$1 == "device" && $6 == r { print $4 }' "$TMP/bus.state"; }
ctl dali dali address devices > "$TMP/addr" 2> "$TMP/addr.err"
check "address devices: exit 0" test $? = 0
diag "$(head -n 1 "$TMP/addr")"
check "address devices: two found, two new short addresses" \
	grep -q "address done .*: 2 control devices found: 2 new short addresses, 0 kept theirs" "$TMP/addr"
# RANDOMISE drew new random addresses: the search finds the lowest first
# and gives it the lowest free short address
order=$(awk '$1 == "device" && ($2 == 0 || $2 == 2) { print $6, $4 }' "$TMP/bus.state" | sort | awk '{ printf "%s ", $2 }')
check "the two new devices, by their random addresses, got 0 and 1: $order" test "$order" = "0 1 "
check "device 5 kept its address: $(short_of 0x123456)" test "$(short_of 0x123456)" = 5
check "the gear kept theirs" grep -q "^short 1 level" "$TMP/bus.state"
ctl dali dali scan > "$TMP/scan" 2> /dev/null
check "scan: three control devices, none without an address" \
	grep -q "3 control devices, without a short address: none" "$TMP/scan"
check "scan: each listed with its instances" test "$(grep -cE '^ +[015] +one +0: 3 ' "$TMP/scan")" = 3
ctl dali dali address devices > "$TMP/addr2" 2> /dev/null
check "a second run: nothing to do" grep -q "nothing to do" "$TMP/addr2"
ctl dali dali identify device 5 > "$TMP/id" 2> /dev/null
check "identify device 5: done" grep -q "identify done .*: control device 5 told to identify itself" "$TMP/id"
check "... the device obeyed IDENTIFY DEVICE once (sent twice, as 103 asks)" \
	test "$(awk '$1 == "device" && $4 == 5 { print $10 }' "$TMP/bus.state")" = 1
ctl dali dali identify device 33 > "$TMP/id2" 2> /dev/null
check "identify device 33: nobody there, said so" grep -q "no control device answers at short address 33" "$TMP/id2"
ctl dali dali address devices sideways > "$TMP/bad" 2>&1
check "a bad mode names the problem" grep -q "address devices new|all: 'sideways' is neither" "$TMP/bad"
pd=$(ctl -j ping | sed -n 's/.*"pid":\([0-9]*\).*/\1/p')
kill -TERM "$pd"; wait $pid
done_testing
