#!/bin/sh
# SPDX-License-Identifier: ISC
# psens -r start:end:step checks its rotation scan against the exact route
# (psens -r R, a peer computed without the scan): the printed estimate is
# the scan's real difference from the exact route at the rotation it names,
# a tolerance below it gives a warning (even with -q) and exit 0, --tolerance
# 0 checks nothing, and a bad tolerance is bad usage.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psens" ] || skip_all "psens not built"
P=config/example/ofb/img/day_0318_sensor_256.hdr
cat >"$TMP/a.sen" <<'SEN'
Elevation field 90
degrees 0 45 90 135 180 225 270 315
0 1 1 1 1 1 1 1 1
20 0.95 0.9 0.7 0.6 0.8 0.9 0.85 0.9
40 0.8 0.6 0.4 0.3 0.5 0.7 0.7 0.75
60 0.5 0.3 0.2 0.1 0.2 0.4 0.45 0.5
80 0.1 0.05 0.02 0.01 0.03 0.08 0.1 0.1
90 0 0 0 0 0 0 0 0
SEN
"$BIN/psens" -q -N -r 0:360:1 -s "$TMP/a.sen" "$P" >"$TMP/scan" 2>"$TMP/err"
check "scan: exit 0" test $? = 0
check "the scan prints its error estimate" grep -q '^Scan error estimate: .* at rotation .* (the exact route at .*; tolerance 0.001)$' "$TMP/scan"
check "within the default tolerance: no warning" test ! -s "$TMP/err"
est=$(sed -n 's/^Scan error estimate: \([^ ]*\) at rotation \([0-9]*\) .*/\1/p' "$TMP/scan")
at=$(sed -n 's/^Scan error estimate: \([^ ]*\) at rotation \([0-9]*\) .*/\2/p' "$TMP/scan")
got=$(sed -n "s/^Rotation: $at Response: //p" "$TMP/scan")
exact=$("$BIN/psens" -q -N -r "$at" -s "$TMP/a.sen" "$P" | sed 's/.*Response: //')
check "the estimate $est is the scan's difference from the exact route at rotation $at ($got against $exact)" \
	awk -v g="$got" -v x="$exact" -v e="$est" 'BEGIN { d = (g - x) / x; if (d < 0) d = -d; exit !(d > 0 && d >= e * 0.99 && d <= e * 1.01) }'
# every checked rotation is within the estimate
for r in $(sed -n 's/.*(the exact route at \([0-9 ]*\);.*/\1/p' "$TMP/scan"); do
	g=$(sed -n "s/^Rotation: $r Response: //p" "$TMP/scan")
	x=$("$BIN/psens" -q -N -r "$r" -s "$TMP/a.sen" "$P" | sed 's/.*Response: //')
	check "checked rotation $r: $g within $est of the exact $x" \
		awk -v g="$g" -v x="$x" -v e="$est" 'BEGIN { d = (g - x) / x; if (d < 0) d = -d; exit !(d <= e * 1.01) }'
done
# a tolerance below the scan's error: a warning naming picture, sensor and
# rotation, not silenced by -q; the numbers are still printed
"$BIN/psens" -q -N -r 0:360:1 --tolerance 1e-7 -s "$TMP/a.sen" "$P" >"$TMP/tight" 2>"$TMP/tighterr"
check "a tight tolerance: exit 0" test $? = 0
check "a tight tolerance: a warning ($(head -c 120 "$TMP/tighterr"))" \
	grep -q "^psens: warning: $P: $TMP/a.sen: the rotation scan is off by .* of the exact route at rotation [0-9]* (tolerance 1e-07)" "$TMP/tighterr"
check "a tight tolerance: 360 rotations still printed" test "$(grep -c '^Rotation: ' "$TMP/tight")" = 360
"$BIN/psens" -q -N -r 0:360:30 -j --tolerance 1e-7 -s "$TMP/a.sen" "$P" >"$TMP/json" 2>/dev/null
check "JSON: the estimate as an object after the rotations" \
	sh -c "tail -n 1 '$TMP/json' | grep -q '\"scan_error_estimate\": [0-9.e+-]*, \"at\": [0-9]*, \"tolerance\": 1e-07, \"checked\": \\[[0-9, ]*\\]}'"
check "JSON: 12 rotations" test "$(grep -c '"route": "rescan"' "$TMP/json")" = 12
"$BIN/psens" -q -N -r 0:360:1 --tolerance 0 -s "$TMP/a.sen" "$P" >"$TMP/none" 2>&1
check "--tolerance 0: no estimate, no warning" sh -c "! grep -q 'estimate\|warning' '$TMP/none'"
check "--tolerance 0: the same numbers" sh -c "grep '^Rotation' '$TMP/scan' | cmp -s - '$TMP/none'"
for bad in abc -1 nan; do
	"$BIN/psens" -q -N -r 0:360:1 --tolerance "$bad" -s "$TMP/a.sen" "$P" >/dev/null 2>"$TMP/bad"
	check "--tolerance $bad is bad usage (exit 2): $(head -n 1 "$TMP/bad")" test $? = 2
done
done_testing
