#!/bin/sh
# SPDX-License-Identifier: ISC
# The control socket's status of every zone at the size psensd is built
# for: 128 zones on the file driver (the most a configuration holds).  The
# reply is one JSON line of some 95 kB, more than 64 KiB; psensctl must
# print it whole, with every
# zone's name in order, and psensd must stay up and answer a ping after it.
# The text form too.  And the web console (when built, with curl), which
# answers through the same request function: its `status` request over
# HTTP names the same 128 zones.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
example_results
S="$TMP/sock"
file_zones 128 > "$TMP/many.conf"
web=0
if ! "$BIN/psensd" -h 2>&1 | grep -q "web:.*not compiled in" && command -v curl > /dev/null; then
	web=1
	PORT=$(free_port)
	PW=correct-horse-653
	printf '%s\n' "$PW" | "$BIN/psensctl" web-passwd "$TMP/web.pass" > /dev/null
	printf '[web]\nbind = 127.0.0.1:%s\npassword_file = web.pass\n' "$PORT" >> "$TMP/many.conf"
fi
"$BIN/psensd" -f "$TMP/many.conf" -t 08:00 -x 10 > "$TMP/out" 2> "$TMP/err" &
PID=$!; track_pid $PID
wait_for 10 "$BIN/psensctl" -s "$S" ping > /dev/null
"$BIN/psensctl" -s "$S" -j status > "$TMP/status.json" 2> "$TMP/status.err"
check "psensctl -j status of 128 zones succeeds ($(head -c 200 "$TMP/status.err"))" test $? = 0
n=$(wc -c < "$TMP/status.json")
diag "status reply: $n bytes"
check "the reply is larger than 64 KiB ($n bytes)" test "$n" -gt 65536
/usr/bin/python3 - "$TMP/status.json" > "$TMP/names" 2>&1 <<'EOP'
import json, sys
d = json.load(open(sys.argv[1]))
assert d["ok"] is True, d
print(" ".join(z["name"] for z in d["zones"]))
EOP
check "the reply is JSON with ok true ($(head -c 200 "$TMP/names"))" test $? = 0
want=$(z=0; while [ $z -lt 128 ]; do printf 'z%d ' $z; z=$((z + 1)); done)
check "every zone, in order" test "$(cat "$TMP/names") " = "$want"
"$BIN/psensctl" -s "$S" status > "$TMP/status.txt" 2> "$TMP/status2.err"
check "psensctl status (text) succeeds ($(head -c 200 "$TMP/status2.err"))" test $? = 0
check "the text names the last zone" grep -q "z127" "$TMP/status.txt"
if [ "$web" = 1 ]; then
	U="http://127.0.0.1:$PORT"
	curl -s -H 'X-PSD: 1' -c "$TMP/cj" --data-urlencode "password=$PW" "$U/api/login" > "$TMP/login"
	curl -s -H 'X-PSD: 1' -b "$TMP/cj" --data-urlencode 'line=status' "$U/api/request" > "$TMP/web.json"
	/usr/bin/python3 - "$TMP/web.json" > "$TMP/webnames" 2>&1 <<'EOP'
import json, sys
d = json.load(open(sys.argv[1]))
assert d["ok"] is True, d
print(" ".join(z["name"] for z in d["zones"]))
EOP
	check "the web console's status names the same 128 zones ($(wc -c < "$TMP/web.json") bytes; $(head -c 120 "$TMP/webnames"))" \
		test "$(cat "$TMP/webnames") " = "$want"
else
	skip "the web console is not built, or curl is missing"
fi
check "psensd still answers" "$BIN/psensctl" -s "$S" ping
kill $PID; wait $PID 2> /dev/null
done_testing
