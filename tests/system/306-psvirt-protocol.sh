#!/bin/sh
# SPDX-License-Identifier: ISC
# psvirt answers like a good Modbus TCP device (psvirt(1), PROTOCOL): every
# function it does not serve (07, 08, 11, 2B, a user code) gets exception 1
# and the connection stays open; a bad count exception 3; an address outside
# the map exception 2 (input registers 0-29, holding 0-999, both edges); an
# MBAP frame with a protocol id other than 0 or a length that does not match
# its PDU is refused and the connection closed.  Raw frames from python3
# sockets (no library sends these), and the same through pymodbus and mbpoll.
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/peers/common.sh"
[ -x "$BIN/psvirt" ] || skip_all "psvirt not built"
need_pymodbus
need mbpoll
make_results
port=$(free_port)
"$BIN/psvirt" --results "$TMP/ofb.results" --tcp "127.0.0.1:$port" --ready-file "$TMP/ready" \
	--start 02:00 -D gain=0.5 > "$TMP/psvirt.out" 2> "$TMP/psvirt.err" &
pv=$!
track_pid $pv
check "psvirt ready" wait_for 10 test -s "$TMP/ready"
raw() { "$PY" "$PEERS/mbraw.py" 127.0.0.1 "$port" "$@"; }
py() { "$PY" "$PEERS/mbclient.py" tcp 127.0.0.1 "$port" "$@"; }
# is REPLY: the reply (hex) is exactly WANT
is() { [ "$1" = "$2" ]; }
# starts REPLY PREFIX
starts() { case "$1" in "$2"*) return 0;; esac; return 1; }

