#!/bin/sh
# SPDX-License-Identifier: ISC
# A full disk under the sample log: the database on a 4 MB tmpfs, psensd at
# 600x publishing to mosquitto.  The tmpfs is filled until a write fails:
# status says degraded with the cause "disk full", one LOG_ERR line says so;
# 5 s later the space is freed: the log is written again (one LOG_ERR line
# with the count held, none dropped), no sample is missing from the log,
# `logged` moves, and MQTT resumes by itself: its cursor passes every sample
# logged after the fault, with no "committing the log" error.  Then a new
# database on a full disk: the start is refused naming "disk full".
# Needs root (mount); skipped with the reason otherwise.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
[ "$(id -u)" = 0 ] || skip_all "needs root to mount a tmpfs"
command -v sqlite3 > /dev/null || skip_all "sqlite3 missing"
PY=/usr/bin/python3
mkdir -p "$TMP/fs"
mount -t tmpfs -o size=4m tmpfs "$TMP/fs" 2>/dev/null || skip_all "cannot mount a tmpfs here (a container without CAP_SYS_ADMIN?)"
_cleanup_fs() {
	for p in $_cleanup_pids; do kill -9 "$p" 2>/dev/null; done
	sleep 0.1
	umount "$TMP/fs" 2>/dev/null || umount -l "$TMP/fs"
	_cleanup
}
trap _cleanup_fs EXIT
MOSQ=$(command -v mosquitto || echo /usr/sbin/mosquitto)
MQ=no
if [ -x "$MOSQ" ] && ! "$BIN/psensd" -h | grep -q "^mqtt: .*not compiled in"; then MQ=yes; fi
example_results
S="$TMP/sock"
DB="$TMP/fs/psensd.db"
sed "s|^results = .*|results = $TMP/state/ofb.results|; s|^database = .*|database = $DB\nsocket = $S|; /^faults = /d; s|^scene = .*|scene = $TMP/example/ofb.scene|" \
	config/psensd.conf > "$TMP/psensd.conf"
if [ $MQ = yes ]; then
	P=$(free_port)
	printf 'listener %s 127.0.0.1\nallow_anonymous true\nuser %s\nlog_dest file %s/mosquitto.log\n' "$P" "$(id -un)" "$TMP" \
		> "$TMP/mosquitto.conf"
	"$MOSQ" -c "$TMP/mosquitto.conf" 2>> "$TMP/mosquitto.err" & track_pid $!
	wait_for 5 mosquitto_pub -p "$P" -t probe -n
	printf '\n[mqtt]\nhost = 127.0.0.1\nport = %s\nsite = full\nkeepalive = 5\nrate = 500\n' "$P" >> "$TMP/psensd.conf"
else
	diag "no mosquitto (or psensd without MQTT): the MQTT checks are skipped"
fi
ctl() { "$BIN/psensctl" -s "$S" "$@"; }
field() { ctl -j status | $PY -c "import json,sys; d=json.load(sys.stdin); print(eval(sys.argv[1]))" "$1"; }
"$BIN/psensd" -f "$TMP/psensd.conf" -t 08:00 -x 600 > "$TMP/out" 2> "$TMP/err" &
PID=$!; track_pid $PID
wait_for 20 ctl ping > /dev/null
wait_for 10 sh -c "[ \$(\"$BIN/psensctl\" -s \"$S\" -j status | grep -o '\"logged\":[0-9]*' | cut -d: -f2) -ge 20 ]"
# fill the tmpfs; SQLite needs new space within a few commits (the WAL grows)
dd if=/dev/zero of="$TMP/fs/fill" bs=64k 2>/dev/null
wait_for 30 sh -c "\"$BIN/psensctl\" -s \"$S\" -j status | grep -q '\"state\":\"degraded\"'"
cause=$(field "d['log']['cause']")
check "disk full: status degraded, the cause named ($cause)" sh -c "echo '$cause' | grep -q '^disk full'"
steps0=$(field "d['zones'][0]['steps']")
sleep 5
steps1=$(field "d['zones'][0]['steps']")
held=$(field "d['log']['held']")
check "disk full: the control steps on ($steps0 -> $steps1 in 5 s), $held samples held" test $((steps1 - steps0)) -ge 10
rm -f "$TMP/fs/fill"
wait_for 15 sh -c "\"$BIN/psensctl\" -s \"$S\" -j status | grep -q '\"state\":\"ok\"'"
check "space freed: the log is ok again" test "$(field "d['log']['state']")" = ok
logged1=$(field "d['logged']")
wait_for 5 sh -c "[ \$(\"$BIN/psensctl\" -s \"$S\" -j status | grep -o '\"logged\":[0-9]*' | cut -d: -f2) -gt $logged1 ]"
check "space freed: logged moves ($logged1 -> $(field "d['logged']"))" test "$(field "d['logged']")" -gt "$logged1"
check "nothing dropped" test "$(field "d['log']['dropped']")" = 0
if [ $MQ = yes ]; then
	last=$(sqlite3 "$DB" "SELECT max(rowid) FROM samples")
	cur() { field "d['mqtt']['cursor']"; }
	wait_for 20 sh -c "[ \$(\"$BIN/psensctl\" -s \"$S\" -j status | $PY -c 'import json,sys; print(json.load(sys.stdin)[\"mqtt\"][\"cursor\"])') -ge $last ]"
	check "MQTT resumed by itself: its cursor ($(cur)) passed the samples logged after the fault ($last)" test "$(cur)" -ge "$last"
	check "MQTT never lost its log (no 'committing the log' error)" sh -c "! grep -q 'mqtt: committing the log' '$TMP/err'"
else
	skip "MQTT resumed by itself: no mosquitto"
	skip "MQTT never lost its log: no mosquitto"
fi
kill -TERM $PID; wait $PID; rc=$?
check "SIGTERM: exit 0" test "$rc" = 0
check "one LOG_ERR line started the fault, naming the disk" test "$(grep -c 'the sample log cannot be written: disk full' "$TMP/err")" = 1
check "one LOG_ERR line ended it, nothing dropped" grep -q "the sample log is written again after .* samples were held, 0 dropped" "$TMP/err"
gap=$(sqlite3 "$DB" "SELECT max(b.t - a.t) FROM samples a JOIN samples b ON b.rowid = a.rowid + 1")
check "no sample lost: consecutive samples less than two periods apart (largest step $gap s)" \
	awk -v g="$gap" 'BEGIN { exit !(g > 0 && g < 120) }'
n=$(sqlite3 "$DB" "SELECT count(*) FROM samples")
check "every step is a row ($n rows; the summary: $(grep -o '[0-9]* samples logged' "$TMP/out"))" grep -q "; $n samples logged" "$TMP/out"

# a new database on a full disk: refused, the cause named, lights safe
dd if=/dev/zero of="$TMP/fs/fill" bs=64k 2>/dev/null
sed -i "s|^database = .*|database = $TMP/fs/new.db|" "$TMP/psensd.conf"
timeout 20 "$BIN/psensd" -f "$TMP/psensd.conf" -t 08:00 > "$TMP/out2" 2> "$TMP/err2"
rc=$?
check "a new log on a full disk: the start is refused (exit $rc)" test "$rc" = 1
check "... naming the cause: $(grep -o 'disk full.*' "$TMP/err2" | head -1 | cut -c1-60)" grep -q "new.db.*disk full" "$TMP/err2"
check "... after the lights were made safe" grep -q "the log cannot be opened: lights at the safe level" "$TMP/err2"
done_testing
