#!/bin/sh
# SPDX-License-Identifier: ISC
# The soak (make soak, not part of make check): psensd in real time at 600x
# for SOAK_SECONDS (600: ten minutes, about four days of room time) with
#  - a loopback zone with its room's faults (open, drop, stuck windows),
#  - two zones on a slow Modbus module (psvirt answering every request
#    300 ms late, timeout 1 s),
#  - two zones on a Modbus module with faults in its rooms that is killed
#    and restarted every 60 s (a lost device, then back),
#  - 50 control-socket clients at once, asking, sending bad lines and
#    reconnecting all the time (tests/soak/ctlcrowd.py),
#  - a reload every 3 s, alternately SIGHUP and `psensctl reload`; every
#    other psensctl reload is of a broken file (refused, the running one
#    kept).
# psensd's descriptors (/proc/PID/fd) and resident memory (VmRSS) are
# sampled every 30 s; start is after a 20 s warm-up, end after the crowd
# has gone.  It fails when the end has more descriptors than the start or
# more than 4 MB more resident memory.
BUILD=${BUILD:-build}
BIN=${BIN:-$BUILD/bin}
SECS=${SOAK_SECONDS:-600}
PY=/usr/bin/python3
[ -x "$BIN/psvirt" ] || { echo "soak: psvirt not built (no Modbus)"; exit 1; }
tmp=$(mktemp -d /tmp/pssoak.XXXXXX)
pids=""
cleanup() { for p in $pids; do kill "$p" 2>/dev/null; done; sleep 0.2; rm -rf "$tmp"; }
trap cleanup EXIT INT TERM
cp -R config/example/ofb config/example/ofb.scene "$tmp/"
"$BIN/psscene" -q -o "$tmp/r" "$tmp/ofb.scene" > /dev/null 2>&1 || { echo "soak: psscene failed"; exit 1; }
port() { $PY -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }
pa=$(port); pb=$(port)
virt() {  # virt NAME PORT ARGS...: a psvirt module at 600x from 06:00
	name=$1; p=$2; shift 2
	rm -f "$tmp/$name.ready"
	"$BIN/psvirt" --results "$tmp/r" --tcp "127.0.0.1:$p" --ready-file "$tmp/$name.ready" --zones 2 \
		--date 03-18 --sunrise 06:00 --sunset 18:30 --start 06:00 --speed 600 \
		-o gain=0.5 -o noise=0.002 -o min_level=0.1 "$@" >> "$tmp/$name.out" 2>&1 &
	echo $!
}
va=$(virt slow "$pa" --fault late --late-ms 300); pids="$pids $va"
vb=$(virt faulty "$pb" -o "faults=open 08:00-08:30, drop 10:00-10:20, stuck 13:00-13:30"); pids="$pids $vb"
conf() {  # conf TARGET
	printf '[psensd]\nresults = r\ndatabase = soak.db\nsocket = sock\nmax_clients = 128\nperiod = 60\nstale_after = 300\nstuck_after = 900\n'
	printf '[device room]\ndriver = loopback\ngain = 0.5\nnoise = 0.002\nfaults = open 12:00-12:20, drop 15:00-15:10, stuck 17:00-17:40\n'
	printf '[point sensor]\ndevice = room\nrole = sensor\n[point lamp]\ndevice = room\nrole = dim\n'
	printf '[zone office]\nsensor = sensor\ndim = lamp\nsensor_gain = 0.5\nmin_level = 0.1\ntarget_lux = %s\n' "$1"
	for m in a b; do
		[ $m = a ] && p=$pa || p=$pb
		printf '[device %s]\ndriver = modbus\nhost = 127.0.0.1\nport = %s\ntimeout = 1\nretries = 0\nbackoff_min = 0.5\nbackoff_max = 4\n' $m "$p"
		for k in 0 1; do
			printf '[point %s%d.s]\ndevice = %s\nrole = sensor\ntable = input_register\naddress = %d\n' $m $k $m $k
			printf '[point %s%d.d]\ndevice = %s\nrole = dim\ntable = holding_register\naddress = %d\nraw_max = 4095\n' $m $k $m $((10 + k))
			printf '[zone %s%d]\nsensor = %s%d.s\ndim = %s%d.d\nsensor_gain = 0.5\nmin_level = 0.1\ntarget_lux = %s\n' $m $k $m $k $m $k "$1"
		done
	done
}
conf 500 > "$tmp/psensd.conf"
n=0; while { [ ! -s "$tmp/slow.ready" ] || [ ! -s "$tmp/faulty.ready" ]; } && [ $n -lt 500 ]; do sleep 0.02; n=$((n + 1)); done
"$BIN/psensd" -f "$tmp/psensd.conf" -t 06:00 -x 600 > /dev/null 2> "$tmp/psensd.err" &
pd=$!; pids="$pids $pd"
n=0; while ! "$BIN/psensctl" -s "$tmp/sock" ping > /dev/null 2>&1 && [ $n -lt 250 ]; do sleep 0.04; n=$((n + 1)); done
fds() { ls "/proc/$pd/fd" 2>/dev/null | wc -l; }
rss() { awk '/^VmRSS/ { print $2 }' "/proc/$pd/status" 2>/dev/null; }
# warm-up: one reload of each kind, then the baseline (no client connected)
"$BIN/psensctl" -s "$tmp/sock" reload > /dev/null 2>&1; kill -HUP $pd; sleep 20
fd0=$(fds); rss0=$(rss)
echo "soak: psensd $pd at 600x for $SECS s: 5 zones (1 loopback, 2 on a slow module, 2 on a module restarted every 60 s)"
printf '%8s %6s %9s\n' "t (s)" fds "RSS (kB)"
printf '%8d %6d %9d\n' 0 "$fd0" "$rss0"
$PY tests/soak/ctlcrowd.py "$tmp/sock" "$SECS" 50 > "$tmp/crowd.out" 2>&1 &
crowd=$!; pids="$pids $crowd"
t0=$(date +%s); i=0; reloads=0; refused=0; restarts=0; last_sample=0; last_restart=0
while :; do
	t=$(( $(date +%s) - t0 )); [ "$t" -ge "$SECS" ] && break
	i=$((i + 1))
	if [ $((i % 4)) = 0 ]; then
		conf 450 > "$tmp/psensd.conf"; printf '[zone broken]\nsensor = nosuch\n' >> "$tmp/psensd.conf"
	else
		conf $((450 + 50 * (i % 2))) > "$tmp/psensd.conf"
	fi
	if [ $((i % 2)) = 0 ]; then
		"$BIN/psensctl" -s "$tmp/sock" reload > /dev/null 2>&1 || refused=$((refused + 1))
	else
		kill -HUP $pd
	fi
	reloads=$((reloads + 1))
	if [ $((t - last_restart)) -ge 60 ]; then
		kill "$vb"; wait "$vb" 2>/dev/null; sleep 1
		vb=$(virt faulty "$pb" -o "faults=open 08:00-08:30, drop 10:00-10:20, stuck 13:00-13:30"); pids="$pids $vb"
		restarts=$((restarts + 1)); last_restart=$t
	fi
	if [ $((t - last_sample)) -ge 30 ]; then
		printf '%8d %6d %9d\n' "$t" "$(fds)" "$(rss)"; last_sample=$t
	fi
	kill -0 $pd 2>/dev/null || { echo "soak: psensd died"; tail -n 20 "$tmp/psensd.err"; exit 1; }
	sleep 3
