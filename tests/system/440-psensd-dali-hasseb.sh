#!/bin/sh
# SPDX-License-Identifier: ISC
# The real psensd dimming DALI ballasts through the hasseb DALI Master
# (transport = hasseb): psensd runs as the child of psemu-run, its real
# libusb reaching the emulated hasseb (04cc:0802, 10-byte reports, no echo,
# no DTR0 prefix) with two ballasts through umockdev, on a clock 120 times
# faster than real from 11:00.  Checked against the standard curve
# X(n) = 10^((n-1)/(253/3)-1) % and the ballasts' own state: the system
# failure level 50 % reaches them (a DTR0 frame, then SET SYSTEM FAILURE
# LEVEL sent twice) and they take it when the bus goes down; they follow
# an override; a garbled answer to every
# try is a fault that drives them to the safe level, and control resumes
# by itself; unplugged, psensd reports the lost bus and resumes on replug;
# SIGTERM leaves them at the safe level.  psensctl dali status shows the
# firmware version the emulated interface reports when asked at connect.
. "$(dirname "$0")/lib.sh"
RUN=$BUILD/tests/psemu-run
[ -x "$RUN" ] || skip_all "the DALI emulator is not built (needs libusb-1.0 and umockdev)"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
need_preload
example_results
S="$TMP/sock"
{ psensd_section 30 120; cat <<EOF
[device room]
driver = loopback
gain = 0.5
noise = 0.002
[device dali]
driver = dali_usb
transport = hasseb
safe_level = 0.5
fade_time = 0
[point sensor]
device = room
role = sensor
[point lamp]
device = room
role = dim
[point ballasts]
device = dali
role = dim
address = broadcast
[zone office]
sensor = sensor
dim = lamp ballasts
sensor_gain = 0.5
min_level = 0.1
EOF
} > "$TMP/psensd.conf"
ctl() { "$BIN/psensctl" -s "$S" "$@"; }
# the arc power level for a light output, by the standard curve (nearest in ratio)
arc() { awk -v u="$1" 'BEGIN { if (u <= 0) { print 0; exit } n = 1 + (253 / 3) * (log(100 * u) / log(10) + 1); n = int(n + 0.5); if (n < 1) n = 1; if (n > 254) n = 254; print n }'; }
dump() { echo dump > "$TMP/ctl"; sleep 0.2; }
field() { dump; awk -v k="$1" '{ for (i = 1; i < NF; i++) if ($i == k) print $(i + 1) }' "$TMP/emu.state" | sort -u | tr '\n' ' ' | sed 's/ $//'; }
levels() { field level; }
at_level() { [ "$(field level)" = "$1" ]; }
LD_PRELOAD=$PRE ASAN_OPTIONS="$EMU_ASAN" \
	"$RUN" -c "$TMP/ctl" -s "$TMP/emu.state" -t 90 -i 1:A1:2:hasseb -- \
	"$BIN/psensd" -f "$TMP/psensd.conf" -t 11:00 -x 120 > "$TMP/out" 2> "$TMP/err" &
pid=$!; track_pid $pid
wait_for 10 ctl ping > /dev/null
check "psensd runs under the hasseb emulator" sh -c "\"$BIN/psensctl\" -s \"$S\" ping > /dev/null"
wait_for 10 test "$(field sfl)" = 229
check "SYSTEM FAILURE LEVEL 229 (50 %, not the default 254) through DTR0 on both ballasts: $(field sfl)" \
	test "$(field sfl)" = 229
# the emulated firmware's version (2.5), asked at connect, in the status
ctl dali dali status > "$TMP/status" 2>&1
check "psensctl dali status shows the interface's firmware: $(head -n 1 "$TMP/status")" \
	grep -q "^dali: interface firmware 2\.5$" "$TMP/status"
ctl override office 0.3 36000 > /dev/null
want=$(arc 0.3)
wait_for 10 at_level "$want"
check "override 30 %: both ballasts at arc level $want: $(levels)" test "$(levels)" = "$want"
# three garbled answers (status 3): the next level's DAPC fails after its
# two retries, the zone goes to its safe level, then control resumes
echo "fault 0 garbled 3" > "$TMP/ctl"
ctl override office 0.5 36000 > /dev/null
wait_for 15 grep -q "zone office: .* fault: .*garbled" "$TMP/err"
check "garbled answers: psensd reports the fault: $(grep -o 'fault: .*' "$TMP/err" | head -n 1 | cut -c1-120)" \
	grep -q "zone office: .* fault: .*garbled answer" "$TMP/err"
wait_for 15 grep -q "fault cleared: control resumes" "$TMP/err"
check "... and resumes by itself" grep -q "fault cleared: control resumes" "$TMP/err"
want=$(arc 0.5)
wait_for 10 at_level "$want"
check "override 50 % on the ballasts after the fault: arc level $want: $(levels)" test "$(levels)" = "$want"
echo "unplug 0" > "$TMP/ctl"
wait_for 10 grep -q "zone office: .* fault: DALI USB interface" "$TMP/err"
check "unplugged: psensd reports the lost bus" \
	grep -q "zone office: .* fault: DALI USB interface: interface unplugged" "$TMP/err"
check "the ballasts, off the bus, hold their system failure level 229 (50 %): $(levels)" test "$(levels)" = 229
echo "replug 0" > "$TMP/ctl"
wait_for 20 test "$(grep -c 'fault cleared: control resumes' "$TMP/err")" -ge 2
check "replugged: psensd resumes by itself" test "$(grep -c 'fault cleared: control resumes' "$TMP/err")" -ge 2
wait_for 10 at_level "$want"
check "the override's level is back on the ballasts ($want): $(levels)" test "$(levels)" = "$want"
pd=$(ctl -j ping | sed -n 's/.*"pid":\([0-9]*\).*/\1/p')
kill -TERM "$pd"
wait $pid
check "SIGTERM: psensd drove the lights to the safe level" grep -q "zone office: Terminated: lights at the safe level 100 %" "$TMP/err"
check "the ballasts' last state: 254 (100 %)" test "$(awk '{ print $6 }' "$TMP/emu.state" | sort -u)" = 254
done_testing
