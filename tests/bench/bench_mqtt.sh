#!/bin/sh
# SPDX-License-Identifier: ISC
# psensd's MQTT publisher against a real mosquitto on 127.0.0.1: the
# catch-up of a day of backlog from 100 zones at a 60 s period (144000
# samples written into the log before psensd starts, as after a broker
# outage), at a bounded rate and unbounded (the publish throughput: QoS 1,
# every message acknowledged), while psensd controls its own zone every
# 0.1 s; the worst lateness of a control step during the catch-up (psensd's
# late_max_s), beside the same run with nothing to catch up, and the longest
# turn the publisher took from the loop (mqtt.turn_max_s, wall; and the most
# CPU time one turn used, turn_cpu_max_s): what MQTT can add to a step's
# lateness, the difference being time spent waiting for a CPU.
BUILD=${BUILD:-build}
BIN=${BIN:-$BUILD/bin}
MOSQ=$(command -v mosquitto || echo /usr/sbin/mosquitto)
if [ ! -x "$MOSQ" ] || ! command -v mosquitto_sub > /dev/null || ! command -v sqlite3 > /dev/null; then
	echo "bench_mqtt: mosquitto, mosquitto-clients or sqlite3 missing: skipped"; exit 0
fi
"$BIN/psensd" -h 2>&1 | grep -q . || exit 1
tmp=$(mktemp -d /tmp/psbench.XXXXXX)
pids=
trap 'for p in $pids; do kill $p 2>/dev/null; done; rm -rf "$tmp"' EXIT
mkdir -p "$tmp/example"
cp -R config/example/ofb config/example/ofb.scene "$tmp/example/"
"$BIN/psscene" -q -N -o "$tmp/r" "$tmp/example/ofb.scene" || { echo "bench_mqtt: psscene failed"; exit 1; }
P=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')
printf 'listener %s 127.0.0.1\nallow_anonymous true\nmax_queued_messages 0\nuser %s\n' "$P" "$(id -un)" > "$tmp/mq.conf"
"$MOSQ" -c "$tmp/mq.conf" 2> /dev/null & pids="$pids $!"
n=0; until mosquitto_pub -p "$P" -t probe -n 2> /dev/null || [ $n -gt 100 ]; do sleep 0.05; n=$((n + 1)); done
ZONES=100 DAY=1440
N=$((ZONES * DAY))
conf() {   # conf RATE [mqtt]
	sed "s|^results = .*|results = $tmp/r|; s|^database = .*|database = $tmp/db|; s|^scene = .*|socket = $tmp/sock|; s|^period = .*|period = 0.1|; /^faults = /d" \
		config/psensd.conf > "$tmp/c.conf"
	[ -n "$2" ] && printf '\n[mqtt]\nhost = 127.0.0.1\nport = %s\nsite = bench\nrate = %s\ndiscovery = no\n' "$P" "$1" >> "$tmp/c.conf"
}
now_ms() { echo $(( $(date +%s%N) / 1000000 )); }
# an empty log of psensd's schema, then the backlog: ZONES zones, DAY samples each
backlog() {
	rm -f "$tmp/db" "$tmp/db-wal" "$tmp/db-shm" "$tmp/sock"
	conf 0
	"$BIN/psensd" -f "$tmp/c.conf" -t 12:00 > /dev/null 2>&1 & pd=$!
	n=0; while [ ! -S "$tmp/sock" ] && [ $n -lt 250 ]; do sleep 0.02; n=$((n + 1)); done
	kill $pd; wait $pd 2> /dev/null
	sqlite3 "$tmp/db" "DELETE FROM samples; WITH RECURSIVE n(i) AS (SELECT 0 UNION ALL SELECT i + 1 FROM n WHERE i < $1 - 1)
		INSERT INTO samples(t, tod_s, sensor_v, output, est_task_lux, task_lux, daylight_v, daylight_lux, condition,
		ratio, fault, zone, utc) SELECT (i / $ZONES) * 60.0, (i / $ZONES) * 60.0, 1.5, 0.5, 500, NULL, 1.0, 300,
		'daylight_mean', 236.1, NULL, 'z' || (i % $ZONES), 1.7e9 + (i / $ZONES) * 60 FROM n;"
}
printf '%-10s %9s %10s %10s %12s %8s %12s %10s\n' "rate /s" backlog "catch-up s" "msg/s" "late max ms" "turn ms" "turn cpu ms" "cursor"
one() {   # one RATE BACKLOG
	backlog "$2"
	conf "$1" mqtt
	rm -f "$tmp/sock"
	if [ "$2" -gt 0 ]; then
		mosquitto_sub -p "$P" -q 1 -t "psensd/bench/z$((ZONES - 1))/state" -C $(($2 / ZONES)) > /dev/null & sub=$!; pids="$pids $sub"
		sleep 0.3
	fi
	t0=$(now_ms)
	"$BIN/psensd" -f "$tmp/c.conf" -t 12:00 > /dev/null 2> "$tmp/err" & pd=$!; pids="$pids $pd"
	if [ "$2" -gt 0 ]; then wait $sub; else sleep "${BENCH_SECS:-15}"; fi
	t1=$(now_ms)
	"$BIN/psensctl" -s "$tmp/sock" -j status > "$tmp/st"
	late=$(/usr/bin/python3 -c 'import json,sys; print("%.2f" % (1000 * json.load(open(sys.argv[1]))["late_max_s"]))' "$tmp/st")
	turn=$(/usr/bin/python3 -c 'import json,sys; print("%.2f" % (1000 * json.load(open(sys.argv[1]))["mqtt"]["turn_max_s"]))' "$tmp/st")
	tcpu=$(/usr/bin/python3 -c 'import json,sys; print("%.2f" % (1000 * json.load(open(sys.argv[1]))["mqtt"]["turn_cpu_max_s"]))' "$tmp/st")
	kill $pd; wait $pd 2> /dev/null
	cur=$(sqlite3 "$tmp/db" "SELECT sample FROM mqtt_cursor")
	s=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.2f", (b - a) / 1000 }')
	r=$(awk -v n="$2" -v a="$t0" -v b="$t1" 'BEGIN { printf "%.0f", n / ((b - a) / 1000) }')
	[ "$2" -gt 0 ] || { s=-; r=-; }
	printf '%-10s %9s %10s %10s %12s %8s %12s %10s\n' "$1" "$2" "$s" "$r" "$late" "$turn" "$tcpu" "$cur"
}
one 200 0

one 2000 $N
one 10000 $N
one 100000 $N
