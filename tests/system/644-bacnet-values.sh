#!/bin/sh
# SPDX-License-Identifier: ISC
# check: alone
# (a vacancy hold timed on the real clock)
# psensd's writable BACnet Values (doc/bacnet-pics.md, psensd.conf(5)
# [bacnet] writes) against an outside BACnet stack, @bacnet-js/client
# (tests/peers/bacnet-values-peer.js), on loopback with psensd in real time
# sped up 600 times on the loopback room.  With writes = lighting-output
# target daylighting: the target lux (Analog Value) and daylight control
# (Binary Value) read with their Priority_Array and Relinquish_Default,
# written at priorities 12 and 8 and relinquished (Present_Value follows
# the highest), writes outside [bacnet] target_min and target_max (50 and
# 1500 lx) and not-writable writes refused with their errors, and with daylight control off the light level is target / the
# electric task lux at full output and follows a new target; every write
# reaches the engine and is logged.  With the Lighting Output alone opened,
# the Values are write-access-denied.  A zone in a sensor fault stays at
# its safe level whatever is written.  A reload that changes the
# configured target keeps a written one (the priority array outlives it).
# A zone with an occupancy input: its vacancy hold written over BACnet
# decides when the lights reach the vacant level.  A word `writes` does not know is
# refused with its line.  Written values are not kept across
# a restart: psensd starts from the configured target.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v node > /dev/null || skip_all "node is not installed (make deps: nodejs)"
[ -d "$TOP/tests/peers/node_modules/@bacnet-js/client" ] ||
	skip_all "the BACnet peer is not installed (make deps-peers, which make check runs: npm ci in tests/peers)"
PEER="$TOP/tests/peers/bacnet-values-peer.js"
example_results
S="$TMP/sock"
ctl() { "$BIN/psensctl" -s "$S" "$@"; }
# zone office's KEY from psensctl status (a points key with points.KEY)
status_of() {
	ctl -j status | /usr/bin/python3 -c 'import json, sys
z = [z for z in json.load(sys.stdin)["zones"] if z.get("name") == "office"][0]
for k in sys.argv[1].split("."):
    z = z[k]
print(int(z) if isinstance(z, float) and z == int(z) else z)' "$1"
}

# start MODE: psensd with [bacnet] on a free port (MODE 0: writes =
# lighting-output; 2: the sensor open from 08:01 to 11:00; else every write)
start() {
	port=$(free_udp_port)
	f="/^faults = /d"; [ "$1" = 2 ] && f="s|^faults = .*|faults = open 08:01-11:00|"
	sed "s|^results = .*|results = state/ofb.results|; s|^database = .*|database = state/psensd$1.db\nsocket = sock|; $f" \
		config/psensd.conf > "$TMP/psensd.conf"
	w="lighting-output target daylighting"; [ "$1" = 0 ] && w=lighting-output
	printf '\n[bacnet]\nbind = 127.0.0.1\nport = %s\ninstance = 2644\nwrites = %s\nrate = 100000\ntarget_min = 50\ntarget_max = 1500\n' \
		"$port" "$w" >> "$TMP/psensd.conf"
	"$BIN/psensd" -f "$TMP/psensd.conf" -t 08:00 -x 600 > "$TMP/out$1" 2>> "$TMP/err$1" &
	PID=$!; track_pid $PID
	wait_for 10 ctl ping > /dev/null
}

# peer MODE: the peer against it, its lines as diagnostics
peer() {
	PEER_PORT=$(free_udp_port) node "$PEER" "$port" 2644 "$1" "$(status_of electric_task_lux)" > "$TMP/peer$1" 2>&1
	rc=$?
	sed -n 's/^\(not \)\{0,1\}ok [0-9]* - /peer: /p' "$TMP/peer$1" | while read -r l; do diag "$l"; done
	grep '^# ' "$TMP/peer$1"
	check "the peer's checks all pass (mode $1; $(grep -c '^ok' "$TMP/peer$1") ok, $(grep -c '^not ok' "$TMP/peer$1") not ok)" \
		test "$rc" = 0 -a "$(grep -c '^not ok' "$TMP/peer$1")" = 0 -a "$(grep -c '^ok' "$TMP/peer$1")" -ge 4
}

start 1
check "psensd logs what a BMS may write" \
	grep -q "bacnet: device 2644 'psensd' on udp 127.0.0.1:$port, 1 zone(s), writes to: the lighting outputs the target daylighting" "$TMP/err1"
peer 1
check "the engine took the target at priority 12" grep -q "zone office: target 300 lx" "$TMP/err1"
check "the BACnet room logged who set it" grep -q "bacnet: zone office: target_lux 300 at priority 12" "$TMP/err1"
check "and the relinquish to the configured value" \
	grep -q "bacnet: zone office: target_lux: every priority relinquished: 500 (the configured value)" "$TMP/err1"
check "daylight control off, then on, in the engine's log" \
	sh -c "grep -q 'zone office: daylight control off' '$TMP/err1' && grep -q 'zone office: daylight control on' '$TMP/err1'"
check "every write relinquished: status shows the configured target and daylight control" \
	test "$(status_of points.target_lux) $(status_of points.daylighting)" = "500 True"
