#!/bin/sh
# SPDX-License-Identifier: ISC
# psvirt's DALI bus short: the virtual gear go to their SYSTEM FAILURE LEVEL
# when the bus loses power (IEC 62386-102), as real gear do.  The gear's
# failure level is set to 200 over the bus (DTR0, then SET SYSTEM FAILURE
# LEVEL twice), the gear dimmed to 170, then the bus shorted through the
# fault registers: the room's light output (holding register 202, x 10000)
# is X(200) = 10^((200-1)/(253/3)-1) %, not X(170), the level the gear had.
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/peers/common.sh"
[ -x "$BIN/psvirt" ] || skip_all "psvirt not built"
make_results
mb=$(free_port)
psvirt_dali --tcp "127.0.0.1:$mb" --start 12:00 -D lag_tau=0
fox() { "$PY" "$PEERS/foxclient.py" "tcp:127.0.0.1:$port" "$@"; }
levels() { fox "ask 16 01A0; ask 16 03A0" | tr '\n' ' ' | sed 's/ $//'; }
hr() { "$PY" "$PEERS/mbraw.py" 127.0.0.1 "$mb" send "0001 0000 0006 01 03 $(printf %04x "$1") 0001" | awk '{ print $10 $11 }' | { read -r h; printf '%d\n' "0x$h"; }; }
whr() { "$PY" "$PEERS/mbraw.py" 127.0.0.1 "$mb" send "0002 0000 0006 01 06 $(printf %04x "$1") $(printf %04x "$2")" > /dev/null; }
x() { awk -v n="$1" 'BEGIN { printf "%d", 10000 * exp(log(10) * ((n - 1) * 3 / 253 - 3)) + 0.5 }'; }

fox "send 16 A3C8; send 16 FF2C twice; send 16 FEAA" > /dev/null
check "the gear's system failure level is 200 ($(fox 'ask 16 01A4; ask 16 03A4' | tr '\n' ' '))" \
	test "$(fox 'ask 16 01A4; ask 16 03A4' | tr '\n' ' ')" = "200 200 "
check "the gear at 170 ($(levels))" test "$(levels)" = "170 170"
check "the room at X(170) = $(x 170) (register 202: $(hr 202))" test "$(hr 202)" = "$(x 170)"
whr 905 255
whr 904 3
check "the bus shorted: a query gets 'power lost'" test "$(fox 'send 16 01A0')" = "power lost"
check "the gear at their failure level: the room at X(200) = $(x 200) (register 202: $(hr 202))" \
	test "$(hr 202)" = "$(x 200)"
kill -TERM $pv
wait $pv
done_testing
