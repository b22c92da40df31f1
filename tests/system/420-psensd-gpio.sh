#!/bin/sh
# SPDX-License-Identifier: ISC
# The real psensd with the gpio driver on an emulated gpiochip (libgpiod's
# real code; the emulator is preloaded into psensd: tests/emu/vgpio_fixture.c).
# A TSL230R light-to-frequency sensor with its divider pins, two relays (one
# active-low) switching the lights in two steps, and an active-low override
# button.  Checked: the frequency against the emulated rate (exact), the
# divider chosen so the edge rate stays countable, the relays' physical
# levels, one event from a bouncing press, an overrun seen and reported
# (never an undercount) with the lights at the safe level, SIGHUP releasing
# and re-requesting the lines, and SIGTERM leaving the relays at the safe
# state with every line released.
. "$(dirname "$0")/lib.sh"
SO=$TOP/$BUILD/tests/libvgpio_fixture.so
[ -f "$SO" ] || skip_all "the GPIO emulator is not built (needs libgpiod and umockdev)"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
need_preload
example_results
S="$TMP/sock"
{ psensd_section 0.5; cat <<EOF
[device io]
driver = gpio
chip = gpiochip0
EOF
gpio_light_point; cat <<EOF
[point step1]
device = io
role = relay
line = 0
[point step2]
device = io
role = relay
line = 1
active_low = yes
[point button]
device = io
role = input
action = override
line = 6
active_low = yes
debounce = 0.02
[zone office]
sensor = light
relay = step1 step2
input = button
algorithm = switching
s_off = 3.0
s_on = 1.0
delay = 1
steps = 2
override_time = 2
EOF
} > "$TMP/psensd.conf"
ctl() { "$BIN/psensctl" -s "$S" "$@"; }
st() { ctl -j status; }
lv() { awk -v l="$1" '$2 == l { print $4 }' "$TMP/vgpio.state"; }
held() { awk '{ h += $6 } END { print h + 0 }' "$TMP/vgpio.state"; }
cmd() { echo "$*" > "$TMP/ctl"; }
LD_PRELOAD=$PRE:$SO VGPIO_TARGET=psensd VGPIO_INIT=6=1 VGPIO_CTL="$TMP/ctl" VGPIO_STATE="$TMP/vgpio.state" \
	ASAN_OPTIONS="$EMU_ASAN" \
	"$BIN/psensd" -f "$TMP/psensd.conf" > "$TMP/out" 2> "$TMP/err" &
