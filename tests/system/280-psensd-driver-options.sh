#!/bin/sh
# SPDX-License-Identifier: ISC
# Driver keys are judged with the configuration, not when a device opens:
# psensd -n (and so SIGHUP) names every misspelt key and every bad value of
# every driver with its file and line, all in one pass, by the drivers'
# option tables.  Each case is one psensd -n must catch, not leave to
# fail one at a time when the device opens.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
"$BIN/psensd" -h | grep -q "modbus .*(not compiled in)" && skip_all "the modbus driver is not compiled in"
# the files the configurations name exist (psensd -n opens them)
example_results
cp "$TMP/state/ofb.results" "$TMP/ofb.results"
cat > "$TMP/bad.conf" <<'EOF'
[psensd]
results = ofb.results
[device room]
driver = loopback
fade_rte = 0.2
gain = 0.5.5
[device io]
driver = modbus
host = 192.0.2.7
timeout = fast
[device line]
driver = modbus
device = /dev/ttyUSB0
baud = 96000
[point light]
device = io
role = sensor
table = input_register
address = 0
word_ordr = cdab
[point lamps]
device = io
role = dim
table = holding_register
address = 10
[zone office]
sensor = light
dim = lamps
EOF
"$BIN/psensd" -f "$TMP/bad.conf" -n > "$TMP/out" 2> "$TMP/err"
rc=$?
check "psensd -n refuses the file (exit $rc)" test "$rc" = 1
check "nothing said OK" test ! -s "$TMP/out"
line() {  # line N TEXT: the error at file:N, exactly once
	check "$TMP/bad.conf:$1: $2" test "$(grep -c -F "psensd: $TMP/bad.conf:$1: $2" "$TMP/err")" = 1
}
line 5 "unknown key 'fade_rte' for driver loopback"
line 6 "gain: '0.5.5' is not a number"
line 10 "timeout: 'fast' is not a number"
line 14 "baud: '96000' is not one of 1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200, 230400"
line 20 "unknown key 'word_ordr' for driver modbus"
check "five errors, no more: $(wc -l < "$TMP/err")" test "$(wc -l < "$TMP/err")" = 5

# the rules across keys run in the same check (the drivers' check methods)
cat > "$TMP/cross.conf" <<'EOF'
[psensd]
results = ofb.results
[device io]
driver = modbus
host = 192.0.2.7
baud = 9600
[device tcp]
driver = modbus
[device room]
driver = loopback
[point light]
device = io
role = sensor
address = 0
[point occupancy]
device = room
role = input
occupied = 07:00-12:00, 13:00-1900
[point lamps]
device = room
role = dim
occupied = 07:00-12:00
[zone office]
sensor = light
dim = lamps
input = occupancy
EOF
"$BIN/psensd" -f "$TMP/cross.conf" -n > /dev/null 2> "$TMP/cross.err"
err() { check "$TMP/cross.conf:$1: $2" grep -q -F "psensd: $TMP/cross.conf:$1: $2" "$TMP/cross.err"; }
err 6 "baud: applies to RTU (device =), not TCP"
err 7 "a modbus device needs either host (TCP) or device (RTU)"
err 11 "table is required"
err 18 "occupied: '13:00-1900' is not HH:MM-HH:MM"
err 22 "occupied: driver loopback takes it on input points, not dim"

# a good file passes, and SIGHUP's check is the same one (psensd.conf(5))
# (its database beside it: the shipped ../build is not beside a copy in $TMP)
sed "s|^results = .*|results = ofb.results|; s|^database = .*|database = psensd.db|" config/psensd.conf > "$TMP/good.conf"
check "the example passes" sh -c "'$BIN/psensd' -f '$TMP/good.conf' -n | grep -q 'configuration OK'"
# the list of drivers in the message comes from the registry
printf '[psensd]\nresults = r\n[device x]\ndriver = nosuch\n[zone z]\ndevice = x\n' > "$TMP/nodrv.conf"
"$BIN/psensd" -f "$TMP/nodrv.conf" -n 2> "$TMP/nodrv.err" > /dev/null
names=$("$BIN/psensd" -h | sed -n '/^drivers:/,$p' | awk 'NR > 1 { printf "%s%s", sep, $1; sep = ", " }')
check "no driver 'nosuch' ($names): from the registry" grep -q -F "driver: no driver 'nosuch' ($names)" "$TMP/nodrv.err"
done_testing
