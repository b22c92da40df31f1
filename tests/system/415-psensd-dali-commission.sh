#!/bin/sh
# SPDX-License-Identifier: ISC
# Commissioning a DALI site through the real psensd and psensctl: psensd runs
# as the child of psemu-run (tests/emu), whose emulated Tridonic interface
# has six ballasts: two with short addresses 0 and 1, four without, two of
# which draw the same random address (answering 3 ms apart, so their "yes"
# frames garble).  Three zones each dim one DALI group.  The test scans the
# bus, addresses the new ballasts, puts two ballasts in each zone's group,
# identifies one, verifies each zone, and then dims the zones; the
# emulator's state says where every ballast ended up.  psensd keeps the
# interface: a second program cannot claim it, and a second job waits.
. "$(dirname "$0")/lib.sh"
RUN=$BUILD/tests/psemu-run
CLIENT=$BUILD/tests/dali-client
[ -x "$RUN" ] && [ -x "$CLIENT" ] || skip_all "the DALI emulator is not built (needs libusb-1.0 and umockdev)"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
need_preload
example_results
S="$TMP/sock"
{
	psensd_section 0.5 5
	cat <<EOF
[device dali]
driver = dali_usb
EOF
	g=0
	for z in east middle west; do
		cat <<EOF
[device room_$z]
driver = loopback
gain = 0.5
noise = 0.002
[point sensor_$z]
device = room_$z
role = sensor
[point lamps_$z]
device = dali
role = dim
address = group $g
[zone $z]
sensor = sensor_$z
dim = lamps_$z
sensor_gain = 0.5
min_level = 0.1
EOF
		g=$((g + 1))
	done
} > "$TMP/psensd.conf"
ctl() { "$BIN/psensctl" -s "$S" "$@"; }
dump() { echo dump > "$TMP/ctl"; sleep 0.3; }
# the slot's value of a dump field (short, level, groups, random)
field() { awk -v s="$1" -v k="$2" '$4 == s { for (i = 1; i < NF; i++) if ($i == k) print $(i + 1) }' "$TMP/emu.state"; }
# the slot whose short address is $1
slot_of() { awk -v a="$1" '{ for (i = 1; i < NF; i++) if ($i == "short" && $(i + 1) == a) print $4 }' "$TMP/emu.state"; }

LD_PRELOAD=$PRE ASAN_OPTIONS="$EMU_ASAN" \
	"$RUN" -c "$TMP/ctl" -s "$TMP/emu.state" -u "$TMP/udir" -t 150 -i 1:A1:6 \
	-b 0:reply=6.0 -b 1:reply=7.0 \
	-b 2:short=none,draw=0x2A0000,reply=8.0 \
	-b 3:short=none,draw=0x5A5A5A,reply=6.5 -b 4:short=none,draw=0x5A5A5A,reply=9.5 \
	-b 5:short=none,draw=0xC30000,reply=10.0 -- \
	"$BIN/psensd" -f "$TMP/psensd.conf" -t 12:00 > "$TMP/out" 2> "$TMP/err" &
pid=$!; track_pid $pid
wait_for 10 ctl ping > /dev/null
check "psensd runs under the emulator with three zones" sh -c "\"$BIN/psensctl\" -s \"$S\" status | grep -c 'name: ' | grep -qx 3"

# 0. requests psensd refuses, and why
ctl dali room_east scan > "$TMP/e1" 2>&1
check "dali on a loopback device: refused" grep -q "device room_east (driver loopback) is not a DALI interface" "$TMP/e1"
ctl dali nosuch scan > "$TMP/e2" 2>&1
check "dali on no device: refused" grep -q "no device 'nosuch'" "$TMP/e2"
ctl dali dali verify nosuch > "$TMP/e3" 2>&1
check "verify of no zone: refused" grep -q "no zone 'nosuch'" "$TMP/e3"
ctl dali dali address sideways > "$TMP/e4" 2>&1
check "a bad request names the problem" grep -q "address new|all: 'sideways' is neither" "$TMP/e4"
ctl dali dali status > "$TMP/e5" 2>&1
check "status before any job" grep -q "dali: no commissioning job since psensd started" "$TMP/e5"

# 1. what is on the bus
ctl dali dali scan > "$TMP/scan1" 2> "$TMP/scan1.err"
check "scan: exit 0" test $? = 0
diag "$(head -n 1 "$TMP/scan1")"
# four without an address answer out of step: their "yes" is one garbled frame
check "scan: short addresses 0 and 1 answer, and several ballasts have no short address" \
	grep -q "scan done .*: 2 short addresses answer; gear without a short address: several" "$TMP/scan1"
check "scan: a line per ballast with its settings" test "$(grep -cE '^ +[01] +one +6 ' "$TMP/scan1")" = 2

