#!/bin/sh
# SPDX-License-Identifier: ISC
# A sensitivity table that does not cover its field is refused, naming the
# file, the last row's line and angle and the missing rows, by psscene and
# psens alike; the whole shipped cosine table still gives the example
# office's daylight ratio: task lux over sensor response from the fixtures'
# Radiance-computed integrals, 179 x 6.690722 / 5.069840 = 236.23 (0.1 %).
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psscene" ] || skip_all "psscene not built"
within() { awk -v g="$1" -v r="$2" -v t="$3" 'BEGIN { d = (g - r) / r; if (d < 0) d = -d; exit !(d <= t) }'; }
val() { sed -n "/^\[condition $2\]/,/^\[/s/^$3 = //p" "$1" | head -n 1; }
SEN=config/example/ofb/sensors/cosine.sen
PIC=config/example/ofb/img/day_0318_sensor_256.hdr
mkdir -p "$TMP/s/ofb"
cp -R config/example/ofb/img config/example/ofb/sensors config/example/ofb/dc config/example/ofb/weather "$TMP/s/ofb/"
cp config/example/ofb.scene "$TMP/s/"

"$BIN/psscene" -N -o "$TMP/whole.results" "$TMP/s/ofb.scene" > "$TMP/out" 2>&1
r=$(val "$TMP/whole.results" day_0318 ratio)
check "whole table: day_0318 ratio $r within 0.1 % of Radiance's 236.23" \
	within "${r:-0}" "$(awk 'BEGIN { printf "%.6f", 179 * 6.690722 / 5.069840 }')" 1e-3

# the cut of the issue: the statement, the axis rows 0, 2 and 4, nothing more
head -n 5 "$SEN" > "$TMP/s/ofb/sensors/cosine.sen"
"$BIN/psscene" -N -o "$TMP/cut.results" "$TMP/s/ofb.scene" > "$TMP/out" 2> "$TMP/err"
rc=$?
check "cut table: psscene exits 1 (got $rc)" test "$rc" = 1
check "cut table: no results written" test ! -e "$TMP/cut.results"
check "cut table: the file, the last row's line and angle, the stated field: $(cat "$TMP/err")" \
	grep -q "ofb/sensors/cosine.sen:5: the table ends at polar angle 4 but line 1 states a field of 90" "$TMP/err"
check "cut table: the missing rows named" \
	grep -q "the rows for 6 to 90 degrees are missing (43 rows at the table's 2-degree step)" "$TMP/err"
"$BIN/psens" -s "$TMP/s/ofb/sensors/cosine.sen" "$PIC" > "$TMP/out" 2> "$TMP/err"
rc=$?
check "cut table: psens exits 1 (got $rc) and prints no response" sh -c "test $rc = 1 && ! grep -q Response '$TMP/out'"
check "cut table: psens names the file and line" grep -q "cosine.sen:5: the table ends at polar angle 4" "$TMP/err"

# a cut of a table that states no field: refused, saying how to state it
grep -v '^Elevation' "$SEN" | head -n 5 > "$TMP/nofield.sen"
"$BIN/psens" -s "$TMP/nofield.sen" "$PIC" > "$TMP/out" 2> "$TMP/err"
rc=$?
check "no statement, non-zero end at 6: psens exits 1 (got $rc)" test "$rc" = 1
check "no statement: the line, the angle and how to state the field: $(cat "$TMP/err")" \
	grep -q "nofield.sen:5: the table ends at polar angle 6 with a non-zero response (0.994522 at azimuth 0) and states no field.*Elevation field 6" "$TMP/err"

# a table stating 90 that stops at 60 is refused; one ending at 0 at 60 is taken
printf 'Elevation field 90\ndegrees 0 90 180 270\n0 1 1 1 1\n30 0.8 0.8 0.8 0.8\n60 0.5 0.5 0.5 0.5\n' > "$TMP/short.sen"
"$BIN/psens" -s "$TMP/short.sen" "$PIC" > "$TMP/out" 2> "$TMP/err"
check "field 90 stopping at 60: refused, row for 90 named" \
	grep -q "short.sen:5: the table ends at polar angle 60 but line 1 states a field of 90: the row for 90 degrees is missing" "$TMP/err"
printf 'degrees 0 90 180 270\n0 1 1 1 1\n30 0.8 0.8 0.8 0.8\n60 0 0 0 0\n' > "$TMP/zero.sen"
"$BIN/psens" -s "$TMP/zero.sen" "$PIC" > "$TMP/out" 2> "$TMP/err"
check "a zero response at 60, no statement: taken ($(cat "$TMP/err"))" grep -q "Response:" "$TMP/out"
done_testing
