#!/bin/sh
# SPDX-License-Identifier: ISC
# psensd in real time (sped up 600 times) on the loopback room: readiness and
# the watchdog through a notification socket, the control socket with good
# and bad requests (socat and a raw client as peers), SIGHUP with a good and
# a bad config, SIGKILL with the log intact and a restart that appends to it,
# and SIGTERM to the safe level.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v socat > /dev/null || skip_all "socat not installed"
PY=/usr/bin/python3
PEERS="$TOP/tests/system/peers"
example_results
S="$TMP/sock"
sed "s|^results = .*|results = state/ofb.results|; s|^database = .*|database = state/psensd.db\nsocket = sock\nmax_clients = 4|; /^faults = /d" \
	config/psensd.conf > "$TMP/psensd.conf"
ctl() { "$BIN/psensctl" -s "$S" "$@"; }
field() { ctl -j status | $PY -c "import json,sys; d=json.load(sys.stdin); v=eval(sys.argv[1]); print(*v) if isinstance(v, tuple) else print(v)" "$1"; }

$PY "$PEERS/notify.py" "$TMP/notify" "$TMP/notify.log" & track_pid $!
wait_for 5 test -S "$TMP/notify"
start() {
	NOTIFY_SOCKET="$TMP/notify" WATCHDOG_USEC=200000 "$BIN/psensd" -f "$TMP/psensd.conf" -t 08:00 -x 600 \
		>> "$TMP/out" 2>> "$TMP/err" &
	PID=$!; track_pid $PID
	wait_for 10 ctl ping > /dev/null
}
start
check "the control socket answers ping" sh -c "\"$BIN/psensctl\" -s \"$S\" ping > /dev/null"
check "the socket is mode 0660" test "$(stat -c %a "$S")" = 660
wait_for 5 grep -q "READY=1" "$TMP/notify.log"
check "READY=1 reached the notification socket" grep -q "READY=1" "$TMP/notify.log"
wait_for 5 grep -q "WATCHDOG=1" "$TMP/notify.log"
check "the watchdog is fed (WATCHDOG_USEC=200000)" grep -q "WATCHDOG=1" "$TMP/notify.log"
wait_for 5 sh -c "[ \$(\"$BIN/psensctl\" -s \"$S\" -j status | grep -o '\"steps\":[0-9]*' | cut -d: -f2) -ge 3 ]"
check "status: one zone on a real clock" test "$(field "d['clock'], len(d['zones']), d['zones'][0]['name']")" = "real 1 office"
# socat speaks the protocol too
echo "status office" | socat - "UNIX-CONNECT:$S" > "$TMP/socat.out"
check "socat gets a JSON status line" grep -q '^{"ok":true,.*"zones":\[{"name":"office"' "$TMP/socat.out"
check "target office 420" ctl target office 420
check "status shows the new target" test "$(field "d['zones'][0]['target_lux']")" = 420.0
check "override office 0.3 for 6000 s" ctl override office 0.3 6000
wait_for 10 sh -c "\"$BIN/psensctl\" -s \"$S\" -j status | grep -q '\"level\":0.3'"
check "the override sets the level at once" test "$(field "d['zones'][0]['level']")" = 0.3
check "release" ctl release office
wait_for 10 sh -c "! \"$BIN/psensctl\" -s \"$S\" -j status | grep -q '\"level\":0.3,'"
check "released: the control takes over again" sh -c "! \"$BIN/psensctl\" -s \"$S\" -j status | grep -q '\"level\":0.3,'"
ctl ratios > "$TMP/ratios"
check "ratios lists the scene's conditions" grep -q "daylight_ratio_mean" "$TMP/ratios"
# bad requests: error replies, nothing crashes
for req in "bogus" "target office" "target nowhere 300" "target office 1e99" "override office 2 60" \
	"override office 0.5 -1" "status a b c" "$(printf 'ping\001')"; do
	r=$($PY "$PEERS/rawctl.py" "$S" send "$req")
	case "$r" in *'"ok":false'*) ok "error reply to '$(printf %s "$req" | tr -d '\001')': $(echo "$r" | cut -c1-80)";;
		*) not_ok "no error reply to '$req': $r";; esac
