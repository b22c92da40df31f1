#!/bin/sh
# SPDX-License-Identifier: ISC
# check: alone
# (chromium and a live page at 600x)
# The web console (psensd.conf(5) [web], doc/console.md) in a real browser:
# Debian's chromium, headless, driven by puppeteer-core
# (tests/peers/web-peer.js) against psensd on the loopback room in real time
# sped up 600 times.  A wrong password refused with its message, the zone
# list and a zone's estimate and output changing live as the room's sun
# rises, a session ending after [web] session seconds (the live page back at
# the login, saying it expired), override and release (a bad level
# refused in the % typed), a night session run to its end and
# accepted, a second agent at the same zone seeing the override live and
# refused a second session, psensd restarted under the page (reconnecting,
# then live), a day session with the lux readings typed in, the acceptance
# tests run and shown, the record downloaded as a PDF, with a QR code on
# the zone's page that opens it in the console ([web] url), the zone's
# year drawn; screenshots at phone and desktop sizes kept in
# $BUILD/artefacts/web/.  Then, without the browser: the password file's
# checks, a [web] without bind, the guard after failed logins, a request
# without the console's header, and psensctl web-passwd's file.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
"$BIN/psensd" -h 2>&1 | grep -q "web:.*not compiled in" && skip_all "psensd is built without the web console"
command -v node > /dev/null || skip_all "node is not installed (make deps: nodejs)"
[ -x /usr/bin/chromium ] || skip_all "chromium is not installed (make deps: chromium)"
[ -d "$TOP/tests/peers/node_modules/puppeteer-core" ] ||
	skip_all "puppeteer-core is not installed (make deps-peers, which make check runs: npm ci in tests/peers)"
