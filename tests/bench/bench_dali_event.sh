#!/bin/sh
# SPDX-License-Identifier: ISC
# Sensor event to gear command on a DALI-2 bus, measured: psvirt's virtual
# bus (Foxtron DALInet on TCP) with the room's multisensor, its morning at
# 600x so the 304 light sensor reports a change every few seconds; psensd
# in real time with a 10 min zone period, so only the events step the zone.
# psvirt (PSVIRT_DEBUG) stamps every frame with the monotonic time it met the bus; for
# each light event carrying a new value: is the next frame on the bus the
# gear's DAPC (nothing in between), and how long after the event it came.
# The bus time of the whole exchange is the event's 24-bit frame, the
# settling time before a new forward frame, the 16-bit DAPC, and this
# reaction time.  The first reading is left out: it comes while psensd
# still configures the instances, and one of those frames may come first.
BUILD=${BUILD:-build}
BIN=${BIN:-$BUILD/bin}
if [ ! -x "$BIN/psvirt" ] || ! "$BIN/psensd" -L 2>/dev/null | grep -q "^dali_usb:"; then
	echo "bench_dali_event: skipped (psvirt or the dali_usb driver not built)"
	exit 0
fi
tmp=$(mktemp -d /tmp/psbench.XXXXXX)
pv=
trap '[ -n "$pv" ] && kill "$pv" 2>/dev/null; rm -rf "$tmp"' EXIT
cp -R config/example/ofb config/example/ofb.scene "$tmp/"
"$BIN/psscene" -q -o "$tmp/ofb.results" "$tmp/ofb.scene" > /dev/null 2>&1 || { echo "bench_dali_event: psscene failed"; exit 1; }
PSVIRT_DEBUG=1 "$BIN/psvirt" --results "$tmp/ofb.results" --dali-tcp 127.0.0.1:0 --ready-file "$tmp/ready" \
	--date 03-18 --sunrise 06:00 --sunset 18:30 --start 06:10 --speed 600 \
	-D gain=0.5 -D noise=0 -D seed=7 -D lag_tau=0 > /dev/null 2> "$tmp/pv.err" &
pv=$!
n=0
while [ ! -s "$tmp/ready" ] && [ $n -lt 250 ]; do sleep 0.02; n=$((n + 1)); done
port=$(sed -n 's/^dali-tcp //p' "$tmp/ready")
cat > "$tmp/ev.conf" <<EOC
[psensd]
results = ofb.results
database = ev.db
socket = sock
period = 600
[device dali]
driver = dali_usb
simulated = psvirt
transport = foxtron
device = 127.0.0.1:$port
timeout = 0.5
[point light]
device = dali
role = sensor
device_address = 0
report_time = 30
valid_max = 1023
sensor_saturation = 1023
[point ballasts]
device = dali
role = dim
address = broadcast
[zone office]
sensor = light
dim = ballasts
algorithm = setpoint
target_lux = 500
min_level = 0.1
sensor_gain = 51.15
EOC
timeout 10 "$BIN/psensd" -f "$tmp/ev.conf" -t 06:10 > /dev/null 2>&1
kill "$pv" 2>/dev/null; wait "$pv" 2>/dev/null; pv=
awk '
function hex(s,   i, v) { v = 0; for (i = 1; i <= length(s); i++) v = v * 16 + index("0123456789ABCDEF", substr(s, i, 1)) - 1; return v }
/DALI [0-9.]+ event 24-bit/ {
	f = hex($6)
	# device/instance scheme: bit 23 = 0, bit 15 = 1, instance number 1 (the 304)
	if (int(f / 8388608) % 2 == 0 && int(f / 32768) % 2 == 1 && int(f / 1024) % 32 == 1) {
		v = f % 1024
		# the first reading comes while psensd still configures the instances
		if (v != last && seen++) { pending = 1; te = $3 + 0; ev = $6 }
		last = v
	}
	next
}
/DALI [0-9.]+ forward / {
	if (!pending) next
	pending = 0
	a = hex(substr($6, 1, 2))
	if ($5 == "16-bit" && a % 2 == 0) { ok++; d[ok] = ($3 - te) * 1000 } else { other++; print "  event " ev " then " $5 " " $6 }
}
END {
	if (ok == 0) { print "no light event was followed by a DAPC: " other + 0 " by another frame"; exit 1 }
	for (i = 1; i <= ok; i++) for (j = i + 1; j <= ok; j++) if (d[j] < d[i]) { t = d[i]; d[i] = d[j]; d[j] = t }
	printf "sensor event to gear command: %d of %d light events with a new value (after the first) had the DAPC as the next frame on the bus (%d another frame first)\n", ok, ok + other, other + 0
	printf "  reaction (event on the bus to DAPC on the bus, psensd through psvirt on TCP): median %.2f ms, max %.2f ms\n", d[int((ok + 1) / 2)], d[ok]
	printf "  bus time (bench_dali_bus frame times): 24-bit event 22.5 ms + settling 17.5 ms + 16-bit DAPC 15.8 ms + the reaction = %.1f ms (with the max reaction)\n", 22.5 + 17.5 + 15.8 + d[ok]
	exit other > 0
}' "$tmp/pv.err"
