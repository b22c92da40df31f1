#!/bin/sh
# SPDX-License-Identifier: ISC
# The serial DALI link (drivers/dali_serial.c) with its three codecs against
# an emulated interface and bus (peers/dalibus.py, written from the
# protocols' descriptions and IEC 62386-102, not from psensd's codecs): the
# AtxLED HAT on a pty, the Foxtron converter on a pty and over TCP.  Answers
# are the levels the bus model was given (200 = 0xC8, 100 = 0x64) and what a
# DAPC set; each fault (a malformed reply, a checksum error, a reply cut
# short, a silent interface, a collision, bus power lost) is a clear error
# naming it, and the next frame is answered correctly again.
. "$(dirname "$0")/lib.sh"
CL=$BUILD/tests/dali-serial
BUS=$(dirname "$0")/peers/dalibus.py
[ -x "$CL" ] || skip_all "dali-serial not built"
command -v python3 > /dev/null || skip_all "python3 not installed"

# start_bus NAME ARGS...: the emulator in the background; $TMP/NAME.where
# holds the pty's path (--pty) or the TCP port (--tcp)
start_bus() {
	name=$1; shift
	python3 "$BUS" --state "$TMP/$name.state" "$@" > "$TMP/$name.log" 2>&1 &
	track_pid $!
}

# 1. AtxLED on a pty: two gear (short 1 at 200, short 2 at 100); frames 4..10 faulty
start_bus atx --codec atx --pty "$TMP/atx.where" --gear 1:200,2:100 \
	--faults 4:malformed,5:checksum,6:short,8:silent,10:collision,12:observed
wait_for 10 test -s "$TMP/atx.where" || not_ok "the atx emulator did not start"
"$CL" atx "$(cat "$TMP/atx.where")" -t 0.3 q:03A0 q:05A0 q:07A0 q:03A0 q:03A0 q:03A0 q:03A0 q:03A0 \
	q:03A0 s:0296 s:0296 q:03A0 q:FFA0 t:0320 q:0391 > "$TMP/atx.out" 2>&1
a() { grep -q "^$1 $2" "$TMP/atx.out"; }
check "atx: QUERY ACTUAL LEVEL of short 1 is 200" a 1 "03A0: answer 0xC8$"
check "atx: short 2 answers 100" a 2 "05A0: answer 0x64$"
check "atx: short 3 (absent) gives no answer" a 3 "07A0: no answer$"
check "atx: a malformed reply is EPROTO, named" a 4 "03A0: error EPROTO: malformed reply"
check "atx: a non-hex answer (the line's checksum) is EPROTO" a 5 "03A0: error EPROTO: malformed"
check "atx: a reply cut short times out and says so" a 6 "03A0: error ETIMEDOUT: a reply cut short"
check "atx: after it, the next query is answered right" a 7 "03A0: answer 0xC8$"
check "atx: a silent interface times out" a 8 "03A0: error ETIMEDOUT: no reply from the interface"
check "atx: and recovers" a 9 "03A0: answer 0xC8$"
check "atx: our frame colliding with another master's is EPROTO" a 10 "0296: error EPROTO: our frame collided"
check "atx: sent again, DAPC 150 goes through" a 11 "0296: no answer$"
check "atx: short 1 now answers 150" a 12 "03A0: answer 0x96$"
check "atx: a broadcast query with 150 and 100 answering is a garbled answer" a 13 "FFA0: error EPROTO: garbled answer"
check "atx: a command sent twice ('t') takes its two replies as one" a 14 "0320: no answer$"
check "atx: QUERY CONTROL GEAR PRESENT is yes (0xFF)" a 15 "0391: answer 0xFF$"
check "atx: another master's frame was seen and counted" grep -q "observed 1 last_observed 7F91" "$TMP/atx.out"
check "atx: the bus model holds short 1 at 150" grep -q "short 1 level 150" "$TMP/atx.state"

# 2. Foxtron on a pty: a checksum error, bus power lost and back, a collision of answers
start_bus foxp --codec foxtron --pty "$TMP/foxp.where" --gear 1:200,2:100 \
	--faults 2:checksum,3:power,5:malformed,6:short,8:silent,10:collision
wait_for 10 test -s "$TMP/foxp.where" || not_ok "the foxtron emulator did not start"
"$CL" foxtron "$(cat "$TMP/foxp.where")" -t 0.3 q:03A0 q:03A0 q:05A0 q:05A0 q:03A0 q:03A0 q:03A0 q:03A0 \
	q:03A0 q:03A0 q:FFA0 s:FE00 q:FFA0 > "$TMP/foxp.out" 2>&1
f() { grep -q "^$1 $2" "$TMP/foxp.out"; }
check "foxtron: short 1 answers 200" f 1 "03A0: answer 0xC8$"
check "foxtron: a wrong checksum is EPROTO, named" f 2 "03A0: error EPROTO: malformed reply from the interface: a message with a wrong checksum"
check "foxtron: bus power lost is EIO" f 3 "05A0: error EIO: bus power lost"
check "foxtron: power back, short 2 answers 100" f 4 "05A0: answer 0x64$"
check "foxtron: a message of an unknown type is EPROTO" f 5 "03A0: error EPROTO: malformed"
check "foxtron: a reply cut short times out and says so" f 6 "03A0: error ETIMEDOUT: a reply cut short"
check "foxtron: and recovers" f 7 "03A0: answer 0xC8$"
check "foxtron: a silent converter times out" f 8 "03A0: error ETIMEDOUT: no reply"
check "foxtron: and recovers" f 9 "03A0: answer 0xC8$"
check "foxtron: answer length 0 is a collision of answers" f 10 "03A0: error EPROTO: garbled answer"
check "foxtron: two gear answering different levels collide" f 11 "FFA0: error EPROTO: garbled answer"
check "foxtron: broadcast DAPC 0 (off)" f 12 "FE00: no answer$"
check "foxtron: now both answer 0, which superimposes into one answer" f 13 "FFA0: answer 0x00$"
check "foxtron: the power came back" grep -q "power_lost 0" "$TMP/foxp.out"

