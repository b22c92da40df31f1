#!/bin/sh
# SPDX-License-Identifier: ISC
# A login's password check (PBKDF2) never holds psensd's loop: with a
# hash of 10,000,000 iterations (the most psensd takes; seconds of work),
# the control socket answers ping while a login is being checked, and the
# login is answered after (the check runs in a worker thread).
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
"$BIN/psensd" -h 2>&1 | grep -q "web:.*not compiled in" && skip_all "psensd is built without the web console"
command -v curl > /dev/null || skip_all "curl is not installed"
B=$(cd "$BIN" && pwd)
PORT=$(free_port)
example_results
# a well-formed hash no password matches: a wrong password still costs
# every iteration
printf 'pbkdf2-sha256$10000000$%s$%s\n' 000102030405060708090a0b0c0d0e0f \
	c914cc4f06cc6e8f46d157e3a1b5aa7abceebb17bb0444cd4c4ac16ca2ae9864 > "$TMP/web.pass"
chmod 600 "$TMP/web.pass"
{ psensd_section 1; loopback_office; cat <<EOC
[web]
bind = 127.0.0.1:$PORT
password_file = web.pass
EOC
} > "$TMP/psensd.conf"
cd "$TMP" || exit 1
"$B/psensd" -v -f psensd.conf > psensd.log 2>&1 &
track_pid $!
wait_for 20 "$B/psensctl" -s sock ping > /dev/null || { cat psensd.log; skip_all "psensd did not start"; }
curl -s -o login.out -H 'X-PSD: 1' -d 'password=not it at all' "http://127.0.0.1:$PORT/api/login" &
CP=$!
track_pid $CP
wait_for 10 grep -q "checking a login from 127.0.0.1" psensd.log
t0=$(date +%s%N)
"$B/psensctl" -s sock -w 120 ping > ping.out 2>&1
diag "ping answered in $(( ($(date +%s%N) - t0) / 1000000 )) ms during the check"
check "the control socket answers while a login is checked" grep -q "^pid: [0-9]" ping.out
check "... before the login is answered" [ ! -s login.out ]
wait $CP
check "the login is answered after: wrong password" grep -q '"wrong password"' login.out
done_testing
