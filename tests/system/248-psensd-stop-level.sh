#!/bin/sh
# SPDX-License-Identifier: ISC
# What each way out of psensd leaves the lights at (psensd(8), STOPPING;
# psensd.conf(5) stop_level).  The office's lamps are the loopback room's
# and a file point beside them, whose file holds the last level psensd
# wrote after it has exited (the gear's level).  Safe level 1, vacant
# level 0.05, the room vacant from 09:00 (vacancy_hold 0).
#  - a planned stop (the simulated run's end, SIGTERM, SIGINT): an
#    occupied zone at its safe level by default (1); a vacant one keeps its
#    vacant level (0.05); stop_level = 0.25 in [psensd] leaves 0.25 in both;
#    stop_level = hold leaves the override an operator set (0.42);
#  - a zone in a sensor fault at a planned stop: its safe level (1), whatever
#    stop_level says;
#  - a refused reload neither stops psensd nor moves the lights (0.42 held),
#    and the SIGTERM after it is still a planned stop;
#  - a reload that cannot reopen the running configuration is a fault:
#    the safe level (1) with stop_level = hold, exit 1;
#  - a start refused for its database: the safe level (1) with
#    stop_level = hold;
#  - psensd -n refuses a stop_level that is none of hold, safe or 0-1 with
#    its file and line.
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/peers/common.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
need sqlite3
example_results
mkdir -p "$TMP/files"
S="$TMP/sock"
# conf NAME OCCUPIED PSENSD_EXTRA ZONE_EXTRA [FAULTS]: the office, its log state/NAME.db
conf() {
	cat > "$TMP/$1.conf" <<EOC
[psensd]
results = state/ofb.results
database = state/$1.db
socket = sock
period = 60
safe_level = 1
$3
[simulate]
start = 12:00
end = 13:00
[device room]
driver = loopback
gain = 0.5
noise = 0
fade_rate = 0
lag_tau = 0
${5:+faults = $5}
[device files]
driver = file
dir = files
[point sensor]
device = room
role = sensor
[point lamp]
device = room
role = dim
[point gear]
device = files
role = dim
path = $1.dim
[point pir]
device = room
role = input
action = occupancy
occupied = $2
[zone office]
sensor = sensor
dim = lamp gear
input = pir
target_lux = 500
sensor_gain = 0.5
min_level = 0.1
vacancy_hold = 0
vacant_level = 0.05
$4
EOC
}
gear() { cat "$TMP/files/$1.dim" 2>/dev/null || echo none; }
# at NAME LEVEL WHAT: the gear's last level is LEVEL
at() {
	if near "$(gear "$1")" "$2" 0.0005; then ok "$3: the gear at $(gear "$1")"
	else not_ok "$3: the gear at $(gear "$1"), not $2"; fi
}
OCC=06:00-20:00
VAC=06:00-09:00

# the simulated run's end
conf endocc "$OCC" "" ""
"$BIN/psensd" -f "$TMP/endocc.conf" -s > /dev/null 2> "$TMP/endocc.err"
at endocc 1 "end of a simulated run, occupied, by default: the safe level"
conf endvac "$VAC" "" ""
"$BIN/psensd" -f "$TMP/endvac.conf" -s > /dev/null 2> "$TMP/endvac.err"
at endvac 0.05 "end of a simulated run, vacant, by default: the vacant level"
check "... said: $(grep -o 'end of the simulated day: .*' "$TMP/endvac.err")" \
	grep -q "zone office: end of the simulated day: lights held at 5 % (vacant)" "$TMP/endvac.err"
conf endlvl "$VAC" "stop_level = 0.25" ""
"$BIN/psensd" -f "$TMP/endlvl.conf" -s > /dev/null 2> "$TMP/endlvl.err"
at endlvl 0.25 "end of a simulated run, vacant, stop_level = 0.25 in [psensd]"
conf endfault "$OCC" "stop_level = hold" "" "open 12:30-13:30"
"$BIN/psensd" -f "$TMP/endfault.conf" -s > /dev/null 2> "$TMP/endfault.err"
at endfault 1 "end of a simulated run in a sensor fault, stop_level = hold: the safe level"

# run NAME: psensd in real time at 12:00, 60 times as fast, until its socket answers
run() {
	rm -f "$S"
	"$BIN/psensd" -f "$TMP/$1.conf" -t 12:00 -x 60 > /dev/null 2> "$TMP/$1.err" &
	pd=$!; track_pid $pd
	wait_for 20 sh -c "'$BIN/psensctl' -s '$S' ping > /dev/null 2>&1"
}
# stop SIGNAL: psensd ended by SIGNAL, its exit status in rc
stop() { kill "-$1" $pd; wait $pd; rc=$?; }
conf termvac "$VAC" "" ""
run termvac
wait_for 20 sh -c "[ \"\$(cat '$TMP/files/termvac.dim' 2>/dev/null)\" = 0.05 ]"
stop TERM
check "SIGTERM: exit 0 (got $rc)" test "$rc" = 0
at termvac 0.05 "SIGTERM, vacant, by default: the vacant level"
conf termocc "$OCC" "" "stop_level = 0.25"
run termocc
stop TERM
at termocc 0.25 "SIGTERM, occupied, stop_level = 0.25 in the zone"
conf inthold "$OCC" "stop_level = hold" ""
run inthold
"$BIN/psensctl" -s "$S" override office 0.42 6000 > /dev/null
stop INT
check "SIGINT: exit 0 (got $rc)" test "$rc" = 0
at inthold 0.42 "SIGINT, stop_level = hold: the operator's override held"
conf intocc "$OCC" "" ""
run intocc
stop INT
at intocc 1 "SIGINT, occupied, by default: the safe level"
conf termfault "$OCC" "" "stop_level = 0.25" "open 12:00-14:00"
run termfault
wait_for 20 sh -c "'$BIN/psensctl' -s '$S' -j status | grep -q '\"fault\":\"sensor'"
stop TERM
at termfault 1 "SIGTERM in a sensor fault, stop_level = 0.25: the safe level"
check "... said: $(grep -o 'Terminated: lights.*' "$TMP/termfault.err")" \
	grep -q "zone office: Terminated: lights at the safe level 100 %" "$TMP/termfault.err"

