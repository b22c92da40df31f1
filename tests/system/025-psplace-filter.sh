#!/bin/sh
# SPDX-License-Identifier: ISC
# psplace's sensors with colour filters (-s SENSOR@FILTER, -s SENSOR@R,G,B),
# on one pose of the placement fixture (tests/data/ofb-place, p01):
#   - the electric response of a cosine sensor behind a blue filter is
#     psens -f's on the same picture with the same filter (an independent
#     route: psens integrates the picture exactly, psplace reads it from its
#     projection; measured 0.02 %, allowed 0.2 %), and the plain sensor's
#     likewise, so the filter is applied and applied alone;
#   - the results carry the filter's coefficients as psfilter gives them;
#   - weights twice V(lambda)'s make every hour's daylight signal twice the
#     plain sensor's (the signal is linear in the weights);
#   - a filter with a bad line is refused naming the file and the line.
. "$(dirname "$0")/lib.sh"
[ -x "$BIN/psplace" ] || skip_all "psplace not built"
[ -x "$BIN/psens" ] || skip_all "psens not built"
[ -x "$BIN/psfilter" ] || skip_all "psfilter not built"
D=$TOP/tests/data/ofb-place
W=$TOP/config/example/ofb/weather/sf-tmy3.wea
tar -xzf "$D/p01.tar.gz" -C "$TMP"
grep "^p01 " "$D/candidates.txt" > "$TMP/c.txt"
sed "s|^database = .*|database = $TMP/psensd.db|; s|^scene = .*|scene = $TOP/config/example/ofb.scene|" \
	"$TOP/config/psensd.conf" > "$TMP/psensd.conf"
# a blue filter: a Gaussian response peaking at 470 nm
awk 'BEGIN { for (l = 380; l <= 780; l += 10) printf "%d %.6f\n", l, exp(-((l - 470) / 60) ^ 2) }' > "$TMP/blue.txt"
place() {
	"$BIN/psplace" -f "$TMP/psensd.conf" -c "$TMP/c.txt" -d "$TMP" -g "$D/grid_mf1.mtx" -e "$D/grid_elec.dat" \
		-w "$W" -r 360 -a setpoint -T 0 "$@"
}
elec_of() { sed -n 's/^electric_sensor_response = //p' "$1"; }

place -s "builtin:cosine@$TMP/blue.txt" -x "$TMP/blue.results" -o "$TMP/blue.json" > "$TMP/out" 2> "$TMP/err"
check "psplace runs with a filtered sensor" test $? = 0
check "the table names the sensor with its filter" grep -q "builtin:cosine@" "$TMP/out"
place -s builtin:cosine -x "$TMP/plain.results" > /dev/null 2> "$TMP/err"
check "psplace runs with the plain sensor" test $? = 0
pb=$(elec_of "$TMP/blue.results"); pp=$(elec_of "$TMP/plain.results")
sb=$("$BIN/psens" -N -s builtin:cosine -f "$TMP/blue.txt" "$TMP/p01/elec_128.hdr" | sed -n 's/.*Response: //p')
sp=$("$BIN/psens" -N -s builtin:cosine "$TMP/p01/elec_128.hdr" | sed -n 's/.*Response: //p')
check "filtered: psplace $pb, psens -f $sb (within 0.2 %)" awk -v a="$pb" -v b="$sb" \
	'BEGIN { d = a / b - 1; if (d < 0) d = -d; exit !(b > 0 && d < 2e-3) }'
check "plain: psplace $pp, psens $sp (within 0.2 %)" awk -v a="$pp" -v b="$sp" \
	'BEGIN { d = a / b - 1; if (d < 0) d = -d; exit !(b > 0 && d < 2e-3) }'
check "the filter changes the response ($pb against $pp)" awk -v a="$pb" -v b="$pp" \
	'BEGIN { d = a / b - 1; if (d < 0) d = -d; exit !(d > 0.05) }'
want=$("$BIN/psfilter" "$TMP/blue.txt" | head -n 1 | awk '{ print $2, $4, $6 }')
got=$(sed -n 's/^rgb = //p' "$TMP/blue.results" | awk '{ printf "%.6f %.6f %.6f\n", $1, $2, $3 }')
check "the results' weights are psfilter's ($got; $want)" test "$got" = "$want"
got=$(python3 -c "import json; d = json.load(open('$TMP/blue.json'))['sensors'][0]
print('%.6f %.6f %.6f' % tuple(d['rgb']))")
check "and the JSON's ($got)" test "$got" = "$want"

# twice V(lambda)'s weights: twice every hour's signal
place -s "builtin:cosine@0.530148252,1.340229262,0.129622486" -x "$TMP/twice.results" > /dev/null 2> "$TMP/err"
check "psplace runs with R,G,B weights" test $? = 0
hours() { sed -n '/^\[year_hours\]/,/^$/s/^h[0-9]* = [0-9]* [0-9]* [0-9.]* \([^ ]*\) .*/\1/p' "$1"; }
hours "$TMP/plain.results" > "$TMP/h1"
hours "$TMP/twice.results" > "$TMP/h2"
check "every hour's signal twice the plain sensor's ($(wc -l < "$TMP/h1") hours)" sh -c "
	test \$(wc -l < '$TMP/h1') -gt 4000 && paste '$TMP/h1' '$TMP/h2' |
	awk '{ d = \$2 - 2 * \$1; if (d < 0) d = -d; if (d > 1e-12 * (1 + \$2)) bad = 1 } END { exit bad }'"

# refusals
printf '400 0.1\n450 0.5\nabc 0.9\n' > "$TMP/bad.txt"
place -s "builtin:cosine@$TMP/bad.txt" > /dev/null 2> "$TMP/err"
check "a bad filter refused" test $? -ne 0
check "naming the file and the line ($(cat "$TMP/err"))" grep -q "bad.txt:3: 'abc' is not a wavelength" "$TMP/err"
place -s "builtin:cosine@$TMP/none.txt" > /dev/null 2> "$TMP/err"
check "a missing filter refused, naming it" grep -q "none.txt" "$TMP/err"
place -s "builtin:cosine@-1,1,0" > /dev/null 2> "$TMP/err"
check "negative weights refused" grep -q "colour weights" "$TMP/err"
done_testing
