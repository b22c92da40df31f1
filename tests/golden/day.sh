#!/bin/sh
# SPDX-License-Identifier: ISC
# The example day as the golden file records it: config/psensd.conf run on
# a simulated clock (psensd -s) in DIR, its samples exported with psensctl.
#   sh tests/golden/day.sh DIR    writes DIR/day.csv and DIR/day.summary
# (the summary without its timing line, which depends on the machine).
# tests/system/200 runs the same steps; make golden runs this.
set -eu
dir=$1
BUILD=${BUILD:-build}
BIN=${BIN:-$BUILD/bin}
top=$(pwd)
mkdir -p "$dir/example" "$dir/state"
cp -R config/example/ofb config/example/ofb.scene "$dir/example/"
sed "s|^results = .*|results = state/ofb.results|; s|^database = .*|database = state/psensd.db|" \
	config/psensd.conf > "$dir/psensd.conf"
(cd "$dir" && PATH="$top/$BIN:$PATH" "$top/$BIN/psensd" -f psensd.conf -s > day.out 2> day.err)
"$BIN/psensctl" -d "$dir/state/psensd.db" export --csv > "$dir/day.csv"
grep -v "reading to command" "$dir/day.out" > "$dir/day.summary"
