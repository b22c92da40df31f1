#!/bin/sh
# SPDX-License-Identifier: ISC
# Modbus RTU (19200 8N1: pyserial cannot set parity on a pty) through a socat
# pseudo-terminal pair: psvirt on one end, mbpoll,
# a pymodbus serial client, raw frames and the driver on the other; a garbled
# reply (bad CRC) is EPROTO, a silent line ETIMEDOUT; an unknown function,
# a bad address or count get their exceptions, a request with a bad CRC no
# reply, a broadcast is done without a reply.
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/peers/common.sh"
[ -x "$BIN/psvirt" ] || skip_all "psvirt not built"
need socat
need mbpoll
need_pymodbus
make_results
S=$(summary electric_sensor_response)
socat "pty,raw,echo=0,link=$TMP/vdev" "pty,raw,echo=0,link=$TMP/site" 2> "$TMP/socat.err" &
sp=$!
track_pid $sp
check "socat made the pty pair" wait_for 10 sh -c "test -e '$TMP/vdev' && test -e '$TMP/site'"
"$BIN/psvirt" --results "$TMP/ofb.results" --rtu "$TMP/vdev" --baud 19200 --unit 7 \
	--ready-file "$TMP/ready" --start 02:00 -D gain=0.5 -D lag_tau=0 > /dev/null 2> "$TMP/psvirt.err" &
pv=$!
track_pid $pv
check "psvirt on the serial line" wait_for 10 test -s "$TMP/ready"
want=$(awk -v s="$S" 'BEGIN { printf "%d", 0.5 * s / 10 * 65535 + 0.5 }')
got=$(mbpoll -m rtu -b 19200 -P none -a 7 -0 -1 -q -r 0 -t 3 "$TMP/site" | sed -n 's/^\[0\]:[[:space:]]*//p')
check "mbpoll over RTU (19200 8N1, unit 7): AI0 $got, want $want +- 1" near "$got" "$want" 1
cat > "$TMP/rtu.conf" <<EOC
[device io]
driver = modbus
device = $TMP/site
baud = 19200
parity = none
unit = 7
timeout = 0.3
retries = 0
EOC
points >> "$TMP/rtu.conf"
"$MBDRIVE" "$TMP/rtu.conf" write dim 0.25 > "$TMP/w.out" 2>&1
check "the driver writes AO0 over RTU: $(cat "$TMP/w.out")" grep -q "dim <- 0.25" "$TMP/w.out"
"$MBDRIVE" "$TMP/rtu.conf" read sensor dim > "$TMP/r.out" 2>&1
v=$(sed -n 's/^sensor = //p' "$TMP/r.out")
want=$(awk -v s="$S" 'BEGIN { print 0.5 * s * 1024 / 4095 }')
check "and reads the sensor at quarter output: $v V, want $want +- 1 count" near "$v" "$want" 0.00016
d=$(sed -n 's/^dim = //p' "$TMP/r.out")
check "AO0 reads back as 1024 of 4095 ($d)" near "$d" 0.2500610500 1e-9
# garbage on RTU is a frame with a bad CRC
mbpoll -m rtu -b 19200 -P none -a 7 -0 -1 -q -r 901 -t 4 "$TMP/site" 1 > /dev/null
mbpoll -m rtu -b 19200 -P none -a 7 -0 -1 -q -r 900 -t 4 "$TMP/site" 3 > /dev/null
"$MBDRIVE" "$TMP/rtu.conf" read sensor > "$TMP/g.out" 2>&1
check "garbage: EPROTO: $(cat "$TMP/g.out")" grep -q "sensor: EPROTO: modbus io unit 7 IR 0: garbled reply" "$TMP/g.out"
# disconnect on a serial line: silence
mbpoll -m rtu -b 19200 -P none -a 7 -0 -1 -q -r 901 -t 4 "$TMP/site" 1 > /dev/null
mbpoll -m rtu -b 19200 -P none -a 7 -0 -1 -q -r 900 -t 4 "$TMP/site" 4 > /dev/null
"$MBDRIVE" "$TMP/rtu.conf" read sensor > "$TMP/s.out" 2>&1
check "a silent line: ETIMEDOUT: $(cat "$TMP/s.out")" grep -q "sensor: ETIMEDOUT: modbus io unit 7 IR 0: no reply within 0.300 s" "$TMP/s.out"
got=$("$PY" - "$TMP/site" <<'EOP'
import sys
from pymodbus.client import ModbusSerialClient
c = ModbusSerialClient(port=sys.argv[1], baudrate=19200, timeout=1, retries=0)
c.connect()
rr = c.read_holding_registers(202, 1, slave=7)
print(rr.registers[0] if not rr.isError() else rr)
c.close()
EOP
)
check "pymodbus over RTU reads the light output x 10000: $got" test "$got" = 2501
# frames no library client sends (tests/system/peers/mbraw.py, CRC added there)
rtu() { "$PY" "$PEERS/mbraw.py" rtu "$TMP/site" 19200 "$@"; }
got=$(rtu send "07 07")
check "function 07 over RTU: exception 1, a good CRC ($got)" sh -c 'case "$1" in "07 87 01 "??" "??) exit 0;; esac; exit 1' sh "$got"
got=$(rtu send "07 04 001e 0001")
check "input register 30: exception 2 ($got)" sh -c 'case "$1" in "07 84 02 "??" "??) exit 0;; esac; exit 1' sh "$got"
got=$(rtu send "07 03 0000 0000")
check "a read of count 0: exception 3 ($got)" sh -c 'case "$1" in "07 83 03 "??" "??) exit 0;; esac; exit 1' sh "$got"
got=$(rtu sendbad "07 03 00ca 0001")
check "a frame with a bad CRC gets no reply ($got)" test "$got" = silent
got=$(rtu send "07 03 00ca 0001")
check "the next good frame is answered: light output 2501 ($got)" sh -c 'case "$1" in "07 03 02 09 c5 "??" "??) exit 0;; esac; exit 1' sh "$got"
got=$(rtu split "07 03 00ca 0001")
check "a frame delivered in two pieces 20 ms apart (10 silences at 19200 baud) is still answered ($got)" \
	sh -c 'case "$1" in "07 03 02 09 c5 "??" "??) exit 0;; esac; exit 1' sh "$got"
got=$(rtu sendbad "07 03 00ca 0001 | 07 03 00ca 0001")
check "a frame with a bad CRC and a good one in one write: the good one is found and answered ($got)" \
	sh -c 'case "$1" in "07 03 02 09 c5 "??" "??) exit 0;; esac; exit 1' sh "$got"
got=$(rtu send "00 06 000a 0fff")
check "a broadcast (address 0) write of AO0 gets no reply ($got)" test "$got" = silent
got=$(rtu send "07 03 00ca 0001")
check "but is done: light output 10000 ($got)" sh -c 'case "$1" in "07 03 02 27 10 "??" "??) exit 0;; esac; exit 1' sh "$got"
# last: a request for another unit gets no answer, as on a shared RS-485 line
got=$(mbpoll -m rtu -b 19200 -P none -a 3 -0 -1 -q -o 0.3 -r 0 -t 3 "$TMP/site" 2>&1)
check "another unit gets no answer" sh -c "printf '%s' \"\$1\" | grep -qi 'timed out'" sh "$got"
done_testing