# unsupported functions: exception 1, and the same connection answers next
unsupported() {  # FC REQUEST WANT
	got=$(raw send "$2 0099 0000 0006 01 04 0000 0001" 2 2)
	check "function 0x$1: exception 1 ($got)" starts "$got" "$3"
	check "  then the same connection serves a read" starts "$got" "$3 00 99 00 00 00 05 01 04 02"
}
unsupported 07 "0002 0000 0002 01 07" "00 02 00 00 00 03 01 87 01"
unsupported 08 "0003 0000 0006 01 08 0000 1234" "00 03 00 00 00 03 01 88 01"
unsupported 11 "0005 0000 0002 01 11" "00 05 00 00 00 03 01 91 01"
unsupported 2B "0004 0000 0005 01 2b 0e 01 00" "00 04 00 00 00 03 01 ab 01"
unsupported 41 "0006 0000 0004 01 41 aa bb" "00 06 00 00 00 03 01 c1 01"
got=$(py status07)
check "pymodbus read_exception_status (07): $got" test "$got" = "exception 1"
# counts: exception 3
got=$(raw send "000a 0000 0006 01 03 0000 0000")
check "read holding registers, count 0: exception 3 ($got)" is "$got" "00 0a 00 00 00 03 01 83 03"
got=$(raw send "000b 0000 0006 01 03 0000 007e")
check "read holding registers, count 126: exception 3 ($got)" is "$got" "00 0b 00 00 00 03 01 83 03"
got=$(raw send "000c 0000 0006 01 04 0000 0000")
check "read input registers, count 0: exception 3 ($got)" is "$got" "00 0c 00 00 00 03 01 84 03"
got=$(raw send "000d 0000 0009 01 10 000a 0002 02 0001")
check "write multiple registers, byte count 2 for 2 registers: exception 3 ($got)" is "$got" "00 0d 00 00 00 03 01 90 03"
got=$(raw send "000e 0000 0006 01 05 0000 1234")
check "write single coil with 0x1234: exception 3 ($got)" is "$got" "00 0e 00 00 00 03 01 85 03"
got=$(raw send "000f 0000 0006 01 01 0000 07d1")
check "read coils, count 2001: exception 3 ($got)" is "$got" "00 0f 00 00 00 03 01 81 03"
# addresses: input registers 0-29, holding registers 0-999
got=$(raw send "0010 0000 0006 01 04 001d 0001")
check "input register 29 (the last): answered ($got)" starts "$got" "00 10 00 00 00 05 01 04 02"
got=$(raw send "0011 0000 0006 01 04 001e 0001")
check "input register 30: exception 2 ($got)" is "$got" "00 11 00 00 00 03 01 84 02"
got=$(raw send "0012 0000 0006 01 04 001c 0002")
check "input registers 28-29: answered ($got)" starts "$got" "00 12 00 00 00 07 01 04 04"
got=$(raw send "0013 0000 0006 01 04 001d 0002")
check "input registers 29-30: exception 2 ($got)" is "$got" "00 13 00 00 00 03 01 84 02"
got=$(raw send "0014 0000 0006 01 03 03e7 0001")
check "holding register 999 (the last): answered ($got)" starts "$got" "00 14 00 00 00 05 01 03 02"
got=$(raw send "0015 0000 0006 01 03 03e7 0002")
check "holding registers 999-1000: exception 2 ($got)" is "$got" "00 15 00 00 00 03 01 83 02"
got=$(raw send "0016 0000 0006 01 06 03e8 0001")
check "write holding register 1000: exception 2 ($got)" is "$got" "00 16 00 00 00 03 01 86 02"
got=$(py ir 29 1)
check "pymodbus: input register 29 reads ($got)" test -n "$got" -a "${got#exception}" = "$got"
got=$(py ir 30 1)
check "pymodbus: input register 30 is exception 2 ($got)" test "$got" = "exception 2"
mbpoll -m tcp -p "$port" -a 1 -0 -1 -r 30 -t 3 127.0.0.1 > "$TMP/mb30" 2>&1
check "mbpoll: input register 30 is an illegal data address" grep -qi "illegal data address" "$TMP/mb30"
got=$(mbpoll -m tcp -p "$port" -a 1 -0 -1 -q -r 28 -c 2 -t 3 127.0.0.1 2>&1 | grep -c '^\[2[89]\]')
check "mbpoll: input registers 28 and 29 read ($got values)" test "$got" = 2
# unit ids: the --unit (1), 0 and 255 are this device; another is exception 0x0B
got=$(raw send "0017 0000 0006 ff 03 00ca 0001")
check "unit 255 is answered ($got)" starts "$got" "00 17 00 00 00 05 ff 03 02"
got=$(raw send "0018 0000 0006 05 03 00ca 0001")
check "unit 5: exception 0x0B, no device behind this address ($got)" is "$got" "00 18 00 00 00 03 05 83 0b"
# MBAP frames that are not Modbus: refused, the connection closed
got=$(raw send "0019 0001 0006 01 03 0000 0001")
check "protocol id 1: closed, no reply ($got)" is "$got" closed
got=$(raw send "001a 0000 0008 01 03 0000 0001 0000")
check "length 8 for a 6-byte read: closed, no reply ($got)" is "$got" closed
got=$(raw send "001b 0000 0004 01 03 0000 0001")
check "length 4 for a 6-byte read: closed, no reply ($got)" is "$got" closed
got=$(raw send "001c 0000 0001 01")
check "length 1 (no function): closed ($got)" is "$got" closed
got=$(raw send "001d 0000 0100 01 03 0000 0001")
check "length 256 (over 254): closed ($got)" is "$got" closed
# two requests in one segment: two replies, in order
got=$(raw send "001e 0000 0006 01 03 00ca 0001 001f 0000 0006 01 04 0000 0001" 2 2)
check "two requests in one segment: two replies ($got)" starts "$got" "00 1e 00 00 00 05 01 03 02"
check "  the second one too" sh -c 'case "$1" in *" 00 1f 00 00 00 05 01 04 02 "*) exit 0;; esac; exit 1' sh "$got"
got=$(raw sendclose "0020 0000 0006 01 03 00ca 0001 0021 0000 0002 01 07" 2 2)
check "two requests, then the client closes its side: both replies still come ($got)" \
	sh -c 'case "$1" in "00 20 00 00 00 05 01 03 02 "*" 00 21 00 00 00 03 01 87 01") exit 0;; esac; exit 1' sh "$got"
# the other functions it serves, through pymodbus
got=$("$PY" - 127.0.0.1 "$port" <<'EOP'
import sys
from pymodbus.client import ModbusTcpClient
c = ModbusTcpClient(sys.argv[1], port=int(sys.argv[2]), timeout=1, retries=0)
c.connect()
out = []
c.write_coils(3, [True, False, True], slave=1)
out.append("".join("1" if b else "0" for b in c.read_coils(3, 3, slave=1).bits[:3]))
c.write_register(500, 0x0f0f, slave=1)
c.mask_write_register(500, 0x00ff, 0x1000, slave=1)
out.append("%04x" % c.read_holding_registers(500, 1, slave=1).registers[0])
rr = c.readwrite_registers(read_address=500, read_count=2, write_address=501, write_registers=[7], slave=1)
out.append(" ".join(str(r) for r in rr.registers))
out.append(str(len(c.read_discrete_inputs(0, 8, slave=1).bits)))
print(" ".join(out))
c.close()
EOP
)
check "pymodbus: coils, mask write (0x0f0f & 0x00ff | 0x1000 & ~0x00ff), read/write multiple, discrete inputs: $got" \
	test "$got" = "101 100f 4111 7 8"
kill "$pv"; wait "$pv"
check "psvirt exits 0" test $? = 0
check "no complaints on stderr: $(head -c 300 "$TMP/psvirt.err")" test ! -s "$TMP/psvirt.err"
done_testing