# 3. LUBA on a pty: no "no answer" message; the window after the sent event decides
start_bus luba --codec luba --pty "$TMP/luba.where" --gear 1:200,2:100 \
	--faults 4:malformed,5:checksum,6:short,8:silent,10:collision,12:observed
wait_for 10 test -s "$TMP/luba.where" || not_ok "the luba emulator did not start"
"$CL" luba "$(cat "$TMP/luba.where")" -t 0.3 q:03A0 q:05A0 q:07A0 q:03A0 q:03A0 q:03A0 q:03A0 q:03A0 \
	q:03A0 q:03A0 s:0296 q:03A0 q:FFA0 t:0320 q:0391 > "$TMP/luba.out" 2>&1
l() { grep -q "^$1 $2" "$TMP/luba.out"; }
check "luba: short 1 answers 200" l 1 "03A0: answer 0xC8$"
check "luba: short 2 answers 100" l 2 "05A0: answer 0x64$"
check "luba: no backward frame within the window: no answer" l 3 "07A0: no answer$"
check "luba: an unknown command is EPROTO" l 4 "03A0: error EPROTO: malformed"
check "luba: a wrong XOR checksum is EPROTO, named" l 5 "03A0: error EPROTO: malformed reply from the interface: a message with a wrong checksum"
check "luba: a reply cut short times out and says so" l 6 "03A0: error ETIMEDOUT: a reply cut short"
check "luba: and recovers" l 7 "03A0: answer 0xC8$"
check "luba: a silent interface times out" l 8 "03A0: error ETIMEDOUT: no reply"
check "luba: and recovers" l 9 "03A0: answer 0xC8$"
check "luba: a framing error after our query is EPROTO" l 10 "03A0: error EPROTO: a framing error"
check "luba: DAPC 150 ends at its sent event" l 11 "0296: no answer$"
check "luba: short 1 now answers 150" l 12 "03A0: answer 0x96$"
check "luba: two gear answering different levels collide" l 13 "FFA0: error EPROTO: a framing error"
check "luba: a frame sent twice waits for both sent events" l 14 "0320: no answer$"
check "luba: QUERY CONTROL GEAR PRESENT is yes" l 15 "0391: answer 0xFF$"
check "luba: another master's frame was seen and counted" grep -q "observed 1 last_observed 7F91 stray 0" "$TMP/luba.out"

# 4. Foxtron over TCP (DALInet): answers, a silent gateway, recovery
start_bus foxt --codec foxtron --tcp "$TMP/foxt.where" --gear 7:254 --faults 2:silent
wait_for 10 test -s "$TMP/foxt.where" || not_ok "the TCP emulator did not start"
"$CL" foxtron "127.0.0.1:$(cat "$TMP/foxt.where")" -t 0.3 q:0FA0 q:0FA0 q:0FA0 s:0E64 q:0FA0 > "$TMP/foxt.out" 2>&1
t() { grep -q "^$1 $2" "$TMP/foxt.out"; }
check "tcp: short 7 answers 254" t 1 "0FA0: answer 0xFE$"
check "tcp: a silent gateway times out" t 2 "0FA0: error ETIMEDOUT"
check "tcp: and recovers" t 3 "0FA0: answer 0xFE$"
check "tcp: DAPC 100 then the query answers 100" t 5 "0FA0: answer 0x64$"
# a gateway that drops a connection silent for 0.5 s (DALInet: 30 s): the
# keep-alive (the firmware-version query) holds it; without it, it is gone
start_bus idle --codec foxtron --tcp "$TMP/idle.where" --gear 7:254 --idle-close 0.5
wait_for 10 test -s "$TMP/idle.where" || not_ok "the idle-closing emulator did not start"
"$CL" foxtron "127.0.0.1:$(cat "$TMP/idle.where")" -k 0.2 q:0FA0 w:1.2 q:0FA0 > "$TMP/ka.out" 2>&1
check "tcp: with keep-alives every 0.2 s the connection outlives 1.2 s of silence" \
	grep -q "^2 0FA0: answer 0xFE$" "$TMP/ka.out"
check "tcp: ... at least 4 keep-alives sent: $(sed -n 's/.*keepalives //p' "$TMP/ka.out")" \
	test "$(sed -n 's/.*keepalives //p' "$TMP/ka.out")" -ge 4
"$CL" foxtron "127.0.0.1:$(cat "$TMP/idle.where")" -k 0 q:0FA0 w:1.2 q:0FA0 > "$TMP/noka.out" 2>&1
check "tcp: without them the gateway closes and the link says so" \
	grep -q "^wait: link gone: the interface is gone: end of file" "$TMP/noka.out"
"$CL" foxtron "127.0.0.1:1" q:0FA0 > "$TMP/refused.out" 2>&1
check "tcp: nobody listening is a clear open error" grep -q "^open: 127.0.0.1:1: Connection refused" "$TMP/refused.out"
"$CL" atx /nonexistent/tty q:0FA0 > "$TMP/nodev.out" 2>&1
check "a missing tty is a clear open error" grep -q "^open: /nonexistent/tty: No such file or directory" "$TMP/nodev.out"
for o in atx foxp luba foxt; do diag "$o: $(tail -n 1 "$TMP/$o.out")"; done
done_testing
