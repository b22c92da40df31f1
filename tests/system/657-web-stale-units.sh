#!/bin/sh
# SPDX-License-Identifier: ISC
# check: alone
# (chromium and a live page at 600x)
# The web console says what it knows, in a real browser (Debian's chromium,
# headless, tests/peers/web-stale-peer.js): psensd stopped under the open
# page leaves every tile stale with the level unknown and the time of the
# last answer (psensd has driven the lights to its stop or safe level; the
# page cannot know which), and the page comes back by itself when psensd
# does; a psensd held by SIGSTOP (its connection open, silent) is noticed by
# the missing updates the same way; the loopback room is shown as
# simulated; an override of 150 % is refused in the unit typed; the
# acceptance table gives every figure its unit and each test its reason
# (the acceptance module's own text).
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
"$BIN/psensd" -h 2>&1 | grep -q "web:.*not compiled in" && skip_all "psensd is built without the web console"
command -v node > /dev/null || skip_all "node is not installed (make deps: nodejs)"
[ -x /usr/bin/chromium ] || skip_all "chromium is not installed (make deps: chromium)"
[ -d "$TOP/tests/peers/node_modules/puppeteer-core" ] ||
	skip_all "puppeteer-core is not installed (make deps-peers, which make check runs: npm ci in tests/peers)"
example_results
S="$TMP/sock"
PW="stale tiles 657"
printf '%s\n' "$PW" | "$BIN/psensctl" web-passwd "$TMP/web.pass" > /dev/null
PORT=$(free_port)
{
	psensd_section 60
	cat <<EOC
[device room]
driver = loopback
gain = 0.5
offset = 0.05
seed = 7
[point sensor]
device = room
role = sensor
[point lamp]
device = room
role = dim
[point meter]
device = room
role = task
[zone office]
sensor = sensor
dim = lamp
task = meter
sensor_gain = 0.5
[web]
bind = 127.0.0.1:$PORT
password_file = web.pass
session = 3600
update = 0.2
EOC
} > "$TMP/psensd.conf"
# control.sh stop|start|pause|resume: psensd stopped (back once it has
# exited), started again (back once it answers), or held by SIGSTOP and let
# go by SIGCONT
B=$(cd "$BIN" && pwd)
cat > "$TMP/control.sh" <<EOS
cd "$TMP"
case "\$1" in pause) kill -STOP \$(cat pid); exit 0 ;; resume) kill -CONT \$(cat pid); exit 0 ;; esac
if [ "\$1" = stop ]; then
	kill -TERM \$(cat pid); while kill -0 \$(cat pid) 2> /dev/null; do sleep 0.05; done
	exit 0
fi
"$B/psensd" -f psensd.conf -t 10:00 -x 600 >> out 2>> err &
echo \$! > pid
i=0; until "$B/psensctl" -s "$S" ping > /dev/null 2>&1; do i=\$((i + 1)); [ \$i -lt 200 ] || exit 1; sleep 0.05; done
EOS
sh "$TMP/control.sh" start || cat "$TMP/err"
track_pid "$(cat "$TMP/pid")"
node "$TOP/tests/peers/web-stale-peer.js" "http://127.0.0.1:$PORT/" "$PW" "$TMP/control.sh" > "$TMP/peer" 2>&1
rc=$?
track_pid "$(cat "$TMP/pid")"
sed -n 's/^\(not \)\{0,1\}ok [0-9]* - /browser: /p; /^# /p' "$TMP/peer" | while read -r l; do diag "$l"; done
check "the browser's checks all pass ($(grep -c '^ok' "$TMP/peer") ok, $(grep -c '^not ok' "$TMP/peer") not ok)" \
	test "$rc" = 0 -a "$(grep -c '^not ok' "$TMP/peer")" = 0 -a "$(grep -c '^ok' "$TMP/peer")" -ge 20
grep '^not ok' "$TMP/peer" | while read -r l; do diag "$l"; done
check "the override of 150 % never reached psensd" sh -c "! grep -q 'asks: override office 1.5' '$TMP/err'"
kill -TERM "$(cat "$TMP/pid")"
done_testing