# a refused reload: the running configuration and its level stay
conf reload "$OCC" "stop_level = hold" ""
run reload
"$BIN/psensctl" -s "$S" override office 0.42 6000 > /dev/null
printf '[zone other]\nsensor = nosuch\n' >> "$TMP/reload.conf"
"$BIN/psensctl" -s "$S" reload > /dev/null 2>&1
rrc=$?
check "a bad configuration: the reload is refused (psensctl exit $rrc)" test "$rrc" = 1
check "... psensd still runs" "$BIN/psensctl" -s "$S" ping
at reload 0.42 "a refused reload: the running level"
stop TERM
check "the SIGTERM after it: exit 0 (got $rc)" test "$rc" = 0
at reload 0.42 "the SIGTERM after it, stop_level = hold"

# a reload refused when it opens (its new database another application's
# file): the running level stays, never a flash to the safe level between
conf reload2 "$OCC" "stop_level = hold" ""
run reload2
"$BIN/psensctl" -s "$S" override office 0.42 6000 > /dev/null
sqlite3 "$TMP/state/other.db" "CREATE TABLE contacts(name TEXT, phone TEXT)"
sed -i "s|^database = .*|database = state/other.db|" "$TMP/reload2.conf"
"$BIN/psensctl" -s "$S" reload > /dev/null 2>&1
rrc=$?
check "a database that is not psensd's: the reload is refused (psensctl exit $rrc)" test "$rrc" = 1
check "... no zone was driven to the safe level meanwhile" sh -c "! grep -q 'safe level' '$TMP/reload2.err'"
at reload2 0.42 "... the running level"
stop TERM
at reload2 0.42 "the SIGTERM after it, stop_level = hold"

# a reload that cannot reopen the running configuration (its database
# now another application's file) ends the run: a fault, the safe level,
# exit 1
conf reopen "$OCC" "stop_level = hold" ""
run reopen
"$BIN/psensctl" -s "$S" override office 0.42 6000 > /dev/null
wait_for 10 sh -c "[ \"\$(cat '$TMP/files/reopen.dim' 2>/dev/null)\" = 0.42 ]"
mv "$TMP/state/reopen.db" "$TMP/state/reopen.moved"
sqlite3 "$TMP/state/reopen.db" "CREATE TABLE contacts(name TEXT, phone TEXT)"
kill -HUP $pd
wait_for 20 sh -c "! kill -0 $pd 2>/dev/null" || kill -TERM $pd   # never a hang
wait $pd
rc=$?
check "a reload that cannot reopen the running configuration: psensd ends, exit 1 (got $rc)" test "$rc" = 1
check "... said at LOG_ERR: $(grep -o 'stopped by a fault: .*' "$TMP/reopen.err")" \
	grep -q "stopped by a fault: a reload could not reopen the running configuration" "$TMP/reopen.err"
at reopen 1 "... with stop_level = hold: the safe level"

# a start refused for its database: a fault, the safe level whatever stop_level says
conf badstart "$OCC" "stop_level = hold" ""
echo 0.3 > "$TMP/files/badstart.dim"
mkdir -p "$TMP/state/badstart.db"
timeout 20 "$BIN/psensd" -f "$TMP/badstart.conf" -t 12:00 > /dev/null 2> "$TMP/badstart.err"
rc=$?
check "a database that is a directory: the start is refused (exit $rc)" test "$rc" = 1
at badstart 1 "a refused start, stop_level = hold: the safe level"

# psensd -n: each bad value at its file and line
for v in half 1.5 -0.1 nan; do
	conf bad "$OCC" "" "stop_level = $v"
	line=$(grep -n "^stop_level = " "$TMP/bad.conf" | cut -d: -f1)
	"$BIN/psensd" -f "$TMP/bad.conf" -n > /dev/null 2> "$TMP/bad.err"
	rc=$?
	check "psensd -n: stop_level = $v refused (exit $rc)" test "$rc" = 1
	check "... at $TMP/bad.conf:$line: $(head -n 1 "$TMP/bad.err" | cut -c1-100)" \
		grep -q "bad.conf:$line: stop_level: '$v' is none of hold, safe or a level from 0 to 1" "$TMP/bad.err"
done
for v in hold safe 0 1 0.3; do
	conf good "$OCC" "stop_level = $v" "stop_level = $v"
	check "psensd -n: stop_level = $v is taken" sh -c "'$BIN/psensd' -f '$TMP/good.conf' -n > /dev/null"
done
done_testing
