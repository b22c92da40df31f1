#!/bin/sh
# SPDX-License-Identifier: ISC
# The real psensd dimming DALI gear through a serial interface: the dali_usb
# driver with transport = atx on a pty, the emulated AtxLED HAT and its bus
# (peers/dalibus.py) behind it with two gear.  Checked against the standard
# curve X(n) = 10^((n-1)/(253/3)-1) %: the gear follow the zone's level and
# an override; the interface falling silent is a fault that drives the zone
# to its safe level, logged once; when it answers again psensd resumes by
# itself and the override's level is back on the gear.  psensd -n refuses
# a serial transport without its device.  Then the Foxtron transport over
# TCP (a DALInet) drives its gear the same way.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v python3 > /dev/null || skip_all "python3 not installed"
"$BIN/psensd" -L 2>/dev/null | grep -q "^dali_usb:" || skip_all "the dali_usb driver is not compiled in"
example_results
S="$TMP/sock"
dalibus_pty "$TMP/bus.log" --codec atx --gear 1:254,2:254 \
	--state "$TMP/bus.state"
dev=$(cat "$TMP/pty")
{ psensd_section 0.5 2; dali_room; cat <<EOF
[device dali]
driver = dali_usb
transport = atx
device = $dev
timeout = 0.1
EOF
dali_room_zone; } > "$TMP/psensd.conf"
ctl() { "$BIN/psensctl" -s "$S" "$@"; }
levels() { awk '{ print $4 }' "$TMP/bus.state" | sort -u | tr '\n' ' ' | sed 's/ $//'; }
at_level() { [ "$(levels)" = "$1" ]; }

sed 's/^device = \/dev.*//' "$TMP/psensd.conf" > "$TMP/nodev.conf"
"$BIN/psensd" -n -f "$TMP/nodev.conf" > "$TMP/n.out" 2>&1
check "psensd -n: transport atx without device is refused, with its line" \
	grep -q "nodev.conf:[0-9]*: .*transport atx needs device" "$TMP/n.out"

"$BIN/psensd" -f "$TMP/psensd.conf" -t 12:00 > "$TMP/out" 2> "$TMP/err" &
pid=$!; track_pid $pid
wait_for 10 ctl ping > /dev/null
check "psensd runs with the serial interface" sh -c "\"$BIN/psensctl\" -s \"$S\" ping > /dev/null"
want=$(dali_arc 0.1)
wait_for 5 at_level "$want"
check "noon, the zone at its minimum 10 %: both gear at arc level $want: $(levels)" at_level "$want"
ctl override office 0.3 600 > /dev/null
want=$(dali_arc 0.3)
wait_for 5 at_level "$want"
check "override 30 %: both gear at arc level $want: $(levels)" at_level "$want"
kill -USR1 $bus
wait_for 10 grep -q "zone office: .* fault: " "$TMP/err"
check "the interface silent: a fault naming it: $(grep -o 'fault: .*' "$TMP/err" | head -n 1 | cut -c1-100)" \
	grep -q "zone office: .* fault: .*no reply from the interface" "$TMP/err"
ctl -j status > "$TMP/st.json"
check "... the zone at its safe level, the fault in its status" grep -Eq '"level":1(\.0)?,.*"fault":"' "$TMP/st.json"
kill -USR2 $bus
wait_for 20 grep -q "fault cleared: control resumes" "$TMP/err"
check "the interface back: psensd resumes by itself" grep -q "fault cleared: control resumes" "$TMP/err"
want=$(dali_arc 0.3)
wait_for 5 at_level "$want"
check "the override's level is back on the gear ($want): $(levels)" at_level "$want"
check "the fault was reported once, not at every period" test "$(grep -c 'zone office: .* fault: ' "$TMP/err")" = 1
pd=$(ctl -j ping | sed -n 's/.*"pid":\([0-9]*\).*/\1/p')
kill -TERM "$pd"
wait $pid
check "SIGTERM: psensd drove the lights to the safe level" grep -q "zone office: Terminated: lights at the safe level 100 %" "$TMP/err"
check "the gear's last state: 254 (100 %): $(levels)" at_level 254

# the same driver on transport foxtron over TCP (a DALInet), gear at short 3 and 4
python3 "$(dirname "$0")/peers/dalibus.py" --codec foxtron --tcp "$TMP/port" --gear 3:254,4:254 \
	--state "$TMP/bus.state" > "$TMP/bus2.log" 2>&1 &
track_pid $!
wait_for 10 test -s "$TMP/port" || not_ok "the TCP emulator did not start"
sed "s|^transport = atx|transport = foxtron|; s|^device = /dev.*|device = 127.0.0.1:$(cat "$TMP/port")|" \
	"$TMP/psensd.conf" > "$TMP/tcp.conf"
"$BIN/psensd" -f "$TMP/tcp.conf" -t 12:00 > "$TMP/out2" 2> "$TMP/err2" &
pid=$!; track_pid $pid
wait_for 10 ctl ping > /dev/null
want=$(dali_arc 0.1)
wait_for 5 at_level "$want"
check "foxtron over TCP: both gear at arc level $want (10 %): $(levels)" at_level "$want"
pd=$(ctl -j ping | sed -n 's/.*"pid":\([0-9]*\).*/\1/p')
kill -TERM "$pd"
wait $pid
check "foxtron over TCP: SIGTERM leaves the gear at 254: $(levels)" at_level 254
check "foxtron over TCP: no fault on the way" sh -c "! grep -q 'fault: ' \"$TMP/err2\""
done_testing
