#!/bin/sh
# SPDX-License-Identifier: ISC
# A night calibration in daylight must not measure the offset from the
# sun.  The shipped example
# (config/psensd.conf: the loopback room, no task meter) in real time from
# 11:00 at 600x: `psensctl calibrate office night` is refused with the
# reason (the simulation's sun is up), nothing is recorded, and the zone
# keeps its control; with the sun check off (a room the simulation thinks
# dark), the reading itself refuses it (daylight above the electric light
# and the offset); after sunset the same request starts a session.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
example_results
S="$TMP/sock"
# the example as shipped, its results and database in $TMP, a socket added
mkdir -p "$TMP/config"
sed -e "s|^results = .*|results = $TMP/state/ofb.results|" \
    -e "s|^database = .*|database = $TMP/state/psensd.db|" \
    -e "s|^scene = .*|scene = $TMP/example/ofb.scene|" \
    -e "s|^socket = .*||" \
    -e "s|^\[psensd\]|[psensd]\nsocket = $S|" config/psensd.conf > "$TMP/config/psensd.conf"
ctl() { "$BIN/psensctl" -s "$S" "$@"; }
start() {  # start HH:MM [extra zone key]
	cp "$TMP/config/psensd.conf" "$TMP/run.conf"
	[ $# -gt 1 ] && printf '%s\n' "$2" >> "$TMP/run.conf"
	"$BIN/psensd" -f "$TMP/run.conf" -t "$1" -x 600 >> "$TMP/out" 2>> "$TMP/err" &
	PID=$!; track_pid $PID
	wait_for 10 sh -c "\"$BIN/psensctl\" -s \"$S\" ping > /dev/null"
}
stop() { kill -TERM $PID; wait $PID 2>/dev/null; }
q() { sqlite3 "$TMP/state/psensd.db" "$1"; }

start 11:00
sleep 0.5   # a few periods: the zone has readings
ctl calibrate office night > "$TMP/c1.out" 2> "$TMP/c1.err"; rc=$?
check "at 11:00 calibrate office night is refused (exit $rc)" test "$rc" != 0
check "with the reason: $(cat "$TMP/c1.err")" grep -q "no night session at 1[01]:[0-9][0-9]: the simulation's sun is up on 03-18 (sunrise 06:00, sunset 18:30)" "$TMP/c1.err"
check "nothing is recorded as a session" test "$(q "select count(*) from cal_sessions")" = 0
ctl calibrate office status > "$TMP/st.out" 2>&1
check "the zone runs no session" sh -c "! grep -q 'state: running' '$TMP/st.out'"
stop

# the sun check off: the sensor's reading (about 1.4 V of daylight over the
# 0.547 V electric signal at full output) refuses it
start 11:00 "cal_night_sun = no"
sleep 0.5
ctl calibrate office night > /dev/null 2> "$TMP/c2.err"; rc=$?
check "without the sun check the reading refuses it (exit $rc): $(cat "$TMP/c2.err")" \
	grep -q "no night session: the sensor reads [0-9.]* V with the lights at [0-9]* %, [0-9.]* V above the" "$TMP/c2.err"
check "still nothing recorded" test "$(q "select count(*) from cal_sessions")" = 0
stop

# after sunset it starts
start 21:00
sleep 0.3
check "at 21:00 the night session starts" ctl calibrate office night
check "and runs" sh -c "\"$BIN/psensctl\" -s \"$S\" calibrate office status | grep -q 'state: running'"
stop
done_testing