pid=$!; track_pid $pid
wait_for 10 sh -c "\"$BIN/psensctl\" -s \"$S\" ping > /dev/null"
check "psensd runs with the gpio driver on the emulated chip" sh -c "\"$BIN/psensctl\" -s \"$S\" ping > /dev/null"
check "it holds the six lines it was given" wait_for 3 sh -c "[ \$(awk '{ h += \$6 } END { print h + 0 }' '$TMP/vgpio.state') = 6 ]"
# dim light: 500 Hz at the pin, signal 0.5 < s_on: full output, both relays on
cmd tsl230 3 500 4 5
wait_for 5 sh -c "\"$BIN/psensctl\" -s \"$S\" -j status | grep -q '\"sensor_v\":0.5,'"
check "500 Hz reads 0.5 exactly (factor 0.001)" sh -c "\"$BIN/psensctl\" -s \"$S\" -j status | grep -q '\"sensor_v\":0.5,'"
check "full output: relay 1 high, relay 2 (active low) low" test "$(lv 0) $(lv 1)" = "1 0"
# daylight: 5 kHz is over max_rate 2000: the divider goes to /10 or /100
cmd tsl230 3 5000 4 5
wait_for 8 sh -c "\"$BIN/psensctl\" -s \"$S\" -j status | grep -q '\"sensor_v\":5,\\|\"sensor_v\":5.0,'"
check "5 kHz reads 5.0 exactly through the divider" sh -c "\"$BIN/psensctl\" -s \"$S\" -j status | grep -q '\"sensor_v\":5\\(.0\\)\\{0,1\\},'"
check "the divider pins S2 S3 = 1 1 (/100: 50 edges/s) or 1 0 (/10: 500)" sh -c "[ \"$(lv 4) $(lv 5)\" = '1 1' ] || [ \"$(lv 4) $(lv 5)\" = '1 0' ]"
wait_for 8 sh -c "[ \"\$(awk '\$2 == 0 || \$2 == 1 { printf \"%s\", \$4 }' '$TMP/vgpio.state')\" = 01 ]"
check "above s_off for the delay: two steps down, both relays off" test "$(lv 0) $(lv 1)" = "0 1"
# the button: five bounces, then held 200 ms: one event, full output
cmd press 6 0 5 200
wait_for 3 grep -q "button: full output" "$TMP/err"
check "a bouncing press is one event" test "$(grep -c 'button: full output' "$TMP/err")" = 1
wait_for 3 sh -c "[ \"\$(awk '\$2 == 0 || \$2 == 1 { printf \"%s\", \$4 }' '$TMP/vgpio.state')\" = 10 ]"
check "override: both relays on" test "$(lv 0) $(lv 1)" = "1 0"
# an overrun: 20 MHz is 200 000 edges/s even at /100; the emulator delivers
# them 40 at a time (every 200 us), more than the kernel's 16-event buffer
cmd tsl230 3 20000000 4 5
overrun() { "$BIN/psensctl" -s "$S" -j status | grep -q '"fault":"gpio io line 3: edges lost at [0-9]* edges/s'; }
# (checked as it happens: under a sanitizer the emulator's own thread can be
# starved for a gate, and a gate of what the emulated pin really delivered
# is a good reading)
if wait_for 8 overrun; then
	ok "lost edges are a fault, not a low count: $("$BIN/psensctl" -s "$S" -j status | grep -o 'edges lost[^)]*)')"
else
	not_ok "lost edges are a fault, not a low count: $("$BIN/psensctl" -s "$S" -j status)"
fi
check "the divider goes up to /100 trying" wait_for 3 sh -c "[ \"\$(awk '\$2 == 4 || \$2 == 5 { printf \"%s\", \$4 }' '$TMP/vgpio.state')\" = 11 ]"
check "the emulated kernel buffer did drop events ($(awk '$2 == 3 { print $8 }' "$TMP/vgpio.state"))" test "$(awk '$2 == 3 { print $8 }' "$TMP/vgpio.state")" -gt 0
wait_for 3 sh -c "[ \"\$(awk '\$2 == 0 || \$2 == 1 { printf \"%s\", \$4 }' '$TMP/vgpio.state')\" = 10 ]"
check "the lights at the safe level: both relays on" test "$(lv 0) $(lv 1)" = "1 0"
at100() { "$BIN/psensctl" -s "$S" -j status | grep -q '"fault":"gpio io line 3: edges lost at [0-9]* edges/s with the divider at /100'; }
check "still overrun at /100: the fault stays" wait_for 5 at100
cleared=$(grep -c "fault cleared" "$TMP/err")
cmd tsl230 3 500 4 5
wait_for 10 sh -c "[ \$(grep -c 'fault cleared' '$TMP/err') -gt $cleared ]"
check "back to 500 Hz: the divider comes down and control resumes" test "$(grep -c 'fault cleared' "$TMP/err")" -gt "$cleared"
# SIGHUP: the lines are released and requested again (else EBUSY)
kill -HUP $pid
wait_for 5 grep -q "reloaded\|running configuration stays" "$TMP/err"
check "SIGHUP reopens the chip: its lines were released" grep -q "reloaded" "$TMP/err"
# SIGTERM: relays to the safe state, every line released
kill -TERM $pid; wait $pid; rc=$?
check "SIGTERM: exit 0" test "$rc" = 0
check "relays left at the safe state (both on)" test "$(lv 0) $(lv 1)" = "1 0"
check "every line released" test "$(held)" = 0
done_testing