# 2. addresses for the new ballasts, with the zones' control running
steps0=$(ctl -j status middle | sed -n 's/.*"steps":\([0-9]*\).*/\1/p')
ctl dali dali address > "$TMP/addr" 2> "$TMP/addr.err"
rc=$?
steps1=$(ctl -j status middle | sed -n 's/.*"steps":\([0-9]*\).*/\1/p')
check "address: exit 0" test "$rc" = 0
diag "$(head -n 1 "$TMP/addr")"
check "address: four new short addresses, the clash separated" \
	grep -Eq "address done .*: 4 ballasts found: 4 new short addresses, 0 kept theirs; [1-9][0-9]* random-address clashes separated" "$TMP/addr"
check "address: progress was shown while it ran" grep -q "searching for ballast" "$TMP/addr.err"
check "the zones kept their control steps during the search ($steps0 -> $steps1)" test "$steps1" -gt $((steps0 + 4))
dump
shorts=$(for s in 0 1 2 3 4 5; do field $s short; done | sort -n | tr '\n' ' ')
check "the emulated ballasts hold short addresses 0 to 5, each once: $shorts" test "$shorts" = "0 1 2 3 4 5 "
check "the ballasts that had addresses kept them" test "$(field 0 short)$(field 1 short)" = 01
check "the colliding pair drew new random addresses: $(field 3 random) $(field 4 random)" \
	test "$(field 3 random)" != "$(field 4 random)"

# 3. groups: two ballasts per zone (group = short address / 2)
ok=1
for a in 0 1 2 3 4 5; do
	ctl dali dali group $a add $((a / 2)) > "$TMP/group$a" 2>&1 || ok=0
done
check "group: six requests done" test "$ok" = 1
check "group: the reply shows the groups afterwards" grep -q "^  5: groups 2$" "$TMP/group5"
dump
grp=""
for a in 0 1 2 3 4 5; do grp="$grp $(field "$(slot_of $a)" groups)"; done
check "the ballasts' groups by short address:$grp" test "$grp" = " 0x0001 0x0001 0x0002 0x0002 0x0004 0x0004"

# 4. identify one; a second job waits for it; nobody else may claim the interface
ctl dali dali identify 3 3 > "$TMP/ident" 2>&1 &
ipid=$!
sleep 0.5
ctl dali dali scan > "$TMP/busy" 2>&1
check "a second job is refused while one runs" grep -q "identify is running" "$TMP/busy"
UMOCKDEV_DIR=$(cat "$TMP/udir") LD_PRELOAD=$PRE ASAN_OPTIONS="$EMU_ASAN" \
	"$CLIENT" -- point 0 dim 3 set 0 0.5 > "$TMP/second" 2>&1
check "a second program cannot claim the interface: $(grep -o 'cannot claim.*' "$TMP/second" | head -n 1)" \
	grep -q "cannot claim it: Resource busy" "$TMP/second"
wait $ipid
check "identify: short 3 flashed and went back" grep -q "identify done .*: flashed 3 times, back at level" "$TMP/ident"

# 5. verify each zone
for z in east middle west; do
	ctl dali dali verify $z > "$TMP/verify_$z" 2> "$TMP/verify_$z.err"
	check "verify $z: exit 0, both of its ballasts follow" sh -c "test $? = 0 && grep -q 'all 2 ballasts follow' \"$TMP/verify_$z\""
done
sed 's/^/# /' "$TMP/verify_middle"
check "verify shows each ballast's levels" grep -Eq "short 2 +expected 254,170 +got 254,170 +ok" "$TMP/verify_middle"

# 6. the zones, controlled: each at its own level, on its own two ballasts
ctl override east 0.5 600 > /dev/null
ctl override middle 0.3 600 > /dev/null
ctl override west 1.0 600 > /dev/null
want="$(dali_arc 0.5) $(dali_arc 0.5) $(dali_arc 0.3) $(dali_arc 0.3) $(dali_arc 1.0) $(dali_arc 1.0)"
zone_levels() {
	dump
	lv=""
	for a in 0 1 2 3 4 5; do lv="$lv $(field "$(slot_of $a)" level)"; done
	test "$lv" = " $want"
}
wait_for 10 zone_levels
check "each zone's two ballasts at its level (by short address 0..5:$lv; want $want)" test "$lv" = " $want"
ctl -j dali dali status > "$TMP/status.json"
check "dali status -j: one JSON line with the last job" grep -q '^{"ok":true,"dali":{"device":"dali","connected":true,"job":"verify","state":"done"' "$TMP/status.json"
check "psensd logged the requests" grep -q "device dali: dali address" "$TMP/err"
pd=$(ctl -j ping | sed -n 's/.*"pid":\([0-9]*\).*/\1/p')
kill -TERM "$pd"
wait $pid
check "psensd stopped cleanly" grep -q "Terminated: lights at the safe level" "$TMP/err"
done_testing
