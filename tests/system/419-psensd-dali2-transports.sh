#!/bin/sh
# SPDX-License-Identifier: ISC
# psensd reading a DALI-2 multisensor (304 light, 303 occupancy) and
# commanding gear through the other interfaces: the Lunatone LUBA on a pty
# and a Foxtron DALInet over TCP, each with the emulated bus of
# peers/dalibus.py behind it.  Checks, on each: the sensor point reads the
# light sensor's value and follows a change; the occupancy input reports
# occupied; an override reaches the gear at the standard curve's level
# (X(n) = 10^((n-1)/(253/3)-1) %); no fault on the way.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v python3 > /dev/null || skip_all "python3 not installed"
"$BIN/psensd" -L 2>/dev/null | grep -q "^dali_usb:" || skip_all "the dali_usb driver is not compiled in"
example_results
S="$TMP/sock"
ctl() { "$BIN/psensctl" -s "$S" "$@"; }
sensor_v() { ctl -j status | sed -n 's/.*"sensor_v":\([0-9.]*\).*/\1/p'; }
reads() { [ "$(sensor_v)" = "$1.0" ]; }
levels() { awk '$1 == "short" { print $4 }' "$TMP/bus.state" | sort -u | tr '\n' ' ' | sed 's/ $//'; }
one() {
	codec=$1 link=$2 where=$3
	{ psensd_section 0.5 2; cat <<EOC
[device dali]
driver = dali_usb
transport = $codec
device = $where
timeout = 0.1
EOC
dali2_light 7 3
dali2_occupancy 7
cat <<EOC
[point ballasts]
device = dali
role = dim
address = broadcast
[zone office]
sensor = light
dim = ballasts
input = occupancy
sensor_gain = 100
min_level = 0.1
EOC
	} > "$TMP/psensd.conf"
	"$BIN/psensd" -f "$TMP/psensd.conf" -t 12:00 > "$TMP/out-$codec" 2> "$TMP/err-$codec" &
	pid=$!; track_pid $pid
	wait_for 10 ctl ping > /dev/null
	wait_for 10 reads 450
	check "$codec over $link: the light sensor read: $(sensor_v)" reads 450
	echo "light 0 800" > "$TMP/ctl"
	wait_for 10 reads 800
	check "$codec over $link: ... and a change: $(sensor_v)" reads 800
	echo "occupied 0 1" >> "$TMP/ctl"
	wait_for 10 grep -q "zone office: .*occupied$" "$TMP/err-$codec"
	check "$codec over $link: occupied reported" grep -q "zone office: .*occupied$" "$TMP/err-$codec"
	ctl override office 0.5 600 > /dev/null
	want=$(dali_arc 0.5)
	wait_for 5 sh -c "[ \"\$(awk '\$1 == \"short\" { print \$4 }' \"$TMP/bus.state\" | sort -u)\" = $want ]"
	check "$codec over $link: override 50 %: the gear at arc level $want: $(levels)" test "$(levels)" = "$want"
	pd=$(ctl -j ping | sed -n 's/.*"pid":\([0-9]*\).*/\1/p')
	kill -TERM "$pd"; wait $pid
	check "$codec over $link: no fault" sh -c "! grep -q 'fault: ' \"$TMP/err-$codec\""
}

echo "light 0 450" > "$TMP/ctl"
dalibus_pty "$TMP/bus1.log" --codec luba --gear 1:254,2:254 \
	--devices 7:0x010203 --control "$TMP/ctl" --state "$TMP/bus.state"
one luba pty "$(cat "$TMP/pty")"
kill $bus; wait $bus 2>/dev/null

echo "light 0 450" > "$TMP/ctl"
python3 "$(dirname "$0")/peers/dalibus.py" --codec foxtron --tcp "$TMP/port" --gear 1:254,2:254 \
	--devices 7:0x010203 --control "$TMP/ctl" --state "$TMP/bus.state" > "$TMP/bus2.log" 2>&1 &
bus=$!; track_pid $bus
wait_for 10 test -s "$TMP/port" || not_ok "the TCP emulator did not start"
one foxtron TCP "127.0.0.1:$(cat "$TMP/port")"
done_testing
