#!/bin/sh
# SPDX-License-Identifier: ISC
# The control socket never waits on a device: 10 zones on 3 Modbus modules
# (psvirt) that answer every request 300, 400 and 500 ms late, psensd at 10x
# real time.  A client asks `status` on a new connection every 20 ms for 15 s
# (tests/system/peers/ctllat.py) and the latencies are reported.  Asserted
# here only what does not depend on the machine's load: no request reaches
# psensctl's 5 s limit, the median is under 1 s, and the control still runs
# (every zone stepped, none in fault, every light moved off full output);
# the watchdog (100 ms, fed every 50 ms) has no gap of a second.
# The 50 ms goal for the 99th percentile is measured by `make bench`
# (tests/bench/ctl-latency.sh).
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/peers/common.sh"
[ -x "$BIN/psvirt" ] || skip_all "psvirt not built"
PY=/usr/bin/python3
make_results
SECS=${CTLLAT_SECONDS:-15}
conf="$TMP/site.conf"
printf '[psensd]\nresults = %s\ndatabase = %s\nsocket = %s\nperiod = 40\nstale_after = 400\nsafe_level = 1\n' \
	"$TMP/ofb.results" "$TMP/site.db" "$TMP/sock" > "$conf"
z=0
for m in 0 1 2; do
	case $m in 0) n=4; late=300 ;; 1) n=3; late=400 ;; 2) n=3; late=500 ;; esac
	port=$(free_port)
	"$BIN/psvirt" --results "$TMP/ofb.results" --tcp "127.0.0.1:$port" --ready-file "$TMP/ready$m" \
		--zones $n --date 03-18 --sunrise 06:00 --sunset 18:30 --start 12:00 --speed 10 \
		-o gain=0.5 -o noise=0.002 -o seed=$((m + 3)) -o fade_rate=0 -o lag_tau=0 -o min_level=0.1 \
		--fault late --late-ms $late > /dev/null 2>> "$TMP/psvirt.err" &
	track_pid $!
	wait_for 10 test -s "$TMP/ready$m"
	printf '[device io%d]\ndriver = modbus\nhost = 127.0.0.1\nport = %d\ntimeout = 1\nretries = 0\nbackoff_min = 0.5\nbackoff_max = 2\n' \
		$m "$port" >> "$conf"
	k=0
	while [ $k -lt $n ]; do
		printf '[point s%d]\ndevice = io%d\nrole = sensor\ntable = input_register\naddress = %d\n' $z $m $k
		printf '[point d%d]\ndevice = io%d\nrole = dim\ntable = holding_register\naddress = %d\nraw_max = 4095\n' \
			$z $m $((10 + k))
		printf '[zone z%d]\nsensor = s%d\ndim = d%d\ntarget_lux = 500\nsensor_gain = 0.5\nmin_level = 0.1\n' $z $z $z
		k=$((k + 1)); z=$((z + 1))
	done >> "$conf"
done
check "three slow modules ready" test -s "$TMP/ready0" -a -s "$TMP/ready1" -a -s "$TMP/ready2"
check "psensd -n accepts 10 zones on 3 modules" sh -c "\"$BIN/psensd\" -f '$conf' -n > /dev/null"
# under a watchdog of 100 ms (psensd notifies every 50 ms), timed by a
# stand-in for systemd's notification socket
$PY "$TOP/tests/system/peers/wdgap.py" "$TMP/notify" "$SECS" > "$TMP/wd.out" &
wd=$!; track_pid $wd
wait_for 5 test -S "$TMP/notify"
NOTIFY_SOCKET="$TMP/notify" WATCHDOG_USEC=100000 "$BIN/psensd" -f "$conf" -t 12:00 -x 10 > /dev/null 2> "$TMP/psensd.err" &
pd=$!; track_pid $pd
wait_for 10 sh -c "\"$BIN/psensctl\" -s \"$TMP/sock\" ping > /dev/null"
# a reload at once reopens the three modules: the first commands go to
# the new I/O threads, not through the loop (then the zones run again)
t0=$(date +%s%N)
"$BIN/psensctl" -s "$TMP/sock" reload > /dev/null 2> "$TMP/reload.err"
rc=$?
ms=$(( ($(date +%s%N) - t0) / 1000000 ))
diag "psensctl reload with the modules 300-500 ms late: $ms ms"
check "the reload answers ok within psensctl's 5 s (exit $rc, $ms ms)" test "$rc" = 0
set -- $($PY "$TOP/tests/system/peers/ctllat.py" "$TMP/sock" "$SECS" 0.02)
diag "status on a new connection every 20 ms for $SECS s: $1 requests, $2 answered, $3 at the 5 s limit;" \
	"median $4 ms, p90 $5 ms, p99 $6 ms, worst $7 ms"
check "no request reaches psensctl's 5 s limit ($3 of $1)" test "${3:-1}" = 0 -a "${2:-0}" -gt 0
check "the median latency is under 1 s ($4 ms)" awk -v m="${4:-nan}" 'BEGIN { exit !(m + 0 < 1000 && m == m + 0) }'
wait $wd
read wdn wdgap < "$TMP/wd.out"
diag "watchdog: $wdn notifications in $SECS s, the largest gap $wdgap ms (every 50 ms asked)"
# The largest gap is the reload's: it waits for the transaction under way
# (up to 500 ms here).  Under AddressSanitizer that wait and the reopening
# take about three times as long, so the 1 s bound is judged on a plain
# build only (make check runs one; CI runs both).
if grep -q __asan_init "$BIN/psensd" 2>/dev/null; then
	skip "the watchdog's 1 s bound under AddressSanitizer (largest gap $wdgap ms)"
else
	check "the watchdog is fed all along: no gap of 1 s ($wdgap ms)" \
		awk -v g="${wdgap:-nan}" -v n="${wdn:-0}" 'BEGIN { exit !(n > 10 && g + 0 < 1000 && g == g + 0) }'
fi
"$BIN/psensctl" -s "$TMP/sock" -j status > "$TMP/st.json"
check "control runs on every zone: stepped, in no fault, off full output; an I/O thread per module" $PY -c '
import json, sys
d = json.load(open(sys.argv[1]))
zs = d["zones"]
bad = [z["name"] for z in zs if z["steps"] < 2 or z["fault"] or not z["level"] < 1]
print("# zones:", " ".join("%s:%d steps, level %.2f%s" % (z["name"], z["steps"], z["level"], ", FAULT " + z["fault"] if z["fault"] else "") for z in zs))
print("# I/O threads, seconds in a transaction:", d["io_busy_s"])
sys.exit(len(zs) != 10 or bool(bad) or sorted(d["io_busy_s"]) != ["io0", "io1", "io2"])' "$TMP/st.json"
kill -TERM $pd; wait $pd
rc=$?
check "psensd stops cleanly (exit $rc)" test "$rc" = 0
done_testing
