#!/bin/sh
# SPDX-License-Identifier: ISC
# One daemon per control socket and per database.  A second psensd on a
# running one's socket is refused, naming the first one's pid, and leaves
# the socket alone (the first still answers, with its own pid); a socket a
# raw peer (python) listens on is refused too, naming that peer's pid; one
# left by a killed process is replaced.  A second psensd on the same
# database, with a socket of its own, is refused with the database named.
# Neither refused daemon commands a light (it stops before opening devices).
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
PY=/usr/bin/python3
example_results
conf() {  # conf NAME SOCKET DB
	sed "s|^results = .*|results = state/ofb.results|; s|^database = .*|database = state/$3\nsocket = $2|; s|^period = .*|period = 1|; /^faults = /d" \
		config/psensd.conf > "$TMP/$1.conf"
}
pid_of() { "$BIN/psensctl" -s "$1" -j ping | sed -n 's/.*"pid":\([0-9]*\).*/\1/p'; }
conf a sock a.db
"$BIN/psensd" -f "$TMP/a.conf" -t 12:00 > /dev/null 2> "$TMP/a.err" &
a=$!; track_pid $a
wait_for 10 sh -c "\"$BIN/psensctl\" -s \"$TMP/sock\" ping > /dev/null"
check "the first psensd answers with its pid $a" test "$(pid_of "$TMP/sock")" = "$a"

# a second one on the same socket (another database)
conf b sock b.db
timeout 10 "$BIN/psensd" -f "$TMP/b.conf" -t 12:00 > /dev/null 2> "$TMP/b.err"
rc=$?
check "a second psensd on the same socket exits 1 (got $rc)" test "$rc" = 1
diag "$(grep -i "in use" "$TMP/b.err" | head -n 1)"
check "it names the pid that holds the socket ($a)" grep -q "sock is in use by psensd pid $a" "$TMP/b.err"
check "the first still answers, with its own pid" test "$(pid_of "$TMP/sock")" = "$a"
check "the refused one opened no database" test ! -e "$TMP/state/b.db"

# a second one on the same database (its own socket)
conf c sock2 a.db
timeout 10 "$BIN/psensd" -f "$TMP/c.conf" -t 12:00 > /dev/null 2> "$TMP/c.err"
rc=$?
check "a second psensd on the same database exits 1 (got $rc)" test "$rc" = 1
diag "$(grep -i "database" "$TMP/c.err" | head -n 1)"
check "it names the database and the pid that writes it ($a)" \
	grep -q "state/a.db is in use by psensd pid $a .*one daemon per database" "$TMP/c.err"
check "its socket is gone with it" test ! -e "$TMP/sock2"
check "the first still answers" test "$(pid_of "$TMP/sock")" = "$a"
n0=$(sqlite3 "$TMP/state/a.db" "select count(*) from samples")
sleep 2.2
n1=$(sqlite3 "$TMP/state/a.db" "select count(*) from samples")
check "the first still logs ($n0 then $n1 samples)" test "$n1" -gt "$n0"
check "every sample of zone office is from one clock (times strictly rising)" \
	test "$(sqlite3 "$TMP/state/a.db" "select count(*) from samples a join samples b on b.rowid = a.rowid + 1 where b.t <= a.t")" = 0
kill -TERM $a; wait $a

# a raw peer listening on the socket path (not a psensd: no lock)
$PY -c '
import os, socket, sys, time
s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM); s.bind(sys.argv[1]); s.listen(8)
print(os.getpid(), flush=True); time.sleep(30)' "$TMP/raw" > "$TMP/raw.pid" &
track_pid $!
wait_for 5 test -s "$TMP/raw.pid"
conf d raw d.db
timeout 10 "$BIN/psensd" -f "$TMP/d.conf" -t 12:00 > /dev/null 2> "$TMP/d.err"
rc=$?
check "psensd on a socket a raw peer serves exits 1 (got $rc)" test "$rc" = 1
check "it names the peer's pid ($(cat "$TMP/raw.pid"))" grep -q "raw is in use: pid $(cat "$TMP/raw.pid") serves it" "$TMP/d.err"
check "the peer's socket is still there" test -S "$TMP/raw"

# a dead socket (its process killed): replaced
$PY -c '
import socket, sys
s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM); s.bind(sys.argv[1]); s.listen(1)' "$TMP/dead"
conf e dead e.db
"$BIN/psensd" -f "$TMP/e.conf" -t 12:00 > /dev/null 2> "$TMP/e.err" &
e=$!; track_pid $e
check "a socket nobody serves is replaced: psensd $e answers on it" \
	wait_for 10 sh -c "test \"\$(\"$BIN/psensctl\" -s \"$TMP/dead\" -j ping | sed -n 's/.*\"pid\":\([0-9]*\).*/\1/p')\" = $e"
kill -9 $e; wait $e 2>/dev/null
# killed: the lock dies with the process, the socket file stays
"$BIN/psensd" -f "$TMP/e.conf" -t 12:00 > /dev/null 2> "$TMP/e2.err" &
e=$!; track_pid $e
check "after a SIGKILL the next psensd starts on the same socket and database" \
	wait_for 10 sh -c "\"$BIN/psensctl\" -s \"$TMP/dead\" ping > /dev/null"
kill -TERM $e; wait $e
done_testing
