#!/bin/sh
# SPDX-License-Identifier: ISC
# psensd in real time on the loopback room (period 1 s, 0.1 s and 0.01 s;
# one zone, the SQLite log committing every sample): CPU time per wall
# second, peak memory (VmHWM), the latency from a reading to the command it
# causes (psensd measures it around the control law and the writes), and the
# worst lateness of a step against its schedule, and the estimate's rms
# error against the room's truth with the commanded level or the ballast's
# read-back output in the estimate (the example ballast fades at 20 %/s).  Then the same at 100 Hz
# with ten clients polling status as fast as they can.
BUILD=${BUILD:-build}
BIN=${BIN:-$BUILD/bin}
SECS=${BENCH_SECS:-5}
tmp=$(mktemp -d /tmp/psbench.XXXXXX)
pids=
trap 'for p in $pids; do kill $p 2>/dev/null; done; rm -rf "$tmp"' EXIT
mkdir -p "$tmp/example"
cp -R config/example/ofb config/example/ofb.scene "$tmp/example/"
"$BIN/psscene" -q -N -o "$tmp/r" "$tmp/example/ofb.scene" || { echo "bench_psensd: psscene failed"; exit 1; }
hz=$(getconf CLK_TCK)
printf '%-8s %-8s %-9s %8s %9s %12s %11s %12s %8s %9s\n' period clients output "cpu %" "VmHWM kB" "lat mean us" "lat max us" "late max ms" samples "est rms %"
one() {  # one PERIOD CLIENTS
	sed "s|^results = .*|results = $tmp/r|; s|^database = .*|database = $tmp/db|; s|^scene = .*|socket = $tmp/sock|; s|^period = .*|period = $1|; /^faults = /d" \
		config/psensd.conf > "$tmp/c.conf"
	[ "$3" = readback ] && echo "readback = yes" >> "$tmp/c.conf"
	rm -f "$tmp/db" "$tmp/db-wal" "$tmp/db-shm"
	"$BIN/psensd" -f "$tmp/c.conf" -t 12:00 > "$tmp/out" 2> "$tmp/err" &
	pd=$!; pids="$pids $pd"
	n=0; while [ ! -S "$tmp/sock" ] && [ $n -lt 250 ]; do sleep 0.02; n=$((n + 1)); done
	cl=""
	i=0; while [ $i -lt "$2" ]; do
		( while :; do "$BIN/psensctl" -s "$tmp/sock" -j status > /dev/null 2>&1; done ) &
		cl="$cl $!"; pids="$pids $!"; i=$((i + 1))
	done
	t0=$(awk '{print $14 + $15}' /proc/$pd/stat)
	sleep "$SECS"
	t1=$(awk '{print $14 + $15}' /proc/$pd/stat)
	hwm=$(awk '/^VmHWM/ {print $2}' /proc/$pd/status)
	st=$("$BIN/psensctl" -s "$tmp/sock" -j status)
	for c in $cl; do kill $c 2>/dev/null; done
	kill -TERM $pd; wait $pd 2>/dev/null
	rms=$(sed -n 's/.*rms \([0-9.]*\) %.*/\1/p' "$tmp/out")
	echo "$st" | /usr/bin/python3 -c "
import json, sys
d = json.load(sys.stdin)
cpu = 100.0 * ($t1 - $t0) / $hz / $SECS
print('%-8s %-8s %-9s %8.2f %9s %12.1f %11.1f %12.2f %8d %9s' % ('$1', '$2', '${3:-command}', cpu, '$hwm',
      1e6 * (d['latency_mean_s'] or 0), 1e6 * (d['latency_max_s'] or 0), 1e3 * d['late_max_s'], d['logged'], '$rms'))"
}
one 1 0
one 0.1 0
one 0.01 0
one 1 0 readback
one 0.01 0 readback
one 0.01 10
