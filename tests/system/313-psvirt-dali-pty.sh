#!/bin/sh
# SPDX-License-Identifier: ISC
# psvirt's virtual DALI bus on a pseudo-terminal, as a serial interface
# psensd opens like any tty: first a Foxtron DALI232, then an AtxLED HAT
# (--dali-protocol atx).  psvirt writes the pty's path to --dali-pty's file;
# psensd's DALI driver (transport = foxtron, then atx) dims two gear on it.
# Checked: the gear's arc levels (read back over the same bus from psvirt's
# DALInet port by peers/foxclient.py) follow the zone's level on the
# standard's curve X(n) = 10^((n-1)/(253/3)-1) %; one gear (short 1) silent
# is a fault naming its point (read back: verify_tolerance), the zone at
# its safe level, and psensd resumes by itself when it answers again; on the
# HAT a collision of answers (--dali-fault collision) is a fault as well.
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/peers/common.sh"
[ -x "$BIN/psvirt" ] && [ -x "$BIN/psensd" ] || skip_all "psvirt or psensd not built"
"$BIN/psensd" -L 2>/dev/null | grep -q "^dali_usb:" || skip_all "the dali_usb driver is not compiled in"
make_results
S="$TMP/sock"
mb=$(free_port)
ctl() { "$BIN/psensctl" -s "$S" "$@"; }
levels() { "$PY" "$PEERS/foxclient.py" "tcp:127.0.0.1:$port" "ask 16 01A0; ask 16 03A0" | tr '\n' ' ' | sed 's/ $//'; }
at_level() { [ "$(levels)" = "$1 $1" ]; }

# run PROTOCOL FAULT: psvirt with its pty speaking PROTOCOL, psensd on it
run() {
	rm -f "$TMP/ready" "$TMP/pty"
	"$BIN/psvirt" --results "$TMP/ofb.results" --tcp "127.0.0.1:$mb" --dali-tcp 127.0.0.1:0 \
		--dali-pty "$TMP/pty" --dali-protocol "$1" --dali-fault "$2" --dali-target 1 \
		--start 12:00 --ready-file "$TMP/ready" -D gain=0.5 -D noise=0 -D lag_tau=0 \
		> "$TMP/pv.out" 2> "$TMP/pv.err" &
	pv=$!; track_pid $pv
	wait_for 10 test -s "$TMP/ready" || not_ok "psvirt did not start: $(cat "$TMP/pv.err")"
	port=$(sed -n 's/^dali-tcp //p' "$TMP/ready")
	dev=$(cat "$TMP/pty")
	{ printf '[psensd]\nresults = ofb.results\ndatabase = %s.db\nsocket = sock\nperiod = 0.5\nstale_after = 2\n' "$1"
	cat <<EOF
[device io]
driver = modbus
host = 127.0.0.1
port = $mb
timeout = 0.2
[device dali]
driver = dali_usb
transport = $1
device = $dev
timeout = 0.2
[point sensor]
device = io
role = sensor
table = input_register
address = 0
[point ballasts]
device = dali
role = dim
address = short 1
[point others]
device = dali
role = dim
address = short 0
[zone office]
sensor = sensor
dim = ballasts others
sensor_gain = 0.5
min_level = 0.1
verify_tolerance = 0.05
EOF
	} > "$TMP/$1.conf"
	"$BIN/psensd" -f "$TMP/$1.conf" -t 12:00 > "$TMP/$1.out" 2> "$TMP/$1.err" &
	ps=$!; track_pid $ps
	wait_for 10 ctl ping > /dev/null || not_ok "psensd did not start: $(cat "$TMP/$1.err")"
}
stop() {
	pd=$(ctl -j ping | sed -n 's/.*"pid":\([0-9]*\).*/\1/p')
	kill -TERM "$pd"
	wait $ps
	kill -TERM $pv
	wait $pv
}

run foxtron silent
check "psvirt printed its DALI232's pty ($dev)" grep -q "DALI bus (Foxtron DALI232) on $dev" "$TMP/pv.out"
check "... a pseudo-terminal's slave" test -c "$dev"
ctl override office 0.3 600 > /dev/null
want=$(dali_arc 0.3)
wait_for 10 at_level "$want"
check "DALI232 on a pty: override 30 %: both gear at arc level $want ($(levels))" at_level "$want"
kill -USR1 $pv
wait_for 15 grep -q "zone office: .* fault: " "$TMP/foxtron.err"
check "gear short 1 silent: a fault naming it: $(grep -o 'fault: .*' "$TMP/foxtron.err" | head -n 1 | cut -c1-120)" \
	grep -q "zone office: .* fault: ballasts: cannot read the output back" "$TMP/foxtron.err"
check "... the other gear (short 0) at the safe level, 254: $(levels)" test "$(levels)" = "254 none"
kill -USR2 $pv
wait_for 20 grep -q "fault cleared: control resumes" "$TMP/foxtron.err"
check "gear short 1 back: psensd resumes by itself" grep -q "fault cleared: control resumes" "$TMP/foxtron.err"
wait_for 10 at_level "$want"
check "... both gear at the override's level again ($want): $(levels)" at_level "$want"
stop

run atx collision
check "psvirt printed its HAT's pty ($dev)" grep -q "DALI bus (AtxLED HAT) on $dev" "$TMP/pv.out"
ctl override office 0.3 600 > /dev/null
wait_for 10 at_level "$want"
check "AtxLED HAT on a pty: override 30 %: both gear at arc level $want ($(levels))" at_level "$want"
kill -USR1 $pv
wait_for 15 grep -q "zone office: .* fault: " "$TMP/atx.err"
check "gear short 1's answers collide: a fault: $(grep -o 'fault: .*' "$TMP/atx.err" | head -n 1 | cut -c1-120)" \
	grep -q "zone office: .* fault: ballasts: cannot read the output back" "$TMP/atx.err"
kill -USR2 $pv
wait_for 20 grep -q "fault cleared: control resumes" "$TMP/atx.err"
check "the collisions end: psensd resumes by itself" grep -q "fault cleared: control resumes" "$TMP/atx.err"
stop
done_testing
