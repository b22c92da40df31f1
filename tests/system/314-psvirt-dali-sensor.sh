#!/bin/sh
# SPDX-License-Identifier: ISC
# psvirt's DALI-2 multisensor (IEC 62386-103 input device, instance 0 an
# occupancy sensor of part 303, instance 1 a light sensor of part 304),
# read by a Foxtron host written from the protocol's description
# (peers/foxclient.py), not by psensd.  The room in real time, without
# noise:
# - the device's instances: 2, types 3 and 4, resolutions 2 and 10 bits;
# - the 304's 10-bit value (QUERY INPUT VALUE, then the latch: the value in
#   the top 10 bits of the two bytes) is the room's sensor signal scaled
#   1023 = 10 V, checked against the same signal on psvirt's Modbus module
#   (input register 0, 65535 = 10 V) to the registers' rounding; the gear
#   dimmed to level 1 lower both alike;
# - enabled with the device event scheme and T_report 1 s, the 304 reports
#   its value as event frames (short address, type 4, the value);
# - the 303 follows --dali-occupancy: occupied (0xFF: "occupied, movement")
#   at 10:00 in the default schedule, vacant (0x00) in its lunch break;
# - unaddressed devices (--dali-unaddressed) are found by the 103 random
#   address search and answer at the short address given;
# - faults: the device's answers colliding (a garbled answer), a bus short
#   (the converter's "power lost"); over the pty as over TCP.
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/peers/common.sh"
[ -x "$BIN/psvirt" ] || skip_all "psvirt not built"
make_results
mb=$(free_port)
start() {  # START ARGS...: psvirt, its room from START
	t=$1; shift
	rm -f "$TMP/ready"
	"$BIN/psvirt" --results "$TMP/ofb.results" --tcp "127.0.0.1:$mb" --dali-tcp 127.0.0.1:0 \
		--start "$t" --ready-file "$TMP/ready" -D gain=0.5 -D noise=0 -D lag_tau=0 "$@" \
		> "$TMP/pv.out" 2> "$TMP/pv.err" &
	pv=$!; track_pid $pv
	wait_for 10 test -s "$TMP/ready" || not_ok "psvirt did not start: $(cat "$TMP/pv.err")"
	port=$(sed -n 's/^dali-tcp //p' "$TMP/ready")
	link="tcp:127.0.0.1:$port"
}
fox() { "$PY" "$PEERS/foxclient.py" "$link" "$@"; }
# the 304's 10-bit value of the device at short $1: the two bytes' top 10 bits
light() {
	a=$(printf '%02X' $(($1 * 2 + 1)))
	set -- $(fox "ask 24 ${a}018C; ask 24 ${a}018D")
	echo $((($1 * 256 + $2) >> 6))
}
# the room's sensor signal from the Modbus module, scaled to 1023 = 10 V
ai10() {
	h=$("$PY" "$PEERS/mbraw.py" 127.0.0.1 "$mb" send "0001 0000 0006 01 04 0000 0001" | awk '{ print $10 $11 }')
	awk -v r=$((0x$h)) 'BEGIN { printf "%d", r / 65535 * 1023 + 0.5 }'
}
near() { [ $(($1 - $2)) -le 1 ] && [ $(($2 - $1)) -le 1 ]; }

