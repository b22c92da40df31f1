#!/bin/sh
# SPDX-License-Identifier: ISC
# Modbus TCP on loopback against psvirt: the driver's round trip (median, 99th
# percentile) and the highest poll rate it sustains without missing its
# deadline, beside mbpoll doing the same reads (its own floor is a 10 ms poll
# interval, so it gets its fastest continuous rate and its one-shot time).
BUILD=${BUILD:-build}
BIN=${BIN:-$BUILD/bin}
MBDRIVE=$BUILD/tests/mbdrive
if [ ! -x "$BIN/psvirt" ] || [ ! -x "$MBDRIVE" ]; then
	echo "bench_modbus: skipped (the modbus driver is not compiled in)"
	exit 0
fi
tmp=$(mktemp -d /tmp/psbench.XXXXXX)
pv=
trap '[ -n "$pv" ] && kill "$pv" 2>/dev/null; rm -rf "$tmp"' EXIT
cp -R config/example/ofb config/example/ofb.scene "$tmp/"
"$BIN/psscene" -q -o "$tmp/r" "$tmp/ofb.scene" > /dev/null 2>&1 || { echo "bench_modbus: psscene failed"; exit 1; }
port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')
"$BIN/psvirt" --results "$tmp/r" --tcp "127.0.0.1:$port" --ready-file "$tmp/ready" > /dev/null 2>&1 &
pv=$!
n=0
while [ ! -s "$tmp/ready" ] && [ $n -lt 250 ]; do sleep 0.02; n=$((n + 1)); done
printf '[device io]\ndriver = modbus\nhost = 127.0.0.1\nport = %s\n[point sensor]\ndevice = io\nrole = sensor\ntable = input_register\naddress = 0\n' \
	"$port" > "$tmp/io.conf"
echo "Modbus TCP on 127.0.0.1, psvirt serving, one input register (FC04) per read"
"$MBDRIVE" "$tmp/io.conf" bench 5000 sensor
if command -v mbpoll > /dev/null; then
	timeout 3 mbpoll -m tcp -p "$port" -a 1 -0 -q -l 11 -r 0 -t 3 127.0.0.1 > "$tmp/mbpoll.out" 2>&1
	polls=$(grep -c '^\[0\]:' "$tmp/mbpoll.out")
	echo "mbpoll -l 11 (its fastest interval, > 10 ms) for 3 s: $polls reads, $(awk -v p="$polls" 'BEGIN { printf "%.0f", p / 3 }') /s"
	s=$(date +%s.%N)
	i=0
	while [ $i -lt 50 ]; do mbpoll -m tcp -p "$port" -a 1 -0 -1 -q -r 0 -t 3 127.0.0.1 > /dev/null 2>&1; i=$((i + 1)); done
	e=$(date +%s.%N)
	echo "mbpoll -1 (a process per read, connect included): $(awk -v a="$s" -v b="$e" 'BEGIN { printf "%.0f", (b - a) / 50 * 1e6 }') us per read (mean of 50)"
else
	echo "mbpoll missing: no comparison"
fi
