#!/bin/sh
# SPDX-License-Identifier: ISC
# The DALI USB driver in its own process against the emulated Tridonic
# interface hosted by psemu-run (tests/emu): real libusb in the child reaches
# the emulator through umockdev.  Levels and query answers across processes,
# choosing one of two interfaces by serial number, and unplug/replug from the
# control FIFO with the safe level on the gear while the bus is down.
. "$(dirname "$0")/lib.sh"
RUN=$BUILD/tests/psemu-run
CLIENT=$BUILD/tests/dali-client
[ -x "$RUN" ] && [ -x "$CLIENT" ] || skip_all "the DALI emulator is not built (needs libusb-1.0 and umockdev)"
need_preload
emu() { LD_PRELOAD=$PRE ASAN_OPTIONS="$EMU_ASAN" "$RUN" "$@"; }

# 1. a level and its answer, across processes; all four ballasts on broadcast
emu -i 1:A1:4 -- "$CLIENT" -- point 0 dim broadcast set 0 0.5 idle 3 get 0 > "$TMP/1.out" 2>&1
check "the client sets 50 % and reads back level 229 (50.53 %)" grep -q "^get 0 0.505309 level 229" "$TMP/1.out"
check "all four emulated ballasts are at 229" test "$(grep -c 'level 229 target 229' "$TMP/1.out")" = 4

# 2. two interfaces: the serial number picks one; a group address on it
emu -i 1:A1:2 -i 2:B2:3 -- "$CLIENT" serial=B2 -- point 0 dim 1 set 0 0.1 idle 3 > "$TMP/2.out" 2>&1
check "serial B2: its short address 1 is at 10 % (level 170)" grep -q "iface 1 slot 1 level 170" "$TMP/2.out"
check "the other interface's ballasts are untouched" test "$(grep -c '^iface 0 .*level 254' "$TMP/2.out")" = 2
emu -i 1:A1:2 -i 2:B2:3 -- "$CLIENT" -- point 0 dim 1 > "$TMP/2b.out" 2>&1
check "without a choice, open fails and names both" grep -Eq "2 tridonic interfaces found \(at 1-[12] and 1-[12]\)" "$TMP/2b.out"
emu -i 1:A1:2 -- "$CLIENT" port=usb1 -- point 0 dim 1 > "$TMP/2c.out" 2>&1
check "a bad option is named with its place" grep -q "(command line):1: port: 'usb1'" "$TMP/2c.out"

# 3. unplug and replug while the client runs: the gear goes to the system
#    failure level programmed from safe_level, the driver rescans and restores
emu -c "$TMP/ctl" -s "$TMP/state" -t 30 -i 1:A1:2 -- "$CLIENT" safe_level=0.5 -- \
	point 0 dim broadcast set 0 0.1 idle 3 mark ready down 10 up 15 idle 3 get 0 > "$TMP/3.out" 2>&1 &
pid=$!
track_pid "$pid"
wait_for 10 grep -q "mark ready" "$TMP/3.out"
echo "dump" > "$TMP/ctl"
check "10 % before the unplug" wait_for 5 grep -q "iface 0 slot 1 level 170" "$TMP/state"
echo "unplug 0" > "$TMP/ctl"
check "the driver notices the unplug" wait_for 10 grep -q "^down ok" "$TMP/3.out"
two_at_safe_level() { test "$(grep -c 'level 229 target 229 .* plugged 0' "$TMP/state")" = 2; }
check "bus down: both ballasts at the safe level 50 % (229)" wait_for 5 two_at_safe_level
echo "replug 0" > "$TMP/ctl"
check "the client finishes after the replug" wait_for 20 sh -c "! kill -0 $pid 2>/dev/null"
wait "$pid"
rc=$?
check "exit status 0 (got $rc)" test "$rc" = 0
check "reconnected without a restart, the last level (10 %) is back" grep -q "^get 0 0.100.* level 170" "$TMP/3.out"
done_testing
