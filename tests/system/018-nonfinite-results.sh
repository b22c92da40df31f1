#!/bin/sh
# SPDX-License-Identifier: ISC
# A result that is not finite (NaN or infinite) is an error naming its
# cause, never output: every program that prints or writes a result
# (psens, psshare, psfilter, pssky, psscene, psensd -n, psensd -Y) exits
# non-zero on inputs that overflow or divide by nothing, says why, and
# prints no "nan" or "inf" as a figure.  Before, psens printed "Total
# sensitivity: inf Response: -nan", psscene wrote "ratio = nan", psensd -n
# took such a results file and psensd -Y printed "-nan % of full".
. "$(dirname "$0")/lib.sh"
for p in psens psshare psfilter pssky psscene psensd; do
	[ -x "$BIN/$p" ] || skip_all "$p not built"
done
P=config/example/ofb/img/day_0318_sensor_256.hdr
# no_figure FILE: no nan or inf where a number would be
no_figure() { ! grep -Eqi '(^|[^a-z])-?(nan|inf)([^a-z]|$)' "$1"; }
# refused NAME WHY COMMAND...: exit non-zero, WHY on stderr, no figure on stdout
refused() {
	_n=$1; _why=$2; shift 2
	"$@" > "$TMP/out" 2> "$TMP/err"
	_rc=$?
	check "$_n: exit $_rc (not 0)" test "$_rc" != 0
	check "$_n: says why ($(head -n 1 "$TMP/err" | cut -c1-100))" grep -q "$_why" "$TMP/err"
	check "$_n: no nan or inf printed" no_figure "$TMP/out"
}

printf 'Elevation field 90\ndegrees 0 90 180 270\n0 1e308 1e308 1e308 1e308\n90 1e308 1e308 1e308 1e308\n' > "$TMP/big.sen"
refused "psens, a table holding 1e308" "add up past the largest number" "$BIN/psens" -N -s "$TMP/big.sen" "$P"
refused "psens -R -G -B 1e308" "colour coefficients (1e+308 1e+308 1e+308)" \
	"$BIN/psens" -N -s builtin:cosine -R 1e308 -G 1e308 -B 1e308 "$P"
refused "psens -j -R -G -B 1e308" "colour coefficients" \
	"$BIN/psens" -N -j -s builtin:cosine -R 1e308 -G 1e308 -B 1e308 "$P"
refused "psens two sensors -R -G -B 1e308" "colour coefficients" \
	"$BIN/psens" -N -s builtin:cosine -s builtin:uniform -R 1e308 -G 1e308 -B 1e308 "$P"
refused "psens rotation scan -R -G -B 1e308" "rotation 0: the response is" \
	"$BIN/psens" -N -s builtin:cosine -r 0:90:30 -R 1e308 -G 1e308 -B 1e308 "$P"
refused "psshare -R -G -B 1e308" "the response is" \
	"$BIN/psshare" -s builtin:cosine -R 1e308 -G 1e308 -B 1e308 "$P"
printf '380 1e308\n500 1e308\n780 1e308\n' > "$TMP/big.flt"
refused "psfilter, transmittances of 1e308" "not finite" "$BIN/psfilter" "$TMP/big.flt"
awk 'NR <= 6 { print; next } NR == 19 { print $1, $2, $3, "1e308", "1e308"; next } NR <= 37 { print }' \
	config/example/ofb/weather/sf-tmy3.wea > "$TMP/big.wea"
refused "pssky, irradiances of 1e308" "big.wea:19: the sky of 1-1 12.50 h is not finite" \
	"$BIN/pssky" -m 1 "$TMP/big.wea"

# psscene: the sensor table, and a condition whose sensor sees nothing
example_results
sed 's|^sensitivity = .*|sensitivity = big.sen|' "$TMP/example/ofb.scene" > "$TMP/example/big.scene"
cp "$TMP/big.sen" "$TMP/example/"
refused "psscene, a table holding 1e308" "add up past the largest number" \
	"$BIN/psscene" -q -N -o "$TMP/state/big.results" "$TMP/example/big.scene"
check "psscene: no results written" test ! -e "$TMP/state/big.results"
{
	printf '#?RADIANCE\nFORMAT=32-bit_rle_rgbe\nVIEW= -vta -vh 180 -vv 180\n\n-Y 256 +X 256\n'
	head -c $((256 * 256 * 4)) /dev/zero
} > "$TMP/example/black.hdr"
sed '/^\[condition day_0318\]/,/^$/s|^sensor_picture = .*|sensor_picture = black.hdr|' \
	"$TMP/example/ofb.scene" > "$TMP/example/dark.scene"
refused "psscene, a sensor picture that is black" "condition day_0318: the sensor's response is 0" \
	"$BIN/psscene" -q -N -o "$TMP/state/dark.results" "$TMP/example/dark.scene"
check "psscene: no ratio = nan written" test ! -e "$TMP/state/dark.results"

# psensd -n: a results file with a computed ratio of nan, named by line
line=$(grep -n '^ratio = ' "$TMP/state/ofb.results" | head -n 1 | cut -d: -f1)
sed "${line}s/^ratio = .*/ratio = nan/" "$TMP/state/ofb.results" > "$TMP/state/nan.results"
sed "s|^results = .*|results = state/nan.results|; s|^database = .*|database = state/n.db|" \
	config/psensd.conf > "$TMP/nan.conf"
"$BIN/psensd" -f "$TMP/nan.conf" -n > "$TMP/out" 2> "$TMP/err"
check "psensd -n refuses a computed ratio of nan" test $? != 0
check "psensd -n names the file and line ($(cut -c1-120 "$TMP/err"))" \
	grep -q "nan.results:$line: ratio: a computed condition's ratio must be a finite number" "$TMP/err"

# psensd -Y: a period that steps outside the occupied hours every day
sed "s|^results = .*|results = state/ofb.results|; s|^database = .*|database = state/y.db|; s|^period = .*|period = 86400|" \
	config/psensd.conf > "$TMP/y.conf"
"$BIN/psensd" -f "$TMP/y.conf" -Y > "$TMP/out" 2> "$TMP/err"
check "psensd -Y, period 86400: exit non-zero" test $? != 0
check "psensd -Y names the cause ($(tail -n 1 "$TMP/err" | cut -c1-110))" \
	grep -q "no control step of the year falls in the occupied hours 08:00-18:00" "$TMP/err"
check "psensd -Y: no nan printed" no_figure "$TMP/out"
done_testing
