#!/bin/sh
# SPDX-License-Identifier: ISC
# A year of control (psensd -Y): the example office's results
# year (San Francisco's TMY3 year: config/example/ofb/weather/README.md), every zone,
# the set-point law and the four others, at control periods of 60 and 10 s:
# steps and wall time (goal: a year at 60 s in at most 5 s), and the
# precompute (psscene: the coefficient sets and the year).
BUILD=${BUILD:-build}
BIN=${BIN:-$BUILD/bin}
tmp=$(mktemp -d /tmp/psyear.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/example"
cp -R config/example/ofb config/example/ofb.scene "$tmp/example/"
"$BIN/psscene" -N -o "$tmp/r" "$tmp/example/ofb.scene" > "$tmp/ps" 2>&1 || { echo "bench_year: psscene failed"; exit 1; }
sed -n 's/^daylight coefficients: \(.*\); \([0-9.]*\) s$/precompute: coefficient rows (\1) \2 s/p; s/^  \([0-9]* steps.*\)$/precompute: year \1/p' "$tmp/ps"
printf '%-8s %10s %10s %12s %s\n' period steps "wall s" "ns a step" "(set-point; then all five laws)"
for p in 60 10; do
	sed "s|^results = .*|results = $tmp/r|; s|^database = .*|database = $tmp/db|; s|^scene = .*|scene = $tmp/example/ofb.scene|; s|^period = .*|period = $p|" \
		config/psensd.conf > "$tmp/c.conf"
	s=$(date +%s.%N)
	"$BIN/psensd" -f "$tmp/c.conf" -Y > "$tmp/out" 2>&1 || { cat "$tmp/out"; exit 1; }
	e=$(date +%s.%N)
	sed -n 's/^  \([0-9]*\) control steps in \([0-9.]*\) s (\([0-9]*\) ns a step).*/\1 \2 \3/p' "$tmp/out" |
		awk -v p="$p" -v w="$(echo "$e - $s" | bc)" '{ printf "%-8s %10d %10.2f %12d   whole run with the five laws: %.2f s\n", p, $1, $2, $3, w }'
done