command -v curl > /dev/null || skip_all "curl is not installed"
ART="$TOP/$BUILD/artefacts/web"
case "$BUILD" in /*) ART="$BUILD/artefacts/web" ;; esac
rm -rf "$ART"; mkdir -p "$ART"
example_results
S="$TMP/sock"
PW="lux meter 42"
printf '%s\n' "$PW" | "$BIN/psensctl" web-passwd "$TMP/web.pass" > "$TMP/passwd.out"
check "psensctl web-passwd writes the hash, mode 0600" sh -c "[ \"\$(stat -c %a '$TMP/web.pass')\" = 600 ] && grep -q '^pbkdf2-sha256\\\$60000\\\$[0-9a-f]\\{32\\}\\\$[0-9a-f]\\{64\\}\$' '$TMP/web.pass'"
check "... not the password" sh -c "! grep -q 'lux meter' '$TMP/web.pass'"
PORT=$(free_port)
conf() {  # conf SESSION
	psensd_section 60; cat <<EOC
[simulate]
sunrise = 06:00
sunset = 18:30
[device room]
driver = loopback
gain = 0.5
offset = 0.05
noise = 0.002
task_noise = 2
seed = 11
fade_rate = 0.2
[point sensor]
device = room
role = sensor
valid_min = 0.01
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
cal_window = 300
cal_day_samples = 64
cal_day_interval = 86400
[web]
bind = 127.0.0.1:$PORT
password_file = web.pass
session = $1
update = 0.2
url = https://console.site.test/psensd/
EOC
}
conf 10 > "$TMP/short.conf"
conf 3600 > "$TMP/long.conf"
# restart.sh HH:MM CONF: psensd (again) from HH:MM; back once it answers
B=$(cd "$BIN" && pwd)
cat > "$TMP/restart.sh" <<EOS
cd "$TMP"
if [ -s pid ]; then kill -TERM \$(cat pid); while kill -0 \$(cat pid) 2> /dev/null; do sleep 0.05; done; fi
"$B/psensd" -f "\$2" -t "\$1" -x 600 >> out 2>> err &
echo \$! > pid
i=0; until "$B/psensctl" -s "$S" ping > /dev/null 2>&1; do i=\$((i + 1)); [ \$i -lt 200 ] || exit 1; sleep 0.05; done
EOS
: > "$TMP/pid"
(cd "$TMP" && sh restart.sh 05:50 short.conf) || cat "$TMP/err"
track_pid "$(cat "$TMP/pid")"
check "psensd logs its console" grep -q "web console on http://127.0.0.1:$PORT/" "$TMP/err"

node "$TOP/tests/peers/web-peer.js" "http://127.0.0.1:$PORT/" "$PW" "$TMP/restart.sh" "$ART" > "$TMP/peer" 2>&1
rc=$?
track_pid "$(cat "$TMP/pid")"
sed -n 's/^\(not \)\{0,1\}ok [0-9]* - /browser: /p; /^# /p' "$TMP/peer" | while read -r l; do diag "$l"; done
check "the browser's checks all pass ($(grep -c '^ok' "$TMP/peer") ok, $(grep -c '^not ok' "$TMP/peer") not ok)" \
	test "$rc" = 0 -a "$(grep -c '^not ok' "$TMP/peer")" = 0 -a "$(grep -c '^ok' "$TMP/peer")" -ge 20
grep '^not ok' "$TMP/peer" | while read -r l; do diag "$l"; done
for s in phone-zones phone-zone phone-night phone-accept phone-year desktop-zone desktop-zones; do
	check "screenshot $s.png kept" sh -c "head -c 8 '$ART/$s.png' | od -An -c | grep -q 'P   N   G'"
done
check "the record the console served is a PDF of the zone's pages" sh -c "pdftotext '$ART/record-office.pdf' - | grep -q 'office'"
if ! command -v zbarimg > /dev/null || ! command -v pdftoppm > /dev/null; then
	skip "the record's QR code: zbarimg or pdftoppm is not installed (make deps: zbar-tools, poppler-utils)"
elif "$BIN/psensd" -h 2>&1 | grep -q "qrencode: not compiled in"; then
	skip "the record's QR code: psensd is built without libqrencode"
else
	pdftoppm -r 150 -png "$ART/record-office.pdf" "$TMP/rec"
	zbarimg -q --raw "$TMP"/rec-*.png > "$TMP/qr" 2> /dev/null
	check "the zone's page has a QR code that opens it in the console: $(cat "$TMP/qr")" \
		test "$(cat "$TMP/qr")" = "https://console.site.test/psensd/#zone=office"
fi
check "psensd logged the console's actions" sh -c "grep -q 'web: .* asks: override office 0.5 36000' '$TMP/err' && grep -q 'web: .* asks: release office' '$TMP/err'"
check "and the failed login" grep -q "web: a failed login from 127.0.0.1" "$TMP/err"

# without the browser
U="http://127.0.0.1:$PORT"
post() { curl -s -H 'X-PSD: 1' "$@"; }
check "a POST without the console's header is refused" sh -c \
	"curl -s -d 'password=x' '$U/api/login' | grep -q 'carries the X-PSD header'"
check "an API call without a login is refused" sh -c "curl -s '$U/api/history?zone=office' | grep -q '\"session not logged in: log in\"'"
for i in 1 2 3; do post -d "password=guess$i" "$U/api/login" > "$TMP/guess$i"; done
check "three wrong passwords: each 'wrong password'" sh -c "cat '$TMP'/guess[123] | grep -o '\"wrong password\"' | wc -l | grep -qx 3"
check "the fourth attempt waits, even with the right password" sh -c \
	"curl -s -H 'X-PSD: 1' --data-urlencode 'password=$PW' '$U/api/login' | grep -q 'too many failed logins from this address: try again in 1 s'"
sleep 1.1
check "after the wait the right password logs in" sh -c \
	"curl -s -H 'X-PSD: 1' -c '$TMP/cj' --data-urlencode 'password=$PW' '$U/api/login' | grep -qx '{\"ok\":true}'"
check "its cookie is HttpOnly" grep -q "^#HttpOnly_127.0.0.1.*psd_session" "$TMP/cj"
check "a request the console does not send is refused" sh -c \
	"curl -s -H 'X-PSD: 1' -b '$TMP/cj' --data-urlencode 'line=reload' '$U/api/request' | grep -q \"'reload' is not a request the web console sends\""
check "the same error as the control socket for an unknown zone" sh -c \
	"[ \"\$(curl -s -H 'X-PSD: 1' -b '$TMP/cj' --data-urlencode 'line=release nosuch' '$U/api/request')\" = \"\$('$BIN/psensctl' -s '$S' -j release nosuch 2>/dev/null)\" ]"
kill -TERM "$(cat "$TMP/pid")"
i=0; while kill -0 "$(cat "$TMP/pid")" 2> /dev/null && [ $i -lt 200 ]; do i=$((i + 1)); sleep 0.05; done
check "psensd stopped on SIGTERM, its log without a sanitizer's report" \
	sh -c "! kill -0 $(cat "$TMP/pid") 2> /dev/null && ! grep -E 'Sanitizer|runtime error' '$TMP/err'"

# the configuration's checks
sed 's/^bind = .*//' "$TMP/long.conf" > "$TMP/nobind.conf"
check "a [web] without bind is refused with its line" sh -c \
	"cd '$TMP' && ! '$B/psensd' -f nobind.conf -n 2> err.n && grep -q 'nobind.conf:[0-9]*: \\[web\\] needs .bind.' err.n"
chmod 644 "$TMP/web.pass"
check "a password file others may read is refused" sh -c \
	"cd '$TMP' && ! '$B/psensd' -f long.conf -n 2> err.n && grep -q 'web.pass is readable by others' err.n"
chmod 600 "$TMP/web.pass"; echo "$PW" > "$TMP/web.pass"
check "a password in clear is refused" sh -c \
	"cd '$TMP' && ! '$B/psensd' -f long.conf -n 2> err.n && grep -q 'not a psensd password hash' err.n"
done_testing