start 10:00
check "the device: 2 instances ($(fox 'ask 24 01FE35'))" test "$(fox 'ask 24 01FE35')" = 2
check "instance 0: type 3, occupancy" test "$(fox 'ask 24 010080')" = 3
check "instance 1: type 4, light sensor" test "$(fox 'ask 24 010180')" = 4
check "resolutions: 2 and 10 bits" test "$(fox 'ask 24 010081; ask 24 010181' | tr '\n' ' ')" = "2 10 "
check "instance type 4 addressed by type (0xC4)" test "$(fox 'ask 24 01C480')" = 4
v=$(light 0); s=$(ai10)
check "the 304's value $v is the room's sensor signal $s (1023 = 10 V)" near "$v" "$s"
check "... a daylit morning with the lights on: well inside the range (100 < $v < 1000)" test "$v" -gt 100 -a "$v" -lt 1000
fox "send 16 FE01" > /dev/null   # broadcast DAPC 1: the gear at 0.1 %
sleep 0.2
v2=$(light 0); s2=$(ai10)
check "the gear dimmed to level 1: the value $v2 follows the signal $s2" near "$v2" "$s2"
check "... lower than with the lights on ($v2 < $v)" test "$v2" -lt "$v"
check "occupied at 10:00 (08:00-12:00): 0xFF ($(fox 'ask 24 01008C'))" test "$(fox 'ask 24 01008C')" = 255
# events: DTR0 1, SET EVENT SCHEME (device), SET REPORT TIMER 1 s, ENABLE INSTANCE
fox "send 24 C13001; send 24 010167 twice; send 24 010130 twice; send 24 010162 twice" > /dev/null
check "SET REPORT TIMER took DTR0 1 (QUERY REPORT TIMER: $(fox 'ask 24 01013E'))" test "$(fox 'ask 24 01013E')" = 1
fox "events 2.6" > "$TMP/events"
want=$(printf 'frame %06X' $((4 << 10 | v2)))
check "the 304 reports every second: $(grep -c "^$want\$" "$TMP/events") x '$want'" \
	test "$(grep -c "^$want\$" "$TMP/events")" -ge 2
# faults through the fault registers: 904 the kind, 905 the target (100 + device)
whr() { "$PY" "$PEERS/mbraw.py" 127.0.0.1 "$mb" send "0002 0000 0006 01 06 $(printf %04x "$1") $(printf %04x "$2")" > /dev/null; }
whr 905 100; whr 904 2
check "device 0's answers collide: a garbled answer ($(fox 'send 24 01018C'))" test "$(fox 'send 24 01018C')" = garbled
check "... the gear still answer ($(fox 'ask 16 01A0'))" test "$(fox 'ask 16 01A0')" = 1
whr 904 3
check "a bus short: the converter says power lost ($(fox 'send 24 01018C'))" test "$(fox 'send 24 01018C')" = "power lost"
whr 904 0
check "the short over: the device answers ($(fox 'ask 24 010180'))" test "$(fox 'ask 24 010180')" = 4
kill -TERM $pv; wait $pv

start 12:30 --dali-pty "$TMP/pty" --dali-unaddressed --zones 2
link="pty:$(cat "$TMP/pty")"
check "over the pty: no device at short 0 yet ($(fox 'send 24 01FE35'))" test "$(fox 'send 24 01FE35')" = none
check "... both miss their short address (the same 'yes': $(fox 'send 24 FFFE33'))" test "$(fox 'send 24 FFFE33')" = "answer FF"
fox "search103 20" > "$TMP/search"
diag "$(cat "$TMP/search")"
check "the 103 search found both devices and gave them 20 and 21" \
	test "$(awk '$5 == "verified" { print $4 }' "$TMP/search" | tr '\n' ' ')" = "20 21 "
check "... in ascending random address" sh -c "awk '{ print \$2 }' '$TMP/search' | sort -c"
check "short 20 and 21: light sensors ($(fox 'ask 24 29C480; ask 24 2BC480' | tr '\n' ' '))" \
	test "$(fox 'ask 24 29C480; ask 24 2BC480' | tr '\n' ' ')" = "4 4 "
check "no one misses a short address now ($(fox 'send 24 FFFE33'))" test "$(fox 'send 24 FFFE33')" = none
check "vacant at 12:30 (the schedule's lunch break): 0x00 ($(fox 'ask 24 29008C'))" test "$(fox 'ask 24 29008C')" = 0
v=$(light 20); v1=$(light 21)
check "over the pty, both zones' 304 values are their sensors' signals ($v, $v1 > 0)" test "$v" -gt 0 -a "$v1" -gt 0
check "a wrong checksum: event 5 ($(fox 'badsum 0B0010FFA000'))" test "$(fox 'badsum 0B0010FFA000')" = 0505
check "the firmware query 06 02: a configuration answer ($(fox 'raw 0602'))" test "$(fox 'raw 0602')" = 07020100
kill -TERM $pv; wait $pv
done_testing