done
wait $crowd
conf 500 > "$tmp/psensd.conf"; kill -HUP $pd; sleep 2
fd1=$(fds); rss1=$(rss)
printf '%8s %6d %9d   (the crowd gone)\n' end "$fd1" "$rss1"
set -- $(cat "$tmp/crowd.out")
echo "clients: $1 replies ($2 error replies to the bad lines), $3 reconnects, $4 refused or lost"
echo "reloads: $reloads ($refused refused through psensctl, as a broken file must be; $(grep -c 'the running configuration stays' "$tmp/psensd.err") refusals logged); module restarts: $restarts"
echo "faults logged: $(grep -c 'fault: ' "$tmp/psensd.err"), cleared: $(grep -c 'fault cleared' "$tmp/psensd.err")"
echo "descriptors: start $fd0, end $fd1; resident memory: start $rss0 kB, end $rss1 kB ($((rss1 - rss0)) kB)"
kill -TERM $pd; wait $pd; rc=$?
echo "psensd exit status after SIGTERM: $rc"
ok=1
[ "$fd1" -le "$fd0" ] || { echo "soak: FAILED: descriptors grew"; ok=0; }
[ $((rss1 - rss0)) -le 4096 ] || { echo "soak: FAILED: resident memory grew by more than 4 MB"; ok=0; }
[ "$rc" = 0 ] || { echo "soak: FAILED: psensd exit status $rc"; ok=0; }
[ $ok = 1 ] && echo "soak: passed"
[ $ok = 1 ]
