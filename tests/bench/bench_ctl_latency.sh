#!/bin/sh
# SPDX-License-Identifier: ISC
# The control socket's latency while the devices are slow: 10 zones on 3
# psvirt Modbus modules answering every request 300, 400 and 500 ms late
# (tests/system/247-psensd-slow-modules.sh, here for 30 s), `status` on a new
# connection every 20 ms.  The goal: the 99th percentile under 50 ms.
BUILD=${BUILD:-build}
BIN=${BIN:-$BUILD/bin}
if [ ! -x "$BIN/psvirt" ]; then
	echo "bench_ctl_latency: skipped (psvirt not built: no Modbus)"
	exit 0
fi
line=$(CTLLAT_SECONDS=${CTLLAT_SECONDS:-30} BUILD=$BUILD BIN=$BIN TOP=$(pwd) \
	sh tests/system/247-psensd-slow-modules.sh 2>/dev/null | grep '^# status on')
echo "control socket under 3 slow Modbus modules (10 zones): ${line#\# }"
p99=$(echo "$line" | sed -n 's/.*p99 \([0-9.]*\) ms.*/\1/p')
if awk -v p="${p99:-nan}" 'BEGIN { exit !(p + 0 < 50 && p == p + 0) }'; then
	echo "goal: 99th percentile under 50 ms: met ($p99 ms)"
else
	echo "goal: 99th percentile under 50 ms: MISSED (${p99:-no measurement} ms)"
	exit 1
fi
