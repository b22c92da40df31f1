#!/bin/sh
# SPDX-License-Identifier: ISC
# psens -r start:end:step (the rotation scan from a picture projected once,
# sim/weights/rescan.h) against psens -r R (the exact route) at several rotations,
# within the stated 2e-4; several sensors in one run give each sensor's own
# numbers, and a matrix gets one row per sensor.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psens" ] || skip_all "psens not built"
I=config/example/ofb/img
P=$I/day_0318_sensor_256.hdr
# a sensor that changes with azimuth, so rotations matter
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
check "scan: 360 rotations" test "$(grep -c '^Rotation: ' "$TMP/scan")" = 360
for r in 0 37 90 181 300; do
	exact=$("$BIN/psens" -q -N -r $r -s "$TMP/a.sen" "$P" | sed 's/.*Response: //')
	got=$(sed -n "s/^Rotation: $r Response: //p" "$TMP/scan")
	check "rotation $r: scan $got within 2e-4 of exact $exact" \
		awk -v g="$got" -v x="$exact" 'BEGIN { d = (g - x) / x; if (d < 0) d = -d; exit !(d <= 2e-4) }'
done
# the scan turns the sensor: a rotation changes the response
check "rotations differ" test "$(sed -n 's/^Rotation: 0 Response: //p' "$TMP/scan")" != \
	"$(sed -n 's/^Rotation: 90 Response: //p' "$TMP/scan")"
# several sensors
both=$("$BIN/psens" -q -N -s builtin:cosine -s "$TMP/a.sen" "$P" $I/elec_sensor_256.hdr)
one=$("$BIN/psens" -q -N -s builtin:cosine "$P" | sed 's/.*Response: //')
two=$("$BIN/psens" -q -N -s "$TMP/a.sen" "$P" | sed 's/.*Response: //')
check "two sensors: four lines" test "$(printf '%s\n' "$both" | grep -c Response)" = 4
check "two sensors: the first's own number" \
	sh -c "printf '%s\n' '$both' | grep -q '^$P: builtin:cosine: .*Response: $one\$'"
check "two sensors: the second's own number" \
	sh -c "printf '%s\n' '$both' | grep -q '^$P: $TMP/a.sen: .*Response: $two\$'"
"$BIN/psens" -q -N -oa -s builtin:cosine -s "$TMP/a.sen" "$P" $I/elec_sensor_256.hdr >"$TMP/m2"
check "matrix of two sensors: NROWS=2" grep -qx 'NROWS=2' "$TMP/m2"
check "matrix of two sensors: NCOLS=2" grep -qx 'NCOLS=2' "$TMP/m2"
"$BIN/psens" -q -N -oa -s "$TMP/a.sen" "$P" $I/elec_sensor_256.hdr | sed '1,/^$/d' >"$TMP/row2"
check "matrix row 2 is the second sensor's matrix" \
	sh -c "sed '1,/^\$/d' '$TMP/m2' | sed '1,/^\$/d' | cmp -s - '$TMP/row2'"
"$BIN/psens" -q -N -r 0:360 -s builtin:cosine "$P" >/dev/null 2>&1
check "-r 0:360 (no step) is bad usage" test $? = 2
"$BIN/psens" -q -N -r 0:360:1 -oa -s builtin:cosine "$P" >/dev/null 2>&1
check "a scan with -oa is bad usage" test $? = 2
done_testing
