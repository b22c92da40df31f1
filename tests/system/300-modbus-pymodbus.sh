#!/bin/sh
# SPDX-License-Identifier: ISC
# psensd's Modbus driver (through mbdrive) against a pymodbus server emulating
# an ADAM-6024-style I/O module with a lux meter; writes checked with mbpoll,
# a second peer; the server killed and restarted: ENODEV, then back.
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/peers/common.sh"
need_pymodbus
need mbpoll
port=$(free_port)
start_server() {
	rm -f "$TMP/srv.ready"
	# 2 V, 10 V; u32 lux 0x0002 0x06F6 = 132854 lx (a lux meter manual's example);
	# f32 100.0 low word first; DI 1 on
	"$PY" "$PEERS/mbserver.py" "$port" "$TMP/srv.ready" ir:0=13107 ir:1=65535 \
		hr:100=0x0002 hr:101=0x06f6 hr:104=0x0000 hr:105=0x42c8 di:1=1 2>>"$TMP/srv.err" &
	srv=$!
	track_pid $srv
	wait_for 10 test -s "$TMP/srv.ready"
}
check "pymodbus server ready" start_server
{ device_tcp "$port" timeout=0.2 backoff_min=0.2 backoff_max=0.4; points; cat <<EOP
[point twelve]
device = io
role = sensor
table = input_register
address = 1
raw_max = 4095
[point flux]
device = io
role = task
table = holding_register
address = 104
type = f32
word_order = cdab
[point far]
device = io
role = sensor
table = input_register
address = 500
[point relay]
device = io
role = relay
table = coil
address = 16
[point button]
device = io
role = input
table = discrete_input
address = 1
EOP
} > "$TMP/io.conf"
"$MBDRIVE" "$TMP/io.conf" read sensor lux flux button > "$TMP/read.out" 2>&1
check "reads succeed: $(tr '\n' ' ' < "$TMP/read.out")" test $? = 0
check "IR 0 13107 is 2 V" grep -qx "sensor = 2" "$TMP/read.out"
check "u32 high word first is 132854 lx" grep -qx "lux = 132854" "$TMP/read.out"
check "f32 CDAB is 100 lx" grep -qx "flux = 100" "$TMP/read.out"
check "discrete input 1" grep -qx "button = 1" "$TMP/read.out"
"$MBDRIVE" "$TMP/io.conf" read twelve > "$TMP/range.out" 2>&1
check "a 12-bit point reading 65535 is ERANGE: $(cat "$TMP/range.out")" \
	grep -qx "twelve: ERANGE: modbus io unit 1 IR 1: raw 65535 outside 0 to 4095" "$TMP/range.out"
"$MBDRIVE" "$TMP/io.conf" read far > "$TMP/far.out" 2>&1
check "pymodbus's exception is EPROTO: $(cat "$TMP/far.out")" \
	grep -qx "far: EPROTO: modbus io unit 1 IR 500: exception 2 (illegal data address)" "$TMP/far.out"
"$MBDRIVE" "$TMP/io.conf" write dim 0.5 > /dev/null && "$MBDRIVE" "$TMP/io.conf" write relay 1 > /dev/null
check "writes succeed" test $? = 0
hr10=$(mbpoll -m tcp -p "$port" -a 1 -0 -1 -q -r 10 -t 4 127.0.0.1 | sed -n 's/^\[10\]:[[:space:]]*//p')
check "mbpoll reads the dim output as 2048 of 4095 (got $hr10)" test "$hr10" = 2048
co16=$(mbpoll -m tcp -p "$port" -a 1 -0 -1 -q -r 16 -t 0 127.0.0.1 | sed -n 's/^\[16\]:[[:space:]]*//p')
check "mbpoll reads the relay coil as 1 (got $co16)" test "$co16" = 1
# the module goes away and comes back: one driver instance sees it all
"$MBDRIVE" "$TMP/io.conf" poll 30 sensor > "$TMP/poll.out" 2>&1 &
poller=$!
track_pid $poller
check "polling reads 2 V" wait_for 10 grep -q "ok 2$" "$TMP/poll.out"
kill "$srv"; wait "$srv" 2>/dev/null
check "server gone: ENODEV" wait_for 10 grep -q "ENODEV" "$TMP/poll.out"
check "the reason is named: $(grep -m1 ENODEV "$TMP/poll.out")" \
	grep -q "ENODEV modbus io.*\(connection lost\|cannot connect\)" "$TMP/poll.out"
check "server restarted" start_server
back() { awk '/ENODEV/ { lost = 1 } lost && / ok 2$/ { found = 1 } END { exit !found }' "$TMP/poll.out"; }
check "the driver reconnects by itself and reads 2 V again" wait_for 10 back
kill "$poller"
diag "$(cat "$TMP/poll.out")"
done_testing
