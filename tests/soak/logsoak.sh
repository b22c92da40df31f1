#!/bin/sh
# SPDX-License-Identifier: ISC
# The sample log's soak (make soak, after soak.sh; not part of make check):
# psensd at 600x on the loopback room publishing to mosquitto for
# SOAK_LOG_SECONDS (600), its database on a 16 MB tmpfs (as root; else in
# /tmp, without the full-disk faults).  Every 30 s one fault in turn:
# another process holds the write lock for 10 s (python3's sqlite3); the
# tmpfs is filled for 15 s; psensd is killed with -9 and restarted.  At the
# end it counts samples logged (rows), published (ids the subscriber got,
# tests/system/peers/mqttcheck.py), dropped (counted by psensd) and lost
# (missing steps in the log's clock times that no count explains), and
# fails when any sample is lost uncounted, outside a kill -9.
BUILD=${BUILD:-build}
BIN=${BIN:-$BUILD/bin}
SECS=${SOAK_LOG_SECONDS:-600}
PY=/usr/bin/python3
MOSQ=$(command -v mosquitto || echo /usr/sbin/mosquitto)
[ -x "$MOSQ" ] || { echo "logsoak: mosquitto not installed"; exit 1; }
tmp=$(mktemp -d /tmp/pslog.XXXXXX)
pids=""
fs="$tmp/fs"
mkdir -p "$fs" "$tmp/example"
full=no
if [ "$(id -u)" = 0 ] && mount -t tmpfs -o size=16m tmpfs "$fs" 2>/dev/null; then full=yes; fi
cleanup() { for p in $pids $PID; do kill -9 "$p" 2>/dev/null; done; sleep 0.2; [ $full = no ] || umount "$fs"; rm -rf "$tmp"; }
trap cleanup EXIT INT TERM
cp -R config/example/ofb config/example/ofb.scene "$tmp/example/"
"$BIN/psscene" -q -N -o "$tmp/ofb.results" "$tmp/example/ofb.scene"
P=$($PY -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')
printf 'listener %s 127.0.0.1\nallow_anonymous true\npersistence false\nmax_queued_messages 0\nuser %s\n' "$P" "$(id -un)" > "$tmp/mq.conf"
"$MOSQ" -c "$tmp/mq.conf" > /dev/null 2>&1 & pids="$pids $!"
sleep 0.5
mosquitto_sub -p "$P" -q 1 -c -i logsoak -v -t 'psensd/+/+/state' > "$tmp/sub.log" 2>/dev/null & pids="$pids $!"
DB="$fs/psensd.db"
sed "s|^results = .*|results = $tmp/ofb.results|; s|^database = .*|database = $DB\nsocket = $tmp/sock|; /^faults = /d; s|^scene = .*|scene = $tmp/example/ofb.scene|" \
	config/psensd.conf > "$tmp/psensd.conf"
printf '\n[mqtt]\nhost = 127.0.0.1\nport = %s\nsite = soak\nrate = 500\n' "$P" >> "$tmp/psensd.conf"
start() {
	"$BIN/psensd" -f "$tmp/psensd.conf" -t 08:00 -x 600 >> "$tmp/out" 2>> "$tmp/err" &
	PID=$!
	i=0; until "$BIN/psensctl" -s "$tmp/sock" ping > /dev/null 2>&1 || [ $i -ge 100 ]; do i=$((i + 1)); sleep 0.1; done
}
start
end=$(($(date +%s) + SECS)); n=0; locks=0; fulls=0; kills=0
while [ "$(date +%s)" -lt "$end" ]; do
	sleep 30
	case $((n % 3)) in
	0)	$PY -c "
import sqlite3, sys, time
c = sqlite3.connect(sys.argv[1], isolation_level=None, timeout=30)
c.execute('BEGIN IMMEDIATE'); time.sleep(10); c.execute('COMMIT')" "$DB"
		locks=$((locks + 1));;
	1)	if [ $full = yes ]; then
			dd if=/dev/zero of="$fs/fill" bs=64k 2>/dev/null; sleep 15; rm -f "$fs/fill"; fulls=$((fulls + 1))
		fi;;
	2)	kill -9 "$PID"; wait "$PID" 2>/dev/null; kills=$((kills + 1)); start;;
	esac
	n=$((n + 1))
done
# let the log and the publisher catch up, then stop
sleep 10
kill -TERM "$PID"; wait "$PID"
rows=$(sqlite3 "$DB" "SELECT count(*) FROM samples")
dropped=$(sed -n 's/.*samples were held, \([0-9]*\) dropped.*/\1/p' "$tmp/err" | awk '{ s += $1 } END { print s + 0 }')
lostclose=$(sed -n 's/.*: \([0-9]*\) samples held in memory could not be written.*/\1/p' "$tmp/err" | awk '{ s += $1 } END { print s + 0 }')
# missing steps: gaps in the clock times of consecutive samples of a run
# (a kill -9 starts a run over at 08:00, not counted), less what was dropped
missing=$($PY -c "
import sqlite3, sys
t = [r[0] for r in sqlite3.connect(sys.argv[1]).execute('SELECT t FROM samples ORDER BY rowid')]
m = 0
for a, b in zip(t, t[1:]):
    if b > a and b - a > 90:
        m += round((b - a) / 60) - 1
print(m)
" "$DB")
$PY tests/system/peers/mqttcheck.py --no-pending "$tmp/sub.log" soak="$DB" > "$tmp/check.out"; mq=$?
published=$($PY -c "
import json, sys
ids = set()
for l in open(sys.argv[1]):
    try: ids.add(json.loads(l.split(' ', 1)[1])['id'])
    except Exception: pass
print(len(ids))" "$tmp/sub.log")
echo "logsoak: $SECS s at 600x: $locks locks of 10 s, $fulls full disks of 15 s$([ $full = yes ] || echo ' (not root: none)'), $kills kill -9"
echo "logsoak: samples logged $rows, published $published (distinct ids), dropped and counted $dropped, lost at a close $lostclose, missing steps $missing"
cat "$tmp/check.out" | sed 's/^/logsoak: mqttcheck: /'
if [ "$missing" -gt "$dropped" ] || [ $mq != 0 ]; then
	echo "logsoak: FAILED: steps missing beyond what was counted, or a logged sample never published"
	exit 1
fi
echo "logsoak: OK"
