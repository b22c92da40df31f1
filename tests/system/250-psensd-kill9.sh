#!/bin/sh
# SPDX-License-Identifier: ISC
# Durability: psensd killed with SIGKILL at random points of a day (real
# time at 3600x, a step every 1/60 s of wall time), 50 times.  Before each
# kill the test asks psensd how many samples it has acknowledged (status
# "logged", counted from committed transactions); afterwards every one of
# them must be in the database, SQLite's integrity check must pass, and the
# next start must append.  PSENSD_KILLS sets the count (default 50).
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
command -v sqlite3 > /dev/null || skip_all "sqlite3 not installed"
KILLS=${PSENSD_KILLS:-50}
example_results
S="$TMP/sock"
sed "s|^results = .*|results = state/ofb.results|; s|^database = .*|database = state/psensd.db\nsocket = sock|" \
	config/psensd.conf > "$TMP/psensd.conf"
db="$TMP/state/psensd.db"
before=0; lost=0; bad=0; appended=0; i=0; hhmm=06:00
while [ $i -lt "$KILLS" ]; do
	"$BIN/psensd" -f "$TMP/psensd.conf" -t "$hhmm" -x 3600 > /dev/null 2>> "$TMP/err" &
	pid=$!
	wait_for 10 sh -c "\"$BIN/psensctl\" -s \"$S\" ping > /dev/null"
	# a random moment: 0 to 250 ms after readiness
	sleep "$(awk -v s=$i 'BEGIN { srand(s * 7919 + 17); printf "%.3f", rand() * 0.25 }')"
	n=$("$BIN/psensctl" -s "$S" -j status | sed -n 's/.*"logged":\([0-9]*\).*/\1/p')
	kill -9 $pid; wait $pid 2>/dev/null
	rows=$(sqlite3 "$db" 'select count(*) from samples')
	[ "$rows" -ge $((before + n)) ] || lost=$((lost + 1))
	[ "$rows" -gt "$before" ] && appended=$((appended + 1))
	[ "$(sqlite3 "$db" 'pragma integrity_check')" = ok ] || bad=$((bad + 1))
	before=$rows
	# the next run starts later in the day
	hhmm=$(awk -v i=$i 'BEGIN { m = 360 + (i * 13) % 780; printf "%02d:%02d", m / 60, m % 60 }')
	i=$((i + 1))
done
diag "$KILLS kills, $before samples in the log"
check "after each of $KILLS SIGKILLs every acknowledged sample was in the log ($lost lost)" test "$lost" = 0
check "SQLite's integrity check passed after every kill ($bad failed)" test "$bad" = 0
check "every restart appended to the log ($appended of $KILLS)" test "$appended" = "$KILLS"
check "no run left an error behind (stale socket replaced each time)" sh -c "! grep -q 'control socket .*:' '$TMP/err'"
done_testing
