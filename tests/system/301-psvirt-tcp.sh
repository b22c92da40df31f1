#!/bin/sh
# SPDX-License-Identifier: ISC
# psvirt over Modbus TCP against clients we did not write (mbpoll, pymodbus):
# the night room's registers against the scene's results, a dim command
# through AO0, the fault registers and options, and the driver's view of
# each fault (late, exception, garbage, disconnect).
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/peers/common.sh"
[ -x "$BIN/psvirt" ] || skip_all "psvirt not built"
need_pymodbus
need mbpoll
make_results
check "psscene wrote the example's results" test -s "$TMP/ofb.results"
S=$(summary electric_sensor_response); L=$(summary electric_task_lux)
check "the results have an electric condition ($S, $L lx)" test -n "$S" -a -n "$L"
port=$(free_port)
# 02:00 on real time: no daylight; instant ballast, sensor gain 0.5 V per unit
"$BIN/psvirt" --results "$TMP/ofb.results" --tcp "127.0.0.1:$port" --ready-file "$TMP/ready" \
	--start 02:00 -D gain=0.5 -D lag_tau=0 -D min_level=0.1 > "$TMP/psvirt.out" 2> "$TMP/psvirt.err" &
pv=$!
track_pid $pv
check "psvirt ready" wait_for 10 test -s "$TMP/ready"
check "the ready file holds the port" test "$(cat "$TMP/ready")" = "$port"
mb() { mbpoll -m tcp -p "$port" -a 1 -0 -1 -q "$@" 127.0.0.1; }
mbw() { _v=$1; shift; mbpoll -m tcp -p "$port" -a 1 -0 -1 -q "$@" 127.0.0.1 "$_v"; }
reg() { sed -n 's/^\[[0-9]*\]:[[:space:]]*//p' | head -n 1; }
py() { "$PY" "$PEERS/mbclient.py" tcp 127.0.0.1 "$port" "$@"; }
# full output at night: AI0 = 0.5 V/unit x S / 10 V x 65535
want=$(awk -v s="$S" 'BEGIN { printf "%d", 0.5 * s / 10 * 65535 + 0.5 }')
got=$(mb -r 0 -t 3 | reg)
check "mbpoll: AI0 (IR 0) is the electric response at full output: $got, want $want +- 1" near "$got" "$want" 1
got=$(py ir 0 1)
check "pymodbus: the same through FC04 ($got)" near "$got" "$want" 1
got=$(py u32 100)
check "pymodbus: u32 task lux is the electric task lux $L ($got)" near "$got" "$L" 0.5
got=$(py f32 104)
check "pymodbus: f32 ABCD task lux ($got)" near "$got" "$L" 0.001
got=$(py f32 106 cdab)
check "pymodbus: f32 CDAB task lux ($got)" near "$got" "$L" 0.001
got=$(mb -r 104 -t 4:float -B | reg)
check "mbpoll: f32 big-endian words at 104 ($got)" near "$got" "$L" 0.01
# dim to half: 2048 of 4095 -> light output 0.50012
mbw 2048 -r 10 -t 4 > /dev/null
check "mbpoll writes AO0" test $? = 0
got=$(py hr 202 1)
check "light output x 10000 follows AO0: $got" test "$got" = 5001
want=$(awk -v s="$S" 'BEGIN { printf "%d", 0.5 * s * 2048 / 4095 / 10 * 65535 + 0.5 }')
got=$(py ir 0 1)
check "AI0 follows the light output: $got, want $want +- 1" near "$got" "$want" 1
# fault registers: 900 kind, 901 count, 902 late ms
py write 900 2 > /dev/null
got=$(py ir 0 1)
check "fault 2: every request answers exception 4 ($got)" test "$got" = "exception 4"
mb -r 0 -t 3 > "$TMP/mb.out" 2>&1
check "mbpoll sees it too: $(grep -i fail "$TMP/mb.out")" grep -qi "slave device or server failure" "$TMP/mb.out"
py write 900 0 > /dev/null
check "cleared" test "$(py hr 202 1)" = 5001
# the driver's view of each fault, each for one request
{ device_tcp "$port" timeout=0.1 retries=0 backoff_min=0.1; points; } > "$TMP/io.conf"
drive() { "$MBDRIVE" "$TMP/io.conf" read sensor 2>&1; }
py write 902 400 > /dev/null; py write 901 1 > /dev/null; py write 900 1 > /dev/null
check "late (400 ms > 100 ms): ETIMEDOUT: $(drive | tee "$TMP/d.out")" \
	grep -q "sensor: ETIMEDOUT: modbus io unit 1 IR 0: no reply within 0.100 s" "$TMP/d.out"
