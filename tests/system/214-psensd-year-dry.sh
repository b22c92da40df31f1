#!/bin/sh
# SPDX-License-Identifier: ISC
# psensd -Y runs the year and leaves no trace: no database created (nor an
# event written or the next run's date moved in one that exists), no
# control socket, so it also runs beside a psensd that holds the socket.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
example_results
sed "s|^results = .*|results = $TMP/state/ofb.results|; s|^database = .*|database = $TMP/state/y.db|; s|^scene = .*|scene = $TMP/example/ofb.scene|" \
	config/psensd.conf > "$TMP/psensd.conf"
printf 'socket = %s/y.sock\n' "$TMP" > "$TMP/sock.conf"
sed "/^\[psensd\]/r $TMP/sock.conf" "$TMP/psensd.conf" > "$TMP/ys.conf"
"$BIN/psensd" -f "$TMP/ys.conf" -Y > "$TMP/out" 2> "$TMP/err"; rc=$?
check "-Y runs the year (exit $rc)" sh -c "[ $rc = 0 ] && grep -q '525600 control steps' '$TMP/out'"
check "-Y created no database" test ! -e "$TMP/state/y.db"
check "-Y left no socket" test ! -e "$TMP/y.sock"
# a database that exists: no event, no sample, the next run's date unmoved
"$BIN/psensd" -f "$TMP/psensd.conf" -s > /dev/null 2>&1
ev=$(sqlite3 "$TMP/state/y.db" 'select count(*) from events')
"$BIN/psensd" -f "$TMP/psensd.conf" -Y > /dev/null 2>&1
check "-Y wrote no event into an existing database ($ev before, $(sqlite3 "$TMP/state/y.db" 'select count(*) from events') after)" \
	test "$(sqlite3 "$TMP/state/y.db" 'select count(*) from events')" = "$ev"
# beside a running psensd holding the socket
"$BIN/psensd" -f "$TMP/ys.conf" -t 12:00 > /dev/null 2>&1 &
pd=$!
track_pid $pd
wait_for 10 test -S "$TMP/y.sock"
"$BIN/psensd" -f "$TMP/ys.conf" -Y > "$TMP/out2" 2> "$TMP/err2"; rc=$?
check "-Y runs while psensd holds the socket (exit $rc): $(head -n 1 "$TMP/err2")" test "$rc" = 0
kill -TERM $pd; wait $pd
done_testing