done
r=$($PY "$PEERS/rawctl.py" "$S" bytes 5000)
check "a 5000-byte request gets 'request longer than' ($r)" sh -c "echo '$r' | grep -q 'request longer than 1023 bytes'"
$PY "$PEERS/rawctl.py" "$S" hold 6 > "$TMP/hold"
check "max_clients = 4: four connections served" test "$(grep -c '"ok":true' "$TMP/hold")" = 4
check "the fifth and sixth are told 'too many clients'" test "$(grep -c 'too many clients' "$TMP/hold")" = 2
check "1000 bad requests on one connection: 1000 error replies" test "$($PY "$PEERS/rawctl.py" "$S" burst 1000)" = 1000
check "psensd still answers" sh -c "\"$BIN/psensctl\" -s \"$S\" ping > /dev/null"
check "psensctl reports an error reply with exit 1" sh -c "! \"$BIN/psensctl\" -s \"$S\" target nowhere 3 2> \"$TMP/e\""
check "... and the reason on stderr" grep -q "no zone 'nowhere'" "$TMP/e"
# peers: the file mode keeps others out; SO_PEERCRED too, if the mode is loosened.
# The other user's client is socat from /usr/bin: psensctl may sit in a
# checkout the other user cannot enter, and then "Permission denied" would be
# about the program, not the socket.
if [ "$(id -u)" = 0 ] && command -v setpriv > /dev/null && command -v socat > /dev/null; then
	chmod 755 "$TMP"
	# read only (-u): psensd refuses at accept, and a request written after
	# its close would fail with EPIPE before socat read the refusal
	nobody() { setpriv --reuid=65534 --regid=65534 --clear-groups socat -t 5 -u "UNIX-CONNECT:$S" - > "$TMP/nobody.out" 2> "$TMP/nobody.err"; }
	nobody
	check "another user cannot connect through mode 0660: $(cat "$TMP/nobody.err")" grep -q "connect.*Permission denied" "$TMP/nobody.err"
	chmod 666 "$S"
	nobody
	check "with the socket opened to all, SO_PEERCRED still refuses: $(cat "$TMP/nobody.out" "$TMP/nobody.err")" grep -qx '{"ok":false,"error":"permission denied"}' "$TMP/nobody.out"
	check "... and psensd logs the refused uid" grep -q "control socket: refused uid 65534" "$TMP/err"
	chmod 660 "$S"
else
	skip "peer credentials: needs root, setpriv and socat"
	skip "peer credentials: needs root, setpriv and socat"
	skip "peer credentials: needs root, setpriv and socat"
fi
# SIGHUP: a good new config replaces the running one
sed -i 's/^target_lux = .*/target_lux = 450/' "$TMP/psensd.conf"
kill -HUP $PID
wait_for 5 grep -q "reloaded" "$TMP/err"
check "SIGHUP reloads a good config" test "$(field "d['reloads'], d['zones'][0]['target_lux']")" = "1 450.0"
# a bad one is refused with its reason and the old one keeps running
cp "$TMP/psensd.conf" "$TMP/good.conf"
printf '[zone other]\nsensor = nosuch\n' >> "$TMP/psensd.conf"
kill -HUP $PID
wait_for 5 grep -q "the running configuration stays" "$TMP/err"
check "a bad config is refused, naming file and line" grep -q "psensd.conf:[0-9]*: sensor: no \[point nosuch\]" "$TMP/err"
check "and the running configuration stays" grep -q "has errors: the running configuration stays" "$TMP/err"
check "still controlling with the old config" test "$(field "d['reloads'], d['zones'][0]['target_lux']")" = "1 450.0"
cp "$TMP/good.conf" "$TMP/psensd.conf"
# SIGKILL: every sample acknowledged before the kill is in the database
sleep 0.5
n=$(field "d['logged']")
kill -9 $PID; wait $PID 2>/dev/null
rows=$(sqlite3 "$TMP/state/psensd.db" 'select count(*) from samples')
check "after SIGKILL: $rows rows >= $n acknowledged" test "$rows" -ge "$n"
check "integrity check after SIGKILL" test "$(sqlite3 "$TMP/state/psensd.db" 'pragma integrity_check')" = ok
# the restart replaces the stale socket and appends to the log
start
check "restarted after SIGKILL (stale socket replaced)" sh -c "\"$BIN/psensctl\" -s \"$S\" ping > /dev/null"
sleep 0.5
check "the restarted daemon appends to the log" test "$(sqlite3 "$TMP/state/psensd.db" 'select count(*) from samples')" -gt "$rows"
# SIGTERM: safe level, clean exit, socket removed
kill -TERM $PID; wait $PID; rc=$?
check "SIGTERM: exit status 0" test "$rc" = 0
check "SIGTERM: lights at the safe level" grep -q "zone office: Terminated: lights at the safe level 100 %" "$TMP/err"
check "SIGTERM: the socket is removed" test ! -e "$S"
check "STOPPING=1 was sent" grep -q "STOPPING=1" "$TMP/notify.log"
"$BIN/psensctl" -s "$S" status > /dev/null 2> "$TMP/e2" && not_ok "psensctl without a daemon succeeded" || ok "psensctl without a daemon fails"
check "... with a clear error: $(cat "$TMP/e2")" grep -q "cannot reach psensd at $S" "$TMP/e2"
done_testing
