#!/bin/sh
# SPDX-License-Identifier: ISC
# The real psensd dimming DALI gear through a daliserver (a Tridonic DALI USB
# shared over TCP): the dali_usb driver with transport = daliserver against
# the emulated server (peers/daliserver.py, written from daliserver's
# published protocol) with two gear behind it.  Checked against the standard
# curve X(n) = 10^((n-1)/(253/3)-1) %: the requests on the wire are version
# 2, type 0 (the emulator drops any other); the gear follow the zone's level
# and an override, and a scan reads their levels back while the 62 empty
# short addresses are "no answer" (status 0), not faults.  Each server fault
# (replies with an unknown status, replies cut short, a silent server, the
# server gone) is a fault naming the transport that drives the zone to its
# safe level, and psensd resumes by itself when the server is back.  psensd
# -n refuses the transport without a device, with a serial port, and with
# safe_level (programmed with a frame sent twice, which daliserver cannot
# send).
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v python3 > /dev/null || skip_all "python3 not installed"
"$BIN/psensd" -L 2>/dev/null | grep -q "^dali_usb:" || skip_all "the dali_usb driver is not compiled in"
example_results
S="$TMP/sock"
echo ok > "$TMP/mode"
python3 "$(dirname "$0")/peers/daliserver.py" --port-file "$TMP/port" --gear 1:254,2:254 \
	--state "$TMP/bus.state" --mode-file "$TMP/mode" > "$TMP/bus.log" 2>&1 &
track_pid $!
wait_for 10 test -s "$TMP/port" || not_ok "the emulator did not start"
{ psensd_section 0.5 2; dali_room; cat <<EOF
[device dali]
driver = dali_usb
transport = daliserver
device = 127.0.0.1:$(cat "$TMP/port")
timeout = 0.1
EOF
dali_room_zone; } > "$TMP/psensd.conf"
ctl() { "$BIN/psensctl" -s "$S" "$@"; }
levels() { awk '{ print $4 }' "$TMP/bus.state" | sort -u | tr '\n' ' ' | sed 's/ $//'; }
at_level() { [ "$(levels)" = "$1" ]; }
faults() { grep -c 'zone office: .* fault: ' "$TMP/err"; }
cleared() { grep -c 'zone office: .*fault cleared: control resumes' "$TMP/err"; }
safe() { ctl -j status | grep -Eq '"level":1(\.0)?,.*"fault":"'; }

sed 's/^device = 127.*//' "$TMP/psensd.conf" > "$TMP/nodev.conf"
"$BIN/psensd" -n -f "$TMP/nodev.conf" > "$TMP/n.out" 2>&1
check "psensd -n: transport daliserver without device is refused, with its line" \
	grep -q "nodev.conf:[0-9]*: .*transport daliserver needs device" "$TMP/n.out"
sed 's|^device = 127.*|device = /dev/ttyS0|' "$TMP/psensd.conf" > "$TMP/tty.conf"
"$BIN/psensd" -n -f "$TMP/tty.conf" > "$TMP/t.out" 2>&1
check "psensd -n: transport daliserver on a serial port is refused: $(head -n 1 "$TMP/t.out" | cut -c1-90)" \
	grep -q "tty.conf:[0-9]*: .*daliserver is reached over TCP: device = HOST:PORT" "$TMP/t.out"

sed 's|^timeout = 0.1|safe_level = 0.5|' "$TMP/psensd.conf" > "$TMP/sfl.conf"
"$BIN/psensd" -n -f "$TMP/sfl.conf" > "$TMP/s.out" 2>&1
check "psensd -n: safe_level (a frame sent twice) refused with daliserver: $(head -n 1 "$TMP/s.out" | cut -c1-90)" \
	grep -q "sfl.conf:[0-9]*: .*safe_level is programmed with a frame sent twice, which daliserver cannot send" "$TMP/s.out"

"$BIN/psensd" -f "$TMP/psensd.conf" -t 12:00 > "$TMP/out" 2> "$TMP/err" &
pid=$!; track_pid $pid
wait_for 10 ctl ping > /dev/null
check "psensd runs with transport daliserver" sh -c "\"$BIN/psensctl\" -s \"$S\" ping > /dev/null"
want=$(dali_arc 0.1)
wait_for 5 at_level "$want"
check "noon, the zone at its minimum 10 %: both gear at arc level $want: $(levels)" at_level "$want"
hex=$(printf '%02X' "$want")
check "DAPC $want to broadcast went out as version 2, type 0, FE $hex and got status 0" \
	grep -q "^req FE$hex -> 02000000$" "$TMP/bus.log"
check "no request was dropped for a wrong version or type" sh -c "! grep -q dropped \"$TMP/bus.log\""
ctl override office 0.3 600 > /dev/null
want=$(dali_arc 0.3)
wait_for 5 at_level "$want"
check "override 30 %: both gear at arc level $want: $(levels)" at_level "$want"
ctl dali dali scan > "$TMP/scan" 2>&1
check "a scan over daliserver: 2 short addresses answer, the other 62 are no answer" \
	grep -q "2 short addresses answer" "$TMP/scan"
check "... and reads both gear's level back: $want" \
	test "$(awk '$1 == 1 || $1 == 2 { print $NF }' "$TMP/scan" | sort -u | tr '\n' ' ')" = "$want "

# fault_cycle MODE WHAT: the server misbehaves (MODE) until a new fault is
# logged, the zone at its safe level, then serves again until it clears.
fault_cycle() {
	nf=$(faults); nc=$(cleared)
	echo "$1" > "$TMP/mode"
	wait_for 20 sh -c "[ \$(grep -c 'zone office: .* fault: ' \"$TMP/err\") -gt $nf ]"
	msg=$(grep 'zone office: .* fault: ' "$TMP/err" | tail -n 1 | sed 's/.*fault: //')
	check "$1: a fault naming daliserver and $2: $(echo "$msg" | cut -c1-110)" \
		sh -c "echo \"\$1\" | grep -q \"$2\"" _ "$msg"
	wait_for 5 safe
	check "$1: the zone at its safe level, the fault in its status" safe
	echo ok > "$TMP/mode"
	wait_for 30 sh -c "[ \$(grep -c 'zone office: .*fault cleared: control resumes' \"$TMP/err\") -gt $nc ]"
	check "$1: the server serves again: psensd resumes by itself" test "$(cleared)" -gt "$nc"
	wait_for 5 at_level "$want"
	check "$1: the override's level is back on the gear ($want): $(levels)" at_level "$want"
}
fault_cycle garbage "daliserver: malformed reply from the interface: status 7"
fault_cycle version "daliserver: malformed reply from the interface: protocol version 3"
fault_cycle short "daliserver: a reply cut short"
fault_cycle silent "daliserver: no reply from the interface"
fault_cycle down "DALI interface daliserver: the interface is gone"
check "each fault reported once, not at every period: $(faults) faults, $(cleared) cleared" \
	test "$(faults)" = 5 -a "$(cleared)" = 5

pd=$(ctl -j ping | sed -n 's/.*"pid":\([0-9]*\).*/\1/p')
kill -TERM "$pd"
wait $pid
check "SIGTERM: psensd drove the lights to the safe level" grep -q "zone office: Terminated: lights at the safe level 100 %" "$TMP/err"
check "the gear's last state: 254 (100 %): $(levels)" at_level 254
done_testing