check "psensd still answers the control socket" sh -c "\"$BIN/psensctl\" -s \"$S\" ping > /dev/null"

# a write left in force is not kept across a restart
peer 3
check "status shows the written target while it is in force" test "$(status_of points.target_lux)" = 321
sed -i 's/^target_lux = 500$/target_lux = 450/' "$TMP/psensd.conf"
ctl reload > "$TMP/reload.out"
wait_for 10 sh -c "grep -q 'bacnet: zone office: target_lux 321 at priority 16' '$TMP/err1' &&
	test \"\$(grep -c 'bacnet: zone office: target_lux 321 at priority 16' '$TMP/err1')\" -ge 2"
check "a reload with a new configured target (450): the priority array puts 321 back" \
	test "$(status_of points.target_lux)" = 321 -a "$(grep -c 'bacnet: zone office: target_lux 321 at priority 16' "$TMP/err1")" = 2
kill "$PID"; wait "$PID" 2> /dev/null
start 1
check "after a restart the configured target holds again" test "$(status_of points.target_lux)" = 500
kill "$PID"; wait "$PID" 2> /dev/null

start 0
peer 0
check "writes not opened: the engine's target never moved" sh -c "! grep -q 'zone office: target ' '$TMP/err0'"
kill "$PID"; wait "$PID" 2> /dev/null

start 2
peer 2
check "the fault was the engine's: the zone went to its safe level" grep -q "zone office: .* fault: sensor .*: lights to the safe level 100 %" "$TMP/err2"
check "the writes reached the engine during the fault" \
	sh -c "grep -q 'zone office: target 100 lx' '$TMP/err2' && grep -q 'zone office: daylight control off' '$TMP/err2'"
kill "$PID"; wait "$PID" 2> /dev/null

sed 's/^writes = .*/writes = lighting-output everything/' "$TMP/psensd.conf" > "$TMP/bad.conf"
"$BIN/psensd" -n -f "$TMP/bad.conf" > "$TMP/bad.out" 2>&1
sed 's/^target_max = .*/target_max = 40/' "$TMP/psensd.conf" > "$TMP/bad2.conf"
"$BIN/psensd" -n -f "$TMP/bad2.conf" > "$TMP/bad2.out" 2>&1
check "target_max below target_min is refused with its line" \
	grep -q "bad2.conf:[0-9]*: target_max (40 lx) must be above target_min (50 lx)" "$TMP/bad2.out"
check "a word [bacnet] writes does not know is refused with its line" \
	grep -q "bad.conf:[0-9]*: writes: 'everything' is not one of none, lighting-output, target, daylighting, vacancy-hold" "$TMP/bad.out"
# the vacancy hold: the occupancy example (occupied from 08:00, vacant at
# 12:00, no random absences) from 11:30, the hold written down from 900 s
# to 120 s before noon: the lights reach the vacant level (0) within the
# hold plus one period (60 s) of the vacancy, not after 900 s
port=$(free_udp_port)
sed -e "s|^scene = .*|scene = example/ofb.scene|; s|^results = .*|results = state/ofb.results|" \
    -e "s|^database = .*|database = state/occ.db\nsocket = sock|; s|^absences = .*|absences = 0|" \
	config/example/occupancy.conf > "$TMP/occ.conf"
printf '\n[bacnet]\nbind = 127.0.0.1\nport = %s\ninstance = 2644\nwrites = vacancy-hold\nrate = 100000\ntarget_min = 50\ntarget_max = 1500\n' \
	"$port" >> "$TMP/occ.conf"
"$BIN/psensd" -f "$TMP/occ.conf" -t 11:30 -x 600 > "$TMP/out4" 2> "$TMP/err4" &
PID=$!; track_pid $PID
wait_for 10 ctl ping > /dev/null
peer 4
check "status shows the written hold" test "$(status_of occupancy.hold_s)" = 120
check "the BACnet room logged it" grep -q "bacnet: zone office: vacancy_hold 120 at priority 8" "$TMP/err4"
if command -v sqlite3 > /dev/null; then
	# the first vacant sample after 11:59, the first at the vacant level
	# (as 225 measures the hold: from the first vacant sample)
	OFF="select min(tod_s) from samples where occupied = 0 and output = 0 and tod_s > 43140 and tod_s < 46800"
	VAC="select min(tod_s) from samples where occupied = 0 and tod_s > 43140 and tod_s < 46800"
	wait_for 20 sh -c "test -n \"\$(sqlite3 '$TMP/state/occ.db' '$OFF')\""
	off=$(sqlite3 "$TMP/state/occ.db" "$OFF"); vac=$(sqlite3 "$TMP/state/occ.db" "$VAC")
	check "vacant at ${vac:-never} s, the lights off ${off:-never} s: after the 120 s hold, within it plus one period (60 s), not after 900 s" \
		awk -v o="${off:-0}" -v v="${vac:-0}" 'BEGIN { exit !(v > 0 && o - v >= 119 && o - v <= 181) }'
else
	diag "sqlite3 not installed: the lights' time at the vacant level is not checked"
fi
kill "$PID"; wait "$PID" 2> /dev/null
done_testing
