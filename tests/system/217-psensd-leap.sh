#!/bin/sh
# SPDX-License-Identifier: ISC
# psensd -Y over a leap year's weather file plays February 29: the example's
# year with a dark February 29 inserted (24 hours of 0 0) runs 366 days,
# 527,040 steps at 60 s, 3660 occupied hours, 290 in February; and the
# 29th's own hours are played: a dark day under the set-point law holds
# target / electric task lux (500 / 1265.4 = 0.3951) for its 10 occupied
# hours, so February's lighting energy is the non-leap run's plus
# 3.951 full-output hours (January and February 1-28 are the same hours in
# both runs; the dark hours add no sky to the ratio table).  The picture is
# 366 days wide.  [simulate] date = 02-29 plays the 29th's hours (dark) and,
# on a year without one, February 28.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psensd" ] || skip_all "psensd not built"
example_results
W=$TMP/example/ofb/weather
awk '{ print } $1 == 2 && $2 == 28 && $3 == "23.500" { for (h = 0; h < 24; h++) printf "2 29 %d.500 0 0\n", h }' \
	"$W/sf-tmy3.wea" > "$W/leap.wea"
check "the leap file has 8784 hours" test "$(awk 'NF == 5 && $1 ~ /^[0-9]+$/' "$W/leap.wea" | wc -l)" = 8784
sed 's|^weather = .*|weather = ofb/weather/leap.wea|' "$TMP/example/ofb.scene" > "$TMP/example/leap.scene"
"$BIN/psscene" -q -N -o "$TMP/state/leap.results" "$TMP/example/leap.scene"
check "psscene runs the leap year" test $? = 0
conf() {   # conf RESULTS SCENE
	sed "s|^results = .*|results = $1|; s|^database = .*|database = $TMP/state/psensd.db|; s|^scene = .*|scene = $2|" \
		config/psensd.conf
}
conf "$TMP/state/ofb.results" "$TMP/example/ofb.scene" > "$TMP/plain.conf"
conf "$TMP/state/leap.results" "$TMP/example/leap.scene" > "$TMP/leap.conf"
"$BIN/psensd" -f "$TMP/plain.conf" -Y > "$TMP/plain.out" 2>&1
check "-Y on the non-leap year" test $? = 0
"$BIN/psensd" -f "$TMP/leap.conf" -Y -P "$TMP/leap.png" > "$TMP/leap.out" 2>&1
check "-Y on the leap year" test $? = 0
check "366 x 1440 = 527040 control steps" grep -q "^  527040 control steps" "$TMP/leap.out"
check "3660 occupied hours" grep -q "occupied 08:00-18:00 every day, 3660 h" "$TMP/leap.out"
check "it says the year has February 29" grep -q "366 days: the weather file's year has February 29" "$TMP/leap.out"
check "the non-leap year stays 525600 steps" grep -q "^  525600 control steps" "$TMP/plain.out"
feb() { awk '$1 == "Feb" { print $2, $3; exit }' "$1"; }
check "February: 290 occupied hours" test "$(feb "$TMP/leap.out" | cut -d' ' -f1)" = 290
check "February: 280 without the 29th" test "$(feb "$TMP/plain.out" | cut -d' ' -f1)" = 280
p=$(feb "$TMP/plain.out" | cut -d' ' -f2); l=$(feb "$TMP/leap.out" | cut -d' ' -f2)
# the dark 29th's ten occupied hours at target / electric task lux (the
# scene's own figure, read from its results: it moves in the last digits
# with the weights' quadrature)
E=$(sed -n 's/^electric_task_lux = //p' "$TMP/state/leap.results" | head -n 1)
dark=$(awk -v e="$E" 'BEGIN { printf "%.3f", 10 * 500 / e }')
# both percentages are printed to 0.05 %: 0.0005 x (280 + 290) h of rounding
check "February's energy $l % x 290 h = $p % x 280 h + $dark h (the dark 29th)" \
	awk -v p="$p" -v l="$l" -v d="$dark" 'BEGIN { x = l / 100 * 290 - (p / 100 * 280 + d); if (x < 0) x = -x; exit !(x <= 0.285) }'
check "the electric task lux $E is the scene's 1265.415 lx" awk -v e="$E" 'BEGIN { exit !(e > 1265.41 && e < 1265.42) }'
# the picture: 50 + 2 x 366 + 230 pixels wide (IHDR width, big-endian at byte 16)
w=$(od -An -tu1 -j16 -N4 "$TMP/leap.png" | awk '{ print $1 * 16777216 + $2 * 65536 + $3 * 256 + $4 }')
check "the picture is 366 days wide ($w px)" test "$w" = 1012
# a simulated 29 February: the leap year's (dark: the lights at 500 / 1265.4 all day)
sed 's/^\[simulate\]/[simulate]\nyear = yes/; s/^date = .*/date = 02-29/; s/^faults = .*//' "$TMP/leap.conf" > "$TMP/d29.conf"
rm -f "$TMP/state/psensd.db"*
"$BIN/psensd" -f "$TMP/d29.conf" -s > "$TMP/d29.out" 2>&1
check "date = 02-29 runs on the leap year" test $? = 0
check "its 14 hours at 500 / 1265.4 of full output: 5.53 full-output hours" grep -q "(5.53 of 14.00 full-output hours)" "$TMP/d29.out"
sed 's/^\[simulate\]/[simulate]\nyear = yes/; s/^date = .*/date = 02-29/; s/^faults = .*//' "$TMP/plain.conf" > "$TMP/p29.conf"
sed 's/^\[simulate\]/[simulate]\nyear = yes/; s/^date = .*/date = 02-28/; s/^faults = .*//' "$TMP/plain.conf" > "$TMP/p28.conf"
rm -f "$TMP/state/psensd.db"*
"$BIN/psensd" -f "$TMP/p29.conf" -s > "$TMP/p29.out" 2>&1
check "date = 02-29 runs on a year without one" test $? = 0
rm -f "$TMP/state/psensd.db"*
"$BIN/psensd" -f "$TMP/p28.conf" -s > "$TMP/p28.out" 2>&1
e29=$(sed -n 's/.*energy: \(.*\)/\1/p' "$TMP/p29.out"); e28=$(sed -n 's/.*energy: \(.*\)/\1/p' "$TMP/p28.out")
check "and plays February 28 ($e29)" test -n "$e29" -a "$e29" = "$e28"
done_testing
