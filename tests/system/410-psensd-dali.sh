#!/bin/sh
# SPDX-License-Identifier: ISC
# The real psensd dimming emulated DALI ballasts: psensd runs as the child of
# psemu-run (tests/emu), its real libusb reaching the emulated Tridonic
# interface with two ballasts through umockdev.  One zone, its sensor on the
# loopback room, its outputs the room's ballast and the DALI broadcast point,
# in real time (the DALI driver's frame gap and timeouts are wall-clock
# facts).  Checked against the standard curve X(n) = 10^((n-1)/(253/3)-1) %:
# the ballasts follow the zone's level and an override; unplugged, psensd
# reports the lost bus and the ballasts sit at their system failure level;
# replugged, psensd resumes by itself; SIGTERM leaves them at the safe level,
# even when it comes while another frame is on the bus.
. "$(dirname "$0")/lib.sh"
RUN=$BUILD/tests/psemu-run
[ -x "$RUN" ] || skip_all "the DALI emulator is not built (needs libusb-1.0 and umockdev)"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
need_preload
example_results
S="$TMP/sock"
{ psensd_section 0.5 2; dali_room; cat <<EOF
[device dali]
driver = dali_usb
safe_level = 1.0
fade_time = 0
EOF
dali_room_zone; } > "$TMP/psensd.conf"
ctl() { "$BIN/psensctl" -s "$S" "$@"; }
levels() { echo dump > "$TMP/ctl"; sleep 0.2; awk '{ print $6 }' "$TMP/emu.state" | sort -u | tr '\n' ' ' | sed 's/ $//'; }
plugged() { awk '{ print $NF }' "$TMP/emu.state" | sort -u; }
at_level() { echo dump > "$TMP/ctl"; sleep 0.1; [ "$(awk '{ print $6 }' "$TMP/emu.state" | sort -u)" = "$1" ]; }
LD_PRELOAD=$PRE ASAN_OPTIONS="$EMU_ASAN" \
	"$RUN" -c "$TMP/ctl" -s "$TMP/emu.state" -t 60 -i 1:A1:2 -- \
	"$BIN/psensd" -f "$TMP/psensd.conf" -t 12:00 > "$TMP/out" 2> "$TMP/err" &
pid=$!; track_pid $pid
wait_for 10 ctl ping > /dev/null
check "psensd runs under the emulator" sh -c "\"$BIN/psensctl\" -s \"$S\" ping > /dev/null"
sleep 1.5
check "noon: the zone is at its minimum level 10 %" test "$(ctl -j status | grep -o '"level":[0-9.]*' | head -n 1)" = '"level":0.1'
want=$(dali_arc 0.1)
wait_for 5 at_level "$want"
check "both ballasts at arc level $want (10 %): $(levels)" test "$(levels)" = "$want"
ctl override office 0.3 600 > /dev/null
want=$(dali_arc 0.3)
wait_for 5 at_level "$want"
check "override 30 %: both ballasts at arc level $want: $(levels)" test "$(levels)" = "$want"
echo "unplug 0" > "$TMP/ctl"
wait_for 10 grep -q "zone office: .* fault: DALI USB interface" "$TMP/err"
check "unplugged: psensd reports the lost bus: $(grep -o 'fault: .*' "$TMP/err" | head -n 1 | cut -c1-100)" \
	grep -q "zone office: .* fault: DALI USB interface: interface unplugged" "$TMP/err"
ctl -j status > "$TMP/st.json"
check "... and its status shows the safe level and the fault" grep -Eq '"level":1(\.0)?,.*"fault":"DALI' "$TMP/st.json"
grep -Eq '"level":1(\.0)?,.*"fault":"DALI' "$TMP/st.json" || diag "$(cat "$TMP/st.json")"
check "the ballasts, off the bus, hold their system failure level 254 (100 %): $(levels)" test "$(levels)" = 254
check "the emulator shows them unplugged" test "$(plugged)" = 0
echo "replug 0" > "$TMP/ctl"
wait_for 20 grep -q "fault cleared: control resumes" "$TMP/err"
check "replugged: psensd resumes by itself" grep -q "fault cleared: control resumes" "$TMP/err"
want=$(dali_arc 0.3)
wait_for 5 at_level "$want"
check "the override's level is back on the ballasts ($want): $(levels)" test "$(levels)" = "$want"
check "the fault was reported once, not at every period" test "$(grep -c 'fault: DALI' "$TMP/err")" = 1
pd=$(ctl -j ping | sed -n 's/.*"pid":\([0-9]*\).*/\1/p')
# SIGTERM just after a new level was asked for: its frame is on the bus (a
# DALI transaction takes 30-50 ms) when the safe level's is queued, and the
# safe level's must still go out before the interface is closed (this was
# the flake "the ballasts' last state": the queued frame was dropped)
ctl override office 0.5 600 > /dev/null
kill -TERM "$pd"
wait $pid
check "SIGTERM: psensd drove the lights to the safe level" grep -q "zone office: Terminated: lights at the safe level 100 %" "$TMP/err"
check "the ballasts' last state: 254 (100 %)" test "$(awk '{ print $6 }' "$TMP/emu.state" | sort -u)" = 254
done_testing