answers() { "$MBDRIVE" "$TMP/io.conf" read sensor | grep -q 'sensor = '; }
check "then answers again (once psvirt is past the late reply)" wait_for 5 answers
py write 901 1 > /dev/null; py write 900 3 > /dev/null
check "garbage: EPROTO: $(drive | tee "$TMP/d.out")" grep -q "sensor: EPROTO: modbus io unit 1 IR 0: garbled reply" "$TMP/d.out"
py write 901 1 > /dev/null; py write 900 4 > /dev/null
check "disconnect: ENODEV: $(drive | tee "$TMP/d.out")" grep -q "sensor: ENODEV: modbus io unit 1 IR 0: connection lost" "$TMP/d.out"
py write 901 1 > /dev/null; py write 900 2 > /dev/null
check "exception: EPROTO: $(drive | tee "$TMP/d.out")" \
	grep -q "sensor: EPROTO: modbus io unit 1 IR 0: exception 4 (server device failure)" "$TMP/d.out"
check "the count ran out: fault register back to 0" test "$(py hr 900 1)" = 0
kill "$pv"; wait "$pv"
check "psvirt exits 0 on SIGTERM" test $? = 0
check "and says what it served: $(cat "$TMP/psvirt.out")" grep -q "^psvirt: [0-9]* requests ([0-9]* faulted)" "$TMP/psvirt.out"
# --fault from the command line, and -f with psensd.conf
sed "s|^results = .*|results = $TMP/ofb.results|" "$TOP/config/psensd.conf" > "$TMP/psensd.conf"
port2=$(free_port)
"$BIN/psvirt" -f "$TMP/psensd.conf" --tcp "127.0.0.1:$port2" --ready-file "$TMP/ready2" \
	--fault exception --fault-count 1 > /dev/null 2>&1 &
pv2=$!
track_pid $pv2
check "psvirt -f psensd.conf ready" wait_for 10 test -s "$TMP/ready2"
got=$("$PY" "$PEERS/mbclient.py" tcp 127.0.0.1 "$port2" hr 200 2)
check "--fault exception --fault-count 1: the first request fails ($got)" test "$got" = "exception 4"
tod=$("$PY" "$PEERS/mbclient.py" tcp 127.0.0.1 "$port2" u32 200)
check "then the clock reads [simulate] start 06:00 ($tod s)" awk -v t="$tod" 'BEGIN { exit !(t >= 21600 && t < 21660) }'
kill "$pv2"
"$BIN/psvirt" --tcp 127.0.0.1:1 > /dev/null 2> "$TMP/e1"
check "no results: a clear error: $(cat "$TMP/e1")" grep -q "no results" "$TMP/e1"
"$BIN/psvirt" --results "$TMP/ofb.results" --tcp 127.0.0.1:1 -D gian=2 > /dev/null 2> "$TMP/e2"
check "a misspelt room option is named: $(cat "$TMP/e2")" grep -q "gian: not a loopback room option" "$TMP/e2"
"$BIN/psvirt" --results "$TMP/ofb.results" --tcp 127.0.0.1:1 --fault slow > /dev/null 2> "$TMP/e3"
check "an unknown fault is named" grep -q "'slow' is not late, exception, garbage or disconnect" "$TMP/e3"
done_testing
